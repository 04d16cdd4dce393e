//! One row of results per run: the case, how it ended, its error metric, its cost. The
//! rows are written as `results.csv` and `results.json` beside the report, so a user can
//! re-plot them.

use serde::Serialize;

use crate::case::{Case, StudyKind};
use crate::runner::RunOutput;

/// The stages of a step as `summary.json` names them, in step order, with the names the
/// report prints.
pub const STAGES: [(&str, &str); 6] = [
    ("stencils", "stencils"),
    ("particles_to_grid", "P2G"),
    ("grid_update", "grid update"),
    ("grid_to_particles", "G2P"),
    ("constitutive", "constitutive"),
    ("checks", "checks"),
];

/// Results of one run.
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    /// Study name.
    pub study: String,
    /// Study kind.
    pub kind: StudyKind,
    /// Scene.
    pub scene: String,
    /// Kernel.
    pub kernel: String,
    /// Transfer (empty: the scene's).
    pub transfer: String,
    /// Variant label.
    pub variant: String,
    /// Refinement factor.
    pub refine: f64,
    /// Particle refinement factor.
    pub particle_refine: f64,
    /// Stability map column value.
    pub x: String,
    /// Stability map row value.
    pub y: String,
    /// Worker threads.
    pub threads: usize,
    /// Repetition of a throughput measurement (0: the first).
    pub repeat: usize,
    /// `completed`, `failed`, `interrupted`, or `no-summary` when the run wrote none.
    pub status: String,
    /// `completed`, `energy-growth` or `failed` (stability maps read this).
    pub outcome: String,
    /// The engine's failure kind (`inverted`, `non-finite`, …), empty if none.
    pub failure_kind: String,
    /// The error message, empty if none.
    pub error: String,
    /// Name of the error metric.
    pub metric_name: String,
    /// Its value (absent if the run did not produce it).
    pub metric: Option<f64>,
    /// Largest energy gain over the run, relative to its largest mechanical energy
    /// (`energy_gain_max`).
    pub energy_gain: Option<f64>,
    /// Energy change at the end, signed, relative the same way (`energy_change_final`).
    pub energy_change: Option<f64>,
    /// Particles.
    pub particles: Option<u64>,
    /// Background nodes.
    pub nodes: Option<u64>,
    /// Steps taken.
    pub steps: Option<u64>,
    /// Last time step.
    pub dt: Option<f64>,
    /// Largest wave Courant number of the run.
    pub max_wave_courant: Option<f64>,
    /// Time in the steps themselves: the sum of the stage times (output, history rows
    /// and setup excluded).
    pub step_time_s: Option<f64>,
    /// Wall time of the run's loop (summary `wall_time_s`: steps plus output).
    pub wall_time_s: Option<f64>,
    /// Whole process wall time (setup, stepping, output).
    pub process_time_s: f64,
    /// Particle-steps per second of the steps themselves (particles × steps /
    /// `step_time_s`).
    pub particle_steps_per_second: Option<f64>,
    /// Peak resident memory of the run's process.
    pub peak_memory_bytes: Option<u64>,
    /// Seconds in each stage, in [`STAGES`] order.
    pub stage_stencils_s: Option<f64>,
    /// P2G seconds.
    pub stage_p2g_s: Option<f64>,
    /// Grid update seconds.
    pub stage_grid_update_s: Option<f64>,
    /// G2P seconds.
    pub stage_g2p_s: Option<f64>,
    /// Constitutive update seconds.
    pub stage_constitutive_s: Option<f64>,
    /// Checks seconds.
    pub stage_checks_s: Option<f64>,
    /// The run's output directory, relative to the report.
    pub out: String,
}

