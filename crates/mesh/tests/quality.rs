//! Quality measures against closed-form values, and generator options.

use std::f64::consts::PI;

use nalgebra::{Vector2, Vector3};
use umls_mesh::generate::{Diagonal, Lattice, Spacing};
use umls_mesh::{MeshError, Orientation, SimplexMesh};

#[test]
fn equilateral_triangle_and_regular_tetrahedron_score_one() {
    let h = 3f64.sqrt() / 2.0;
    let tri = SimplexMesh::new(
        vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.5, h),
        ],
        vec![0, 1, 2],
        Orientation::Fix,
    )
    .unwrap();
    let q = tri.simplex_quality(0);
    assert!((q.radius_ratio - 1.0).abs() < 1e-14);
    assert!((q.min_angle.unwrap() - PI / 3.0).abs() < 1e-14);
    assert!((q.max_angle.unwrap() - PI / 3.0).abs() < 1e-14);
    assert!((q.edge_ratio - 1.0).abs() < 1e-14);

    let s = 1.0 / 2f64.sqrt();
    let tet = SimplexMesh::new(
        vec![
            Vector3::new(1.0, 0.0, -s),
            Vector3::new(-1.0, 0.0, -s),
            Vector3::new(0.0, 1.0, s),
            Vector3::new(0.0, -1.0, s),
        ],
        vec![0, 1, 2, 3],
        Orientation::Fix,
    )
    .unwrap();
    let q = tet.simplex_quality(0);
    assert!((q.radius_ratio - 1.0).abs() < 1e-14);
    // Regular tetrahedron dihedral angle: acos(1/3).
    assert!((q.min_angle.unwrap() - (1.0f64 / 3.0).acos()).abs() < 1e-14);
}

#[test]
fn right_isosceles_triangle_values() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [1, 1])
        .triangles(Diagonal::Right)
        .unwrap();
    let q = mesh.simplex_quality(0);
    // r = (2 − √2)/2, R = √2/2 → 2r/R = 2√2 − 2.
    assert!((q.radius_ratio - (2.0 * 2f64.sqrt() - 2.0)).abs() < 1e-14);
    assert!((q.min_angle.unwrap() - PI / 4.0).abs() < 1e-14);
    assert!((q.max_angle.unwrap() - PI / 2.0).abs() < 1e-14);
    assert!((q.edge_ratio - 2f64.sqrt()).abs() < 1e-14);
    let summary = mesh.quality_summary();
    assert_eq!(summary.simplices, 2);
    assert!((summary.max_volume - 0.5).abs() < 1e-15);
}

#[test]
fn kuhn_tetrahedra_dihedral_angles() {
    // Every Kuhn (path) tetrahedron has dihedral angles 45°, 60° and 90° only.
    let mesh = Lattice::new([0.0; 3], [1.0; 3], [2, 2, 2])
        .tetrahedra()
        .unwrap();
    let summary = mesh.quality_summary();
    assert!((summary.min_angle.unwrap() - PI / 4.0).abs() < 1e-12);
    assert!((summary.max_angle.unwrap() - PI / 2.0).abs() < 1e-12);
    assert_eq!(mesh.simplex_count(), 48);
    assert!((summary.min_volume - summary.max_volume).abs() < 1e-15);
}

#[test]
fn graded_spacing_has_requested_ratio() {
    let mesh = Lattice::new([0.0], [1.0], [10])
        .spacing([Spacing::Graded { ratio: 4.0 }])
        .segments()
        .unwrap();
    let first = mesh.volume(0);
    let last = mesh.volume(9);
    assert!((last / first - 4.0).abs() < 1e-12);
    assert!((mesh.total_volume() - 1.0).abs() < 1e-14);
}

#[test]
fn rotation_preserves_quality_and_volume() {
    let base = Lattice::new([0.0, 0.0], [2.0, 1.0], [6, 3]).jitter(0.2, 3);
    let plain = base.clone().triangles(Diagonal::Alternating).unwrap();
    let turned = base
        .rotate_by(0.7)
        .triangles(Diagonal::Alternating)
        .unwrap();
    let (a, b) = (plain.quality_summary(), turned.quality_summary());
    assert!((a.min_radius_ratio - b.min_radius_ratio).abs() < 1e-12);
    assert!((plain.total_volume() - turned.total_volume()).abs() < 1e-12);
    assert!(
        plain
            .vertices()
            .iter()
            .zip(turned.vertices())
            .any(|(p, q)| (p - q).norm() > 0.1)
    );
}

