//! Weakly compressible fluid with a J-based (Tait-type) equation of state.

use crate::error::ConstitutiveError;
use crate::linalg::{Matrix, positive_jacobian};
use crate::model::Constitutive;

/// Pressure p = K (J^(−γ) − 1), stress σ = −p I (inviscid), as in the common MPM fluid
/// demos. ψ(J) = K (J − 1 − (J^(1−γ) − 1)/(1 − γ)) (K (J − 1 − ln J) for γ = 1), so that
/// τ = ψ'(J) J I. Only J matters: shear costs nothing. Needs det F > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeaklyCompressibleFluid {
    bulk: f64,
    gamma: f64,
}

impl WeaklyCompressibleFluid {
    /// Bulk modulus K > 0 and exponent γ ≥ 1 (7 for water-like stiffening).
    pub fn new(bulk: f64, gamma: f64) -> Result<Self, ConstitutiveError> {
        if !(bulk.is_finite() && bulk > 0.0) {
            return Err(ConstitutiveError::InvalidParameter {
                parameter: "K (bulk modulus)",
                value: bulk,
                reason: "must be finite and positive",
            });
        }
        if !(gamma.is_finite() && gamma >= 1.0) {
            return Err(ConstitutiveError::InvalidParameter {
                parameter: "γ (exponent)",
                value: gamma,
                reason: "must be finite and ≥ 1",
            });
        }
        Ok(Self { bulk, gamma })
    }

    /// Pressure at volume ratio J.
    pub fn pressure(&self, j: f64) -> f64 {
        // γ = 1 (the common choice, and Taichi's J-fluid) is a division, several times
        // cheaper than `powf` in the step's hottest material call.
        let compression = if self.gamma == 1.0 {
            1.0 / j
        } else {
            j.powf(-self.gamma)
        };
        self.bulk * (compression - 1.0)
    }
}

impl WeaklyCompressibleFluid {
    /// Model name used in error messages.
    pub const NAME: &'static str = "weakly compressible fluid";
}

impl<const D: usize> Constitutive<D> for WeaklyCompressibleFluid {
    type State = ();

    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn initial_state(&self) {}

    fn kirchhoff_stress(&self, f: &Matrix<D>, _: &()) -> Result<Matrix<D>, ConstitutiveError> {
        let j = positive_jacobian(Self::NAME, f)?;
        Ok(Matrix::<D>::identity() * (-j * self.pressure(j)))
    }

    fn out_of_plane_stress(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        if D != 2 {
            return Ok(0.0);
        }
        let j = positive_jacobian(Self::NAME, f)?;
        Ok(-j * self.pressure(j))
    }

    fn energy_density(&self, f: &Matrix<D>, _: &()) -> Result<f64, ConstitutiveError> {
        let j = positive_jacobian(Self::NAME, f)?;
        let k = self.bulk;
        Ok(if (self.gamma - 1.0).abs() < 1e-12 {
            k * (j - 1.0 - j.ln())
        } else {
            k * (j - 1.0 - (j.powf(1.0 - self.gamma) - 1.0) / (1.0 - self.gamma))
        })
    }

    /// The tangent stiffness K γ at J = 1 (dp/d(ln ρ)), so the sound speed is √(Kγ/ρ).
    fn p_wave_modulus(&self) -> f64 {
        self.bulk * self.gamma
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_isothermal_division_continues_the_general_power_law() {
        // γ = 1 takes the division; γ just above 1 takes `powf`: both must meet, and the
        // division must be K (1/J − 1) itself.
        let exact = WeaklyCompressibleFluid::new(400.0, 1.0).unwrap();
        let near = WeaklyCompressibleFluid::new(400.0, 1.0 + 1e-10).unwrap();
        for j in [0.5, 0.9, 0.999, 1.0, 1.01, 1.7] {
            let (p, q) = (exact.pressure(j), near.pressure(j));
            assert!(
                (p - q).abs() <= 1e-7 * (1.0 + p.abs()),
                "J = {j}: {p} vs {q}"
            );
            let independent = 400.0 * (1.0 - j) / j;
            assert!(
                (p - independent).abs() <= 1e-12 * (1.0 + p.abs()),
                "J = {j}"
            );
        }
    }
}
