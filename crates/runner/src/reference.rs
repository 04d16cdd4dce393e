//! Errors of a run against the scene's analytic references, as the run loop samples
//! them: particles are compared by their initial positions X (world frame), which go
//! back into the scene frame the references are written in.

use nalgebra::SVector;

use crate::error::Result;
use crate::expression::VectorField;
use crate::scene::Scene;
use crate::setup::Setup;

/// RMS over particles of |v − v_ref(X, t)|, divided by the reference's scale; `None`
/// without a velocity reference. `time` is when the last step ended and `step_dt` its
/// length (0 before the first step); with `velocity_time = "mid-step"` the reference is
/// taken at `time − step_dt / 2`.
pub fn velocity_error<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    initial: &[SVector<f64, D>],
    velocities: &[SVector<f64, D>],
    time: f64,
    step_dt: f64,
) -> Result<Option<f64>> {
    let Some(reference) = &setup.reference else {
        return Ok(None);
    };
    let time = if reference.mid_step {
        time - 0.5 * step_dt
    } else {
        time
    };
    let rms = rms_error(
        scene,
        "reference.velocity",
        setup,
        &reference.field,
        initial,
        time,
        |i| velocities[i],
    )?;
    Ok(Some(rms / reference.scale))
}

/// RMS over particles of |x − X − u_ref(X, t)| (a length: the displacement has no
/// natural scale at t = 0); `None` without a displacement reference.
pub fn displacement_error<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    initial: &[SVector<f64, D>],
    positions: &[SVector<f64, D>],
    time: f64,
) -> Result<Option<f64>> {
    let Some(field) = &setup.displacement else {
        return Ok(None);
    };
    rms_error(
        scene,
        "reference.displacement",
        setup,
        field,
        initial,
        time,
        |i| positions[i] - initial[i],
    )
    .map(Some)
}

/// RMS over particles of |computed(i) − field(X_i, t)|, the field evaluated in the
/// scene frame and turned into the world.
fn rms_error<const D: usize>(
    scene: &Scene,
    key: &str,
    setup: &Setup<D>,
    field: &VectorField<D>,
    initial: &[SVector<f64, D>],
    time: f64,
    computed: impl Fn(usize) -> SVector<f64, D>,
) -> Result<f64> {
    let frame = &setup.frame;
    let mut sum = 0.0;
    for (i, x0) in initial.iter().enumerate() {
        let exact = field
            .eval(&frame.point_to_scene(x0), time)
            .map(|v| frame.vector_to_world(&v))
            .map_err(|reason| scene.value_error(key, reason))?;
        sum += (computed(i) - exact).norm_squared();
    }
    Ok((sum / initial.len().max(1) as f64).sqrt())
}
