//! The `umls` command line, as a library: scene files, runs and reports.
//!
//! - `umls run SCENE` runs a built-in scene or a TOML scene file ([`schema`]) with any
//!   kernel and writes ParaView files (`particles.pvd` with `.vtu` frames, `mesh.vtu`),
//!   `history.csv`, `energies.svg` and `summary.json` ([`run`]).
//! - `umls scenes` lists the built-in scenes ([`builtin`]).
//! - `umls mesh-info FILE.msh` describes a Gmsh mesh ([`mesh_info`]).
//!
//! Dependencies beyond the workspace's: `clap` (argument parsing and `--help`),
//! `indicatif` (progress bar), `toml` + `serde` (scene files, with unknown keys
//! rejected), `serde_json` (the run summary), `exmex` (velocity expressions such as
//! `"0.1 * sin(PI * x / 50)"`) and `ctrlc` (Ctrl-C ends a run with its output written,
//! portably across platforms): each a maintained crate that does its job better than a
//! hand-written one would.
//!
//! ```
//! use umls_cli::run::{run, RunOptions};
//! use umls_cli::scene::Scene;
//!
//! let scene = Scene::load("vibrating-bar")?;
//! let out = std::env::temp_dir().join("umls-doc-bar");
//! let options = RunOptions { kernel: None, out: out.clone(), end_time: Some(0.5), threads: Some(1), progress: false, interrupt: None };
//! let report = run(&scene, &options)?;
//! assert_eq!(report.summary["status"], "completed");
//! assert!(report.summary["metrics"]["velocity_rmse"].as_f64().unwrap() < 1e-3);
//! assert!(out.join("particles.pvd").is_file());
//! # Ok::<(), umls_cli::CliError>(())
//! ```

pub mod background;
pub mod builtin;
mod conditions;
pub mod edit;
mod end_metrics;
mod error;
pub mod expression;
pub mod frame;
pub mod hydrostatic;
pub mod jitter;
mod memory;
pub mod mesh_info;
mod output;
pub mod plot;
pub mod pressure;
pub mod probes;
mod progress;
mod reference;
pub mod run;
pub mod scene;
pub mod schema;
pub mod setup;

pub use error::{CliError, Result};
