//! The run loop: plan the time step, apply the boundaries, step to the end time (or to
//! a failure or an interruption) with the observers recording at their intervals, then
//! write the end state and the summary.

use std::time::Instant;

use crate::conditions;
use crate::context::{Context, RunPlan, RunReport};
use crate::error::{Result, RunError};
use crate::handle::Run;
use crate::output::OutputDir;
use crate::recorder::Recorder;
use crate::summarise::{Outcome, summarise};
use crate::time_plan::{TimePlan, plan_time_step};

/// Runs `sim` to the context's end time and reports.
pub(crate) fn drive<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
) -> Result<RunReport> {
    let (plan, mut warnings) = prologue(ctx, sim)?;
    let mut out = OutputDir::create(ctx.options.out.as_deref(), ctx.encoding)?;
    let mut recorder = Recorder::new(ctx, sim, &out)?;
    sim.write_particles(&mut out, recorder.reference_positions())?;
    recorder.record_first(sim)?;
    if let Some(progress) = &ctx.options.progress {
        progress.start(&run_plan(ctx, sim, &plan, &warnings));
    }
    let start = Instant::now();
    let failure = step_to_end(ctx, sim, &plan, &mut recorder, &mut out);
    let wall = start.elapsed().as_secs_f64();
    if let Some(progress) = &ctx.options.progress {
        progress.finish();
    }
    let failure = match failure {
        Ok(()) => None,
        Err(e) => {
            // The state the run stopped in (the last frame may be far behind it), and its
            // history row. A state whose stresses cannot be evaluated (an inverted
            // particle) has no frame; the summary still says why the run stopped.
            if let Err(e) = sim.write_particles(&mut out, recorder.reference_positions()) {
                warnings.push(format!("the state the run stopped in has no frame: {e}"));
            }
            recorder.record_stop(sim);
            Some(e)
        }
    };
    let history = recorder.finish()?;
    write_background(ctx, sim, &out)?;
    recorder.energy_plot(&out)?;
    let outcome = Outcome {
        plan: &plan,
        warnings,
        failure: failure.as_ref(),
        wall,
        frames: out.frames(),
        max_wave_courant: sim.max_wave_courant(),
    };
    let metrics = recorder.metrics(sim, failure.is_some())?;
    let summary = summarise(ctx, sim, &outcome, metrics);
    if let Some(path) = out.path("summary.json") {
        summary.write(&path)?;
    }
    match failure {
        Some(e) => Err(e),
        None => Ok(RunReport {
            summary,
            history,
            out: ctx.options.out.clone(),
        }),
    }
}

/// What a run does before its first step: the geostatic stress, the time step planned to
/// the end time, the boundaries; the plan and the set-up's and the plan's warnings.
pub(crate) fn prologue<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
) -> Result<(TimePlan, Vec<String>)> {
    if let Some(k0) = ctx.setup.geostatic_k0 {
        sim.set_geostatic_stress(k0)?;
    }
    let mut warnings = ctx.setup.warnings.clone();
    let plan = plan_time_step(ctx, sim, &mut warnings)?;
    conditions::apply_boundaries(ctx, sim)?;
    Ok((plan, warnings))
}

/// Steps until the end time; the error that stopped the run early, if any.
fn step_to_end<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &mut dyn Run<D>,
    plan: &TimePlan,
    recorder: &mut Recorder<D>,
    out: &mut OutputDir,
) -> Result<()> {
    let history_every = ctx.scene.spec.output.history_every;
    let frames = plan.frames;
    let frame_time = |k: usize| ctx.end_time * k as f64 / (frames - 1) as f64;
    let mut next_frame = 1;
    let mut step = 0;
    let end = ctx.end_time * (1.0 - 1e-12);
    while !sim.reached(ctx.end_time) {
        step += 1;
        if ctx
            .options
            .interrupt
            .as_ref()
            .is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed))
        {
            return Err(RunError::Interrupted {
                time: sim.time(),
                step: sim.step_count(),
            });
        }
        // The longest this step may be: an adaptive one stops at the end time.
        let dt = match sim.settings().time_step {
            umls_engine::TimeStepControl::Adaptive { .. } => {
                plan.dt_cap.min(ctx.end_time - sim.time())
            }
            umls_engine::TimeStepControl::Fixed => sim.settings().dt,
        };
        // Reactions are summed only for the steps whose history row reads them (the last
        // step is predicted with half a step of margin).
        sim.settings_mut().measure_reactions =
            step % history_every == 0 || sim.time() + 1.5 * dt >= end;
        sim.step_until(ctx.end_time)?;
        recorder.after_step(sim)?;
        if step % history_every == 0 || sim.reached(ctx.end_time) {
            recorder.record(sim)?;
        }
        if next_frame < frames && sim.time() >= frame_time(next_frame) - 0.5 * dt {
            sim.write_particles(out, recorder.reference_positions())?;
            next_frame += 1;
        }
        if let Some(progress) = &ctx.options.progress {
            progress.step();
        }
    }
    Ok(())
}

/// Bytes of one particle in a binary frame: position, velocity and displacement (3
/// each), the Cauchy stress and the deformation gradient (9 each), mean stress,
/// Jacobian, mass, id and material, as 8-byte values, and a third more for base64.
const FRAME_BYTES_PER_PARTICLE: u64 = (3 * 3 + 2 * 9 + 5) * 8 * 4 / 3;

/// The plan [`crate::context::Progress::start`] hears.
fn run_plan<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &dyn Run<D>,
    plan: &TimePlan,
    warnings: &[String],
) -> RunPlan {
    let particles = sim.positions().len();
    let writes = ctx.options.out.is_some();
    let frames = if writes { plan.frames } else { 0 };
    RunPlan {
        scene: ctx.scene.spec.scene.name.clone(),
        particles,
        steps: plan.steps,
        frames,
        output_bytes: frames as u64 * particles as u64 * FRAME_BYTES_PER_PARTICLE,
        warnings: warnings.to_vec(),
    }
}

/// `mesh.vtu` (with the nodal fields of a mesh kernel) and, for a grid kernel,
/// `grid.vtu`.
fn write_background<const D: usize>(
    ctx: &Context<'_, D>,
    sim: &dyn Run<D>,
    out: &OutputDir,
) -> Result<()> {
    let (mass, velocity) = sim.grid();
    let mesh = ctx.setup.background.mesh();
    if let Some(mesh) = mesh {
        let fields = ctx.mesh_kernel.then_some((mass, velocity));
        out.write_mesh(mesh, &ctx.setup.groups, fields)?;
    }
    if !ctx.mesh_kernel {
        out.write_grid(&sim.node_positions(), mass, velocity)?;
    }
    Ok(())
}
