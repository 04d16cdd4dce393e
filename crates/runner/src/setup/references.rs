//! `[reference]`: the solutions a run is measured against (an analytic velocity or
//! displacement, the hydrostatic closed form, a stored probe history) and the wall
//! whose pressure is recorded.

use nalgebra::SVector;

use super::VelocityReference;
use crate::error::Result;
use crate::expression::{Definitions, VectorField};
use crate::frame::SceneFrame;
use crate::hydrostatic::Hydrostatic;
use crate::probes::ProbeReference;
use crate::scene::Scene;
use crate::schema::VelocityTimeSpec;

/// The scene's references, compiled and checked.
pub(super) struct References<const D: usize> {
    pub velocity: Option<VelocityReference<D>>,
    pub hydrostatic: Option<Hydrostatic<D>>,
    pub displacement: Option<VectorField<D>>,
    pub probe: Option<ProbeReference<D>>,
    pub pressure: Option<(usize, SVector<f64, D>, f64)>,
}

/// The references of `scene`; `positions` are the particles' starts (scene frame),
/// `gravity` the scene's, and the pressure centre is turned into the world by `frame`.
pub(super) fn references<const D: usize>(
    scene: &Scene,
    definitions: &Definitions,
    gravity: &SVector<f64, D>,
    seeds: &crate::seeds::Seeds<D>,
    frame: &SceneFrame<D>,
) -> Result<References<D>> {
    let Some(r) = &scene.spec.reference else {
        return Ok(References {
            velocity: None,
            hydrostatic: None,
            displacement: None,
            probe: None,
            pressure: None,
        });
    };
    if r.velocity.is_none()
        && r.hydrostatic.is_none()
        && r.displacement.is_none()
        && r.probe.is_none()
        && r.pressure.is_none()
    {
        return Err(scene.value_error(
            "reference",
            "give at least one of `velocity`, `displacement`, `hydrostatic`, `probe` and `pressure`",
        ));
    }
    let velocity = velocity(scene, definitions, &seeds.position)?;
    let hydrostatic = match &r.hydrostatic {
        Some(h) => Some(Hydrostatic::new(scene, h, gravity, seeds)?),
        None => None,
    };
    let displacement = match &r.displacement {
        None => None,
        Some(u) => Some(
            VectorField::<D>::compile(u, true, definitions)
                .map_err(|reason| scene.value_error("reference.displacement", reason))?,
        ),
    };
    Ok(References {
        velocity,
        hydrostatic,
        displacement,
        probe: probe(scene)?,
        pressure: pressure(scene, frame)?,
    })
}

/// `reference.velocity` with its scale (given, or the largest speed at t = 0) and time.
fn velocity<const D: usize>(
    scene: &Scene,
    definitions: &Definitions,
    positions: &[SVector<f64, D>],
) -> Result<Option<VelocityReference<D>>> {
    let Some(r) = &scene.spec.reference else {
        return Ok(None);
    };
    let Some(velocity) = &r.velocity else {
        if r.velocity_time != VelocityTimeSpec::End {
            return Err(scene.value_error(
                "reference.velocity_time",
                "times `reference.velocity`, which is not given",
            ));
        }
        if r.scale.is_some() {
            return Err(scene.value_error(
                "reference.scale",
                "scales `reference.velocity`, which is not given",
            ));
        }
        return Ok(None);
    };
    let error = |reason: String| scene.value_error("reference.velocity", reason);
    let field = VectorField::<D>::compile(velocity, true, definitions).map_err(error)?;
    let scale = match r.scale {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(_) => return Err(scene.value_error("reference.scale", "must be positive")),
        None => {
            let mut largest = 0.0f64;
            for x in positions {
                largest = largest.max(field.eval(x, 0.0).map_err(error)?.norm());
            }
            if largest == 0.0 {
                return Err(scene.value_error(
                    "reference.scale",
                    "the reference velocity is zero at t = 0; give a scale",
                ));
            }
            largest
        }
    };
    Ok(Some(VelocityReference {
        field,
        scale,
        mid_step: r.velocity_time == VelocityTimeSpec::MidStep,
    }))
}

/// `reference.probe`: a stored displacement history of one of `output.probes`.
fn probe<const D: usize>(scene: &Scene) -> Result<Option<ProbeReference<D>>> {
    let spec = &scene.spec;
    let Some(p) = spec.reference.as_ref().and_then(|r| r.probe.as_ref()) else {
        return Ok(None);
    };
    let probes = spec.output.probes.len();
    if p.probe >= probes {
        return Err(scene.value_error(
            "reference.probe.probe",
            format!(
                "{} is not a probe (`output.probes` lists {probes})",
                p.probe
            ),
        ));
    }
    let bytes = scene.file_bytes("reference.probe.file", &p.file)?;
    let text = String::from_utf8_lossy(&bytes);
    ProbeReference::parse(scene, "reference.probe.file", &text, p.probe).map(Some)
}

/// `reference.pressure`: the boundary, its centre (world frame) and area.
fn pressure<const D: usize>(
    scene: &Scene,
    frame: &SceneFrame<D>,
) -> Result<Option<(usize, SVector<f64, D>, f64)>> {
    let spec = &scene.spec;
    let Some(p) = spec.reference.as_ref().and_then(|r| r.pressure.as_ref()) else {
        return Ok(None);
    };
    if p.boundary >= spec.boundaries.len() {
        return Err(scene.value_error(
            "reference.pressure.boundary",
            format!(
                "{} is not a boundary (`boundaries` lists {})",
                p.boundary,
                spec.boundaries.len()
            ),
        ));
    }
    if !(p.area.is_finite() && p.area > 0.0) {
        return Err(scene.value_error("reference.pressure.area", "must be positive"));
    }
    let centre: SVector<f64, D> = scene.vector("reference.pressure.centre", &p.centre)?;
    Ok(Some((p.boundary, frame.point_to_world(&centre), p.area)))
}
