//! Return mapping: admissibility, elastic states untouched, idempotence, non-negative
//! dissipation, the fused return map and stress equal to the two separate calls,
//! closed-form pure-shear and apex answers, path independence of radial
//! loading, and 2D plane strain against 3D with ε_zz = 0.

use nalgebra::{Matrix2, Matrix3, SMatrix, Vector3};
use proptest::prelude::*;
use umls_constitutive::{
    ConeFit, Constitutive, DruckerPrager, ElasticParameters, ElastoPlastic, PlasticState, VonMises,
    YieldCriterion,
};

fn params() -> ElasticParameters {
    ElasticParameters::from_young_poisson(1.0e4, 0.25).unwrap()
}

fn dp(dilatancy: f64) -> ElastoPlastic<DruckerPrager> {
    ElastoPlastic::new(
        params(),
        DruckerPrager::from_mohr_coulomb(10.0, 0.5, dilatancy, ConeFit::PlaneStrain).unwrap(),
    )
}

fn j2(hardening: f64) -> ElastoPlastic<VonMises> {
    ElastoPlastic::new(params(), VonMises::new(30.0, hardening).unwrap())
}

fn deformation3() -> impl Strategy<Value = Matrix3<f64>> {
    prop::array::uniform9(-0.1f64..0.1)
        .prop_map(|g| Matrix3::identity() + Matrix3::from_row_slice(&g))
        .prop_filter("det F > 0.5", |f| f.determinant() > 0.5)
}

/// f(τ) after the return map, relative to the criterion's stress scale.
fn yield_after<const D: usize, Y: YieldCriterion>(
    m: &ElastoPlastic<Y>,
    f: &SMatrix<f64, D, D>,
    s: &PlasticState<D>,
) -> f64 {
    let tau = m.principal_stress(f, s).unwrap();
    m.criterion
        .yield_function(&tau, s.accumulated_plastic_strain)
        / m.criterion.stress_scale(s.accumulated_plastic_strain)
}

/// τ : Δεᵖ over the step, with Δεᵖ = εᵉ_trial − εᵉ_new (in-plane tensor + out-of-plane term).
fn dissipation<const D: usize, Y: YieldCriterion>(
    m: &ElastoPlastic<Y>,
    f: &SMatrix<f64, D, D>,
    before: &PlasticState<D>,
    after: &PlasticState<D>,
) -> f64 {
    let (trial, trial_p) = m.elastic_log_strain(f, before).unwrap();
    let (new, new_p) = m.elastic_log_strain(f, after).unwrap();
    let tau = m.kirchhoff_stress(f, after).unwrap();
    let out_of_plane = if D == 2 {
        m.principal_stress(f, after).unwrap()[2] * (trial_p[2] - new_p[2])
    } else {
        0.0
    };
    (tau.component_mul(&(trial - new))).sum() + out_of_plane
}

