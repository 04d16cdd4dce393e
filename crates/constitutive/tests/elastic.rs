//! Properties of every model: zero stress at rest, objectivity, symmetry, stress as the
//! derivative of the energy, the small-strain limit, and parameter/deformation errors.

use nalgebra::{Matrix2, Matrix3, Rotation3, SMatrix, Vector3};
use proptest::prelude::*;
use umls_constitutive::{
    ConeFit, Constitutive, ConstitutiveError, DruckerPrager, ElasticParameters, ElastoPlastic,
    FixedCorotated, LinearElastic, NeoHookean, StVenantKirchhoff, VonMises,
    WeaklyCompressibleFluid,
};

fn params() -> ElasticParameters {
    ElasticParameters::from_young_poisson(2.0e3, 0.3).unwrap()
}

fn plastic_dp() -> ElastoPlastic<DruckerPrager> {
    ElastoPlastic::new(
        params(),
        DruckerPrager::from_mohr_coulomb(5.0, 0.5, 0.1, ConeFit::PlaneStrain).unwrap(),
    )
}

fn plastic_j2() -> ElastoPlastic<VonMises> {
    ElastoPlastic::new(params(), VonMises::new(20.0, 50.0).unwrap())
}

/// Random F with det F > 0: a rotation times a stretch near the identity.
fn deformation3() -> impl Strategy<Value = Matrix3<f64>> {
    (
        prop::array::uniform9(-0.3f64..0.3),
        prop::array::uniform3(-3.2f64..3.2),
    )
        .prop_filter_map("det F > 0.2", |(g, axis)| {
            let f = Rotation3::from_scaled_axis(Vector3::from(axis)).matrix()
                * (Matrix3::identity() + Matrix3::from_row_slice(&g));
            (f.determinant() > 0.2).then_some(f)
        })
}

fn rotation3() -> impl Strategy<Value = Matrix3<f64>> {
    prop::array::uniform3(-3.2f64..3.2)
        .prop_map(|a| *Rotation3::from_scaled_axis(Vector3::from(a)).matrix())
}

/// ∂ψ/∂F by central differences against P = τ F⁻ᵀ.
fn check_energy_derivative<const D: usize, M: Constitutive<D>>(
    model: &M,
    f: &SMatrix<f64, D, D>,
    state: &M::State,
) -> Result<(), TestCaseError> {
    let p = model.first_piola(f, state).unwrap();
    let h = 1e-6;
    let mut fd = SMatrix::<f64, D, D>::zeros();
    for i in 0..D {
        for j in 0..D {
            let mut plus = *f;
            let mut minus = *f;
            plus[(i, j)] += h;
            minus[(i, j)] -= h;
            fd[(i, j)] = (model.energy_density(&plus, state).unwrap()
                - model.energy_density(&minus, state).unwrap())
                / (2.0 * h);
        }
    }
    let rel = (fd - p).norm() / p.norm().max(1e-3);
    prop_assert!(rel < 1e-6, "{}: relative error {:e}", model.name(), rel);
    Ok(())
}

