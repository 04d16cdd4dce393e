//! The time step of a run: a fixed step that lands on the end time, or the cap of the
//! adaptive one, and the number of steps and frames planned.

use umls_engine::{EngineError, MAX_PLANNED_STEPS, TimeStepControl};

use crate::context::Context;
use crate::error::Result;
use crate::handle::Run;
use crate::setup;

/// What the run loop steps by.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TimePlan {
    /// Steps planned (the adaptive step may take others).
    pub(crate) steps: usize,
    /// The fixed step, or the cap of the adaptive one.
    pub(crate) dt_cap: f64,
    /// The kernel's stable step at wave Courant number 1.
    pub(crate) stable_dt: f64,
    /// Particle frames to write, the first and the last included.
    pub(crate) frames: usize,
}

/// Plans the time step of `sim` for the context's end time and sets it; warns when a
/// fixed step exceeds the stable one.
pub(crate) fn plan_time_step<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
    warnings: &mut Vec<String>,
) -> Result<TimePlan> {
    let (scene, spec) = (ctx.scene, &ctx.scene.spec);
    let stable_dt = sim.stable_time_step(1.0);
    let target_dt = match (spec.time.dt, spec.time.cfl, spec.time.adaptive) {
        (_, Some(cfl), true) => {
            sim.settings_mut().time_step = TimeStepControl::Adaptive { cfl };
            spec.time
                .dt
                .unwrap_or(f64::INFINITY)
                .min(sim.stable_time_step(cfl))
        }
        (Some(dt), _, _) => dt,
        (_, Some(cfl), _) => sim.stable_time_step(cfl),
        // `check_header` guarantees a time step setting.
        _ => return Err(scene.value_error("time", "give exactly one of `dt` and `cfl`")),
    };
    if sim.settings().time_step != TimeStepControl::Fixed {
        // The adaptive step's cap: the scene's Δt, else none below the end time.
        sim.settings_mut().dt = spec.time.dt.unwrap_or(ctx.end_time);
    }
    let planned = sim
        .plan_until(ctx.end_time, target_dt)
        .map_err(|e| match e {
            EngineError::InvalidParameter {
                parameter: "steps",
                value,
                ..
            } => scene.value_error(
                "scene.end_time",
                format!(
                    "{} with a time step of {target_dt:.4e} is {value:.3e} steps (limit {MAX_PLANNED_STEPS:.0e})",
                    ctx.end_time
                ),
            ),
            e => e.into(),
        })?;
    let (steps, dt_cap) = (planned.steps, planned.dt);
    if sim.settings().time_step == TimeStepControl::Fixed && dt_cap > stable_dt {
        warnings.push(format!(
            "time.dt = {dt_cap:.4e} exceeds the stable step {stable_dt:.4e} (wave Courant number {:.3} > 1): expect the run to blow up",
            dt_cap / stable_dt
        ));
    }
    Ok(TimePlan {
        steps,
        dt_cap,
        stable_dt,
        frames: setup::frame_count(scene, ctx.end_time),
    })
}