fn check_return_map<Y: YieldCriterion>(
    m: &ElastoPlastic<Y>,
    f: &Matrix3<f64>,
) -> Result<(), TestCaseError> {
    let before = Constitutive::<3>::initial_state(m);
    let mut after = before.clone();
    m.return_map(f, &mut after).unwrap();
    // The fused call (one SVD) updates the state alike and returns the stress that the
    // separate call computes from the new state.
    let mut fused = before.clone();
    let tau = m.return_map_and_stress(f, &mut fused).unwrap();
    prop_assert_eq!(&fused, &after);
    let separate = m.kirchhoff_stress(f, &after).unwrap();
    prop_assert!(
        (tau - separate).norm() <= 1e-9 * m.parameters.mu(),
        "{}: fused stress {} against {}",
        Y::NAME,
        tau,
        separate
    );
    prop_assert!(
        yield_after(m, f, &after) <= 1e-8,
        "{}: outside the surface by {}",
        Y::NAME,
        yield_after(m, f, &after)
    );
    let d = dissipation(m, f, &before, &after);
    prop_assert!(
        d >= -1e-9 * m.parameters.mu(),
        "{}: negative dissipation {}",
        Y::NAME,
        d
    );
    let mut again = after.clone();
    m.return_map(f, &mut again).unwrap();
    prop_assert!(
        (again.plastic_inverse - after.plastic_inverse).norm() < 1e-12,
        "{}: not idempotent",
        Y::NAME
    );
    prop_assert_eq!(
        again.accumulated_plastic_strain,
        after.accumulated_plastic_strain
    );
    if after == before {
        prop_assert!(
            yield_after(m, f, &before) <= 1e-10,
            "elastic state must be admissible"
        );
    } else {
        // A plastic step ends on the surface (consistency), not merely inside it.
        prop_assert!(
            yield_after(m, f, &after).abs() <= 1e-8,
            "{}: plastic step ends at f = {}",
            Y::NAME,
            yield_after(m, f, &after)
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn return_map_properties(f in deformation3()) {
        check_return_map(&dp(0.0), &f)?;
        check_return_map(&dp(0.3), &f)?;
        check_return_map(&j2(0.0), &f)?;
        check_return_map(&j2(500.0), &f)?;
    }

    /// 2D plane strain through a loading sequence equals 3D with F = diag(F₂, 1).
    #[test]
    fn plane_strain_matches_three_dimensions(steps in prop::collection::vec(prop::array::uniform4(-0.02f64..0.02), 1..6)) {
        for model in [dp(0.2), dp(0.0)] {
            compare_2d_3d(&model, &steps)?;
        }
        compare_2d_3d(&j2(200.0), &steps)?;
    }
}

fn compare_2d_3d<Y: YieldCriterion>(
    m: &ElastoPlastic<Y>,
    steps: &[[f64; 4]],
) -> Result<(), TestCaseError> {
    let mut f2 = Matrix2::identity();
    let mut s2 = Constitutive::<2>::initial_state(m);
    let mut s3 = Constitutive::<3>::initial_state(m);
    for g in steps {
        f2 = (Matrix2::identity() + Matrix2::from_row_slice(g)) * f2;
        let mut f3 = Matrix3::identity();
        f3.fixed_view_mut::<2, 2>(0, 0).copy_from(&f2);
        // 2D through the fused call, 3D through the separate ones.
        let t2_fused = m.return_map_and_stress(&f2, &mut s2).unwrap();
        m.return_map(&f3, &mut s3).unwrap();
        let t2 = m.kirchhoff_stress(&f2, &s2).unwrap();
        let t3 = m.kirchhoff_stress(&f3, &s3).unwrap();
        let scale = 1.0 + t3.norm();
        prop_assert!(
            (t2_fused - t2).norm() < 1e-9 * scale,
            "{}: fused 2D stress",
            Y::NAME
        );
        prop_assert!(
            (t3.fixed_view::<2, 2>(0, 0) - t2).norm() < 1e-9 * scale,
            "{}: in-plane {} vs {}",
            Y::NAME,
            t2,
            t3
        );
        let zz2 = m.principal_stress(&f2, &s2).unwrap()[2];
        prop_assert!(
            (t3[(2, 2)] - zz2).abs() < 1e-9 * scale,
            "{}: τ_zz {} vs {}",
            Y::NAME,
            zz2,
            t3[(2, 2)]
        );
        prop_assert!((s2.accumulated_plastic_strain - s3.accumulated_plastic_strain).abs() < 1e-12);
    }
    Ok(())
}

fn pure_shear(gamma: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(gamma.exp(), (-gamma).exp(), 1.0))
}

#[test]
fn von_mises_pure_shear_closed_form() {
    let mu = params().mu();
    let gamma = 0.01;
    // Perfect plasticity: the shear stress saturates at σ_y/√3.
    let perfect = j2(0.0);
    let mut s = Constitutive::<3>::initial_state(&perfect);
    perfect.return_map(&pure_shear(gamma), &mut s).unwrap();
    let tau = perfect.kirchhoff_stress(&pure_shear(gamma), &s).unwrap();
    assert!(
        (tau[(0, 0)] - 30.0 / 3f64.sqrt()).abs() < 1e-9,
        "{}",
        tau[(0, 0)]
    );
    assert!((tau[(1, 1)] + 30.0 / 3f64.sqrt()).abs() < 1e-9 && tau[(2, 2)].abs() < 1e-9);
    // Linear hardening: ‖s_tr‖ = 2√2 μ γ, Δγ = (‖s_tr‖ − √(2/3) σ_y)/(2μ + 2H/3), ᾱ = √(2/3) Δγ.
    let h = 800.0;
    let hard = j2(h);
    let mut s = Constitutive::<3>::initial_state(&hard);
    hard.return_map(&pure_shear(gamma), &mut s).unwrap();
    let trial = 2.0 * 2f64.sqrt() * mu * gamma;
    let dgamma = (trial - (2.0f64 / 3.0).sqrt() * 30.0) / (2.0 * mu + 2.0 * h / 3.0);
    let t = (trial - 2.0 * mu * dgamma) / 2f64.sqrt();
    let tau = hard.kirchhoff_stress(&pure_shear(gamma), &s).unwrap();
    assert!((tau[(0, 0)] - t).abs() < 1e-9, "{} vs {t}", tau[(0, 0)]);
    assert!((s.accumulated_plastic_strain - (2.0f64 / 3.0).sqrt() * dgamma).abs() < 1e-12);
    // Radial loading with linear hardening: many small steps end where one step does.
    let mut stepped = Constitutive::<3>::initial_state(&hard);
    for k in 1..=50 {
        hard.return_map(&pure_shear(gamma * k as f64 / 50.0), &mut stepped)
            .unwrap();
    }
    assert!((stepped.accumulated_plastic_strain - s.accumulated_plastic_strain).abs() < 1e-12);
    assert!((hard.kirchhoff_stress(&pure_shear(gamma), &stepped).unwrap() - tau).norm() < 1e-8);
}

#[test]
fn drucker_prager_closed_forms() {
    let m = dp(0.0);
    let k = m.criterion.k();
    let phi: f64 = 0.5;
    assert!((k - 3.0 * 10.0 / (9.0 + 12.0 * phi.tan().powi(2)).sqrt()).abs() < 1e-12);
    // Pure shear at zero mean stress with no dilatancy: shear strength k, I₁ stays 0.
    let mut s = Constitutive::<3>::initial_state(&m);
    m.return_map(&pure_shear(0.02), &mut s).unwrap();
    let tau = m.principal_stress(&pure_shear(0.02), &s).unwrap();
    let (t, i1) = (tau[0], tau.iter().sum::<f64>());
    assert!(
        (t - k).abs() < 1e-9 && i1.abs() < 1e-9,
        "t = {t}, I1 = {i1}"
    );
    // Hydrostatic tension beyond the apex returns to the apex: s = 0, I₁ = k/α.
    let stretch = Matrix3::identity() * 1.01;
    let mut s = Constitutive::<3>::initial_state(&m);
    m.return_map(&stretch, &mut s).unwrap();
    let tau = m.principal_stress(&stretch, &s).unwrap();
    for t in tau {
        assert!((t - k / m.criterion.alpha() / 3.0).abs() < 1e-9, "{tau:?}");
    }
    // Hydrostatic compression never yields: the cone is open.
    let squeeze = Matrix3::identity() * 0.95;
    let mut s = Constitutive::<3>::initial_state(&m);
    m.return_map(&squeeze, &mut s).unwrap();
    assert_eq!(s, Constitutive::<3>::initial_state(&m));
    // Confinement raises the shear strength: f = ‖s‖/√2 + α I₁ − k = 0 with I₁ < 0.
    let confined = pure_shear(0.02) * 0.99;
    let mut s = Constitutive::<3>::initial_state(&m);
    m.return_map(&confined, &mut s).unwrap();
    let tau = m.principal_stress(&confined, &s).unwrap();
    let i1: f64 = tau.iter().sum();
    let dev: f64 = tau
        .iter()
        .map(|t| (t - i1 / 3.0).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(i1 < 0.0 && (dev / 2f64.sqrt() - (k - m.criterion.alpha() * i1)).abs() < 1e-8);
}

#[test]
fn state_scalars_report_plastic_strain_and_volume_change() {
    let f = pure_shear(0.01) * 1.002;
    // J2 flow is isochoric: det Fᵖ stays 1 while plastic strain accumulates.
    let m = j2(800.0);
    let mut s = Constitutive::<3>::initial_state(&m);
    m.return_map(&f, &mut s).unwrap();
    let mut out = Vec::new();
    Constitutive::<3>::state_scalars(&m, &s, &mut out);
    assert_eq!(
        Constitutive::<3>::state_scalar_names(&m),
        ["plastic_strain", "plastic_jacobian"]
    );
    assert_eq!(out[0], s.accumulated_plastic_strain);
    assert!(out[0] > 1e-4);
    assert!((out[1] - 1.0).abs() < 1e-12, "{}", out[1]);
    // Drucker–Prager with dilatancy: shear makes the material dilate plastically.
    let m = dp(0.3);
    let mut s = Constitutive::<3>::initial_state(&m);
    m.return_map(&pure_shear(0.01), &mut s).unwrap();
    out.clear();
    Constitutive::<3>::state_scalars(&m, &s, &mut out);
    assert!(out[0] > 0.0 && out[1] > 1.0, "{out:?}");
}
