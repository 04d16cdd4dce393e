//! The summary of a finished run loop, from the simulation's end state and how the loop
//! ended.

use serde_json::Value;
use umls_engine::TimeStepControl;

use crate::context::Context;
use crate::error::RunError;
use crate::handle::Run;
use crate::summary::{EngineMemory, Outputs, RunStatus, RunSummary, StageSeconds, transfer_name};
use crate::time_plan::TimePlan;

/// How the run loop ended, for the summary.
pub(crate) struct Outcome<'a> {
    pub(crate) plan: &'a TimePlan,
    pub(crate) warnings: Vec<String>,
    pub(crate) failure: Option<&'a RunError>,
    pub(crate) wall: f64,
    pub(crate) frames: usize,
    pub(crate) max_wave_courant: f64,
}

/// The summary of a run of `ctx` that ended in `sim` as `outcome` says.
pub(crate) fn summarise<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &dyn Run<D>,
    outcome: &Outcome<'_>,
    metrics: serde_json::Map<String, Value>,
) -> RunSummary {
    let spec = &ctx.scene.spec;
    let settings = sim.settings();
    let taken = sim.step_count();
    let particle_steps = (sim.positions().len() * taken) as f64;
    let stage_seconds = StageSeconds::from(&sim.stage_times());
    let per = |seconds: f64| {
        if seconds > 0.0 {
            particle_steps / seconds
        } else {
            0.0
        }
    };
    let fixed = settings.time_step == TimeStepControl::Fixed;
    RunSummary {
        scene: spec.scene.name.clone(),
        source: ctx.scene.label.clone(),
        dimension: D,
        kernel: ctx.kernel_name.clone(),
        transfer: transfer_name(&spec.transfer),
        stress_update: spec.time.stress_update.name().into(),
        stencils: spec.kernel.stencils.name().into(),
        particle_sort_interval: spec.kernel.particle_sort_interval,
        particle_sorts: sim.particle_sorts(),
        materials: ctx.setup.material_names.clone(),
        particles: sim.positions().len(),
        nodes: sim.node_count(),
        cells: ctx.setup.background.cell_count(),
        dt: sim.last_dt(),
        time_step: if fixed { "fixed" } else { "adaptive" }.into(),
        stable_dt: outcome.plan.stable_dt,
        dt_exceeds_stable: fixed && settings.dt > outcome.plan.stable_dt,
        max_wave_courant: outcome.max_wave_courant,
        warnings: outcome.warnings.clone(),
        end_time: ctx.end_time,
        steps_planned: outcome.plan.steps,
        steps: taken,
        threads: rayon::current_num_threads(),
        status: match outcome.failure {
            None => RunStatus::Completed,
            Some(RunError::Interrupted { .. }) => RunStatus::Interrupted,
            Some(_) => RunStatus::Failed,
        },
        error: outcome.failure.map(|e| e.to_string()),
        failure_kind: match outcome.failure {
            Some(RunError::Engine(e)) => Some(e.kind().into()),
            Some(RunError::Interrupted { .. }) | None => None,
            Some(_) => Some("other".into()),
        },
        peak_memory_bytes: crate::memory::peak_resident_bytes(),
        engine_memory: EngineMemory::from(&sim.memory_use()),
        wall_time_s: outcome.wall,
        particle_steps_per_second: per(stage_seconds.total),
        particle_steps_per_wall_second: per(outcome.wall),
        stage_seconds,
        metrics: metrics.into_iter().collect(),
        outputs: ctx.options.out.as_ref().map(|_| Outputs {
            particles: "particles.pvd".into(),
            frames: outcome.frames,
            mesh: ctx.setup.background.mesh().map(|_| "mesh.vtu".into()),
            grid: (!ctx.mesh_kernel).then(|| "grid.vtu".into()),
            history: "history.csv".into(),
            energy_plot: "energies.svg".into(),
        }),
    }
}
