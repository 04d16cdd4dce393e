//! Ill-conditioned moment matrices: typed errors naming the simplex, or the documented
//! regularisation; and the other error paths of the UMLS kernel.

use nalgebra::{Vector1, Vector2};
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mls::{
    Conditioning, CubicBSpline, DEFAULT_SUPPORT_FACTOR, GradientKind, IllConditionedPolicy, Linear,
    MlsError, Quadratic, Stencil, SupportRadius, UmlsKernel, WeightFunction, WendlandC2,
};

/// At the end vertex of a 1D mesh only two samples carry weight (η of the third vanishes),
/// too few for three quadratic monomials.
#[test]
fn too_few_weighted_samples_fail_naming_the_simplex() {
    let line = Lattice::new([0.0], [1.0], [6]).segments().unwrap();
    let kernel = UmlsKernel::new(&line);
    let mut st = Stencil::new();
    let err = kernel
        .evaluate::<3, Quadratic>(
            &line,
            0,
            &Vector1::new(0.0),
            GradientKind::Reconstructed,
            &mut st,
        )
        .unwrap_err();
    match &err {
        MlsError::IllConditioned {
            simplex,
            samples,
            basis,
            ..
        } => {
            assert_eq!((*simplex, *samples, *basis), (Some(0), 2, 3));
        }
        other => panic!("unexpected {other}"),
    }
    assert!(err.to_string().contains("in simplex 0"), "{err}");
    // The linear basis is fine there, and reproduces x exactly.
    kernel
        .evaluate::<2, Linear>(
            &line,
            0,
            &Vector1::new(0.0),
            GradientKind::Reconstructed,
            &mut st,
        )
        .unwrap();
    let x: f64 = st
        .iter()
        .map(|(v, n, _)| n * line.vertex(v as usize)[0])
        .sum();
    assert!(x.abs() < 1e-15);
}

#[test]
fn regularisation_keeps_partition_of_unity() {
    let line = Lattice::new([0.0], [1.0], [6]).segments().unwrap();
    let mut kernel = UmlsKernel::new(&line);
    kernel.conditioning = Conditioning {
        policy: IllConditionedPolicy::Regularize { strength: 1e-6 },
        ..Conditioning::default()
    };
    let mut st = Stencil::new();
    kernel
        .evaluate::<3, Quadratic>(&line, 0, &Vector1::new(0.0), GradientKind::Full, &mut st)
        .unwrap();
    let sum: f64 = st.values().iter().sum();
    assert!((sum - 1.0).abs() < 1e-12, "partition of unity {sum}");
    // Linear reproduction degrades by O(strength) only.
    let x: f64 = st
        .iter()
        .map(|(v, n, _)| n * line.vertex(v as usize)[0])
        .sum();
    assert!(x.abs() < 1e-5, "x = {x}");
    assert!(st.condition_number().is_finite());
}

/// A sliver mesh (aspect ratio 10⁷): every stencil is nearly collinear and the linear
/// moment matrix is ill-conditioned.
#[test]
fn sliver_elements_are_detected_and_regularised() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1e-7], [8, 2])
        .triangles(Diagonal::Right)
        .unwrap();
    let mut kernel = UmlsKernel::new(&mesh);
    let mut st = Stencil::new();
    let x = mesh.centroid(5);
    let err = kernel
        .evaluate::<3, Linear>(&mesh, 5, &x, GradientKind::Reconstructed, &mut st)
        .unwrap_err();
    match err {
        MlsError::IllConditioned {
            simplex,
            condition,
            limit,
            ..
        } => {
            assert_eq!(simplex, Some(5));
            assert!(
                condition > limit && condition > 1e12,
                "condition {condition}"
            );
        }
        other => panic!("unexpected {other}"),
    }
    kernel.conditioning.policy = IllConditionedPolicy::Regularize { strength: 1e-8 };
    kernel
        .evaluate::<3, Linear>(&mesh, 5, &x, GradientKind::Reconstructed, &mut st)
        .unwrap();
    assert!((st.values().iter().sum::<f64>() - 1.0).abs() < 1e-12);
    // Along the well-resolved axis the fit still reproduces x.
    let x_fit: f64 = st
        .iter()
        .map(|(v, n, _)| n * mesh.vertex(v as usize).x)
        .sum();
    assert!((x_fit - x.x).abs() < 1e-6);
}

