//! The constitutive port: what the MPM engine asks of a material.

use std::fmt::Debug;

use crate::error::ConstitutiveError;
use crate::linalg::{Matrix, inverse_transpose, positive_jacobian};

/// A material model in D dimensions.
///
/// The engine keeps the total deformation gradient F per particle and one
/// [`Self::State`]. Each step it updates F and calls [`Self::return_map_and_stress`]:
/// the return map (plastic models project onto the yield surface and update the state;
/// elastic models do nothing), then the Kirchhoff stress τ = Jσ of the returned state,
/// which the next step's internal force f_i = −Σ_p V_p⁰ τ_p ∇N_i needs without a
/// division by J. [`Self::kirchhoff_stress`] alone is asked before the first step and
/// after particles or material were edited.
pub trait Constitutive<const D: usize>: Send + Sync + Debug {
    /// Per-particle internal state (`()` for elastic models).
    type State: Clone + Debug + PartialEq + Send + Sync;

    /// A short name for messages.
    fn name(&self) -> &'static str;

    /// The state of undeformed, virgin material.
    fn initial_state(&self) -> Self::State;

    /// The explicit return-mapping step for total deformation `f`: updates `state` so that
    /// the stress lies on or inside the yield surface. Elastic models: no-op.
    fn return_map(&self, f: &Matrix<D>, state: &mut Self::State) -> Result<(), ConstitutiveError> {
        let _ = (f, state);
        Ok(())
    }

    /// [`Self::return_map`], then the Kirchhoff stress of the returned state: what the
    /// engine asks at the end of every step (the stress is the next step's). Plastic
    /// models override it to take both from one decomposition of the trial elastic
    /// deformation instead of two; the result equals the two calls up to round-off.
    fn return_map_and_stress(
        &self,
        f: &Matrix<D>,
        state: &mut Self::State,
    ) -> Result<Matrix<D>, ConstitutiveError> {
        self.return_map(f, state)?;
        self.kirchhoff_stress(f, state)
    }

    /// Kirchhoff stress τ = J σ (symmetric).
    fn kirchhoff_stress(
        &self,
        f: &Matrix<D>,
        state: &Self::State,
    ) -> Result<Matrix<D>, ConstitutiveError>;

    /// The out-of-plane Kirchhoff stress τ_zz of a 2D (plane-strain) model, where F_zz = 1
    /// but τ_zz is not zero (λ ln J for neo-Hookean). Zero in 1D (uniaxial stress) and 3D
    /// (where τ has all its components). Default: zero, the plane-stress answer; plane-
    /// strain models override it.
    fn out_of_plane_stress(
        &self,
        f: &Matrix<D>,
        state: &Self::State,
    ) -> Result<f64, ConstitutiveError> {
        let _ = (f, state);
        Ok(0.0)
    }

    /// Stored (elastic) energy per unit reference volume, ψ(F).
    fn energy_density(&self, f: &Matrix<D>, state: &Self::State) -> Result<f64, ConstitutiveError>;

    /// P-wave modulus λ + 2μ (the stiffness of longitudinal waves; E in 1D).
    fn p_wave_modulus(&self) -> f64;

    /// Names of the scalars a particle's state carries, for output (plastic strain, …);
    /// none for elastic models.
    fn state_scalar_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// Appends the values of [`Self::state_scalar_names`] for `state` to `out`, in order.
    fn state_scalars(&self, state: &Self::State, out: &mut Vec<f64>) {
        let _ = (state, out);
    }

    /// Cauchy stress σ = τ / J; needs det F > 0.
    fn cauchy_stress(
        &self,
        f: &Matrix<D>,
        state: &Self::State,
    ) -> Result<Matrix<D>, ConstitutiveError> {
        let det = positive_jacobian(self.name(), f)?;
        Ok(self.kirchhoff_stress(f, state)? / det)
    }

    /// First Piola–Kirchhoff stress P = τ F⁻ᵀ; for hyperelastic models P = ∂ψ/∂F.
    fn first_piola(
        &self,
        f: &Matrix<D>,
        state: &Self::State,
    ) -> Result<Matrix<D>, ConstitutiveError> {
        let det = crate::linalg::determinant(f);
        let inv_t = inverse_transpose(f).ok_or(ConstitutiveError::NonPositiveJacobian {
            model: self.name(),
            det,
        })?;
        Ok(self.kirchhoff_stress(f, state)? * inv_t)
    }

    /// Longitudinal wave speed √((λ + 2μ)/ρ) for the CFL bound.
    fn p_wave_speed(&self, density: f64) -> f64 {
        (self.p_wave_modulus() / density).sqrt()
    }
}
