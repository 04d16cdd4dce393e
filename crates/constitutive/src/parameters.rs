//! Elastic parameters with validated construction.

use crate::error::ConstitutiveError;

/// Isotropic elastic constants (Lamé λ, μ), validated.
///
/// In 2D the models are plane strain, so the 3D constants apply unchanged. In 1D they are
/// uniaxial stress: the models use λ = 0 and μ = E/2, so the modulus is Young's E and the
/// wave speed √(E/ρ), as in the 1D bar benchmarks ([`Self::for_dimension`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticParameters {
    lambda: f64,
    mu: f64,
}

fn invalid(parameter: &'static str, value: f64, reason: &'static str) -> ConstitutiveError {
    ConstitutiveError::InvalidParameter {
        parameter,
        value,
        reason,
    }
}

impl ElasticParameters {
    /// From Young's modulus E > 0 and Poisson's ratio −1 < ν < 0.5.
    pub fn from_young_poisson(young: f64, poisson: f64) -> Result<Self, ConstitutiveError> {
        if !(young.is_finite() && young > 0.0) {
            return Err(invalid(
                "E (Young's modulus)",
                young,
                "must be finite and positive",
            ));
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(invalid(
                "ν (Poisson's ratio)",
                poisson,
                "must lie in (−1, 0.5) for a compressible model",
            ));
        }
        Ok(Self {
            lambda: young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)),
            mu: young / (2.0 * (1.0 + poisson)),
        })
    }

    /// From Lamé constants: μ > 0 and bulk modulus λ + 2μ/3 > 0.
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Self, ConstitutiveError> {
        if !(mu.is_finite() && mu > 0.0) {
            return Err(invalid(
                "μ (shear modulus)",
                mu,
                "must be finite and positive",
            ));
        }
        if !(lambda.is_finite() && lambda + 2.0 * mu / 3.0 > 0.0) {
            return Err(invalid(
                "λ (Lamé's first parameter)",
                lambda,
                "needs a positive bulk modulus λ + 2μ/3",
            ));
        }
        Ok(Self { lambda, mu })
    }

    /// From bulk modulus K > 0 and shear modulus G > 0.
    pub fn from_bulk_shear(bulk: f64, shear: f64) -> Result<Self, ConstitutiveError> {
        if !(bulk.is_finite() && bulk > 0.0) {
            return Err(invalid(
                "K (bulk modulus)",
                bulk,
                "must be finite and positive",
            ));
        }
        if !(shear.is_finite() && shear > 0.0) {
            return Err(invalid(
                "G (shear modulus)",
                shear,
                "must be finite and positive",
            ));
        }
        Ok(Self {
            lambda: bulk - 2.0 * shear / 3.0,
            mu: shear,
        })
    }

    /// Lamé's first parameter λ (3D, and 2D plane strain).
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// Shear modulus μ.
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Young's modulus E = μ(3λ + 2μ)/(λ + μ).
    pub fn young(&self) -> f64 {
        self.mu * (3.0 * self.lambda + 2.0 * self.mu) / (self.lambda + self.mu)
    }

    /// Poisson's ratio ν = λ / (2(λ + μ)).
    pub fn poisson(&self) -> f64 {
        self.lambda / (2.0 * (self.lambda + self.mu))
    }

    /// The (λ, μ) the D-dimensional models use: (λ, μ) for D = 2, 3; (0, E/2) for D = 1.
    pub fn for_dimension(&self, dim: usize) -> (f64, f64) {
        if dim == 1 {
            (0.0, 0.5 * self.young())
        } else {
            (self.lambda, self.mu)
        }
    }

    /// P-wave modulus λ + 2μ in D dimensions (E in 1D).
    pub fn p_wave_modulus(&self, dim: usize) -> f64 {
        let (lambda, mu) = self.for_dimension(dim);
        lambda + 2.0 * mu
    }
}
