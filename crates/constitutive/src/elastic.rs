//! Elastic models: small-strain linear elasticity and the finite-strain hyperelastic
//! models (compressible neo-Hookean, St. Venant–Kirchhoff, fixed corotated).

use crate::error::ConstitutiveError;
use crate::linalg::{Matrix, determinant, finite, positive_jacobian, signed_svd};
use crate::model::Constitutive;
use crate::parameters::ElasticParameters;

/// Small-strain linear elasticity: ε = sym(F) − I, σ = λ tr(ε) I + 2μ ε, ψ = μ ε:ε + λ/2 tr(ε)².
///
/// Not objective (it is the linearisation about F = I): meant for small-deformation
/// benchmarks such as the vibrating bar and the colliding disks. Accepts any F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Elastic constants.
    pub parameters: ElasticParameters,
}

fn small_strain<const D: usize>(f: &Matrix<D>) -> Matrix<D> {
    (f + f.transpose()) * 0.5 - Matrix::<D>::identity()
}

impl LinearElastic {
    /// Model name used in error messages.
    pub const NAME: &'static str = "linear elasticity";
}

impl<const D: usize> Constitutive<D> for LinearElastic {
    type State = ();

    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn initial_state(&self) {}

    /// τ = J σ with the small-strain σ, so that [`Constitutive::cauchy_stress`] is exactly σ.
    fn kirchhoff_stress(&self, f: &Matrix<D>, _: &()) -> Result<Matrix<D>, ConstitutiveError> {
        finite(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let eps = small_strain(f);
        let sigma = Matrix::<D>::identity() * (lambda * eps.trace()) + eps * (2.0 * mu);
        Ok(sigma * determinant(f))
    }

    fn out_of_plane_stress(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        if D != 2 {
            return Ok(0.0);
        }
        finite(Self::NAME, f)?;
        let (lambda, _) = self.parameters.for_dimension(D);
        Ok(lambda * small_strain(f).trace() * determinant(f))
    }

    fn energy_density(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        finite(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let eps = small_strain(f);
        Ok(mu * eps.norm_squared() + 0.5 * lambda * eps.trace().powi(2))
    }

    fn p_wave_modulus(&self) -> f64 {
        self.parameters.p_wave_modulus(D)
    }
}

/// Compressible neo-Hookean: ψ = μ/2 (tr(FᵀF) − D) − μ ln J + λ/2 (ln J)²,
/// τ = μ (F Fᵀ − I) + λ ln J I. Needs det F > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    /// Elastic constants.
    pub parameters: ElasticParameters,
}

impl NeoHookean {
    /// Model name used in error messages.
    pub const NAME: &'static str = "neo-Hookean";
}

impl<const D: usize> Constitutive<D> for NeoHookean {
    type State = ();

    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn initial_state(&self) {}

    fn kirchhoff_stress(&self, f: &Matrix<D>, _: &()) -> Result<Matrix<D>, ConstitutiveError> {
        let j = positive_jacobian(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        Ok((f * f.transpose() - Matrix::<D>::identity()) * mu
            + Matrix::<D>::identity() * (lambda * j.ln()))
    }

    fn out_of_plane_stress(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        if D != 2 {
            return Ok(0.0);
        }
        let j = positive_jacobian(Self::NAME, f)?;
        let (lambda, _) = self.parameters.for_dimension(D);
        Ok(lambda * j.ln())
    }

    fn energy_density(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        let j = positive_jacobian(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let log_j = j.ln();
        Ok(0.5 * mu * (f.norm_squared() - D as f64) - mu * log_j + 0.5 * lambda * log_j * log_j)
    }

    fn p_wave_modulus(&self) -> f64 {
        self.parameters.p_wave_modulus(D)
    }
}

/// St. Venant–Kirchhoff: E = (FᵀF − I)/2, S = λ tr(E) I + 2μ E, τ = F S Fᵀ,
/// ψ = μ E:E + λ/2 tr(E)². Accepts any F (but softens in compression, a known limitation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StVenantKirchhoff {
    /// Elastic constants.
    pub parameters: ElasticParameters,
}

impl StVenantKirchhoff {
    fn green_strain<const D: usize>(f: &Matrix<D>) -> Matrix<D> {
        (f.transpose() * f - Matrix::<D>::identity()) * 0.5
    }
}

impl StVenantKirchhoff {
    /// Model name used in error messages.
    pub const NAME: &'static str = "St. Venant-Kirchhoff";
}

impl<const D: usize> Constitutive<D> for StVenantKirchhoff {
    type State = ();

    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn initial_state(&self) {}

    fn kirchhoff_stress(&self, f: &Matrix<D>, _: &()) -> Result<Matrix<D>, ConstitutiveError> {
        finite(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let e = Self::green_strain(f);
        let s = Matrix::<D>::identity() * (lambda * e.trace()) + e * (2.0 * mu);
        Ok(f * s * f.transpose())
    }

    fn out_of_plane_stress(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        if D != 2 {
            return Ok(0.0);
        }
        finite(Self::NAME, f)?;
        let (lambda, _) = self.parameters.for_dimension(D);
        Ok(lambda * Self::green_strain(f).trace())
    }

    fn energy_density(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        finite(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let e = Self::green_strain(f);
        Ok(mu * e.norm_squared() + 0.5 * lambda * e.trace().powi(2))
    }

    fn p_wave_modulus(&self) -> f64 {
        self.parameters.p_wave_modulus(D)
    }
}

/// Fixed corotated (Stomakhin et al. 2012): ψ = μ Σ (σ_i − 1)² + λ/2 (J − 1)²,
/// τ = 2μ (F − R) Fᵀ + λ (J − 1) J I with R the rotation of the polar decomposition.
/// The sign-fixed SVD makes it well defined for inverted F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedCorotated {
    /// Elastic constants.
    pub parameters: ElasticParameters,
}

impl FixedCorotated {
    /// Model name used in error messages.
    pub const NAME: &'static str = "fixed corotated";
}

impl<const D: usize> Constitutive<D> for FixedCorotated {
    type State = ();

    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn initial_state(&self) {}

    fn kirchhoff_stress(&self, f: &Matrix<D>, _: &()) -> Result<Matrix<D>, ConstitutiveError> {
        finite(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let (u, _, v) = signed_svd(f);
        let rotation = u * v.transpose();
        let j = determinant(f);
        Ok((f - rotation) * f.transpose() * (2.0 * mu)
            + Matrix::<D>::identity() * (lambda * (j - 1.0) * j))
    }

    fn out_of_plane_stress(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        if D != 2 {
            return Ok(0.0);
        }
        finite(Self::NAME, f)?;
        let (lambda, _) = self.parameters.for_dimension(D);
        let j = determinant(f);
        Ok(lambda * (j - 1.0) * j)
    }

    fn energy_density(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        finite(Self::NAME, f)?;
        let (lambda, mu) = self.parameters.for_dimension(D);
        let (_, sigma, _) = signed_svd(f);
        let j = determinant(f);
        Ok(mu * sigma.iter().map(|s| (s - 1.0).powi(2)).sum::<f64>()
            + 0.5 * lambda * (j - 1.0).powi(2))
    }

    fn p_wave_modulus(&self) -> f64 {
        self.parameters.p_wave_modulus(D)
    }
}
