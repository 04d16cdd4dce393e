//! Checks every dimension shares before any work (end time, time step, output counts),
//! and the frame count they imply.

use crate::error::{Result, RunError};
use crate::scene::Scene;

/// Checks shared by every dimension before any work: end time, time step, output counts.
pub fn check_header(scene: &Scene) -> Result<()> {
    let spec = &scene.spec;
    if !(spec.scene.end_time.is_finite() && spec.scene.end_time > 0.0) {
        return Err(scene.value_error("scene.end_time", "must be finite and positive"));
    }
    let dt_ok = |dt: f64| dt.is_finite() && dt > 0.0;
    let cfl_ok = |cfl: f64| cfl.is_finite() && cfl > 0.0 && cfl <= 1.0;
    match (spec.time.dt, spec.time.cfl, spec.time.adaptive) {
        (Some(dt), None, false) if dt_ok(dt) => {}
        (None, Some(cfl), _) if cfl_ok(cfl) => {}
        (Some(dt), Some(cfl), true) if dt_ok(dt) && cfl_ok(cfl) => {}
        (Some(dt), _, _) if !dt_ok(dt) => {
            return Err(scene.value_error("time.dt", "must be finite and positive"));
        }
        (_, Some(cfl), _) if !cfl_ok(cfl) => {
            return Err(scene.value_error("time.cfl", "must be in (0, 1]"));
        }
        (_, None, true) => {
            return Err(scene.value_error("time.adaptive", "an adaptive time step needs `cfl`"));
        }
        _ => {
            return Err(scene.value_error(
                "time",
                "give exactly one of `dt` and `cfl` (both only with `adaptive = true`)",
            ));
        }
    }
    if let Some(limit) = spec.time.max_wave_courant {
        if limit.is_nan() || limit <= 0.0 {
            return Err(scene.value_error(
                "time.max_wave_courant",
                "must be positive (`inf` switches the guard off)",
            ));
        }
    }
    match (spec.output.frames, spec.output.interval) {
        (Some(_), Some(_)) => {
            return Err(scene.value_error("output", "give at most one of `frames` and `interval`"));
        }
        (Some(n), None) if n < 2 => {
            return Err(
                scene.value_error("output.frames", "at least 2 (the first and the last state)")
            );
        }
        (None, Some(i)) if !(i.is_finite() && i > 0.0) => {
            return Err(scene.value_error("output.interval", "must be finite and positive"));
        }
        _ => {}
    }
    if spec.output.history_every == 0 {
        return Err(scene.value_error("output.history_every", "must be at least 1"));
    }
    if !(0.0..=1.0).contains(&spec.transfer.alpha) {
        return Err(scene.value_error("transfer.alpha", "must be in [0, 1]"));
    }
    if !(1..=3).contains(&spec.scene.dimension) {
        return Err(scene.value_error("scene.dimension", "must be 1, 2 or 3"));
    }
    Ok(())
}

/// Default number of particle frames.
pub const DEFAULT_FRAMES: usize = 50;

/// Particle frames over a run ending at `end_time`: `frames`, or one per `interval`
/// (the initial state included).
pub fn frame_count(scene: &Scene, end_time: f64) -> usize {
    match (scene.spec.output.frames, scene.spec.output.interval) {
        (Some(n), _) => n,
        (None, Some(i)) => ((end_time / i).round().max(1.0) as usize) + 1,
        (None, None) => DEFAULT_FRAMES,
    }
}

/// The error for a scene that is plastic in 1D.
pub fn plastic_in_1d(scene: &Scene) -> RunError {
    scene.value_error(
        "materials",
        "plastic models need dimension 2 (plane strain) or 3",
    )
}