#[test]
fn well_shaped_stencils_are_well_conditioned() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [10, 10])
        .jitter(0.2, 2)
        .triangles(Diagonal::Alternating)
        .unwrap();
    let kernel = UmlsKernel::new(&mesh);
    let mut st = Stencil::new();
    let worst = (0..mesh.simplex_count())
        .map(|s| {
            kernel
                .evaluate::<3, Linear>(
                    &mesh,
                    s as u32,
                    &mesh.centroid(s),
                    GradientKind::Reconstructed,
                    &mut st,
                )
                .unwrap();
            st.condition_number()
        })
        .fold(0.0, f64::max);
    eprintln!("worst condition number, linear basis, jittered 10x10: {worst:.1}");
    assert!(worst < 1e3, "{worst}");
}

#[test]
fn kernel_error_paths() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [3, 3])
        .triangles(Diagonal::Right)
        .unwrap();
    let kernel = UmlsKernel::new(&mesh);
    let mut st = Stencil::new();
    let far = Vector2::new(5.0, 5.0);
    assert!(matches!(
        kernel.evaluate::<3, Linear>(&mesh, 0, &far, GradientKind::Reconstructed, &mut st),
        Err(MlsError::OutsideHost { simplex: 0, .. })
    ));
    assert!(matches!(
        kernel.evaluate::<3, Linear>(&mesh, 99, &far, GradientKind::Reconstructed, &mut st),
        Err(MlsError::NoSuchSimplex {
            simplex: 99,
            count: 18
        })
    ));
    assert!(matches!(
        kernel.evaluate_at::<3, Linear>(&mesh, &far, Some(0), GradientKind::Reconstructed, &mut st),
        Err(MlsError::OutsideMesh { .. })
    ));
    let other = Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4])
        .triangles(Diagonal::Right)
        .unwrap();
    assert!(matches!(
        kernel.evaluate::<3, Linear>(
            &other,
            0,
            &other.centroid(0),
            GradientKind::Reconstructed,
            &mut st
        ),
        Err(MlsError::InvalidParameter {
            parameter: "mesh vertex count",
            ..
        })
    ));
    assert!(
        UmlsKernel::with_weight(&mesh, WendlandC2, SupportRadius::Global { factor: 0.0 }).is_err()
    );
    // Field shorter than the node indices.
    kernel
        .evaluate::<3, Linear>(
            &mesh,
            0,
            &mesh.centroid(0),
            GradientKind::Reconstructed,
            &mut st,
        )
        .unwrap();
    assert!(matches!(
        st.interpolate(&[1.0, 2.0]),
        Err(MlsError::FieldTooShort { len: 2, .. })
    ));
}

/// The per-vertex reach keeps every stencil distance within r ≤ 1 (so d_v ≥ W(1) > 0);
/// the incident-edge rule (the default) reaches every vertex of every simplex a vertex
/// belongs to within its support 2h_v, so host vertices always weigh; the global rule
/// uses the longest edge.
#[test]
fn support_radii_cover_every_stencil() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [6, 6])
        .jitter(0.2, 8)
        .triangles(Diagonal::Crossed)
        .unwrap();
    let reach = UmlsKernel::with_weight(
        &mesh,
        CubicBSpline,
        SupportRadius::PerVertex { factor: 1.0 },
    )
    .unwrap();
    for s in 0..mesh.simplex_count() {
        for &v in mesh.topology().one_ring(s).vertices {
            for &n in mesh.simplex(s) {
                let d = (mesh.vertex(v as usize) - mesh.vertex(n as usize)).norm();
                assert!(d <= reach.support_radii()[v as usize] * (1.0 + 1e-12));
            }
        }
    }
    let incident = UmlsKernel::new(&mesh);
    assert_eq!(
        SupportRadius::default(),
        SupportRadius::IncidentEdge {
            factor: DEFAULT_SUPPORT_FACTOR
        }
    );
    for s in 0..mesh.simplex_count() {
        let simplex = mesh.simplex(s);
        for &v in simplex {
            let h = incident.support_radii()[v as usize];
            let longest = simplex
                .iter()
                .map(|&n| (mesh.vertex(v as usize) - mesh.vertex(n as usize)).norm())
                .fold(0.0, f64::max);
            assert!(
                longest <= h / DEFAULT_SUPPORT_FACTOR * (1.0 + 1e-12),
                "vertex {v}"
            );
            // So the distance weight of a host vertex is positive all over its host.
            assert!(CubicBSpline.evaluate(longest / h).0 > 0.0, "vertex {v}");
            // And narrower than the reach: farther ring vertices fade out.
            assert!(h <= DEFAULT_SUPPORT_FACTOR * reach.support_radii()[v as usize]);
        }
    }
    let global =
        UmlsKernel::with_weight(&mesh, WendlandC2, SupportRadius::Global { factor: 1.0 }).unwrap();
    assert!(
        global
            .support_radii()
            .iter()
            .all(|&h| h == mesh.max_edge_length())
    );
}

