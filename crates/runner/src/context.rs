//! What a run is given and what it gives back: the options, the progress port, the plan,
//! the report with its history, and the context the typed part of a run reads.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use umls_io::vtk::Encoding;

use crate::scene::Scene;
use crate::schema::KernelKind;
use crate::setup::Setup;
use crate::summary::RunSummary;

/// What a caller hears of a run while it goes: its planned steps, each step, the end.
/// The command line draws a progress bar with it; the default methods do nothing.
pub trait Progress: Send + Sync {
    /// The run starts as `plan` says.
    fn start(&self, plan: &RunPlan) {
        let _ = plan;
    }
    /// One step is done.
    fn step(&self) {}
    /// The run loop ended (completed, failed or interrupted).
    fn finish(&self) {}
}

/// What a run is about to do, told to [`Progress::start`] before the first step.
#[derive(Debug, Clone, PartialEq)]
pub struct RunPlan {
    /// The scene's name.
    pub scene: String,
    /// Particles.
    pub particles: usize,
    /// Steps planned.
    pub steps: usize,
    /// Particle frames to write (none are written without an output folder).
    pub frames: usize,
    /// The files the run is about to write, estimated from the frames' sizes (zero
    /// without an output folder).
    pub output_bytes: u64,
    /// What the user should hear about the set-up and the time step (the summary
    /// repeats them).
    pub warnings: Vec<String>,
}

impl RunPlan {
    /// Particles × steps: the work of the run.
    pub fn particle_steps(&self) -> f64 {
        self.particles as f64 * self.steps as f64
    }
}

/// Overrides and output settings of a run; the default runs the scene as written, on
/// every core, and writes no files.
#[derive(Clone, Default)]
pub struct RunOptions {
    /// Kernel instead of the scene's.
    pub kernel: Option<KernelKind>,
    /// Where the files go (`particles.pvd` and its frames, `mesh.vtu` or `grid.vtu`,
    /// `history.csv`, `energies.svg`, `summary.json`); `None` writes nothing, and the
    /// history and summary are in the [`RunReport`] alone.
    pub out: Option<PathBuf>,
    /// End time instead of the scene's.
    pub end_time: Option<f64>,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Told of the run's progress.
    pub progress: Option<Arc<dyn Progress>>,
    /// Set (by a signal handler) to stop the run after the current step; the output up
    /// to then is written and the summary says "interrupted".
    pub interrupt: Option<Arc<AtomicBool>>,
}

impl std::fmt::Debug for RunOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunOptions")
            .field("kernel", &self.kernel)
            .field("out", &self.out)
            .field("end_time", &self.end_time)
            .field("threads", &self.threads)
            .field("progress", &self.progress.is_some())
            .field("interrupt", &self.interrupt)
            .finish()
    }
}

/// What a finished run reports.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// The summary, as `summary.json` has it.
    pub summary: RunSummary,
    /// The history, as `history.csv` has it: column names and one row per recorded step.
    pub history: History,
    /// Where the files are (`None` when none were written).
    pub out: Option<PathBuf>,
}

/// The recorded history of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    /// Column names.
    pub columns: Vec<String>,
    /// One row per recorded step, in the order of `columns`.
    pub rows: Vec<Vec<f64>>,
}

impl History {
    /// The values of column `name` over the rows, if the history has that column.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }
}

/// Everything the typed part of a run reads.
pub(crate) struct Context<'a, const D: usize> {
    pub(crate) scene: &'a Scene,
    pub(crate) setup: Setup<D>,
    pub(crate) options: &'a RunOptions,
    /// The kernel's name, for the summary and messages.
    pub(crate) kernel_name: String,
    /// Whether the kernel's nodes are the mesh's vertices.
    pub(crate) mesh_kernel: bool,
    pub(crate) end_time: f64,
    pub(crate) encoding: Encoding,
}
