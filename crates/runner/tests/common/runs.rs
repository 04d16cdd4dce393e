//! Helpers shared by the test files that run scenes through the library: run options,
//! summary metrics, edited built-in scenes and `history.csv` columns.
#![allow(dead_code)] // each test file uses its own subset

use std::path::Path;

use umls_runner::run::RunOptions;
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;

/// Two threads, no progress bar, output under the test target's scratch directory.
pub fn options(name: &str, kernel: Option<KernelKind>, end_time: Option<f64>) -> RunOptions {
    RunOptions {
        kernel,
        out: Some(std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)),
        end_time,
        threads: Some(2),
        ..RunOptions::default()
    }
}

/// A metric of `summary.json`, which must be there.
pub fn metric(summary: &serde_json::Value, name: &str) -> f64 {
    summary["metrics"][name]
        .as_f64()
        .unwrap_or_else(|| panic!("no metric `{name}` in {summary}"))
}

/// The metric `key` of `scene` run with `kernel` (output under `name`); the run must
/// complete.
pub fn completed_metric(scene: &Scene, name: &str, kernel: KernelKind, key: &str) -> f64 {
    metric(&completed_run(scene, name, kernel, None).0, key)
}

/// The summary and history of `scene` run with `kernel` to `end_time` (the scene's own
/// when `None`), output under `name`; the run must complete.
pub fn completed_run(
    scene: &Scene,
    name: &str,
    kernel: KernelKind,
    end_time: Option<f64>,
) -> (serde_json::Value, History) {
    let report = umls_runner::run::run(scene, &options(name, Some(kernel), end_time)).unwrap();
    let summary = report.summary.to_json();
    assert_eq!(summary["status"], "completed", "{name}: {summary}");
    let history = History::read(report.out.as_deref().unwrap());
    (summary, history)
}

/// The built-in scene with each `find` replaced by its `replace` (which must occur).
pub fn variant(name: &str, edits: &[(&str, &str)]) -> Scene {
    Scene::parse(&variant_text(name, edits), "variant.toml", None).unwrap()
}

/// The text of [`variant`], for edits the parser is meant to refuse.
pub fn variant_text(name: &str, edits: &[(&str, &str)]) -> String {
    let mut text = umls_runner::builtin::BUILTIN
        .iter()
        .find(|b| b.name == name)
        .unwrap()
        .toml
        .to_string();
    for (find, replace) in edits {
        assert!(text.contains(find), "{find}");
        text = text.replacen(find, replace, 1);
    }
    text
}

/// The header and rows of a run's `history.csv`.
pub struct History {
    /// Column names.
    pub header: Vec<String>,
    /// Rows of numbers.
    pub rows: Vec<Vec<f64>>,
}

impl History {
    /// Reads `out/history.csv`.
    pub fn read(out: &Path) -> Self {
        let text = std::fs::read_to_string(out.join("history.csv")).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        Self { header, rows }
    }

    /// The index of column `name`, which must be there.
    pub fn column(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column `{name}` in {:?}", self.header))
    }

    /// Column `name` of the last row.
    pub fn last(&self, name: &str) -> f64 {
        self.rows.last().unwrap()[self.column(name)]
    }
}
