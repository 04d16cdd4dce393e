//! CSV time histories: a header row, then one row of numbers per record, written as the
//! run goes so that a stopped run still leaves its history.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{IoError, Result};

/// A CSV file of numeric columns.
#[derive(Debug)]
pub struct HistoryWriter {
    path: PathBuf,
    out: BufWriter<File>,
    columns: usize,
    line: String,
}

impl HistoryWriter {
    /// Creates (or truncates) `path` and writes the header. Column names must not contain
    /// commas, quotes or newlines.
    pub fn create(path: impl AsRef<Path>, header: &[&str]) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        if let Some(bad) = header
            .iter()
            .find(|h| h.is_empty() || h.contains([',', '"', '\n', '\r']))
        {
            return Err(IoError::FieldLength {
                field: format!("CSV column name `{bad}` (empty or with a comma, quote or newline)"),
                found: 0,
                expected: 1,
            });
        }
        let file = File::create(&path).map_err(|source| IoError::File {
            path: path.clone(),
            source,
        })?;
        let mut writer = Self {
            path,
            out: BufWriter::new(file),
            columns: header.len(),
            line: String::new(),
        };
        writer.write_line(&header.join(","))?;
        Ok(writer)
    }

    fn write_line(&mut self, line: &str) -> Result<()> {
        writeln!(self.out, "{line}").map_err(|source| IoError::File {
            path: self.path.clone(),
            source,
        })
    }

    /// Appends a row; it must have one value per column. Values are written in the
    /// shortest form that reads back to the same f64.
    pub fn row(&mut self, values: &[f64]) -> Result<()> {
        if values.len() != self.columns {
            return Err(IoError::FieldLength {
                field: format!("row of {}", self.path.display()),
                found: values.len(),
                expected: self.columns,
            });
        }
        use std::fmt::Write as _;
        let mut line = std::mem::take(&mut self.line);
        line.clear();
        for (i, v) in values.iter().enumerate() {
            if i > 0 {
                line.push(',');
            }
            let _ = write!(line, "{v}");
        }
        let result = self.write_line(&line);
        self.line = line;
        result
    }

    /// Flushes buffered rows to the file.
    pub fn flush(&mut self) -> Result<()> {
        self.out.flush().map_err(|source| IoError::File {
            path: self.path.clone(),
            source,
        })
    }
}
