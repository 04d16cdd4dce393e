//! The full derivative agrees with central finite differences of the shape functions
//! inside simplices, for both bases and both weight profiles.

mod common;

use nalgebra::SVector;
use proptest::prelude::*;
use umls_mesh::SimplexMesh;
use umls_mls::{
    CubicBSpline, GradientKind, Linear, PolynomialBasis, Quadratic, Stencil, SupportRadius,
    UmlsKernel, WeightFunction, WendlandC2,
};

fn check_fd<const D: usize, const N: usize, B: PolynomialBasis<D, N>, W: WeightFunction>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
    weight: W,
) -> Result<(), TestCaseError> {
    let kernel =
        UmlsKernel::with_weight(mesh, weight, SupportRadius::PerVertex { factor: 1.0 }).unwrap();
    // Keep the point well inside so x ± δ stays in the host.
    let raw: Vec<f64> = raw.iter().map(|r| r + 0.5).collect();
    let x = common::point_in(mesh, s, &raw);
    let mut st = Stencil::new();
    kernel
        .evaluate::<N, B>(mesh, s as u32, &x, GradientKind::Full, &mut st)
        .unwrap();
    let delta = 1e-6 * mesh.max_edge_length();
    let (mut plus, mut minus) = (Stencil::new(), Stencil::new());
    for k in 0..D {
        let e = SVector::<f64, D>::from_fn(|i, _| if i == k { delta } else { 0.0 });
        kernel
            .evaluate::<N, B>(mesh, s as u32, &(x + e), GradientKind::Full, &mut plus)
            .unwrap();
        kernel
            .evaluate::<N, B>(mesh, s as u32, &(x - e), GradientKind::Full, &mut minus)
            .unwrap();
        let scale = st.gradients().iter().map(|g| g.norm()).fold(0.0, f64::max);
        for i in 0..st.len() {
            let fd = (plus.values()[i] - minus.values()[i]) / (2.0 * delta);
            prop_assert!(
                (fd - st.gradients()[i][k]).abs() < 1e-6 * scale,
                "node {} axis {}: analytic {} vs fd {}",
                st.nodes()[i],
                k,
                st.gradients()[i][k],
                fd
            );
        }
    }
    Ok(())
}

fn raw_weights() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.0f64..1.0, 4)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn full_gradient_matches_fd_1d(mesh in common::interval(), s in any::<usize>(), raw in raw_weights()) {
        check_fd::<1, 2, Linear, _>(&mesh, s % mesh.simplex_count(), &raw, CubicBSpline)?;
        let interior = common::interior_simplices(&mesh);
        check_fd::<1, 3, Quadratic, _>(&mesh, interior[s % interior.len()], &raw, WendlandC2)?;
    }

    #[test]
    fn full_gradient_matches_fd_2d(mesh in common::rectangle(), s in any::<usize>(), raw in raw_weights()) {
        check_fd::<2, 3, Linear, _>(&mesh, s % mesh.simplex_count(), &raw, CubicBSpline)?;
        let interior = common::interior_simplices(&mesh);
        check_fd::<2, 6, Quadratic, _>(&mesh, interior[s % interior.len()], &raw, WendlandC2)?;
    }

    #[test]
    fn full_gradient_matches_fd_3d(mesh in common::fine_cuboid(), s in any::<usize>(), raw in raw_weights()) {
        check_fd::<3, 4, Linear, _>(&mesh, s % mesh.simplex_count(), &raw, WendlandC2)?;
        let interior = common::interior_simplices(&mesh);
        check_fd::<3, 10, Quadratic, _>(&mesh, interior[s % interior.len()], &raw, CubicBSpline)?;
    }
}

/// The weight profiles' derivatives match finite differences, and both vanish at r ≥ 2.
#[test]
fn weight_profile_derivatives() {
    fn check<W: WeightFunction>(w: W) {
        for i in 1..400 {
            let r = i as f64 * 0.005;
            let d = 1e-7;
            let fd = (w.evaluate(r + d).0 - w.evaluate(r - d).0) / (2.0 * d);
            assert!(
                (fd - w.evaluate(r).1).abs() < 1e-6,
                "r = {r}: {fd} vs {}",
                w.evaluate(r).1
            );
        }
        assert_eq!(w.evaluate(2.0), (0.0, 0.0));
        assert_eq!(w.evaluate(0.0).1, 0.0);
    }
    check(CubicBSpline);
    check(WendlandC2);
    assert!((CubicBSpline.evaluate(0.0).0 - 2.0 / 3.0).abs() < 1e-15);
    assert!((CubicBSpline.evaluate(1.0).0 - 1.0 / 6.0).abs() < 1e-15);
}