#[test]
fn generator_rejects_bad_parameters() {
    let err = Lattice::new([0.0, 0.0], [1.0, 1.0], [0, 3])
        .triangles(Diagonal::Right)
        .unwrap_err();
    assert!(matches!(
        err,
        MeshError::InvalidParameter {
            parameter: "cells",
            ..
        }
    ));
    let err = Lattice::new([0.0], [1.0], [3])
        .jitter(0.6, 1)
        .segments()
        .unwrap_err();
    assert!(matches!(
        err,
        MeshError::InvalidParameter {
            parameter: "jitter",
            ..
        }
    ));
    let err = Lattice::new([1.0], [0.0], [3]).segments().unwrap_err();
    assert!(matches!(
        err,
        MeshError::InvalidParameter {
            parameter: "lower/upper",
            ..
        }
    ));
    let err = Lattice::new([0.0; 3], [1.0; 3], [1, 1, 1])
        .rotate_about([0.0; 3], 1.0)
        .tetrahedra()
        .unwrap_err();
    assert!(matches!(
        err,
        MeshError::InvalidParameter {
            parameter: "rotation",
            ..
        }
    ));
    let err = Lattice::new([0.0], [1.0], [3])
        .spacing([Spacing::Graded { ratio: -1.0 }])
        .segments()
        .unwrap_err();
    assert!(matches!(
        err,
        MeshError::InvalidParameter {
            parameter: "spacing ratio",
            ..
        }
    ));
}

#[test]
fn crossed_pattern_adds_centres() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [3, 2])
        .jitter(0.2, 9)
        .triangles(Diagonal::Crossed)
        .unwrap();
    assert_eq!(mesh.vertex_count(), 12 + 6);
    assert_eq!(mesh.simplex_count(), 24);
    assert_eq!(mesh.entity_counts().euler_characteristic(), 1);
}

/// Sample volumes sum to the mesh volume; the centroid rule integrates linear fields and
/// the Gauss rule quadratic fields exactly, in 1D, 2D and 3D.
#[test]
fn sample_rules_integrate_exactly() {
    use umls_mesh::SampleRule;
    fn check<const D: usize>(mesh: &SimplexMesh<D>, exact_linear: f64, exact_quadratic: f64) {
        let linear = |x: &nalgebra::SVector<f64, D>| {
            1.0 + x
                .iter()
                .enumerate()
                .map(|(k, c)| (k as f64 + 1.0) * c)
                .sum::<f64>()
        };
        let quadratic =
            |x: &nalgebra::SVector<f64, D>| x.iter().map(|c| c * c).sum::<f64>() + x[0] * x[D - 1];
        for rule in [SampleRule::Centroid, SampleRule::Gauss2] {
            let samples = mesh.sample_points(rule);
            assert_eq!(samples.len(), mesh.simplex_count() * rule.count(D));
            let volume: f64 = samples.iter().map(|(_, v)| v).sum();
            assert!((volume - mesh.total_volume()).abs() < 1e-12);
            let integral: f64 = samples.iter().map(|(x, v)| linear(x) * v).sum();
            assert!(
                (integral - exact_linear).abs() < 1e-12,
                "{rule:?} linear: {integral} vs {exact_linear}"
            );
            if rule == SampleRule::Gauss2 {
                let integral: f64 = samples.iter().map(|(x, v)| quadratic(x) * v).sum();
                assert!(
                    (integral - exact_quadratic).abs() < 1e-12,
                    "quadratic: {integral} vs {exact_quadratic}"
                );
            }
            for (x, _) in &samples {
                assert!(mesh.locate(x).is_some());
            }
        }
    }
    // On [0, 1]^D: ∫ 1 + Σ (k+1) x_k = 1 + Σ (k+1)/2; ∫ Σ x_k² + x_0 x_{D−1} = D/3 + (1/3 if D = 1 else 1/4).
    check(
        &Lattice::new([0.0], [1.0], [7])
            .jitter(0.2, 1)
            .segments()
            .unwrap(),
        1.5,
        1.0 / 3.0 + 1.0 / 3.0,
    );
    check(
        &Lattice::new([0.0; 2], [1.0; 2], [5, 4])
            .jitter(0.2, 2)
            .triangles(Diagonal::Crossed)
            .unwrap(),
        1.0 + 0.5 + 1.0,
        2.0 / 3.0 + 0.25,
    );
    check(
        &Lattice::new([0.0; 3], [1.0; 3], [3, 3, 3])
            .jitter(0.2, 3)
            .tetrahedra()
            .unwrap(),
        1.0 + 0.5 + 1.0 + 1.5,
        1.0 + 0.25,
    );
}

