//! Regions of the scene file and the mesh's physical groups they may name.

use nalgebra::SVector;
use umls_engine::Region;
use umls_io::gmsh::PhysicalGroup;

use crate::error::Result;
use crate::scene::Scene;
use crate::schema::RegionSpec;

pub(super) fn group<'a>(
    scene: &Scene,
    groups: &'a [PhysicalGroup],
    key: &str,
    name: &str,
) -> Result<&'a PhysicalGroup> {
    groups.iter().find(|g| g.name == name).ok_or_else(|| {
        let known: Vec<&str> = groups.iter().map(|g| g.name.as_str()).collect();
        scene.value_error(
            key,
            if known.is_empty() {
                format!("no physical group `{name}`: the mesh has none (only Gmsh files do)")
            } else {
                format!(
                    "no physical group `{name}` (the mesh has: {})",
                    known.join(", ")
                )
            },
        )
    })
}

/// A region of the file (not a physical group) at `key`.
pub(super) fn region<const D: usize>(
    scene: &Scene,
    key: &str,
    spec: &RegionSpec,
) -> Result<Region<D>> {
    let parts = |name: &str, list: &[RegionSpec]| -> Result<Vec<Region<D>>> {
        if list.is_empty() {
            return Err(scene.value_error(format!("{key}.{name}"), "lists no region"));
        }
        list.iter()
            .enumerate()
            .map(|(i, r)| region(scene, &format!("{key}.{name}[{i}]"), r))
            .collect()
    };
    Ok(match spec {
        RegionSpec::Everywhere(true) => Region::Everywhere,
        RegionSpec::Everywhere(false) => {
            return Err(scene.value_error(
                format!("{key}.everywhere"),
                "`false` selects nothing; omit the region instead",
            ));
        }
        RegionSpec::Box { lower, upper } => Region::Box {
            lower: scene.vector(&format!("{key}.box.lower"), lower)?,
            upper: scene.vector(&format!("{key}.box.upper"), upper)?,
        },
        RegionSpec::Ball { centre, radius } => Region::Ball {
            centre: scene.vector(&format!("{key}.ball.centre"), centre)?,
            radius: *radius,
        },
        RegionSpec::HalfSpace { normal, offset } => Region::HalfSpace {
            normal: scene.vector(&format!("{key}.half-space.normal"), normal)?,
            offset: *offset,
        },
        RegionSpec::Group(_) => {
            return Err(scene.value_error(
                format!("{key}.group"),
                "a physical group can only be a body's whole region",
            ));
        }
        RegionSpec::Intersection(list) => Region::Intersection(parts("intersection", list)?),
        RegionSpec::Union(list) => Region::Union(parts("union", list)?),
        RegionSpec::Difference(list) => Region::Difference(parts("difference", list)?),
    })
}

/// A point's or vector's components as "a, b, c", for messages.
pub(super) fn listed<const D: usize>(u: &SVector<f64, D>) -> String {
    u.iter()
        .map(|c| format!("{c}"))
        .collect::<Vec<_>>()
        .join(", ")
}
