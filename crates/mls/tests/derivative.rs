//! The full derivative agrees with central finite differences of the shape functions
//! inside simplices, for both bases and both weight profiles; the derivative at frozen η
//! agrees with central differences of a fit whose diminishing factors are held fixed.

mod common;

use nalgebra::SVector;
use proptest::prelude::*;
use umls_mesh::SimplexMesh;
use umls_mls::{
    Conditioning, CubicBSpline, DEFAULT_SHARPENING, GradientKind, Linear, PolynomialBasis,
    Quadratic, Samples, SharpenedBSpline, Stencil, SupportRadius, UmlsKernel, WeightFunction,
    WendlandC2, diminishing_factor, shape_functions,
};

fn check_fd<const D: usize, const N: usize, B: PolynomialBasis<D, N>, W: WeightFunction>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
    weight: W,
) -> Result<(), TestCaseError> {
    check_fd_powered::<D, N, B, W>(mesh, s, raw, weight, 1)
}

/// [`check_fd`] with weights η^p · d.
fn check_fd_powered<const D: usize, const N: usize, B: PolynomialBasis<D, N>, W: WeightFunction>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
    weight: W,
    exponent: u32,
) -> Result<(), TestCaseError> {
    let kernel = UmlsKernel::with_weight(mesh, weight, SupportRadius::PerVertex { factor: 1.0 })
        .unwrap()
        .with_diminishing_exponent(exponent)
        .unwrap();
    // Keep the point well inside so x ± δ stays in the host.
    let raw: Vec<f64> = raw.iter().map(|r| r + 0.5).collect();
    let x = common::point_in(mesh, s, &raw);
    let mut st = Stencil::new();
    kernel
        .evaluate::<N, B>(mesh, s as u32, &x, GradientKind::Full, &mut st)
        .unwrap();
    let delta = 1e-6 * mesh.max_edge_length();
    matches_central_differences(&st, &x, delta, |y| {
        let mut out = Stencil::new();
        kernel
            .evaluate::<N, B>(mesh, s as u32, y, GradientKind::Full, &mut out)
            .unwrap();
        out
    })
}

/// Every gradient of `st` (evaluated at `x`) against central differences of the values
/// `eval` gives at x ± δ e_k, relative to the largest gradient.
fn matches_central_differences<const D: usize>(
    st: &Stencil<D>,
    x: &SVector<f64, D>,
    delta: f64,
    eval: impl Fn(&SVector<f64, D>) -> Stencil<D>,
) -> Result<(), TestCaseError> {
    let scale = st.gradients().iter().map(|g| g.norm()).fold(0.0, f64::max);
    for k in 0..D {
        let e = SVector::<f64, D>::from_fn(|i, _| if i == k { delta } else { 0.0 });
        let (plus, minus) = (eval(&(x + e)), eval(&(x - e)));
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

    /// With η raised to a power (2 to 8; `umls-eta4` and `umls-eta8` use 4 and 8) the
    /// full derivative carries p η^{p−1} ∇η, checked the same way.
    #[test]
    fn full_gradient_with_a_powered_diminishing_factor_matches_fd(
        mesh in common::rectangle(),
        cube in common::fine_cuboid(),
        s in any::<usize>(),
        p in 2u32..=8,
        raw in raw_weights(),
    ) {
        check_fd_powered::<2, 3, Linear, _>(&mesh, s % mesh.simplex_count(), &raw, CubicBSpline, p)?;
        check_fd_powered::<3, 4, Linear, _>(&cube, s % cube.simplex_count(), &raw, CubicBSpline, p)?;
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
    for epsilon in [0.2, DEFAULT_SHARPENING, 1.0] {
        let sharp = SharpenedBSpline::new(epsilon).unwrap();
        check(sharp);
        // The B-spline divided by 1 + (r/ε)², computed independently.
        for r in [0.0, 0.3, 0.9, 1.0, 1.5, 1.99] {
            let expected =
                CubicBSpline.evaluate(r).0 * epsilon * epsilon / (r * r + epsilon * epsilon);
            assert!(
                (sharp.evaluate(r).0 - expected).abs() < 1e-15,
                "ε {epsilon}, r {r}"
            );
        }
    }
    // A wide ε is the plain spline to O(1/ε²).
    let wide = SharpenedBSpline::new(1e4).unwrap();
    assert!((wide.evaluate(1.0).0 - 1.0 / 6.0).abs() < 1e-8);
    for bad in [0.0, -0.4, f64::NAN, f64::INFINITY] {
        assert!(SharpenedBSpline::new(bad).is_err(), "ε = {bad} accepted");
    }
    assert!((CubicBSpline.evaluate(0.0).0 - 2.0 / 3.0).abs() < 1e-15);
    assert!((CubicBSpline.evaluate(1.0).0 - 1.0 / 6.0).abs() < 1e-15);
}

/// The derivative at frozen η against central differences of an independent fit: the
/// public `shape_functions` over the host's 1-ring with weights η_v(x) W(|y − x_v| / h_v),
/// η computed once at x from the ring's adjacency masks and barycentric coordinates, and
/// y = x ± δ e_k.
fn check_frozen_eta_fd<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
) -> Result<(), TestCaseError> {
    let kernel = UmlsKernel::new(mesh);
    let raw: Vec<f64> = raw.iter().map(|r| r + 0.5).collect();
    let x = common::point_in(mesh, s, &raw);
    let mut st = Stencil::new();
    kernel
        .evaluate::<N, B>(mesh, s as u32, &x, GradientKind::FrozenEta, &mut st)
        .unwrap();
    let ring = mesh.topology().one_ring(s);
    let lambda = mesh.barycentric(s, &x);
    let eta: Vec<f64> = ring
        .masks
        .iter()
        .map(|&m| diminishing_factor(m, lambda.as_slice()))
        .collect();
    let positions: Vec<SVector<f64, D>> = ring
        .vertices
        .iter()
        .map(|&v| *mesh.vertex(v as usize))
        .collect();
    let radii = kernel.support_radii();
    let scale = radii[mesh.simplex(s)[0] as usize];
    let fit = |y: &SVector<f64, D>| {
        let weights: Vec<f64> = ring
            .vertices
            .iter()
            .zip(&positions)
            .zip(&eta)
            .map(|((&v, xv), e)| e * CubicBSpline.evaluate((y - xv).norm() / radii[v as usize]).0)
            .collect();
        let samples = Samples {
            nodes: ring.vertices,
            positions: &positions,
            weights: &weights,
            weight_gradients: &[],
        };
        let mut out = Stencil::new();
        shape_functions::<D, N, B>(
            y,
            &samples,
            scale,
            GradientKind::Reconstructed,
            &Conditioning::default(),
            &mut out,
        )
        .unwrap();
        out
    };
    for (a, b) in fit(&x).values().iter().zip(st.values()) {
        prop_assert!((a - b).abs() < 1e-12, "values differ: {} vs {}", a, b);
    }
    matches_central_differences(&st, &x, 1e-6 * mesh.max_edge_length(), fit)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn frozen_eta_gradient_matches_fd_of_the_frozen_fit(
        rect in common::rectangle(),
        cube in common::fine_cuboid(),
        s in any::<usize>(),
        raw in raw_weights(),
    ) {
        check_frozen_eta_fd::<2, 3, Linear>(&rect, s % rect.simplex_count(), &raw)?;
        check_frozen_eta_fd::<3, 4, Linear>(&cube, s % cube.simplex_count(), &raw)?;
    }
}
