//! A beam 3 × 0.5 with its left sixth embedded in a clamp region x ≤ 0, on a lattice of
//! alternating triangles that can be moved along the beam and turned under it: the
//! fixture of the clamp tests.

use std::sync::Arc;

use nalgebra::Vector2;
use umls_engine::Particles;
use umls_kernels::HostCache;
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};

/// Cell size of the lattices.
pub const H: f64 = 0.25;

/// The room [−1.5, 3.5] × [−2, 1.5] in cells of 0.25, moved by `shift` cells along −x
/// and turned by `angle` about its centre.
pub fn mesh(shift: f64, angle: f64) -> Arc<SimplexMesh<2>> {
    let dx = shift * H;
    Arc::new(
        Lattice::new([-1.5 - dx, -2.0], [3.5 - dx, 1.5], [20, 14])
            .rotate_by(angle)
            .triangles(Diagonal::Alternating)
            .unwrap(),
    )
}

/// The beam [−0.5, 2.5] × [0, 0.5], 0.125 apart; the part at x < 0 is embedded.
pub fn beam() -> Particles<2, (), HostCache<2>> {
    let mut x = Vec::new();
    for i in 0..24 {
        for j in 0..4 {
            x.push(Vector2::new(
                -0.5 + (i as f64 + 0.5) * 0.125,
                (j as f64 + 0.5) * 0.125,
            ));
        }
    }
    let n = x.len();
    Particles::at_rest(x, vec![0.125 * 0.125; n], 1000.0, ())
}
