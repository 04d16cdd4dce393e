//! `[[boundaries]]`: each condition resolved to the geometry it holds (a plane, a
//! physical group's vertices, a region of the scene frame, or the surface of an
//! obstacle or a container).

use nalgebra::SVector;
use umls_io::gmsh::PhysicalGroup;

use super::BoundaryTarget;
use super::regions::{group, region};
use crate::background::Background;
use crate::error::Result;
use crate::scene::Scene;
use crate::schema::{BoundaryKind, BoundarySpec, Imposed, RegionSpec};

/// Every boundary condition of the scene, in file order.
pub(super) fn boundaries<const D: usize>(
    scene: &Scene,
    groups: &[PhysicalGroup],
    background: &Background<D>,
) -> Result<Vec<(BoundaryKind, BoundaryTarget<D>)>> {
    scene
        .spec
        .boundaries
        .iter()
        .enumerate()
        .map(|(i, b)| Ok((b.kind, target(scene, i, b, groups, background)?)))
        .collect()
}

fn target<const D: usize>(
    scene: &Scene,
    i: usize,
    b: &BoundarySpec,
    groups: &[PhysicalGroup],
    background: &Background<D>,
) -> Result<BoundaryTarget<D>> {
    let key = |field: &str| format!("boundaries[{i}].{field}");
    if b.imposed.is_some() && b.region.is_none() {
        return Err(scene.value_error(key("imposed"), "only a `region` condition takes `imposed`"));
    }
    if b.penalty.is_some() && b.imposed != Some(Imposed::Face) {
        return Err(scene.value_error(
            key("penalty"),
            "weighs a clamp held on its face: give it with imposed = \"face\"",
        ));
    }
    match (b.friction, b.kind) {
        (Some(mu), BoundaryKind::Slip) if !(mu.is_finite() && mu >= 0.0) => {
            return Err(scene.value_error(key("friction"), "must be finite and not negative"));
        }
        (Some(_), BoundaryKind::Fixed) => {
            return Err(scene.value_error(
                key("friction"),
                "applies to slip conditions (a fixed one sticks already)",
            ));
        }
        _ => {}
    }
    if b.normal.is_some() && b.region.is_none() {
        return Err(scene.value_error(
            key("normal"),
            "only a `region` condition takes a normal (a plane has its own)",
        ));
    }
    let given = [
        b.plane.is_some(),
        b.group.is_some(),
        b.region.is_some(),
        b.obstacle.is_some(),
        b.container.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(scene.value_error(
            format!("boundaries[{i}]"),
            "give exactly one of `plane`, `group`, `region`, `obstacle` and `container`",
        ));
    }
    if let Some((name, spec, inside)) = b
        .obstacle
        .as_ref()
        .map(|s| ("obstacle", s, false))
        .or(b.container.as_ref().map(|s| ("container", s, true)))
    {
        let shape = region::<D>(scene, &key(name), spec)?;
        if shape.signed_distance(&SVector::zeros()).is_none() {
            return Err(scene.value_error(
                key(name),
                "needs a surface: a box, ball or half-space, or their combinations",
            ));
        }
        let velocity = match &b.velocity {
            Some(v) => scene.vector(&key("velocity"), v)?,
            None => SVector::zeros(),
        };
        return Ok(BoundaryTarget::Shape {
            region: shape,
            inside,
            velocity,
        });
    }
    if b.velocity.is_some() {
        return Err(scene.value_error(key("velocity"), "only an `obstacle` or a `container` moves"));
    }
    match (&b.plane, &b.group, &b.region) {
        (None, None, Some(spec)) => region_target(scene, i, b, spec),
        (Some(plane), None, None) => {
            let normal: SVector<f64, D> = scene.vector(&key("plane.normal"), &plane.normal)?;
            if normal.norm() == 0.0 {
                return Err(scene.value_error(key("plane.normal"), "must not be zero"));
            }
            Ok(BoundaryTarget::Plane {
                point: scene.vector(&key("plane.point"), &plane.point)?,
                normal: normal.normalize(),
            })
        }
        (None, Some(name), None) => {
            let g = group(scene, groups, &key("group"), name)?;
            let Some(mesh) = background.mesh() else {
                return Err(scene.value_error(key("group"), "a group needs the mesh it belongs to"));
            };
            Ok(BoundaryTarget::Vertices(
                g.vertices
                    .iter()
                    .map(|&v| (v, mesh.topology().vertex_normal(v as usize)))
                    .collect(),
            ))
        }
        _ => Err(scene.value_error(
            format!("boundaries[{i}]"),
            "give exactly one of `plane`, `group`, `region`, `obstacle` and `container`",
        )),
    }
}

/// A condition on a region: its wall normal (slip), how a fixed one is imposed, and the
/// face clamp's penalty.
fn region_target<const D: usize>(
    scene: &Scene,
    i: usize,
    b: &BoundarySpec,
    spec: &RegionSpec,
) -> Result<BoundaryTarget<D>> {
    let key = |field: &str| format!("boundaries[{i}].{field}");
    let normal = match (&b.normal, b.kind) {
        (None, BoundaryKind::Fixed) => None,
        (Some(n), BoundaryKind::Slip) => {
            let n: SVector<f64, D> = scene.vector(&key("normal"), n)?;
            if n.norm() == 0.0 {
                return Err(scene.value_error(key("normal"), "must not be zero"));
            }
            Some(n.normalize())
        }
        (None, BoundaryKind::Slip) => {
            return Err(scene.value_error(
                key("normal"),
                "a slip condition on a region needs the wall's normal",
            ));
        }
        (Some(_), BoundaryKind::Fixed) => {
            return Err(scene.value_error(key("normal"), "a fixed condition takes no normal"));
        }
    };
    let imposed = match (b.imposed, b.kind) {
        (None | Some(Imposed::Nodes), _) => Imposed::Nodes,
        (Some(imposed), BoundaryKind::Fixed) => imposed,
        (Some(_), BoundaryKind::Slip) => {
            return Err(scene.value_error(
                key("imposed"),
                "only a fixed region can be imposed on the fit or its face",
            ));
        }
    };
    // Given only with imposed = "face" (checked by the caller).
    let penalty = match b.penalty {
        Some(w) if !(w.is_finite() && w > 0.0) => {
            return Err(scene.value_error(key("penalty"), "must be finite and positive"));
        }
        w => w,
    };
    Ok(BoundaryTarget::Region {
        region: region(scene, &key("region"), spec)?,
        normal,
        imposed,
        penalty,
    })
}
