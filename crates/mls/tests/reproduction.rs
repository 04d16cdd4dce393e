//! Partition of unity and polynomial reproduction of the UMLS shape functions, for both
//! gradients (reconstructed, full, at frozen η), on random jittered and rotated meshes in 1D, 2D and 3D.

mod common;

use nalgebra::{SMatrix, SVector};
use proptest::prelude::*;
use umls_mesh::SimplexMesh;
use umls_mls::{
    DEFAULT_SHARPENING, GradientKind, Linear, PolynomialBasis, Profile, Quadratic,
    SharpenedBSpline, Stencil, SupportRadius, UmlsKernel,
};

/// The UMLS variants the CLI names (docs/umls-kernel.md): profile and radius rule (the
/// exponent of η is in [`EXPONENTS`]).
const VARIANTS: [(Profile, SupportRadius); 9] = [
    (
        Profile::CubicBSpline,
        SupportRadius::IncidentEdge { factor: 0.9 },
    ),
    (
        Profile::CubicBSpline,
        SupportRadius::PerVertex { factor: 1.0 },
    ),
    (Profile::CubicBSpline, SupportRadius::Global { factor: 1.0 }),
    (
        Profile::WendlandC2,
        SupportRadius::IncidentEdge { factor: 0.9 },
    ),
    (
        Profile::CubicBSpline,
        SupportRadius::IncidentEdge { factor: 0.6 },
    ),
    (
        Profile::Sharpened(SharpenedBSpline {
            epsilon: DEFAULT_SHARPENING,
        }),
        SupportRadius::IncidentEdge { factor: 0.9 },
    ),
    (
        Profile::CubicBSpline,
        SupportRadius::IncidentEdge { factor: 1.4 },
    ),
    (
        Profile::CubicBSpline,
        SupportRadius::IncidentEdge { factor: 2.8 },
    ),
    (
        Profile::CubicBSpline,
        SupportRadius::ElementSize { factor: 1.0 },
    ),
];

/// The exponent p of the weights η^p · d of each of [`VARIANTS`]: 4 and 8 for
/// `umls-eta4` and `umls-eta8`, 1 for the others.
const EXPONENTS: [u32; 9] = [1, 1, 1, 1, 1, 1, 4, 8, 1];

/// Σ N_v = 1, Σ ∇N_v = 0, Σ N_v x_v = x, Σ x_v ∇N_vᵀ = I, for the linear basis and the
/// default kernel.
fn check_linear<const D: usize, const N: usize>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
    gradient: GradientKind,
) -> Result<(), TestCaseError>
where
    Linear: PolynomialBasis<D, N>,
{
    let kernel =
        UmlsKernel::with_weight(mesh, Profile::CubicBSpline, SupportRadius::default()).unwrap();
    check_linear_with::<D, N, Linear>(&kernel, mesh, s, raw, gradient)
}

/// The same for any kernel and basis containing the linear monomials.
fn check_linear_with<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    kernel: &UmlsKernel<D, Profile>,
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
    gradient: GradientKind,
) -> Result<(), TestCaseError> {
    let x = common::point_in(mesh, s, raw);
    let mut st = Stencil::new();
    kernel
        .evaluate::<N, B>(mesh, s as u32, &x, gradient, &mut st)
        .unwrap();
    let h = mesh.max_edge_length();
    let sum: f64 = st.values().iter().sum();
    let grad_sum: SVector<f64, D> = st.gradients().iter().sum();
    let mut moment = SVector::<f64, D>::zeros();
    let mut jacobian = SMatrix::<f64, D, D>::zeros();
    for (v, n, g) in st.iter() {
        moment += mesh.vertex(v as usize) * n;
        jacobian += mesh.vertex(v as usize) * g.transpose();
    }
    prop_assert!((sum - 1.0).abs() < 1e-12, "partition of unity: {}", sum);
    prop_assert!(grad_sum.norm() * h < 1e-10, "gradient sum {:?}", grad_sum);
    prop_assert!(
        (moment - x).norm() < 1e-12 * (1.0 + x.norm()),
        "linear reproduction {:?} vs {:?}",
        moment,
        x
    );
    prop_assert!(
        (jacobian - SMatrix::<f64, D, D>::identity()).norm() < 1e-9,
        "gradient reproduction {}",
        jacobian
    );
    Ok(())
}

/// A fixed quadratic q(x) = Σ a_ij x_i x_j + b·x + c and its gradient.
fn quadratic<const D: usize>(x: &SVector<f64, D>) -> (f64, SVector<f64, D>) {
    let mut value = 0.7;
    let mut grad = SVector::<f64, D>::zeros();
    for i in 0..D {
        value += (i as f64 + 1.0) * 0.3 * x[i];
        grad[i] += (i as f64 + 1.0) * 0.3;
        for j in i..D {
            let a = 1.0 + 0.5 * i as f64 - 0.8 * j as f64;
            value += a * x[i] * x[j];
            grad[i] += a * x[j];
            grad[j] += a * x[i];
        }
    }
    (value, grad)
}

/// The quadratic basis reproduces quadratic fields: value and gradient.
fn check_quadratic<const D: usize, const N: usize>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
    gradient: GradientKind,
) -> Result<(), TestCaseError>
where
    Quadratic: PolynomialBasis<D, N>,
{
    let kernel = UmlsKernel::new(mesh);
    let x = common::point_in(mesh, s, raw);
    let mut st = Stencil::new();
    kernel
        .evaluate::<N, Quadratic>(mesh, s as u32, &x, gradient, &mut st)
        .unwrap();
    let field: Vec<f64> = mesh.vertices().iter().map(|v| quadratic(v).0).collect();
    let (value, grad) = st.interpolate(&field).unwrap();
    let (exact, exact_grad) = quadratic(&x);
    prop_assert!(
        (value - exact).abs() < 1e-10,
        "value {} vs {}",
        value,
        exact
    );
    prop_assert!(
        (grad - exact_grad).norm() < 1e-8,
        "gradient {:?} vs {:?}",
        grad,
        exact_grad
    );
    Ok(())
}

