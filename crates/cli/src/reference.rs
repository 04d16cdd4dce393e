//! Errors of a run against the scene's analytic references, as the run loop samples
//! them: particles are compared by their initial positions X (world frame), which go
//! back into the scene frame the references are written in.

use nalgebra::SVector;

use crate::error::Result;
use crate::scene::Scene;
use crate::setup::Setup;

/// RMS over particles of |v − v_ref(X, t)|, divided by the reference's scale; `None`
/// without a velocity reference.
pub fn velocity_error<const D: usize>(
    scene: &Scene,
    setup: &Setup<D>,
    initial: &[SVector<f64, D>],
    velocities: &[SVector<f64, D>],
    time: f64,
) -> Result<Option<f64>> {
    let Some((field, scale)) = &setup.reference else {
        return Ok(None);
    };
    let frame = &setup.frame;
    let mut sum = 0.0;
    for (v, x0) in velocities.iter().zip(initial) {
        let exact = field
            .eval(&frame.point_to_scene(x0), time)
            .map(|v| frame.vector_to_world(&v))
            .map_err(|reason| scene.value_error("reference.velocity", reason))?;
        sum += (v - exact).norm_squared();
    }
    Ok(Some((sum / initial.len().max(1) as f64).sqrt() / scale))
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
    let frame = &setup.frame;
    let mut sum = 0.0;
    for (x, x0) in positions.iter().zip(initial) {
        let exact = field
            .eval(&frame.point_to_scene(x0), time)
            .map(|u| frame.vector_to_world(&u))
            .map_err(|reason| scene.value_error("reference.displacement", reason))?;
        sum += (x - x0 - exact).norm_squared();
    }
    Ok(Some((sum / initial.len().max(1) as f64).sqrt()))
}
