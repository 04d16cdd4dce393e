//! The scene's background: a Gmsh file, or a lattice split into simplices (or kept as a
//! box when only a grid kernel reads it), turned by `mesh.transform`.

use std::sync::Arc;

use nalgebra::SVector;
use umls_io::gmsh::{PhysicalGroup, ReadOptions, parse_msh};
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mesh::{Orientation, SimplexMesh};

use super::MAX_LATTICE_POINTS;
use crate::background::Background;
use crate::error::Result;
use crate::frame::SceneFrame;
use crate::scene::Scene;
use crate::schema::{DiagonalSpec, SeedingSpec};

/// The background, the lattice spacing and the file's physical groups.
pub(super) type Read<const D: usize> = (Background<D>, Option<f64>, Vec<PhysicalGroup>);

/// The scene's background, turned by `mesh.transform`; a lattice stays a box when
/// `grid_kernel` says only a grid reads it, no body is seeded at mesh quadrature
/// points and no transform turns it.
pub(super) fn mesh_for<const D: usize>(
    scene: &Scene,
    split: Split<D>,
    grid_kernel: bool,
) -> Result<Read<D>> {
    let spec = &scene.spec;
    let lean = grid_kernel
        && spec.bodies.iter().all(|b| {
            matches!(
                b.seeding,
                SeedingSpec::Lattice(_) | SeedingSpec::LatticeFrom { .. }
            )
        })
        && spec.mesh.transform.is_none();
    let (mut background, lattice_spacing, groups) = background::<D>(scene, split, lean)?;
    if spec.mesh.transform.is_some() {
        let turn =
            SceneFrame::<D>::from_spec(scene, "mesh.transform", spec.mesh.transform.as_ref())?;
        if let Background::Mesh(mesh) = &background {
            background = Background::Mesh(Arc::new(
                turn.mesh_to_world(mesh)
                    .map_err(|e| scene.value_error("mesh.transform", e.to_string()))?,
            ));
        }
    }
    Ok((background, lattice_spacing, groups))
}

/// Splits a lattice into simplices (segments, triangles with the given diagonals, or
/// tetrahedra); the generator's split exists per dimension, so the caller supplies it.
pub type Split<const D: usize> =
    fn(&Lattice<D>, Diagonal) -> std::result::Result<SimplexMesh<D>, umls_mesh::MeshError>;

/// [`Split`] for D = 1: segments.
pub fn segments(
    l: &Lattice<1>,
    _: Diagonal,
) -> std::result::Result<SimplexMesh<1>, umls_mesh::MeshError> {
    l.segments()
}

/// [`Split`] for D = 2: triangles with the given diagonals.
pub fn triangles(
    l: &Lattice<2>,
    d: Diagonal,
) -> std::result::Result<SimplexMesh<2>, umls_mesh::MeshError> {
    l.triangles(d)
}

/// [`Split`] for D = 3: Kuhn tetrahedra.
pub fn tetrahedra(
    l: &Lattice<3>,
    _: Diagonal,
) -> std::result::Result<SimplexMesh<3>, umls_mesh::MeshError> {
    l.tetrahedra()
}

/// The scene's background; a lattice is split into simplices unless `lean` (a grid
/// kernel, no mesh seeding) says no one will read them.
fn background<const D: usize>(scene: &Scene, split: Split<D>, lean: bool) -> Result<Read<D>> {
    let spec = &scene.spec.mesh;
    match (&spec.file, &spec.lattice) {
        (Some(file), None) => {
            let options = ReadOptions {
                orientation: if spec.reject_inverted {
                    Orientation::Reject
                } else {
                    Orientation::Fix
                },
            };
            let read = parse_msh::<D>(&scene.mesh_bytes(file)?, options)
                .map_err(|e| scene.value_error("mesh.file", format!("{file}: {e}")))?;
            Ok((Background::Mesh(Arc::new(read.mesh)), None, read.groups))
        }
        (None, Some(l)) => {
            let lower: SVector<f64, D> = scene.vector("mesh.lattice.lower", &l.lower)?;
            let upper: SVector<f64, D> = scene.vector("mesh.lattice.upper", &l.upper)?;
            if l.cells.len() != D {
                return Err(scene.value_error("mesh.lattice.cells", format!("needs {D} counts")));
            }
            let cells: [usize; D] = std::array::from_fn(|k| l.cells[k]);
            let total = cells.iter().map(|&n| n as f64).product::<f64>();
            if total > MAX_LATTICE_POINTS {
                return Err(scene.value_error(
                    "mesh.lattice.cells",
                    format!("{total:.3e} cells (limit {MAX_LATTICE_POINTS:.0e})"),
                ));
            }
            let spacing = (0..D)
                .map(|k| (upper[k] - lower[k]) / cells[k].max(1) as f64)
                .fold(f64::INFINITY, f64::min);
            let lattice = Lattice::new(lower.into(), upper.into(), cells).jitter(l.jitter, l.seed);
            if l.diagonal.is_some() && D != 2 {
                return Err(
                    scene.value_error("mesh.lattice.diagonal", "only 2D lattices have diagonals")
                );
            }
            let diagonal = match l.diagonal.unwrap_or_default() {
                DiagonalSpec::Alternating => Diagonal::Alternating,
                DiagonalSpec::Right => Diagonal::Right,
                DiagonalSpec::Left => Diagonal::Left,
                DiagonalSpec::Crossed => Diagonal::Crossed,
            };
            if lean {
                // The same checks as the split's, so that a scene is refused or accepted
                // alike whatever the kernel.
                lattice
                    .validate()
                    .map_err(|e| scene.value_error("mesh.lattice", e.to_string()))?;
                let frame = SceneFrame::default();
                return Ok((
                    Background::Box {
                        lower,
                        upper,
                        frame,
                    },
                    Some(spacing),
                    Vec::new(),
                ));
            }
            let mesh = split(&lattice, diagonal)
                .map_err(|e| scene.value_error("mesh.lattice", e.to_string()))?;
            Ok((Background::Mesh(Arc::new(mesh)), Some(spacing), Vec::new()))
        }
        _ => Err(scene.value_error("mesh", "give exactly one of `file` and `lattice`")),
    }
}