/// The element-size rule gives h_v = (D! · mean volume of v's simplices)^(1/D): h at every
/// vertex of a lattice of cells h however the cells are split (alternating and one-way
/// triangles, Kuhn tetrahedra), h/√2 on the crossed lattice, where the incident-edge rule
/// gives the diagonal's vertices √2 times the others' radius; on a jittered lattice it
/// stays near h, and it scales with a graded mesh's local cells.
#[test]
fn element_size_radii_are_the_cell_size_however_the_cells_are_split() {
    let radii = |mesh: &umls_mesh::SimplexMesh<2>, factor: f64| {
        UmlsKernel::with_weight(mesh, CubicBSpline, SupportRadius::ElementSize { factor })
            .unwrap()
            .support_radii()
            .to_vec()
    };
    let h = 0.25;
    for (diagonal, size) in [
        (Diagonal::Alternating, h),
        (Diagonal::Right, h),
        (Diagonal::Left, h),
        (Diagonal::Crossed, h / 2f64.sqrt()),
    ] {
        let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4])
            .triangles(diagonal)
            .unwrap();
        for (v, r) in radii(&mesh, 0.9).into_iter().enumerate() {
            assert!(
                (r - 0.9 * size).abs() < 1e-14,
                "{diagonal:?} vertex {v}: {r}"
            );
        }
        if diagonal == Diagonal::Alternating {
            let incident = UmlsKernel::new(&mesh);
            let radii = incident.support_radii();
            let spread = radii.iter().fold(0.0, |m: f64, &r| m.max(r))
                / radii.iter().fold(f64::MAX, |m, &r| m.min(r));
            assert!((spread - 2f64.sqrt()).abs() < 1e-12, "{spread}");
        }
    }
    let kuhn = Lattice::new([0.0; 3], [1.0; 3], [4, 4, 4])
        .tetrahedra()
        .unwrap();
    let tets = UmlsKernel::with_weight(
        &kuhn,
        CubicBSpline,
        SupportRadius::ElementSize { factor: 1.0 },
    )
    .unwrap();
    assert!(tets.support_radii().iter().all(|&r| (r - h).abs() < 1e-14));
    let jittered = Lattice::new([0.0, 0.0], [1.0, 1.0], [8, 8])
        .jitter(0.2, 3)
        .triangles(Diagonal::Alternating)
        .unwrap();
    let r = radii(&jittered, 1.0);
    assert!(r.iter().all(|&r| (r - 0.125).abs() < 0.2 * 0.125), "{r:?}");
    // The same radii from the triangles' corners (cross products), independently of the
    // mesh's stored volumes: a graded mesh's radii follow its cells.
    let mut area = vec![0.0; jittered.vertex_count()];
    let mut count = vec![0.0; jittered.vertex_count()];
    for t in jittered.simplices() {
        let [a, b, c] = [t[0], t[1], t[2]].map(|v| jittered.vertex(v as usize));
        let (e1, e2) = (b - a, c - a);
        for &v in t {
            area[v as usize] += 0.5 * (e1.x * e2.y - e1.y * e2.x).abs();
            count[v as usize] += 1.0;
        }
    }
    for (v, r) in r.iter().enumerate() {
        let expected = (2.0 * area[v] / count[v]).sqrt();
        assert!(
            (r - expected).abs() < 1e-14,
            "vertex {v}: {r} against {expected}"
        );
    }
}