fn check_objectivity<const D: usize, M: Constitutive<D>>(
    model: &M,
    f: &SMatrix<f64, D, D>,
    r: &SMatrix<f64, D, D>,
) -> Result<(), TestCaseError> {
    // Return-map both configurations from virgin state: the states must agree too.
    let (mut s1, mut s2) = (model.initial_state(), model.initial_state());
    model.return_map(f, &mut s1).unwrap();
    model.return_map(&(r * f), &mut s2).unwrap();
    let tau = model.kirchhoff_stress(f, &s1).unwrap();
    let tau_r = model.kirchhoff_stress(&(r * f), &s2).unwrap();
    let expected = r * tau * r.transpose();
    prop_assert!(
        (tau_r - expected).norm() <= 1e-9 * (1.0 + tau.norm()),
        "{}: {} vs {}",
        model.name(),
        tau_r,
        expected
    );
    let sigma = model.cauchy_stress(f, &s1).unwrap();
    prop_assert!(
        (sigma - sigma.transpose()).norm() <= 1e-10 * (1.0 + sigma.norm()),
        "{}: asymmetric σ",
        model.name()
    );
    let (psi, psi_r) = (
        model.energy_density(f, &s1).unwrap(),
        model.energy_density(&(r * f), &s2).unwrap(),
    );
    prop_assert!((psi - psi_r).abs() <= 1e-9 * (1.0 + psi.abs()));
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn finite_strain_models_are_objective_and_symmetric(f in deformation3(), r in rotation3()) {
        check_objectivity(&NeoHookean { parameters: params() }, &f, &r)?;
        check_objectivity(&StVenantKirchhoff { parameters: params() }, &f, &r)?;
        check_objectivity(&FixedCorotated { parameters: params() }, &f, &r)?;
        check_objectivity(&WeaklyCompressibleFluid::new(1e3, 7.0).unwrap(), &f, &r)?;
        check_objectivity(&plastic_dp(), &f, &r)?;
        check_objectivity(&plastic_j2(), &f, &r)?;
    }

    #[test]
    fn stress_is_the_derivative_of_the_energy_3d(f in deformation3()) {
        check_energy_derivative(&NeoHookean { parameters: params() }, &f, &())?;
        check_energy_derivative(&StVenantKirchhoff { parameters: params() }, &f, &())?;
        check_energy_derivative(&FixedCorotated { parameters: params() }, &f, &())?;
        check_energy_derivative(&WeaklyCompressibleFluid::new(1e3, 7.0).unwrap(), &f, &())?;
        check_energy_derivative(&WeaklyCompressibleFluid::new(1e3, 1.0).unwrap(), &f, &())?;
        // Plastic models: ψ of the elastic part at a fixed (return-mapped) state.
        let dp = plastic_dp();
        let mut state = Constitutive::<3>::initial_state(&dp);
        dp.return_map(&f, &mut state).unwrap();
        check_energy_derivative(&dp, &f, &state)?;
        let j2 = plastic_j2();
        let mut state = Constitutive::<3>::initial_state(&j2);
        j2.return_map(&f, &mut state).unwrap();
        check_energy_derivative(&j2, &f, &state)?;
    }

    #[test]
    fn stress_is_the_derivative_of_the_energy_2d(g in prop::array::uniform4(-0.3f64..0.3)) {
        let f = Matrix2::identity() + Matrix2::from_row_slice(&g);
        prop_assume!(f.determinant() > 0.2);
        check_energy_derivative(&NeoHookean { parameters: params() }, &f, &())?;
        check_energy_derivative(&StVenantKirchhoff { parameters: params() }, &f, &())?;
        check_energy_derivative(&FixedCorotated { parameters: params() }, &f, &())?;
        let j2 = plastic_j2();
        let mut state = Constitutive::<2>::initial_state(&j2);
        j2.return_map(&f, &mut state).unwrap();
        check_energy_derivative(&j2, &f, &state)?;
    }

    /// Every finite-strain model agrees with linear elasticity to O(ε) relative error for
    /// F = I + εG.
    #[test]
    fn small_strain_limit(g in prop::array::uniform9(-1.0f64..1.0)) {
        let g = Matrix3::from_row_slice(&g);
        prop_assume!(g.norm() > 0.1);
        let linear = LinearElastic { parameters: params() };
        for eps in [1e-3, 1e-5] {
            let f = Matrix3::identity() + g * eps;
            let reference = linear.cauchy_stress(&f, &()).unwrap();
            let models: [(&str, Matrix3<f64>); 5] = [
                ("neo-Hookean", NeoHookean { parameters: params() }.cauchy_stress(&f, &()).unwrap()),
                ("StVK", StVenantKirchhoff { parameters: params() }.cauchy_stress(&f, &()).unwrap()),
                ("corotated", FixedCorotated { parameters: params() }.cauchy_stress(&f, &()).unwrap()),
                ("DP", { let m = plastic_dp(); m.cauchy_stress(&f, &Constitutive::<3>::initial_state(&m)).unwrap() }),
                ("J2", { let m = plastic_j2(); m.cauchy_stress(&f, &Constitutive::<3>::initial_state(&m)).unwrap() }),
            ];
            for (name, sigma) in models {
                let rel = (sigma - reference).norm() / reference.norm();
                prop_assert!(rel < 20.0 * eps, "{} at ε = {}: relative difference {:e}", name, eps, rel);
            }
        }
    }
}

#[test]
fn zero_stress_and_energy_at_rest() {
    fn check<const D: usize, M: Constitutive<D>>(m: &M) {
        let i = SMatrix::<f64, D, D>::identity();
        let s = m.initial_state();
        assert!(
            m.kirchhoff_stress(&i, &s).unwrap().norm() < 1e-12,
            "{}",
            m.name()
        );
        assert!(
            m.energy_density(&i, &s).unwrap().abs() < 1e-12,
            "{}",
            m.name()
        );
    }
    for_all_elastic::<1>();
    for_all_elastic::<2>();
    for_all_elastic::<3>();
    fn for_all_elastic<const D: usize>() {
        check::<D, _>(&LinearElastic {
            parameters: params(),
        });
        check::<D, _>(&NeoHookean {
            parameters: params(),
        });
        check::<D, _>(&StVenantKirchhoff {
            parameters: params(),
        });
        check::<D, _>(&FixedCorotated {
            parameters: params(),
        });
        check::<D, _>(&WeaklyCompressibleFluid::new(1e3, 7.0).unwrap());
    }
    check::<2, _>(&plastic_dp());
    check::<3, _>(&plastic_j2());
}

