//! Every kind of bad input gives the matching typed error; no input panics.

use nalgebra::{Vector1, Vector2, Vector3};
use proptest::prelude::*;
use umls_mesh::{MeshError, Orientation, SimplexMesh};

fn square() -> Vec<Vector2<f64>> {
    vec![
        Vector2::new(0.0, 0.0),
        Vector2::new(1.0, 0.0),
        Vector2::new(1.0, 1.0),
        Vector2::new(0.0, 1.0),
    ]
}

#[test]
fn rejects_out_of_range_index_naming_simplex_and_slot() {
    let err = SimplexMesh::new(square(), vec![0, 1, 2, 0, 2, 7], Orientation::Fix).unwrap_err();
    assert_eq!(
        err,
        MeshError::VertexIndexOutOfRange {
            simplex: 1,
            local: 2,
            index: 7,
            vertex_count: 4
        }
    );
    assert!(err.to_string().contains("simplex 1"));
}

#[test]
fn rejects_repeated_vertex() {
    let err = SimplexMesh::new(square(), vec![0, 1, 1], Orientation::Fix).unwrap_err();
    assert_eq!(
        err,
        MeshError::RepeatedVertex {
            simplex: 0,
            vertex: 1
        }
    );
}

#[test]
fn rejects_degenerate_triangle() {
    let mut v = square();
    v.push(Vector2::new(2.0, 0.0));
    let err = SimplexMesh::new(v, vec![0, 1, 2, 0, 1, 4], Orientation::Fix).unwrap_err();
    assert!(
        matches!(err, MeshError::DegenerateSimplex { simplex: 1, .. }),
        "{err}"
    );
}

#[test]
fn inverted_simplex_is_fixed_or_rejected() {
    // (0, 2, 1) is clockwise.
    let err = SimplexMesh::new(square(), vec![0, 1, 2, 0, 3, 2], Orientation::Reject).unwrap_err();
    assert!(
        matches!(err, MeshError::InvertedSimplex { simplex: 1, .. }),
        "{err}"
    );
    let mesh = SimplexMesh::new(square(), vec![0, 1, 2, 0, 3, 2], Orientation::Fix).unwrap();
    assert!((mesh.volume(1) - 0.5).abs() < 1e-15);
    assert_eq!(mesh.simplex(1), &[0, 2, 3]);
}

#[test]
fn rejects_non_manifold_facet() {
    let mut v = square();
    v.push(Vector2::new(0.5, -1.0));
    // Edge 0-1 is shared by three triangles.
    let err = SimplexMesh::new(v, vec![0, 1, 2, 0, 1, 3, 0, 4, 1], Orientation::Fix).unwrap_err();
    match err {
        MeshError::NonManifoldFacet { facet, third, .. } => {
            assert_eq!(facet, vec![0, 1]);
            assert_eq!(third, 2);
        }
        other => panic!("unexpected {other}"),
    }
}

#[test]
fn rejects_bad_lengths_empty_and_non_finite() {
    assert_eq!(
        SimplexMesh::new(square(), vec![0, 1, 2, 3], Orientation::Fix).unwrap_err(),
        MeshError::ConnectivityLength { len: 4, stride: 3 }
    );
    assert!(matches!(
        SimplexMesh::<2>::new(square(), vec![], Orientation::Fix).unwrap_err(),
        MeshError::Empty { simplices: 0, .. }
    ));
    let mut v = square();
    v[2].y = f64::NAN;
    assert_eq!(
        SimplexMesh::new(v, vec![0, 1, 2], Orientation::Fix).unwrap_err(),
        MeshError::NonFiniteCoordinate { vertex: 2, axis: 1 }
    );
    assert_eq!(
        SimplexMesh::from_arrays(square(), &[[0u32, 1]], Orientation::Fix).unwrap_err(),
        MeshError::ConnectivityLength { len: 2, stride: 3 }
    );
}

