//! Barycentric coordinates and point location against brute force.

use umls_mesh::strategies as common;

use nalgebra::SVector;
use proptest::prelude::*;
use umls_mesh::{SimplexMesh, Walk};

/// For random points (inside and outside the bounding box): BVH and walk agree with brute
/// force on inside/outside, found hosts really contain the point, and λ reconstructs it.
fn check_location<const D: usize>(
    mesh: &SimplexMesh<D>,
    fractions: &[f64],
    hint: usize,
) -> Result<(), TestCaseError> {
    let (lo, hi) = mesh.bounding_box();
    let span = hi - lo;
    for chunk in fractions.chunks_exact(D) {
        // Fractions in [−0.2, 1.2] of the bounding box: some points outside.
        let x = lo + SVector::<f64, D>::from_fn(|k, _| chunk[k] * span[k]);
        let brute = mesh.locate_brute_force(&x);
        let bvh = mesh.locate(&x);
        let walk = mesh.locate_from(&x, (hint % mesh.simplex_count()) as u32);
        prop_assert_eq!(brute.is_some(), bvh.is_some(), "bvh disagrees at {:?}", x);
        prop_assert_eq!(brute.is_some(), walk.is_some(), "walk disagrees at {:?}", x);
        for found in [bvh, walk].into_iter().flatten() {
            let lambda = found.barycentric.as_slice();
            prop_assert!((lambda.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            prop_assert!(found.barycentric.min() >= -1e-10);
            let back = mesh.point_at(found.simplex as usize, &found.barycentric);
            prop_assert!((back - x).norm() < 1e-12 * (1.0 + x.norm()));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn interval_location(mesh in common::interval(), f in prop::collection::vec(-0.2f64..1.2, 20), hint in any::<usize>()) {
        check_location(&mesh, &f, hint)?;
    }

    #[test]
    fn rectangle_location(mesh in common::rectangle(), f in prop::collection::vec(-0.2f64..1.2, 40), hint in any::<usize>()) {
        check_location(&mesh, &f, hint)?;
    }

    #[test]
    fn box_location(mesh in common::cuboid(), f in prop::collection::vec(-0.2f64..1.2, 60), hint in any::<usize>()) {
        check_location(&mesh, &f, hint)?;
    }

    /// Barycentric gradients are constant and match finite differences of λ; Σ∇λ = 0.
    #[test]
    fn barycentric_gradients_match_differences(mesh in common::cuboid(), s in any::<usize>()) {
        let s = s % mesh.simplex_count();
        let x = mesh.centroid(s);
        let grads = mesh.barycentric_gradients(s);
        let sum: SVector<f64, 3> = grads.as_slice().iter().sum();
        prop_assert!(sum.norm() < 1e-12 * grads.as_slice()[0].norm());
        let h = 1e-6 * mesh.max_edge_length();
        for k in 0..3 {
            let e = SVector::<f64, 3>::ith(k, h);
            let plus = mesh.barycentric(s, &(x + e));
            let minus = mesh.barycentric(s, &(x - e));
            for n in 0..4 {
                let fd = (plus.as_slice()[n] - minus.as_slice()[n]) / (2.0 * h);
                prop_assert!((fd - grads.as_slice()[n][k]).abs() < 1e-6 * grads.as_slice()[n].norm());
            }
        }
    }
}

#[test]
fn vertices_and_facet_points_are_found() {
    let mesh = umls_mesh::generate::Lattice::new([0.0, 0.0], [1.0, 1.0], [3, 3])
        .triangles(umls_mesh::generate::Diagonal::Right)
        .unwrap();
    for v in mesh.vertices() {
        assert!(mesh.locate(v).is_some(), "vertex {v:?} not found");
        assert!(mesh.locate_from(v, 0).is_some());
    }
    let outside = nalgebra::Vector2::new(1.0 + 1e-6, 0.5);
    assert!(mesh.locate(&outside).is_none());
    assert_eq!(mesh.walk(&outside, 0), Walk::Stuck);
    // An out-of-range hint is ignored, not a panic.
    assert!(
        mesh.locate_from(&nalgebra::Vector2::new(0.5, 0.5), 10_000)
            .is_some()
    );
}
