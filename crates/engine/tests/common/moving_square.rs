//! A square block of particles, [0.3, 0.7]², moving with a given velocity field on a
//! quadratic B-spline grid of spacing 0.1 around it: the scene of the tests that follow
//! the stresses and deformation gradients a step leaves.

use nalgebra::Vector2;
use umls_engine::Particles;
use umls_kernels::{BSplineKernel, BSplineOrder};

/// The grid: 14 × 14 cells of 0.1 from (−0.2, −0.2).
pub fn grid() -> BSplineKernel<2> {
    BSplineKernel::new(
        Vector2::new(-0.2, -0.2),
        0.1,
        [14, 14],
        BSplineOrder::Quadratic,
    )
    .unwrap()
}

/// The block's particles, `spacing` apart, density 1000, with velocity `velocity(x)`.
pub fn particles<S: Clone, C: Copy + Default>(
    spacing: f64,
    state: S,
    velocity: impl Fn(&Vector2<f64>) -> Vector2<f64>,
) -> Particles<2, S, C> {
    let (x, volume): (Vec<Vector2<f64>>, Vec<f64>) =
        umls_engine::lattice_points(Vector2::new(0.3, 0.3), Vector2::new(0.7, 0.7), spacing)
            .unzip();
    let mut particles = Particles::at_rest(x, volume, 1000.0, state);
    for (v, x) in particles.velocity.iter_mut().zip(&particles.position) {
        *v = velocity(x);
    }
    particles
}
