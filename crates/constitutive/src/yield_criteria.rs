//! Yield criteria: Drucker–Prager (cohesion, friction, dilatancy) and von Mises with
//! linear isotropic hardening.

use crate::error::ConstitutiveError;
use crate::plastic::{Principal, YieldCriterion, split};

/// How the Drucker–Prager cone is fitted to the Mohr–Coulomb parameters (c, φ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ConeFit {
    /// Through the compressive meridians (outer cone): α = 2 sin φ / (√3 (3 − sin φ)).
    Compression,
    /// Through the tensile meridians (inner cone): α = 2 sin φ / (√3 (3 + sin φ)).
    Tension,
    /// Same collapse load in plane strain: α = tan φ / √(9 + 12 tan² φ). The default, for
    /// 2D slope-stability style problems.
    #[default]
    PlaneStrain,
}

impl ConeFit {
    /// (α, k / c) for an angle φ.
    fn coefficients(self, angle: f64) -> (f64, f64) {
        let (sin, cos, tan) = (angle.sin(), angle.cos(), angle.tan());
        let root3 = 3f64.sqrt();
        match self {
            ConeFit::Compression => (
                2.0 * sin / (root3 * (3.0 - sin)),
                6.0 * cos / (root3 * (3.0 - sin)),
            ),
            ConeFit::Tension => (
                2.0 * sin / (root3 * (3.0 + sin)),
                6.0 * cos / (root3 * (3.0 + sin)),
            ),
            ConeFit::PlaneStrain => {
                let d = (9.0 + 12.0 * tan * tan).sqrt();
                (tan / d, 3.0 / d)
            }
        }
    }
}

/// Drucker–Prager: f = ‖s‖/√2 + α I₁ − k (I₁ = tr τ, tension positive) with
/// non-associative flow potential g = ‖s‖/√2 + β I₁ (β from the dilatancy angle ψ ≤ φ).
///
/// Return map: Δγ = f / (μ + 3αβ(3λ + 2μ)), ‖s‖ ← ‖s‖ − √2 μ Δγ, I₁ ← I₁ − 3(3λ + 2μ) β Δγ;
/// where that would overshoot the cone's axis the stress returns to the apex
/// (s = 0, I₁ = k/α).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DruckerPrager {
    alpha: f64,
    beta: f64,
    k: f64,
}

impl DruckerPrager {
    /// From cohesion c ≥ 0, friction angle φ ∈ [0, 90°) and dilatancy angle ψ ∈ [0, φ]
    /// (radians), fitted per `fit`. c = φ = 0 (no strength at all) is rejected.
    pub fn from_mohr_coulomb(
        cohesion: f64,
        friction: f64,
        dilatancy: f64,
        fit: ConeFit,
    ) -> Result<Self, ConstitutiveError> {
        let invalid = |parameter, value, reason| {
            Err(ConstitutiveError::InvalidParameter {
                parameter,
                value,
                reason,
            })
        };
        if !(cohesion.is_finite() && cohesion >= 0.0) {
            return invalid("cohesion", cohesion, "must be finite and non-negative");
        }
        if !(0.0..std::f64::consts::FRAC_PI_2).contains(&friction) {
            return invalid("friction angle (rad)", friction, "must lie in [0, π/2)");
        }
        if !(0.0..=friction).contains(&dilatancy) {
            return invalid(
                "dilatancy angle (rad)",
                dilatancy,
                "must lie in [0, friction angle]",
            );
        }
        if cohesion == 0.0 && friction == 0.0 {
            return invalid(
                "cohesion",
                cohesion,
                "cohesion and friction angle cannot both be zero",
            );
        }
        let (alpha, k_per_c) = fit.coefficients(friction);
        let (beta, _) = fit.coefficients(dilatancy);
        Ok(Self {
            alpha,
            beta,
            k: k_per_c * cohesion,
        })
    }

    /// Friction coefficient α.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Dilatancy coefficient β.
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// Shear strength at zero mean stress, k.
    pub fn k(&self) -> f64 {
        self.k
    }
}

impl YieldCriterion for DruckerPrager {
    const NAME: &'static str = "Drucker-Prager";

    fn yield_function(&self, tau: &Principal, _: f64) -> f64 {
        let (i1, _, norm) = split(tau);
        norm / 2f64.sqrt() + self.alpha * i1 - self.k
    }

    fn project(&self, trial: &Principal, accumulated: f64, lambda: f64, mu: f64) -> Principal {
        let (i1, s, norm) = split(trial);
        let bulk3 = 3.0 * lambda + 2.0 * mu;
        let f = self.yield_function(trial, accumulated);
        let dgamma = f / (mu + 3.0 * self.alpha * self.beta * bulk3);
        let new_norm = norm - 2f64.sqrt() * mu * dgamma;
        if new_norm <= 0.0 {
            // Apex: purely volumetric stress at the tip of the cone.
            let apex_i1 = if self.alpha > 0.0 {
                self.k / self.alpha
            } else {
                i1
            };
            return [apex_i1 / 3.0; 3];
        }
        let new_i1 = i1 - 3.0 * bulk3 * self.beta * dgamma;
        let scale = new_norm / norm;
        s.map(|x| x * scale + new_i1 / 3.0)
    }

    fn stress_scale(&self, _: f64) -> f64 {
        self.k.max(1e-300)
    }
}

/// Von Mises (J2) with linear isotropic hardening: f = ‖s‖ − √(2/3) (σ_y + H ᾱ).
/// Radial return: Δγ = f / (2μ + 2H/3), s ← s (1 − 2μΔγ/‖s‖); pressure is untouched.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VonMises {
    yield_stress: f64,
    hardening: f64,
}

impl VonMises {
    /// Initial uniaxial yield stress σ_y > 0 and hardening modulus H ≥ 0.
    pub fn new(yield_stress: f64, hardening: f64) -> Result<Self, ConstitutiveError> {
        if !(yield_stress.is_finite() && yield_stress > 0.0) {
            return Err(ConstitutiveError::InvalidParameter {
                parameter: "yield stress",
                value: yield_stress,
                reason: "must be finite and positive",
            });
        }
        if !(hardening.is_finite() && hardening >= 0.0) {
            return Err(ConstitutiveError::InvalidParameter {
                parameter: "hardening modulus",
                value: hardening,
                reason: "must be finite and non-negative",
            });
        }
        Ok(Self {
            yield_stress,
            hardening,
        })
    }

    /// Current uniaxial yield stress σ_y + H ᾱ.
    pub fn current_yield_stress(&self, accumulated: f64) -> f64 {
        self.yield_stress + self.hardening * accumulated
    }
}

impl YieldCriterion for VonMises {
    const NAME: &'static str = "von Mises";

    fn yield_function(&self, tau: &Principal, accumulated: f64) -> f64 {
        let (_, _, norm) = split(tau);
        norm - (2.0f64 / 3.0).sqrt() * self.current_yield_stress(accumulated)
    }

    fn project(&self, trial: &Principal, accumulated: f64, _: f64, mu: f64) -> Principal {
        let (i1, s, norm) = split(trial);
        let f = self.yield_function(trial, accumulated);
        let dgamma = f / (2.0 * mu + 2.0 * self.hardening / 3.0);
        let scale = 1.0 - 2.0 * mu * dgamma / norm;
        s.map(|x| x * scale + i1 / 3.0)
    }

    fn stress_scale(&self, accumulated: f64) -> f64 {
        self.current_yield_stress(accumulated)
    }
}
