//! Elastoplasticity with Hencky (logarithmic-strain) elasticity and a return map in
//! principal Kirchhoff stress space, shared by every yield criterion.
//!
//! F = Fᵉ Fᵖ. The state keeps (Fᵖ)⁻¹ so the engine can keep the total F. With
//! Fᵉ = U diag(e^{ε_i}) Vᵀ, the Kirchhoff stress is coaxial with the elastic left stretch:
//! τ = U diag(τ_i) Uᵀ, τ_i = λ Σ_j ε_j + 2μ ε_i. The return map always works on three
//! principal values: in 3D from the SVD; in 2D (plane strain) the third is the elastic
//! out-of-plane strain εᵉ_zz kept in the state, because the total ε_zz = 0 while plastic
//! flow may have a zz component. That makes 2D results exactly those of 3D plane strain.

use nalgebra::SVector;

use crate::error::ConstitutiveError;
use crate::linalg::{Matrix, positive_jacobian, signed_svd};
use crate::model::Constitutive;
use crate::parameters::ElasticParameters;

/// Principal values in 3D (the plane-strain third one included in 2D).
pub type Principal = [f64; 3];

/// A yield criterion with its return map in principal Kirchhoff stress space.
pub trait YieldCriterion: Clone + std::fmt::Debug + Send + Sync {
    /// Model name for messages.
    const NAME: &'static str;

    /// f(τ, ᾱ): ≤ 0 inside the elastic domain; ᾱ is the accumulated plastic strain.
    fn yield_function(&self, tau: &Principal, accumulated: f64) -> f64;

    /// Projects a trial stress with f > 0 back onto the yield surface, given the elastic
    /// constants of the Hencky law. Returns the corrected principal stresses.
    fn project(&self, trial: &Principal, accumulated: f64, lambda: f64, mu: f64) -> Principal;

    /// Stress scale for the tolerance deciding "on the surface" (e.g. the yield stress).
    fn stress_scale(&self, accumulated: f64) -> f64;
}

/// The internal state of a plastic particle.
#[derive(Debug, Clone, PartialEq)]
pub struct PlasticState<const D: usize> {
    /// (Fᵖ)⁻¹, so that Fᵉ = F (Fᵖ)⁻¹.
    pub plastic_inverse: Matrix<D>,
    /// Elastic out-of-plane Hencky strain εᵉ_zz (2D plane strain only; 0 otherwise).
    pub out_of_plane_strain: f64,
    /// Accumulated equivalent plastic strain ᾱ = Σ √(2/3) ‖Δεᵖ‖.
    pub accumulated_plastic_strain: f64,
}

impl<const D: usize> Default for PlasticState<D> {
    fn default() -> Self {
        Self {
            plastic_inverse: Matrix::<D>::identity(),
            out_of_plane_strain: 0.0,
            accumulated_plastic_strain: 0.0,
        }
    }
}

/// Hencky elasticity + a yield criterion: Drucker–Prager or von Mises (J2).
///
/// Available for D = 2 (plane strain) and D = 3; using it in 1D is a compile-time error.
#[derive(Debug, Clone, PartialEq)]
pub struct ElastoPlastic<Y: YieldCriterion> {
    /// Elastic constants of the Hencky law.
    pub parameters: ElasticParameters,
    /// The yield criterion.
    pub criterion: Y,
}

/// Relative tolerance on f for "on the surface": makes the return map idempotent.
const YIELD_TOLERANCE: f64 = 1e-10;

struct ElasticStrain<const D: usize> {
    u: Matrix<D>,
    v: Matrix<D>,
    eps: Principal,
}

fn hencky_stress(eps: &Principal, lambda: f64, mu: f64) -> Principal {
    let trace = eps.iter().sum::<f64>();
    eps.map(|e| lambda * trace + 2.0 * mu * e)
}

fn hencky_strain(tau: &Principal, lambda: f64, mu: f64) -> Principal {
    let trace_eps = tau.iter().sum::<f64>() / (3.0 * lambda + 2.0 * mu);
    tau.map(|t| (t - lambda * trace_eps) / (2.0 * mu))
}

impl<Y: YieldCriterion> ElastoPlastic<Y> {
    /// Hencky elasticity with the given constants and yield criterion.
    pub fn new(parameters: ElasticParameters, criterion: Y) -> Self {
        Self {
            parameters,
            criterion,
        }
    }

    fn elastic_strain<const D: usize>(
        &self,
        f: &Matrix<D>,
        state: &PlasticState<D>,
    ) -> Result<ElasticStrain<D>, ConstitutiveError> {
        const {
            assert!(
                D == 2 || D == 3,
                "plastic models exist for D = 2 (plane strain) and D = 3"
            )
        };
        positive_jacobian(Y::NAME, f)?;
        let fe = f * state.plastic_inverse;
        let (u, sigma, v) = signed_svd(&fe);
        if sigma.iter().any(|&s| s <= 0.0) {
            return Err(ConstitutiveError::NonPositiveJacobian {
                model: Y::NAME,
                det: sigma.product(),
            });
        }
        let mut eps = [0.0, 0.0, state.out_of_plane_strain];
        for i in 0..D {
            eps[i] = sigma[i].ln();
        }
        Ok(ElasticStrain { u, v, eps })
    }

    /// The elastic Hencky strain: in-plane tensor U diag(ε_i) Uᵀ and all three principal values.
    pub fn elastic_log_strain<const D: usize>(
        &self,
        f: &Matrix<D>,
        state: &PlasticState<D>,
    ) -> Result<(Matrix<D>, Principal), ConstitutiveError> {
        let e = self.elastic_strain(f, state)?;
        let diag = SVector::<f64, D>::from_fn(|i, _| e.eps[i]);
        Ok((
            e.u * Matrix::<D>::from_diagonal(&diag) * e.u.transpose(),
            e.eps,
        ))
    }

