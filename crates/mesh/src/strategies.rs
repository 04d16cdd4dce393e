//! Proptest strategies for random valid meshes (feature `proptest`): graded, jittered
//! intervals; jittered, rotated rectangles with any split pattern; jittered, rotated box
//! tetrahedralisations. The crate's property tests use them, and so can any crate that
//! tests code on meshes:
//!
//! ```
//! use proptest::prelude::*;
//! use umls_mesh::strategies;
//!
//! proptest!(|(mesh in strategies::rectangle())| {
//!     let area: f64 = (0..mesh.simplex_count()).map(|s| mesh.volume(s)).sum();
//!     // The rectangle [0, 2] × [0, 1], turned and jittered inside: its area stays 2.
//!     prop_assert!((area - 2.0).abs() < 1e-9);
//! });
//! ```

use proptest::prelude::*;

use crate::SimplexMesh;
use crate::generate::{Diagonal, Lattice, MAX_JITTER, Spacing};

/// Random graded, jittered interval meshes.
pub fn interval() -> impl Strategy<Value = SimplexMesh<1>> {
    (1usize..30, 0.0f64..=MAX_JITTER, any::<u64>(), 0.2f64..5.0).prop_filter_map(
        "generated mesh is valid",
        |(n, jitter, seed, ratio)| {
            Lattice::new([-1.0], [2.0], [n])
                .spacing([Spacing::Graded { ratio }])
                .jitter(jitter, seed)
                .segments()
                .ok()
        },
    )
}

/// Any triangle split pattern.
pub fn diagonal() -> impl Strategy<Value = Diagonal> {
    prop_oneof![
        Just(Diagonal::Right),
        Just(Diagonal::Left),
        Just(Diagonal::Alternating),
        Just(Diagonal::Crossed)
    ]
}

/// Random jittered, rotated rectangle meshes with any split pattern.
pub fn rectangle() -> impl Strategy<Value = SimplexMesh<2>> {
    (
        1usize..9,
        1usize..9,
        0.0f64..=MAX_JITTER,
        any::<u64>(),
        0.0f64..6.3,
        diagonal(),
    )
        .prop_filter_map(
            "generated mesh is valid",
            |(nx, ny, jitter, seed, angle, diagonal)| {
                Lattice::new([0.0, 0.0], [2.0, 1.0], [nx, ny])
                    .jitter(jitter, seed)
                    .rotate_by(angle)
                    .triangles(diagonal)
                    .ok()
            },
        )
}

/// Random jittered, rotated box tetrahedralisations.
pub fn cuboid() -> impl Strategy<Value = SimplexMesh<3>> {
    (
        1usize..5,
        1usize..5,
        1usize..5,
        0.0f64..=MAX_JITTER,
        any::<u64>(),
        0.0f64..6.3,
    )
        .prop_filter_map(
            "generated mesh is valid",
            |(nx, ny, nz, jitter, seed, angle)| {
                Lattice::new([0.0, 0.0, 0.0], [1.0, 1.5, 0.5], [nx, ny, nz])
                    .jitter(jitter, seed)
                    .rotate_about([1.0, 2.0, 3.0], angle)
                    .tetrahedra()
                    .ok()
            },
        )
}
