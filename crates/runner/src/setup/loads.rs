//! What drives the bodies besides their start: gravity and its ramp, the body force,
//! damping, the stress update and a geostatic initial stress.

use nalgebra::SVector;
use umls_engine::{Damping, StressUpdate};

use crate::error::Result;
use crate::expression::{Definitions, VectorField};
use crate::scene::Scene;
use crate::schema::{ForcePosition, StressUpdateSpec};

/// The scene's loads and step options, checked (scene frame).
pub(super) struct Loads<const D: usize> {
    pub gravity: SVector<f64, D>,
    pub stress_update: StressUpdate,
    pub gravity_ramp: f64,
    pub damping: Damping,
    pub geostatic_k0: Option<f64>,
}

pub(super) fn loads<const D: usize>(scene: &Scene) -> Result<Loads<D>> {
    let spec = &scene.spec;
    let gravity: SVector<f64, D> = match &spec.scene.gravity {
        None => SVector::zeros(),
        Some(g) => scene.vector("scene.gravity", g)?,
    };
    let stress_update = match spec.time.stress_update {
        StressUpdateSpec::Usl => StressUpdate::Usl,
        StressUpdateSpec::Musl => StressUpdate::Musl,
    };
    let gravity_ramp = spec.scene.gravity_ramp.unwrap_or(0.0);
    if !(gravity_ramp.is_finite() && gravity_ramp >= 0.0) {
        return Err(scene.value_error("scene.gravity_ramp", "must be finite and non-negative"));
    }
    let damping = match &spec.damping {
        None => Damping::None,
        Some(d) => match (d.local, d.mass) {
            (Some(alpha), None) if (0.0..1.0).contains(&alpha) => Damping::Local { alpha },
            (Some(_), None) => return Err(scene.value_error("damping.local", "must lie in [0, 1)")),
            (None, Some(beta)) if beta.is_finite() && beta >= 0.0 => {
                Damping::MassProportional { beta }
            }
            (None, Some(_)) => {
                return Err(scene.value_error("damping.mass", "must be finite and non-negative"));
            }
            _ => return Err(scene.value_error("damping", "give exactly one of `local` and `mass`")),
        },
    };
    let geostatic_k0 = match &spec.initial_stress {
        None => None,
        Some(i) if !(i.geostatic_k0.is_finite() && i.geostatic_k0 >= 0.0) => {
            return Err(scene.value_error(
                "initial_stress.geostatic_k0",
                "must be finite and non-negative",
            ));
        }
        Some(_) if gravity.norm() == 0.0 => {
            return Err(scene.value_error(
                "initial_stress.geostatic_k0",
                "a geostatic stress needs `scene.gravity`",
            ));
        }
        Some(i) => Some(i.geostatic_k0),
    };
    Ok(Loads {
        gravity,
        stress_update,
        gravity_ramp,
        damping,
        geostatic_k0,
    })
}

/// `[body_force]`, compiled and checked finite where the particles start.
pub(super) fn body_force<const D: usize>(
    scene: &Scene,
    definitions: &Definitions,
    positions: &[SVector<f64, D>],
) -> Result<Option<(VectorField<D>, ForcePosition)>> {
    let Some(b) = &scene.spec.body_force else {
        return Ok(None);
    };
    let error = |reason: String| scene.value_error("body_force.acceleration", reason);
    let field = VectorField::<D>::compile(&b.acceleration, true, definitions).map_err(error)?;
    // A field that is not finite where the particles start would poison the run.
    for x in positions {
        let value = field.eval(x, 0.0).map_err(error)?;
        if !value.iter().all(|c| c.is_finite()) {
            return Err(error(format!(
                "is not finite at the particle {:?} at t = 0",
                x.as_slice()
            )));
        }
    }
    Ok(Some((field, b.position)))
}
