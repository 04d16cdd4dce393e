//! Backgrounds over the unit square that several engine tests share: a jittered 20 × 20
//! triangle lattice and a B-spline grid of the same spacing.

use std::sync::Arc;

use nalgebra::SVector;
use umls_kernels::{BSplineKernel, BSplineOrder};
use umls_mesh::generate::{Diagonal, Lattice};

/// The unit square in 20 × 20 cells, jittered by 0.2 (seed 3), alternating diagonals.
pub fn mesh() -> Arc<umls_mesh::SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [20, 20])
            .jitter(0.2, 3)
            .triangles(Diagonal::Alternating)
            .unwrap(),
    )
}

/// A B-spline grid of spacing 0.05 over the unit square.
pub fn grid(order: BSplineOrder) -> BSplineKernel<2> {
    BSplineKernel::new(SVector::from([0.0, 0.0]), 0.05, [20, 20], order).unwrap()
}
