//! The engine's error type: a failing simulation stops with the step, the particle or
//! node, and the cause.

use thiserror::Error;
use umls_constitutive::ConstitutiveError;
use umls_transfer::KernelError;

/// Why a simulation stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EngineError {
    /// The kernel could not evaluate a particle's stencil (outside the domain, or an
    /// ill-conditioned MLS system).
    #[error("step {step}, particle {particle}: {source}")]
    Kernel {
        /// Step number.
        step: usize,
        /// Particle index.
        particle: usize,
        /// The kernel's error.
        source: KernelError,
    },
    /// The material model rejected a particle's deformation.
    #[error("step {step}, particle {particle}: {source}")]
    Material {
        /// Step number.
        step: usize,
        /// Particle index.
        particle: usize,
        /// The model's error.
        source: ConstitutiveError,
    },
    /// A NaN or infinity in a particle or node field.
    #[error("step {step}: non-finite {field} at {entity} {index}")]
    NonFinite {
        /// Step number.
        step: usize,
        /// Field name.
        field: &'static str,
        /// "particle" or "node".
        entity: &'static str,
        /// Its index.
        index: usize,
    },
    /// det F ≤ 0 after the deformation update.
    #[error("step {step}, particle {particle}: det F = {det:e} ≤ 0 (material inverted)")]
    Inverted {
        /// Step number.
        step: usize,
        /// Particle index.
        particle: usize,
        /// det F.
        det: f64,
    },
    /// Total energy grew beyond the configured factor of its initial value.
    #[error(
        "step {step}: total energy {energy:e} exceeds {factor} × the initial {initial:e} (instability)"
    )]
    EnergyBlowUp {
        /// Step number.
        step: usize,
        /// Current total energy.
        energy: f64,
        /// Initial total energy.
        initial: f64,
        /// The configured factor.
        factor: f64,
    },
    /// A parameter out of range.
    #[error("parameter `{parameter}` = {value}: {reason}")]
    InvalidParameter {
        /// Name.
        parameter: &'static str,
        /// Value.
        value: f64,
        /// Valid range.
        reason: &'static str,
    },
}
