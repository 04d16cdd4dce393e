//! Shared mesh strategies and helpers for the MLS property tests.
#![allow(dead_code)]

use nalgebra::SVector;
use proptest::prelude::*;
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice, MAX_JITTER};

/// Random graded, jittered interval meshes.
pub fn interval() -> impl Strategy<Value = SimplexMesh<1>> {
    (4usize..20, 0.0f64..=MAX_JITTER, any::<u64>()).prop_filter_map(
        "generated mesh is valid",
        |(n, jitter, seed)| {
            Lattice::new([-1.0], [1.0], [n])
                .jitter(jitter, seed)
                .segments()
                .ok()
        },
    )
}

/// Random jittered, rotated rectangle meshes with any split pattern.
pub fn rectangle() -> impl Strategy<Value = SimplexMesh<2>> {
    let diagonal = prop_oneof![
        Just(Diagonal::Right),
        Just(Diagonal::Alternating),
        Just(Diagonal::Crossed)
    ];
    (
        3usize..8,
        3usize..8,
        0.0f64..=MAX_JITTER,
        any::<u64>(),
        0.0f64..6.3,
        diagonal,
    )
        .prop_filter_map(
            "generated mesh is valid",
            |(nx, ny, jitter, seed, angle, diagonal)| {
                Lattice::new([0.0, 0.0], [1.0, 1.0], [nx, ny])
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
        2usize..4,
        2usize..4,
        2usize..4,
        0.0f64..=MAX_JITTER,
        any::<u64>(),
        0.0f64..6.3,
    )
        .prop_filter_map(
            "generated mesh is valid",
            |(nx, ny, nz, jitter, seed, angle)| {
                Lattice::new([0.0; 3], [1.0; 3], [nx, ny, nz])
                    .jitter(jitter, seed)
                    .rotate_about([0.3, -1.0, 0.5], angle)
                    .tetrahedra()
                    .ok()
            },
        )
}

/// A point inside simplex `s` from D+1 positive weights (normalised to barycentric coordinates).
pub fn point_in<const D: usize>(mesh: &SimplexMesh<D>, s: usize, raw: &[f64]) -> SVector<f64, D> {
    let total: f64 = raw[..=D].iter().sum();
    mesh.simplex(s)
        .iter()
        .zip(raw)
        .fold(SVector::zeros(), |acc, (&v, &w)| {
            acc + mesh.vertex(v as usize) * (w / total)
        })
}

/// Whether every vertex of simplex `s` is interior (its 1-ring is complete).
pub fn is_interior<const D: usize>(mesh: &SimplexMesh<D>, s: usize) -> bool {
    mesh.simplex(s).iter().all(|v| {
        mesh.topology()
            .boundary_vertices()
            .binary_search(v)
            .is_err()
    })
}

/// Simplices whose vertices are all interior, or every simplex if there are none.
pub fn interior_simplices<const D: usize>(mesh: &SimplexMesh<D>) -> Vec<usize> {
    let interior: Vec<usize> = (0..mesh.simplex_count())
        .filter(|&s| is_interior(mesh, s))
        .collect();
    assert!(
        !interior.is_empty(),
        "mesh too coarse to have interior simplices"
    );
    interior
}

/// A larger box for the quadratic basis: enough cells for simplices with complete 1-rings.
pub fn fine_cuboid() -> impl Strategy<Value = SimplexMesh<3>> {
    (4usize..6, 0.0f64..=MAX_JITTER, any::<u64>(), 0.0f64..6.3).prop_filter_map(
        "generated mesh is valid",
        |(n, jitter, seed, angle)| {
            Lattice::new([0.0; 3], [1.0; 3], [n, n, n])
                .jitter(jitter, seed)
                .rotate_about([0.3, -1.0, 0.5], angle)
                .tetrahedra()
                .ok()
        },
    )
}

/// Node indices, shape-function values and gradients of one stencil.
pub type Entries<const D: usize> = (Vec<u32>, Vec<f64>, Vec<SVector<f64, D>>);

/// `kernel.evaluate_into` at `x` in simplex `s` into vectors of the 1-ring's length: the
/// entries and the condition number.
pub fn evaluate_into_vecs<const D: usize, const N: usize, B: umls_mls::PolynomialBasis<D, N>>(
    kernel: &umls_mls::UmlsKernel<D>,
    mesh: &SimplexMesh<D>,
    s: usize,
    x: &SVector<f64, D>,
    gradient: umls_mls::GradientKind,
) -> Result<(Entries<D>, f64), umls_mls::MlsError> {
    let ring = mesh.topology().one_ring(s).len();
    let (mut nodes, mut values) = (vec![0u32; ring], vec![0.0; ring]);
    let mut gradients = vec![SVector::<f64, D>::zeros(); ring];
    let located = umls_mesh::Located {
        simplex: s as u32,
        barycentric: mesh.barycentric(s, x),
    };
    let condition = kernel.evaluate_into::<N, B>(
        mesh,
        &located,
        x,
        gradient,
        &mut nodes,
        &mut values,
        &mut gradients,
    )?;
    Ok(((nodes, values, gradients), condition))
}

/// The same nodes, and values and gradients equal to the last bit.
pub fn same_entries<const D: usize>(
    got: (&[u32], &[f64], &[SVector<f64, D>]),
    expected: (&[u32], &[f64], &[SVector<f64, D>]),
) -> Result<(), TestCaseError> {
    prop_assert_eq!(got.0, expected.0);
    prop_assert_eq!(got.1.len(), expected.1.len());
    for (a, b) in got.1.iter().zip(expected.1) {
        prop_assert_eq!(a.to_bits(), b.to_bits(), "N {} against {}", a, b);
    }
    prop_assert_eq!(got.2.len(), expected.2.len());
    for (a, b) in got.2.iter().zip(expected.2) {
        for (p, q) in a.iter().zip(b.iter()) {
            prop_assert_eq!(p.to_bits(), q.to_bits(), "∇N {} against {}", a, b);
        }
    }
    Ok(())
}
