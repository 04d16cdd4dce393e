//! The report's error type: every message names the file, the study or the run.

use std::path::PathBuf;

use thiserror::Error;

/// Why a report could not be made. A run that fails is not an error of the report: it
/// is a result, recorded with its cause.
#[derive(Debug, Error)]
pub enum ReportError {
    /// The study matrix is not valid TOML or does not match the schema.
    #[error("{file}: {message}")]
    Matrix {
        /// The matrix file (or built-in matrix name).
        file: String,
        /// What is wrong, naming the key.
        message: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    File {
        /// The file.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// The `umls` executable could not be started.
    #[error("cannot start {exe}: {source}")]
    Spawn {
        /// The executable.
        exe: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// A run's `summary.json` or `history.csv` is unreadable.
    #[error("{path}: {message}")]
    RunOutput {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Drawing a chart failed.
    #[error(transparent)]
    Chart(#[from] umls_io::IoError),
}

/// The report's result type.
pub type Result<T> = std::result::Result<T, ReportError>;

/// A `ReportError::File` for `path`.
pub(crate) fn file_error(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> ReportError {
    let path = path.into();
    move |source| ReportError::File { path, source }
}