fn raw_weights() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.001f64..1.0, 4)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn linear_reproduction_1d(mesh in common::interval(), s in any::<usize>(), raw in raw_weights()) {
        let s = s % mesh.simplex_count();
        check_linear::<1, 2>(&mesh, s, &raw, GradientKind::Reconstructed)?;
        check_linear::<1, 2>(&mesh, s, &raw, GradientKind::Full)?;
        check_linear::<1, 2>(&mesh, s, &raw, GradientKind::FrozenEta)?;
    }

    #[test]
    fn linear_reproduction_2d(mesh in common::rectangle(), s in any::<usize>(), raw in raw_weights()) {
        let s = s % mesh.simplex_count();
        check_linear::<2, 3>(&mesh, s, &raw, GradientKind::Reconstructed)?;
        check_linear::<2, 3>(&mesh, s, &raw, GradientKind::Full)?;
        check_linear::<2, 3>(&mesh, s, &raw, GradientKind::FrozenEta)?;
    }

    #[test]
    fn linear_reproduction_3d(mesh in common::cuboid(), s in any::<usize>(), raw in raw_weights()) {
        let s = s % mesh.simplex_count();
        check_linear::<3, 4>(&mesh, s, &raw, GradientKind::Reconstructed)?;
        check_linear::<3, 4>(&mesh, s, &raw, GradientKind::Full)?;
        check_linear::<3, 4>(&mesh, s, &raw, GradientKind::FrozenEta)?;
    }

    /// Quadratic reproduction on hosts with complete 1-rings (boundary hosts can have too few
    /// weighted samples for six or ten monomials; the conditioning tests cover those).
    #[test]
    fn quadratic_reproduction_1d(mesh in common::interval(), s in any::<usize>(), raw in raw_weights()) {
        let interior = common::interior_simplices(&mesh);
        let s = interior[s % interior.len()];
        check_quadratic::<1, 3>(&mesh, s, &raw, GradientKind::Reconstructed)?;
        check_quadratic::<1, 3>(&mesh, s, &raw, GradientKind::Full)?;
        check_quadratic::<1, 3>(&mesh, s, &raw, GradientKind::FrozenEta)?;
    }

    #[test]
    fn quadratic_reproduction_2d(mesh in common::rectangle(), s in any::<usize>(), raw in raw_weights()) {
        let interior = common::interior_simplices(&mesh);
        let s = interior[s % interior.len()];
        check_quadratic::<2, 6>(&mesh, s, &raw, GradientKind::Reconstructed)?;
        check_quadratic::<2, 6>(&mesh, s, &raw, GradientKind::Full)?;
        check_quadratic::<2, 6>(&mesh, s, &raw, GradientKind::FrozenEta)?;
    }

    #[test]
    fn quadratic_reproduction_3d(mesh in common::fine_cuboid(), s in any::<usize>(), raw in raw_weights()) {
        let interior = common::interior_simplices(&mesh);
        let s = interior[s % interior.len()];
        check_quadratic::<3, 10>(&mesh, s, &raw, GradientKind::Reconstructed)?;
        check_quadratic::<3, 10>(&mesh, s, &raw, GradientKind::Full)?;
        check_quadratic::<3, 10>(&mesh, s, &raw, GradientKind::FrozenEta)?;
    }

    /// Every named variant reproduces linear fields on every host, boundary hosts
    /// included; so does the quadratic basis with its ridge (the ridge penalises only
    /// quadratic coefficients, which a linear field does not have).
    #[test]
    fn every_variant_reproduces_linear_fields(
        mesh in common::rectangle(),
        cube in common::cuboid(),
        s in any::<usize>(),
        v in 0..VARIANTS.len(),
        raw in raw_weights(),
    ) {
        let (profile, support) = VARIANTS[v];
        let k2 = UmlsKernel::with_weight(&mesh, profile, support)
            .and_then(|k| k.with_diminishing_exponent(EXPONENTS[v]))
            .unwrap();
        let s2 = s % mesh.simplex_count();
        for gradient in [GradientKind::Reconstructed, GradientKind::Full, GradientKind::FrozenEta] {
            check_linear_with::<2, 3, Linear>(&k2, &mesh, s2, &raw, gradient)?;
        }
        let k3 = UmlsKernel::with_weight(&cube, profile, support)
            .and_then(|k| k.with_diminishing_exponent(EXPONENTS[v]))
            .unwrap();
        let s3 = s % cube.simplex_count();
        for gradient in [GradientKind::Reconstructed, GradientKind::Full, GradientKind::FrozenEta] {
            check_linear_with::<3, 4, Linear>(&k3, &cube, s3, &raw, gradient)?;
        }
        let mut ridge = k2.clone();
        ridge.conditioning.higher_order_ridge = 1e-3;
        check_linear_with::<2, 6, Quadratic>(&ridge, &mesh, s2, &raw, GradientKind::Reconstructed)?;
        let mut ridge = k3.clone();
        ridge.conditioning.higher_order_ridge = 1e-3;
        check_linear_with::<3, 10, Quadratic>(&ridge, &cube, s3, &raw, GradientKind::Reconstructed)?;
    }
}
