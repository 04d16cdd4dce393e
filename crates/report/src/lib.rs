//! The comparison report of umls: a study matrix of scenes × kernels × transfers ×
//! resolutions, run through the `umls` binary (`umls report`, `cargo xtask bench`), and
//! written as `report.md` with SVG charts — error against run time, convergence with
//! fitted orders, stability maps, histories, throughput by stage — and the raw results
//! as CSV and JSON.
//!
//! - [`matrix`]: the study matrix (TOML; `quick` and `full` built in);
//! - [`case`]: the runs a matrix expands into;
//! - [`runner`]: one run in a process of its own;
//! - [`record`]: one row of results per run;
//! - [`analysis`]: convergence orders and the Pareto front;
//! - [`charts`]: the charts of each study, in panels of at most eight curves;
//! - [`styles`]: one colour, marker and dash per kernel, the same in every chart;
//! - [`criterion`]: criterion's results, with throughput and the change against a
//!   baseline;
//! - [`summary`]: the generated summary that opens the report;
//! - [`report`]: the whole report;
//! - [`host`] and [`cpu`]: the machine and revision it was made on (the processor's
//!   family, model and vector extensions besides its name; `xtask` shares `cpu.rs` for
//!   its speed reports).
//!
//! Dependencies beyond the workspace's: `toml` and `serde` (the matrix file), `serde_json`
//! (runs' summaries, `results.json`) and `csv` (histories, `results.csv`).
//!
//! ```
//! use umls_report::case::cases;
//! use umls_report::matrix::Matrix;
//!
//! let matrix = Matrix::parse(r#"
//!     title = "two kernels on the bar"
//!     [[accuracy]]
//!     name = "bar"
//!     title = "Vibrating bar"
//!     scene = "vibrating-bar"
//!     metric = "velocity_rmse"
//!     metric_label = "velocity RMSE [m/s]"
//!     kernels = ["umls", "bspline2"]
//!     transfers = ["apic", "flip:0.99"]
//!     refine = [1, 2]
//!     h = 0.02
//! "#, "example")?;
//! let runs = cases(&matrix);
//! assert_eq!(runs.len(), 2 * 2 * 2);
//! assert!(runs[1].arguments().join(" ").contains("--refine 2"));
//! # Ok::<(), umls_report::ReportError>(())
//! ```

#![forbid(unsafe_code)]

pub mod analysis;
pub mod case;
pub mod charts;
pub mod cpu;
pub mod criterion;
mod error;
pub mod host;
pub mod matrix;
pub mod record;
pub mod report;
pub mod runner;
pub mod styles;
pub mod summary;

pub use error::{ReportError, Result};
