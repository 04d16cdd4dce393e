//! What a scene runs on: a simplicial mesh, or — for a grid kernel on a `[mesh.lattice]`
//! the run never needs as simplices — just the lattice's box. A 64³ lattice split into
//! Kuhn tetrahedra is 1.57 M cells, seconds to build and about a gigabyte to hold; a
//! B-spline run on that scene only reads its box and spacing.

use std::sync::Arc;

use nalgebra::SVector;
use umls_mesh::SimplexMesh;

use crate::frame::SceneFrame;

/// The background of a run.
#[derive(Debug, Clone)]
pub enum Background<const D: usize> {
    /// A simplicial mesh (mesh kernels, Gmsh files, mesh seeding).
    Mesh(Arc<SimplexMesh<D>>),
    /// The box of a lattice whose simplices no one reads: every point of it is inside.
    Box {
        /// Lower corner.
        lower: SVector<f64, D>,
        /// Upper corner.
        upper: SVector<f64, D>,
        /// The frame the box is turned into (the world box is its bounding box).
        frame: SceneFrame<D>,
    },
}

impl<const D: usize> Background<D> {
    /// The mesh, if one was built.
    pub fn mesh(&self) -> Option<&Arc<SimplexMesh<D>>> {
        match self {
            Self::Mesh(mesh) => Some(mesh),
            Self::Box { .. } => None,
        }
    }

    /// Axis-aligned bounding box in the world.
    pub fn bounding_box(&self) -> (SVector<f64, D>, SVector<f64, D>) {
        match self {
            Self::Mesh(mesh) => mesh.bounding_box(),
            Self::Box {
                lower,
                upper,
                frame,
            } => {
                let mut world: (SVector<f64, D>, SVector<f64, D>) = (
                    SVector::from_element(f64::INFINITY),
                    SVector::from_element(f64::NEG_INFINITY),
                );
                for corner in 0..1usize << D {
                    let x = SVector::<f64, D>::from_fn(|k, _| {
                        if corner >> k & 1 == 1 {
                            upper[k]
                        } else {
                            lower[k]
                        }
                    });
                    let w = frame.point_to_world(&x);
                    world.0 = world.0.inf(&w);
                    world.1 = world.1.sup(&w);
                }
                world
            }
        }
    }

    /// Whether a scene-frame point lies in the domain (before any turning).
    pub fn contains(&self, x: &SVector<f64, D>) -> bool {
        match self {
            Self::Mesh(mesh) => mesh.locate(x).is_some(),
            Self::Box { lower, upper, .. } => (0..D).all(|k| lower[k] <= x[k] && x[k] <= upper[k]),
        }
    }

    /// Number of simplices, if there is a mesh.
    pub fn cell_count(&self) -> Option<usize> {
        self.mesh().map(|m| m.simplex_count())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, Vector2};

    #[test]
    fn a_turned_box_is_bounded_by_its_turned_corners() {
        let (s, c) = 90f64.to_radians().sin_cos();
        let b = Background::<2>::Box {
            lower: Vector2::new(0.0, 0.0),
            upper: Vector2::new(1.0, 4.0),
            frame: SceneFrame {
                rotation: SMatrix::<f64, 2, 2>::new(c, -s, s, c),
                centre: Vector2::zeros(),
            },
        };
        let (lo, hi) = b.bounding_box();
        assert!((lo - Vector2::new(-4.0, 0.0)).norm() < 1e-15, "{lo}");
        assert!((hi - Vector2::new(0.0, 1.0)).norm() < 1e-15, "{hi}");
        assert!(b.contains(&Vector2::new(0.5, 4.0)));
        assert!(!b.contains(&Vector2::new(0.5, 4.0 + 1e-12)));
        assert_eq!(b.cell_count(), None);
    }
}