impl Record {
    /// The record of `case` from its output; `metric` names the error metric to read and
    /// `growth` is the energy gain (a fraction of the run's largest mechanical energy)
    /// that counts as unstable.
    pub fn new(case: &Case, output: &RunOutput, metric: &str, growth: f64, out: String) -> Self {
        let s = output.summary.as_ref();
        let field = |name: &str| s.and_then(|s| s.get(name)).filter(|v| !v.is_null());
        let float = |name: &str| field(name).and_then(serde_json::Value::as_f64);
        let uint = |name: &str| field(name).and_then(serde_json::Value::as_u64);
        let text = |name: &str| {
            field(name)
                .and_then(serde_json::Value::as_str)
                .unwrap_or_default()
                .to_string()
        };
        let metrics = field("metrics");
        let metric_value = |name: &str| {
            metrics
                .and_then(|m| m.get(name))
                .and_then(serde_json::Value::as_f64)
        };
        let stage = |name: &str| {
            field("stage_seconds")
                .and_then(|st| st.get(name))
                .and_then(serde_json::Value::as_f64)
        };
        let status = if s.is_some() {
            text("status")
        } else {
            "no-summary".into()
        };
        let energy_gain = metric_value("energy_gain_max");
        let outcome = match status.as_str() {
            "completed" if energy_gain.is_some_and(|e| e > growth) => "energy-growth",
            "completed" => "completed",
            _ => "failed",
        };
        let error = if s.is_some() {
            text("error")
        } else {
            output.stderr_tail.clone()
        };
        let failure_kind = match (text("failure_kind"), status.as_str()) {
            (kind, _) if !kind.is_empty() => kind,
            (_, "no-summary") => "no-summary".into(),
            _ => String::new(),
        };
        let (x, y) = case
            .cell
            .as_ref()
            .map(|((_, x), (_, y))| (x.clone(), y.clone()))
            .unwrap_or_default();
        Self {
            study: case.study.clone(),
            kind: case.kind,
            scene: case.scene.clone(),
            kernel: case.kernel.clone(),
            transfer: case.transfer.clone(),
            variant: case.variant.clone(),
            refine: case.refine,
            particle_refine: case.particle_refine,
            x,
            y,
            threads: case.threads,
            repeat: case.repeat,
            status,
            outcome: outcome.into(),
            failure_kind,
            error,
            metric_name: metric.to_string(),
            // `-name` reads a metric negated (an energy change as the energy lost).
            metric: match metric.strip_prefix('-') {
                _ if metric.is_empty() => None,
                Some(name) => metric_value(name).map(|v| -v),
                None => metric_value(metric),
            },
            energy_gain,
            energy_change: metric_value("energy_change_final"),
            particles: uint("particles"),
            nodes: uint("nodes"),
            steps: uint("steps"),
            dt: float("dt"),
            max_wave_courant: float("max_wave_courant"),
            step_time_s: stage("total"),
            wall_time_s: float("wall_time_s"),
            process_time_s: output.process_seconds,
            particle_steps_per_second: match (uint("particles"), uint("steps"), stage("total")) {
                (Some(n), Some(k), Some(t)) if t > 0.0 => Some((n * k) as f64 / t),
                _ => None,
            },
            peak_memory_bytes: uint("peak_memory_bytes"),
            stage_stencils_s: stage("stencils"),
            stage_p2g_s: stage("particles_to_grid"),
            stage_grid_update_s: stage("grid_update"),
            stage_g2p_s: stage("grid_to_particles"),
            stage_constitutive_s: stage("constitutive"),
            stage_checks_s: stage("checks"),
            out,
        }
    }

    /// Seconds per stage in [`STAGES`] order.
    pub fn stages(&self) -> [Option<f64>; 6] {
        [
            self.stage_stencils_s,
            self.stage_p2g_s,
            self.stage_grid_update_s,
            self.stage_g2p_s,
            self.stage_constitutive_s,
            self.stage_checks_s,
        ]
    }

    /// The chart series this run belongs to.
    pub fn series(&self) -> String {
        let mut label = self.kernel.clone();
        for part in [&self.transfer, &self.variant] {
            if !part.is_empty() {
                label.push_str(", ");
                label.push_str(part);
            }
        }
        label
    }

    /// Whether the run completed.
    pub fn completed(&self) -> bool {
        self.status == "completed"
    }
}

/// The records as CSV text.
pub fn to_csv(records: &[Record]) -> String {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for r in records {
        // Serializing plain fields into memory cannot fail.
        let _ = writer.serialize(r);
    }
    String::from_utf8(writer.into_inner().unwrap_or_default()).unwrap_or_default()
}
