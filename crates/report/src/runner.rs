//! Running one case: `umls run` in a process of its own, so that each run's wall time
//! and peak memory are its own and a run that fails (or crashes) is a result, not the
//! end of the report.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::case::Case;
use crate::error::{ReportError, Result};

/// What one run left behind.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// `summary.json`, if the run got far enough to write it.
    pub summary: Option<serde_json::Value>,
    /// The last lines of the run's standard error (the reason when there is no summary).
    pub stderr_tail: String,
    /// Wall time of the whole process: setup, stepping and output.
    pub process_seconds: f64,
    /// The run's output directory.
    pub dir: PathBuf,
}

/// Runs cases with one `umls` executable, each in a directory under `work`.
#[derive(Debug, Clone)]
pub struct Runner {
    /// The `umls` executable.
    pub exe: PathBuf,
    /// Directory the runs write into (`<work>/<case slug>`).
    pub work: PathBuf,
}

impl Runner {
    /// Runs `case` and collects its output.
    pub fn run(&self, case: &Case) -> Result<RunOutput> {
        let dir = self.work.join(case.slug());
        // A summary left by an earlier run in the same place must not pass for this one.
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(crate::error::file_error(&dir))?;
        }
        let start = Instant::now();
        let output = Command::new(&self.exe)
            .arg("run")
            .arg(&case.scene)
            .arg("--out")
            .arg(&dir)
            .args(case.arguments())
            .output()
            .map_err(|source| ReportError::Spawn {
                exe: self.exe.clone(),
                source,
            })?;
        let process_seconds = start.elapsed().as_secs_f64();
        let stderr = String::from_utf8_lossy(&output.stderr);
        let stderr_tail = stderr
            .lines()
            .rev()
            .take(3)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect::<Vec<_>>()
            .join("\n");
        let summary_path = dir.join("summary.json");
        let summary = if summary_path.is_file() {
            let text = std::fs::read_to_string(&summary_path)
                .map_err(crate::error::file_error(&summary_path))?;
            Some(
                serde_json::from_str(&text).map_err(|e| ReportError::RunOutput {
                    path: summary_path.clone(),
                    message: e.to_string(),
                })?,
            )
        } else {
            None
        };
        Ok(RunOutput {
            summary,
            stderr_tail,
            process_seconds,
            dir,
        })
    }
}

/// Column `column` of a run's `history.csv` against its `time` column.
pub fn history_column(dir: &Path, column: &str) -> Result<Vec<(f64, f64)>> {
    let path = dir.join("history.csv");
    let bad = |message: String| ReportError::RunOutput {
        path: path.clone(),
        message,
    };
    let mut reader = csv::Reader::from_path(&path).map_err(|e| bad(e.to_string()))?;
    let header = reader.headers().map_err(|e| bad(e.to_string()))?.clone();
    let find = |name: &str| {
        header.iter().position(|h| h == name).ok_or_else(|| {
            bad(format!(
                "no column `{name}` (columns: {})",
                header.iter().collect::<Vec<_>>().join(", ")
            ))
        })
    };
    let (t, c) = (find("time")?, find(column)?);
    let mut points = Vec::new();
    for (line, row) in reader.records().enumerate() {
        let row = row.map_err(|e| bad(e.to_string()))?;
        let value = |i: usize| {
            row.get(i)
                .and_then(|v| v.parse::<f64>().ok())
                .ok_or_else(|| bad(format!("line {}: column {i} is not a number", line + 2)))
        };
        points.push((value(t)?, value(c)?));
    }
    Ok(points)
}
