//! Scenes as a library: the TOML scene format and the built-in scenes, the set-up of a
//! scene (mesh, bodies, materials, boundaries, references), and a runner that advances
//! a simulation to its end time with observers (history, probes, frames, wall
//! pressure) and returns a typed summary. The `umls` command line, the comparison
//! report and a researcher's own program all run scenes through it.
//!
//! - [`Scene`] loads a built-in scene or a scene file ([`schema`]), with `--set`-style
//!   edits and refinement ([`edit`]).
//! - [`run()`] runs it with the scene's kernel or a built-in preset
//!   ([`schema::KernelKind`]); [`run_with`] runs it with any kernel type through the
//!   [`KernelFactory`] port, with the same outputs and metrics.
//! - [`RunOptions::out`] chooses whether files are written (ParaView frames
//!   `particles.pvd`, `mesh.vtu` or `grid.vtu`, `history.csv`, `energies.svg`,
//!   `summary.json`); the [`RunReport`] carries the [`RunSummary`] and the history
//!   either way.
//!
//! Dependencies beyond the workspace's: `toml` + `serde` (scene files, with unknown keys
//! rejected), `serde_json` (the run summary) and `exmex` (velocity expressions such as
//! `"0.1 * sin(PI * x / 50)"`): each a maintained crate that does its job better than a
//! hand-written one would.
//!
//! ```
//! use umls_runner::{RunOptions, Scene, run};
//!
//! let scene = Scene::load("vibrating-bar")?;
//! let options = RunOptions { end_time: Some(0.5), threads: Some(1), ..RunOptions::default() };
//! let report = run(&scene, &options)?;
//! assert_eq!(report.summary.status, umls_runner::RunStatus::Completed);
//! assert!(report.summary.metric("velocity_rmse").unwrap() < 1e-3);
//! assert_eq!(report.history.rows.len(), report.summary.steps + 1);
//! # Ok::<(), umls_runner::RunError>(())
//! ```

pub mod background;
pub mod builtin;
mod conditions;
mod context;
mod drive;
pub mod edit;
mod end_metrics;
mod error;
pub mod expression;
pub mod frame;
mod group_wall;
mod handle;
pub mod hydrostatic;
pub mod jitter;
pub mod kernel_choice;
mod material_transfer;
mod memory;
mod output;
pub mod plot;
pub mod pressure;
pub mod probes;
mod recorder;
mod reference;
pub mod run;
mod sampled_wall;
pub mod scene;
pub mod schema;
mod seeds;
pub mod setup;
mod summarise;
pub mod summary;
mod time_plan;

pub use error::{Result, RunError};
pub use kernel_choice::KernelFactory;
pub use run::{
    Dim, History, Prepared, Progress, RunOptions, RunPlan, RunReport, SceneDimension, WithFactory,
    prepare, prepare_with, run, run_with,
};
pub use scene::Scene;
pub use setup::Setup;
pub use summary::{RunStatus, RunSummary};