    /// Principal Kirchhoff stresses (three, the out-of-plane one included in 2D).
    pub fn principal_stress<const D: usize>(
        &self,
        f: &Matrix<D>,
        state: &PlasticState<D>,
    ) -> Result<Principal, ConstitutiveError> {
        let (lambda, mu) = (self.parameters.lambda(), self.parameters.mu());
        Ok(hencky_stress(
            &self.elastic_strain(f, state)?.eps,
            lambda,
            mu,
        ))
    }
}

impl<const D: usize, Y: YieldCriterion> Constitutive<D> for ElastoPlastic<Y> {
    type State = PlasticState<D>;

    fn name(&self) -> &'static str {
        Y::NAME
    }

    fn initial_state(&self) -> PlasticState<D> {
        PlasticState::default()
    }

    fn state_scalar_names(&self) -> &'static [&'static str] {
        &["plastic_strain", "plastic_jacobian"]
    }

    /// Accumulated equivalent plastic strain, and det Fᵖ (plastic volume change: > 1 for
    /// a dilating Drucker–Prager material, 1 for J2).
    fn state_scalars(&self, state: &PlasticState<D>, out: &mut Vec<f64>) {
        out.push(state.accumulated_plastic_strain);
        out.push(1.0 / crate::linalg::determinant(&state.plastic_inverse));
    }

    fn return_map(
        &self,
        f: &Matrix<D>,
        state: &mut PlasticState<D>,
    ) -> Result<(), ConstitutiveError> {
        self.return_map_and_stress(f, state).map(|_| ())
    }

    /// One SVD of the trial elastic deformation gives both the return map and the
    /// stress: τ = U diag(τ_i) Uᵀ with the trial principal stresses if they are
    /// admissible, the projected ones otherwise (the returned Fᵉ = U diag(e^ε) Vᵀ shares
    /// U, so this is the stress `kirchhoff_stress` would compute from the new state).
    fn return_map_and_stress(
        &self,
        f: &Matrix<D>,
        state: &mut PlasticState<D>,
    ) -> Result<Matrix<D>, ConstitutiveError> {
        let (lambda, mu) = (self.parameters.lambda(), self.parameters.mu());
        let trial = self.elastic_strain(f, state)?;
        let tau = hencky_stress(&trial.eps, lambda, mu);
        let rotate = |principal: &Principal| {
            let diag = SVector::<f64, D>::from_fn(|i, _| principal[i]);
            trial.u * Matrix::<D>::from_diagonal(&diag) * trial.u.transpose()
        };
        let accumulated = state.accumulated_plastic_strain;
        let f_trial = self.criterion.yield_function(&tau, accumulated);
        if f_trial <= YIELD_TOLERANCE * self.criterion.stress_scale(accumulated) {
            return Ok(rotate(&tau));
        }
        let projected = self.criterion.project(&tau, accumulated, lambda, mu);
        let eps = hencky_strain(&projected, lambda, mu);
        let plastic_increment = (0..3)
            .map(|i| (trial.eps[i] - eps[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let stretch = SVector::<f64, D>::from_fn(|i, _| eps[i].exp());
        let fe = trial.u * Matrix::<D>::from_diagonal(&stretch) * trial.v.transpose();
        let det = crate::linalg::determinant(f);
        let f_inverse = f
            .try_inverse()
            .ok_or(ConstitutiveError::NonPositiveJacobian {
                model: Y::NAME,
                det,
            })?;
        state.plastic_inverse = f_inverse * fe;
        if D == 2 {
            state.out_of_plane_strain = eps[2];
        }
        state.accumulated_plastic_strain += (2.0f64 / 3.0).sqrt() * plastic_increment;
        Ok(rotate(&projected))
    }

    fn kirchhoff_stress(
        &self,
        f: &Matrix<D>,
        state: &PlasticState<D>,
    ) -> Result<Matrix<D>, ConstitutiveError> {
        let (lambda, mu) = (self.parameters.lambda(), self.parameters.mu());
        let e = self.elastic_strain(f, state)?;
        let tau = hencky_stress(&e.eps, lambda, mu);
        let diag = SVector::<f64, D>::from_fn(|i, _| tau[i]);
        Ok(e.u * Matrix::<D>::from_diagonal(&diag) * e.u.transpose())
    }

    fn out_of_plane_stress(
        &self,
        f: &Matrix<D>,
        state: &PlasticState<D>,
    ) -> Result<f64, ConstitutiveError> {
        if D != 2 {
            return Ok(0.0);
        }
        Ok(self.principal_stress(f, state)?[2])
    }

    fn energy_density(
        &self,
        f: &Matrix<D>,
        state: &PlasticState<D>,
    ) -> Result<f64, ConstitutiveError> {
        let (lambda, mu) = (self.parameters.lambda(), self.parameters.mu());
        let eps = self.elastic_strain(f, state)?.eps;
        let trace = eps.iter().sum::<f64>();
        Ok(mu * eps.iter().map(|e| e * e).sum::<f64>() + 0.5 * lambda * trace * trace)
    }

    fn p_wave_modulus(&self) -> f64 {
        self.parameters.p_wave_modulus(D)
    }
}

/// Mean and deviator of principal stresses: (I₁ = Σ τ_i, s_i = τ_i − I₁/3, ‖s‖).
pub(crate) fn split(tau: &Principal) -> (f64, Principal, f64) {
    let i1 = tau.iter().sum::<f64>();
    let s = tau.map(|t| t - i1 / 3.0);
    let norm = s.iter().map(|x| x * x).sum::<f64>().sqrt();
    (i1, s, norm)
}