/// Closed forms: uniaxial linear elasticity, 1D uniaxial stress with modulus E, neo-Hookean
/// under hydrostatic stretch, fluid pressure.
#[test]
fn closed_form_values() {
    let p = params();
    let (lambda, mu) = (p.lambda(), p.mu());
    let eps = 1e-3;
    let f = Matrix3::from_diagonal(&Vector3::new(1.0 + eps, 1.0, 1.0));
    let sigma = LinearElastic { parameters: p }
        .cauchy_stress(&f, &())
        .unwrap();
    assert!((sigma[(0, 0)] - (lambda + 2.0 * mu) * eps).abs() < 1e-9);
    assert!((sigma[(1, 1)] - lambda * eps).abs() < 1e-9);
    // 1D: uniaxial stress, σ = E ε, wave speed √(E/ρ).
    let bar = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(100.0, 0.3).unwrap(),
    };
    let f1 = SMatrix::<f64, 1, 1>::new(1.0 + eps);
    assert!((bar.cauchy_stress(&f1, &()).unwrap()[(0, 0)] - 100.0 * eps).abs() < 1e-12);
    assert!((Constitutive::<1>::p_wave_speed(&bar, 1.0) - 10.0).abs() < 1e-12);
    // Neo-Hookean, F = a I: τ = μ(a² − 1) I + λ 3 ln a I.
    let a: f64 = 1.1;
    let tau = NeoHookean { parameters: p }
        .kirchhoff_stress(&(Matrix3::identity() * a), &())
        .unwrap();
    assert!((tau[(0, 0)] - (mu * (a * a - 1.0) + lambda * 3.0 * a.ln())).abs() < 1e-9);
    // Fluid: σ = −p I with p = K(J^−γ − 1).
    let fluid = WeaklyCompressibleFluid::new(1e3, 7.0).unwrap();
    let sigma = fluid
        .cauchy_stress(&(Matrix3::identity() * 0.99), &())
        .unwrap();
    let j: f64 = 0.99f64.powi(3);
    assert!((sigma[(0, 0)] + 1e3 * (j.powf(-7.0) - 1.0)).abs() < 1e-9);
    assert!((Constitutive::<3>::p_wave_speed(&fluid, 1000.0) - (7.0f64).sqrt()).abs() < 1e-12);
    // Parameter conversions round-trip.
    let q = ElasticParameters::from_bulk_shear(p.lambda() + 2.0 * p.mu() / 3.0, p.mu()).unwrap();
    assert!((q.young() - 2.0e3).abs() < 1e-9 && (q.poisson() - 0.3).abs() < 1e-12);
}

