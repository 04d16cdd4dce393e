//! The typed summary of a run, written as `summary.json` and returned in the
//! [`crate::RunReport`]: what ran (scene, kernel, transfer, sizes), how it ended, how
//! fast it went and what it measured.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use umls_engine::{MemoryUse, StageTimes};

use crate::error::RunError;
use crate::schema::{TransferKind, TransferSpec};

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RunStatus {
    /// It reached its end time.
    Completed,
    /// The engine stopped it (`error` and `failure_kind` say why).
    Failed,
    /// A signal stopped it; its output up to then is written.
    Interrupted,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// The scene's name.
    pub scene: String,
    /// The scene file or built-in name it came from.
    pub source: String,
    /// 1, 2 or 3.
    pub dimension: usize,
    /// The kernel's name.
    pub kernel: String,
    /// The transfer scheme, with its parameters.
    pub transfer: String,
    /// USL or MUSL.
    pub stress_update: String,
    /// How stencils were kept (`auto`, `stored`, `factored`, `recompute`).
    pub stencils: String,
    /// Steps between particle sorts (0: never).
    pub particle_sort_interval: usize,
    /// Sorts done.
    pub particle_sorts: usize,
    /// Material names, by index.
    pub materials: Vec<String>,
    /// Particles.
    pub particles: usize,
    /// The kernel's nodes.
    pub nodes: usize,
    /// Simplices of the mesh (none for a lattice that a grid kernel did not split).
    pub cells: Option<usize>,
    /// The last step's Δt.
    pub dt: f64,
    /// `fixed` or `adaptive`.
    pub time_step: String,
    /// The kernel's stable step at wave Courant number 1.
    pub stable_dt: f64,
    /// Whether a fixed Δt exceeds `stable_dt`.
    pub dt_exceeds_stable: bool,
    /// The largest wave Courant number Δt / Δt_stable a step was asked to take, measured
    /// as the guard measures it; the step the guard refused included.
    pub max_wave_courant: f64,
    /// What the user should hear about the set-up and the run.
    pub warnings: Vec<String>,
    /// Simulated end time.
    pub end_time: f64,
    /// Steps planned.
    pub steps_planned: usize,
    /// Steps taken.
    pub steps: usize,
    /// Worker threads.
    pub threads: usize,
    /// How the run ended.
    pub status: RunStatus,
    /// Why it stopped early.
    pub error: Option<String>,
    /// The engine's kind of failure (`nan`, `energy-blow-up`, …; `other` for the rest).
    pub failure_kind: Option<String>,
    /// Peak resident memory of the process, where the system reports it.
    pub peak_memory_bytes: Option<u64>,
    /// The simulation's own accounting of its memory.
    pub engine_memory: EngineMemory,
    /// Wall time of the run loop: the steps, the observers and the output.
    pub wall_time_s: f64,
    /// Seconds per stage of the step, their total and their shares.
    pub stage_seconds: StageSeconds,
    /// Particles × steps per second of stepping alone (`stage_seconds.total`): the
    /// engine's throughput.
    pub particle_steps_per_second: f64,
    /// Particles × steps per second of the run loop's wall time (output included).
    pub particle_steps_per_wall_second: f64,
    /// The scene's metrics by name: numbers, and a few lists (probe displacements,
    /// body velocities, surface profiles).
    pub metrics: BTreeMap<String, Value>,
    /// The files written, by role (none when the run wrote no files).
    pub outputs: Option<Outputs>,
}

impl RunSummary {
    /// Metric `name` as a number, if the run measured it.
    pub fn metric(&self, name: &str) -> Option<f64> {
        self.metrics.get(name).and_then(Value::as_f64)
    }

    /// Writes the summary to `path` as pretty-printed JSON (`summary.json`).
    pub fn write(&self, path: &std::path::Path) -> Result<(), RunError> {
        let text = serde_json::to_string_pretty(self).unwrap_or_default();
        std::fs::write(path, text + "\n").map_err(|source| RunError::File {
            path: path.to_path_buf(),
            source,
        })
    }

    /// The summary as JSON, as `summary.json` holds it.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }
}

/// [`RunSummary::engine_memory`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EngineMemory {
    /// Particle state.
    pub particle_state_bytes: usize,
    /// Per-step particle scratch.
    pub particle_scratch_bytes: usize,
    /// Stored stencils.
    pub stored_stencil_bytes: usize,
    /// Nodal fields.
    pub node_bytes: usize,
    /// State and scratch per particle.
    pub bytes_per_particle: f64,
    /// The same with the stored stencils.
    pub bytes_per_particle_with_stencils: f64,
}

impl From<&MemoryUse> for EngineMemory {
    fn from(m: &MemoryUse) -> Self {
        Self {
            particle_state_bytes: m.particles,
            particle_scratch_bytes: m.particle_scratch,
            stored_stencil_bytes: m.stencils,
            node_bytes: m.nodes,
            bytes_per_particle: m.bytes_per_particle(),
            bytes_per_particle_with_stencils: m.bytes_per_particle_with_stencils(),
        }
    }
}

/// [`RunSummary::stage_seconds`]: each stage's seconds by name, their total, and each
/// stage's share of the total.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageSeconds {
    /// Seconds by stage.
    #[serde(flatten)]
    pub stages: BTreeMap<String, f64>,
    /// Their sum: the stepping time.
    pub total: f64,
    /// Shares of the total by stage.
    pub fractions: BTreeMap<String, f64>,
}

impl From<&StageTimes> for StageSeconds {
    fn from(times: &StageTimes) -> Self {
        let total = times.total();
        let share = |s: f64| if total > 0.0 { s / total } else { 0.0 };
        Self {
            stages: times
                .stages()
                .iter()
                .map(|(n, s)| (n.to_string(), *s))
                .collect(),
            total,
            fractions: times
                .stages()
                .iter()
                .map(|(n, s)| (n.to_string(), share(*s)))
                .collect(),
        }
    }
}

/// [`RunSummary::outputs`]: file names inside the output folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outputs {
    /// The frame collection.
    pub particles: String,
    /// Frames written.
    pub frames: usize,
    /// The mesh, where the scene has one.
    pub mesh: Option<String>,
    /// The grid of a grid kernel.
    pub grid: Option<String>,
    /// The history.
    pub history: String,
    /// The energy chart.
    pub energy_plot: String,
}

/// The transfer scheme's name with its parameters, as the summary and charts give it.
pub(crate) fn transfer_name(spec: &TransferSpec) -> String {
    let name = transfer_kind_name(spec);
    match spec.mass {
        None => name,
        Some(m) => format!(
            "{name}, consistent mass ({} iterations{})",
            m.iterations,
            match m.forces.share() {
                0.0 => String::new(),
                1.0 => ", forces too".into(),
                beta => format!(", forces with share {beta}"),
            }
        ),
    }
}

fn transfer_kind_name(spec: &TransferSpec) -> String {
    match spec.kind {
        TransferKind::Pic => "pic".into(),
        TransferKind::Flip => format!("flip (alpha {})", spec.alpha),
        TransferKind::ApicFlip => format!("apic-flip (alpha {})", spec.alpha),
        TransferKind::Apic => "apic".into(),
        TransferKind::QuadraticApic => "quadratic-apic".into(),
        TransferKind::QuadraticApicFlip => format!("quadratic-apic-flip (alpha {})", spec.alpha),
        TransferKind::VelocityGradient => "velocity-gradient".into(),
        TransferKind::MlsMpm => "mls-mpm".into(),
    }
}
