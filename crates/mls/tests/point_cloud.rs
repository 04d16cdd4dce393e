//! The mesh-free MLS core on a user's point set.

use nalgebra::{Matrix2, SVector, Vector2};
use umls_mls::{
    Conditioning, CubicBSpline, GradientKind, Linear, MAX_STENCIL, MlsError, PointCloudMls,
    Quadratic, Samples, Stencil, WendlandC2, shape_functions,
};

fn cloud() -> Vec<Vector2<f64>> {
    // A scattered 5×5 patch.
    (0..25)
        .map(|i| {
            let (a, b) = ((i % 5) as f64, (i / 5) as f64);
            Vector2::new(
                0.25 * a + 0.03 * (3.0 * b).sin(),
                0.25 * b + 0.04 * (2.0 * a).cos(),
            )
        })
        .collect()
}

#[test]
fn reproduces_linear_and_quadratic_fields() {
    let points = cloud();
    let mls = PointCloudMls::new(0.4, CubicBSpline).unwrap();
    let x = Vector2::new(0.52, 0.47);
    let mut st = Stencil::new();
    mls.evaluate::<2, 3, Linear>(&x, &points, GradientKind::Full, &mut st)
        .unwrap();
    let mut jac = Matrix2::zeros();
    let mut pos = Vector2::zeros();
    for (v, n, g) in st.iter() {
        pos += points[v as usize] * n;
        jac += points[v as usize] * g.transpose();
    }
    assert!((pos - x).norm() < 1e-13);
    assert!((jac - Matrix2::identity()).norm() < 1e-11);

    let mls = PointCloudMls::new(0.5, WendlandC2).unwrap();
    mls.evaluate::<2, 6, Quadratic>(&x, &points, GradientKind::Reconstructed, &mut st)
        .unwrap();
    let q = |p: &Vector2<f64>| 1.0 + p.x - 2.0 * p.y + 3.0 * p.x * p.y - p.y * p.y;
    let field: Vec<f64> = points.iter().map(q).collect();
    let (value, grad) = st.interpolate(&field).unwrap();
    assert!((value - q(&x)).abs() < 1e-12);
    assert!((grad - Vector2::new(1.0 + 3.0 * x.y, -2.0 + 3.0 * x.x - 2.0 * x.y)).norm() < 1e-10);
}

/// The coordinate scale only conditions the solve; it does not change the result.
#[test]
fn result_is_independent_of_the_scale() {
    let points = cloud();
    let x = Vector2::new(0.3, 0.6);
    let weights: Vec<f64> = points
        .iter()
        .map(|p| cubic_weight((p - x).norm() / 0.4))
        .collect();
    let nodes: Vec<u32> = (0..points.len() as u32).collect();
    let samples = Samples {
        nodes: &nodes,
        positions: &points,
        weights: &weights,
        weight_gradients: &[],
    };
    let (mut a, mut b) = (Stencil::new(), Stencil::new());
    shape_functions::<2, 3, Linear>(
        &x,
        &samples,
        0.25,
        GradientKind::Reconstructed,
        &Conditioning::default(),
        &mut a,
    )
    .unwrap();
    shape_functions::<2, 3, Linear>(
        &x,
        &samples,
        3.0,
        GradientKind::Reconstructed,
        &Conditioning::default(),
        &mut b,
    )
    .unwrap();
    for i in 0..a.len() {
        assert!((a.values()[i] - b.values()[i]).abs() < 1e-13);
        assert!((a.gradients()[i] - b.gradients()[i]).norm() < 1e-11);
    }
}

fn cubic_weight(r: f64) -> f64 {
    use umls_mls::WeightFunction;
    CubicBSpline.evaluate(r).0
}

#[test]
fn core_error_paths() {
    let points = cloud();
    let x = Vector2::new(0.5, 0.5);
    let mut st = Stencil::new();
    assert!(matches!(
        PointCloudMls::new(-1.0, CubicBSpline),
        Err(MlsError::InvalidParameter {
            parameter: "radius",
            ..
        })
    ));
    // A tiny radius leaves one weighted sample: singular for the linear basis.
    let lonely = PointCloudMls::new(0.01, CubicBSpline).unwrap();
    let near = points[12] + Vector2::new(0.001, 0.0);
    assert!(matches!(
        lonely.evaluate::<2, 3, Linear>(&near, &points, GradientKind::Reconstructed, &mut st),
        Err(MlsError::IllConditioned {
            simplex: None,
            samples: 1,
            basis: 3,
            ..
        })
    ));
    let many = vec![x; MAX_STENCIL + 1];
    let mls = PointCloudMls::new(0.4, CubicBSpline).unwrap();
    assert!(matches!(
        mls.evaluate::<2, 3, Linear>(&x, &many, GradientKind::Reconstructed, &mut st),
        Err(MlsError::StencilOverflow {
            samples: 65,
            capacity: 64,
            ..
        })
    ));
    let nodes = [0u32, 1, 2];
    let positions = [SVector::<f64, 2>::zeros(); 3];
    let bad = Samples {
        nodes: &nodes,
        positions: &positions,
        weights: &[1.0, -1.0, 1.0],
        weight_gradients: &[],
    };
    assert!(matches!(
        shape_functions::<2, 3, Linear>(
            &x,
            &bad,
            1.0,
            GradientKind::Reconstructed,
            &Conditioning::default(),
            &mut st
        ),
        Err(MlsError::InvalidWeight { sample: 1, .. })
    ));
    let short = Samples {
        nodes: &nodes,
        positions: &positions,
        weights: &[1.0],
        weight_gradients: &[],
    };
    assert!(matches!(
        shape_functions::<2, 3, Linear>(
            &x,
            &short,
            1.0,
            GradientKind::Full,
            &Conditioning::default(),
            &mut st
        ),
        Err(MlsError::LengthMismatch {
            positions: 3,
            weights: 1,
            ..
        })
    ));
}