#[test]
fn parameter_and_deformation_errors() {
    let bad = |r: Result<ElasticParameters, ConstitutiveError>, name: &str| match r {
        Err(ConstitutiveError::InvalidParameter { parameter, .. }) => {
            assert!(parameter.contains(name), "{parameter}")
        }
        other => panic!("expected an error naming {name}, got {other:?}"),
    };
    bad(ElasticParameters::from_young_poisson(-1.0, 0.3), "E");
    bad(ElasticParameters::from_young_poisson(1.0, 0.5), "ν");
    bad(ElasticParameters::from_young_poisson(1.0, -1.0), "ν");
    bad(ElasticParameters::from_lame(1.0, 0.0), "μ");
    bad(ElasticParameters::from_lame(-1.0, 1.0), "λ");
    bad(ElasticParameters::from_bulk_shear(0.0, 1.0), "K");
    assert!(
        ElasticParameters::from_young_poisson(1.0, 0.5)
            .unwrap_err()
            .to_string()
            .contains("0.5")
    );
    assert!(DruckerPrager::from_mohr_coulomb(-1.0, 0.5, 0.0, ConeFit::Compression).is_err());
    assert!(DruckerPrager::from_mohr_coulomb(1.0, 1.6, 0.0, ConeFit::Compression).is_err());
    assert!(DruckerPrager::from_mohr_coulomb(1.0, 0.5, 0.6, ConeFit::Compression).is_err());
    assert!(DruckerPrager::from_mohr_coulomb(0.0, 0.0, 0.0, ConeFit::Compression).is_err());
    assert!(VonMises::new(0.0, 1.0).is_err() && VonMises::new(1.0, -1.0).is_err());
    assert!(WeaklyCompressibleFluid::new(1.0, 0.5).is_err());

    let inverted = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -0.5));
    let p = params();
    assert!(matches!(
        NeoHookean { parameters: p }.kirchhoff_stress(&inverted, &()),
        Err(ConstitutiveError::NonPositiveJacobian { .. })
    ));
    assert!(matches!(
        WeaklyCompressibleFluid::new(1.0, 7.0)
            .unwrap()
            .kirchhoff_stress(&inverted, &()),
        Err(ConstitutiveError::NonPositiveJacobian { .. })
    ));
    let j2 = plastic_j2();
    let mut state = Constitutive::<3>::initial_state(&j2);
    assert!(matches!(
        j2.return_map(&inverted, &mut state),
        Err(ConstitutiveError::NonPositiveJacobian { .. })
    ));
    assert!(matches!(
        LinearElastic { parameters: p }.cauchy_stress(&inverted, &()),
        Err(ConstitutiveError::NonPositiveJacobian { .. })
    ));
    // Models defined for inverted F still answer.
    assert!(
        FixedCorotated { parameters: p }
            .kirchhoff_stress(&inverted, &())
            .is_ok()
    );
    assert!(
        StVenantKirchhoff { parameters: p }
            .kirchhoff_stress(&inverted, &())
            .is_ok()
    );
    let nan = Matrix3::from_element(f64::NAN);
    assert!(matches!(
        StVenantKirchhoff { parameters: p }.kirchhoff_stress(&nan, &()),
        Err(ConstitutiveError::NonFiniteDeformation { .. })
    ));
    let message = NeoHookean { parameters: p }
        .kirchhoff_stress(&inverted, &())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("neo-Hookean") && message.contains("det F"),
        "{message}"
    );
}

/// The out-of-plane stress of a plane-strain model is the τ_zz of the same model in 3D
/// with F_zz = 1, for every model (and zero in 1D and 3D, where it has no meaning).
#[test]
fn out_of_plane_stress_is_the_3d_models_zz_component() {
    let parameters = ElasticParameters::from_young_poisson(2e6, 0.3).unwrap();
    let f2 = Matrix2::new(1.05, 0.08, -0.03, 0.93);
    let f3 = Matrix3::new(1.05, 0.08, 0.0, -0.03, 0.93, 0.0, 0.0, 0.0, 1.0);
    fn check<M: Constitutive<2, State = ()> + Constitutive<3, State = ()>>(
        model: &M,
        f2: &Matrix2<f64>,
        f3: &Matrix3<f64>,
    ) {
        let zz = Constitutive::<2>::out_of_plane_stress(model, f2, &()).unwrap();
        let tau = Constitutive::<3>::kirchhoff_stress(model, f3, &()).unwrap();
        assert!(
            (zz - tau[(2, 2)]).abs() < 1e-9 * tau.amax(),
            "{}: {zz} vs {}",
            Constitutive::<2>::name(model),
            tau[(2, 2)]
        );
        assert!(zz.abs() > 0.0);
        assert_eq!(
            Constitutive::<3>::out_of_plane_stress(model, f3, &()).unwrap(),
            0.0
        );
    }
    check(&LinearElastic { parameters }, &f2, &f3);
    check(&NeoHookean { parameters }, &f2, &f3);
    check(&StVenantKirchhoff { parameters }, &f2, &f3);
    check(&FixedCorotated { parameters }, &f2, &f3);
    check(&WeaklyCompressibleFluid::new(1e6, 7.0).unwrap(), &f2, &f3);
    // Plastic models, elastic state: the Hencky stress's out-of-plane principal value.
    let dp = ElastoPlastic::new(
        parameters,
        DruckerPrager::from_mohr_coulomb(1e9, 0.5, 0.0, ConeFit::PlaneStrain).unwrap(),
    );
    let vm = ElastoPlastic::new(parameters, VonMises::new(1e9, 0.0).unwrap());
    let zz =
        Constitutive::<2>::out_of_plane_stress(&dp, &f2, &Constitutive::<2>::initial_state(&dp))
            .unwrap();
    let tau = Constitutive::<3>::kirchhoff_stress(&dp, &f3, &Constitutive::<3>::initial_state(&dp))
        .unwrap();
    assert!(
        (zz - tau[(2, 2)]).abs() < 1e-9 * tau.amax(),
        "{zz} vs {}",
        tau[(2, 2)]
    );
    let zz =
        Constitutive::<2>::out_of_plane_stress(&vm, &f2, &Constitutive::<2>::initial_state(&vm))
            .unwrap();
    assert!((zz - tau[(2, 2)]).abs() < 1e-9 * tau.amax());
}