#[test]
fn one_and_three_dimensional_validation() {
    let line = vec![Vector1::new(0.0), Vector1::new(1.0), Vector1::new(1.0)];
    assert!(matches!(
        SimplexMesh::new(line, vec![0, 1, 1, 2], Orientation::Fix).unwrap_err(),
        MeshError::RepeatedVertex {
            simplex: 1,
            vertex: 1
        } | MeshError::DegenerateSimplex { simplex: 1, .. }
    ));
    let tet = vec![
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, 1.0),
    ];
    let err = SimplexMesh::new(tet.clone(), vec![0, 2, 1, 3], Orientation::Reject).unwrap_err();
    assert!(matches!(err, MeshError::InvertedSimplex { simplex: 0, .. }));
    let fixed = SimplexMesh::new(tet, vec![0, 2, 1, 3], Orientation::Fix).unwrap();
    assert!((fixed.volume(0) - 1.0 / 6.0).abs() < 1e-15);
}

proptest! {
    /// Arbitrary coordinates and connectivity: construction returns Ok or Err, never panics,
    /// and an Ok mesh has positive volumes only.
    #[test]
    fn arbitrary_input_never_panics(
        coords in prop::collection::vec((-2.0f64..2.0, -2.0f64..2.0), 0..12),
        conn in prop::collection::vec(0u32..14, 0..40),
    ) {
        let vertices: Vec<Vector2<f64>> = coords.into_iter().map(|(x, y)| Vector2::new(x, y)).collect();
        if let Ok(mesh) = SimplexMesh::new(vertices, conn, Orientation::Fix) {
            prop_assert!((0..mesh.simplex_count()).all(|s| mesh.volume(s) > 0.0));
        }
    }
}

/// Validation runs in parallel chunks of simplices; with invalid simplices in several
/// chunks the error is still the first one in simplex order, on any number of threads,
/// and inverted simplices are fixed in every chunk.
#[test]
fn the_first_invalid_simplex_is_reported_whatever_the_chunking_and_threads() {
    use umls_mesh::generate::{Diagonal, Lattice};
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [120, 120])
        .triangles(Diagonal::Right)
        .expect("valid lattice");
    let vertices = mesh.vertices().to_vec();
    let good: Vec<u32> = mesh.connectivity().to_vec();
    let n = mesh.simplex_count();
    assert!(n > 3 * 4096, "the mesh must span several validation chunks");
    let (early, late) = (5_000, n - 10);
    let mut bad = good.clone();
    // A repeated vertex late, an out-of-range index early: the early one is reported.
    bad[late * 3 + 1] = bad[late * 3];
    bad[early * 3 + 2] = vertices.len() as u32 + 3;
    // Inverted simplices in the first and the last chunk are fixed (Orientation::Fix).
    let mut inverted = good.clone();
    for s in [1, n - 2] {
        inverted.swap(s * 3 + 1, s * 3 + 2);
    }
    for threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let err = pool
            .install(|| SimplexMesh::new(vertices.clone(), bad.clone(), Orientation::Fix))
            .unwrap_err();
        assert_eq!(
            err,
            MeshError::VertexIndexOutOfRange {
                simplex: early,
                local: 2,
                index: vertices.len() as u32 + 3,
                vertex_count: vertices.len(),
            },
            "{threads} threads"
        );
        let fixed = pool
            .install(|| SimplexMesh::new(vertices.clone(), inverted.clone(), Orientation::Fix))
            .expect("inverted simplices are fixed");
        assert!((0..n).all(|s| fixed.volume(s) > 0.0));
        assert_eq!(fixed.total_volume(), mesh.total_volume());
        let rejected = pool
            .install(|| SimplexMesh::new(vertices.clone(), inverted.clone(), Orientation::Reject))
            .unwrap_err();
        assert!(
            matches!(rejected, MeshError::InvertedSimplex { simplex: 1, .. }),
            "{rejected}"
        );
    }
}