/// The mean element size of a lattice of cells h is h for every split and every jitter,
/// while the longest edge grows with the jitter (what made it a poor default for a grid's
/// spacing on a mesh).
#[test]
fn mean_element_size_of_a_lattice_is_its_cell_size_under_jitter() {
    let h = 0.05;
    for jitter in [0.0, 0.1, 0.2] {
        for diagonal in [Diagonal::Right, Diagonal::Alternating, Diagonal::Crossed] {
            let mesh = Lattice::new([0.0, 0.0], [1.0, 0.5], [20, 10])
                .jitter(jitter, 3)
                .triangles(diagonal)
                .unwrap();
            // The crossed split has four triangles per cell: (2 · h²/4)^(1/2) = h/√2.
            let expected = if diagonal == Diagonal::Crossed {
                h / 2f64.sqrt()
            } else {
                h
            };
            let size = mesh.mean_element_size();
            assert!(
                (size - expected).abs() < 1e-12,
                "{jitter} {diagonal:?}: {size}"
            );
        }
        let tets = Lattice::new([0.0; 3], [1.0, 0.5, 0.5], [20, 10, 10])
            .jitter(jitter, 3)
            .tetrahedra()
            .unwrap();
        assert!((tets.mean_element_size() - h).abs() < 1e-12, "{jitter}");
        if jitter > 0.0 {
            assert!(tets.max_edge_length() / 3f64.sqrt() > 1.05 * h, "{jitter}");
        }
    }
}

/// In 2D the jitter reaches slivers: at 0.45 of the cell every split but the crossed one
/// builds for many seeds, every triangle keeps a positive area (the mesh is built
/// rejecting inverted simplices), and triangles with an angle near 180° appear. Up to the
/// 3D bound no cell takes the other diagonal, so those meshes are the plain splits.
#[test]
fn planar_jitter_reaches_slivers_without_inverting_a_triangle() {
    let mut widest = 0.0f64;
    for seed in 0..40 {
        for diagonal in [Diagonal::Alternating, Diagonal::Right, Diagonal::Left] {
            let lattice = Lattice::new([0.0, 0.0], [1.0, 1.0], [12, 12]).jitter(0.45, seed);
            let mesh = lattice
                .triangles(diagonal)
                .unwrap_or_else(|e| panic!("seed {seed}, {diagonal:?}: {e}"));
            assert_eq!(mesh.simplex_count(), 2 * 144);
            for s in 0..mesh.simplex_count() {
                widest = widest.max(mesh.simplex_quality(s).max_angle.unwrap());
            }
        }
        // At 0.2 the chosen diagonal is kept in every cell: the first triangle of cell 0
        // of the right split is (v00, v10, v11).
        let mild = Lattice::new([0.0, 0.0], [1.0, 1.0], [12, 12]).jitter(0.2, seed);
        let right = mild.triangles(Diagonal::Right).unwrap();
        let plain = Lattice::new([0.0, 0.0], [1.0, 1.0], [12, 12])
            .triangles(Diagonal::Right)
            .unwrap();
        for s in 0..right.simplex_count() {
            let mut a = right.simplex(s).to_vec();
            let mut b = plain.simplex(s).to_vec();
            a.sort_unstable();
            b.sort_unstable();
            assert_eq!(
                a, b,
                "seed {seed}: cell of simplex {s} changed its diagonal at 0.2"
            );
        }
    }
    assert!(
        widest > 170f64.to_radians(),
        "widest angle {}°",
        widest.to_degrees()
    );
    // Beyond ½ a cell can fold: refused, naming the parameter and the 2D bound.
    let err = Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4])
        .jitter(0.5, 1)
        .triangles(Diagonal::Right)
        .unwrap_err()
        .to_string();
    assert!(err.contains("jitter") && err.contains("0.45"), "{err}");
    // 3D keeps its bound.
    let err = Lattice::new([0.0; 3], [1.0; 3], [2; 3])
        .jitter(0.3, 1)
        .tetrahedra()
        .unwrap_err()
        .to_string();
    assert!(err.contains("0.2"), "{err}");
}
