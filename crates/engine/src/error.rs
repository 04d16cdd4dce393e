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
        /// Particle index (at construction: [`crate::Simulation::particle_id`]).
        particle: usize,
        /// The kernel's error.
        source: KernelError,
    },
    /// The kernel could not evaluate the stencil at a face clamp's point (outside the
    /// domain, or an ill-conditioned MLS system), when the clamp was built.
    #[error("face point {point}: {source}")]
    FacePoint {
        /// The point's position in [`crate::FaceClamp::points`].
        point: usize,
        /// The kernel's error.
        source: KernelError,
    },
    /// The material model rejected a particle's deformation.
    #[error("step {step}, particle {particle}: {source}")]
    Material {
        /// Step number.
        step: usize,
        /// Particle index (at construction: [`crate::Simulation::particle_id`]).
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
        /// Its index (a particle's at construction: [`crate::Simulation::particle_id`]).
        index: usize,
    },
    /// det F ≤ 0 after the deformation update.
    #[error("step {step}, particle {particle}: det F = {det:.4e} ≤ 0 (material inverted)")]
    Inverted {
        /// Step number.
        step: usize,
        /// Particle index (at construction: [`crate::Simulation::particle_id`]).
        particle: usize,
        /// det F.
        det: f64,
    },
    /// Kinetic plus elastic energy grew beyond the configured factor of the energy put
    /// into the body (initial energy plus the work of gravity and body forces).
    #[error(
        "step {step}: kinetic + elastic energy {energy:.4e} exceeds {factor} × the {initial:.4e} put in (initial energy plus work of gravity and body forces): unstable"
    )]
    EnergyBlowUp {
        /// Step number.
        step: usize,
        /// Current kinetic plus elastic energy.
        energy: f64,
        /// Energy put in: the initial energy plus the largest external work so far.
        initial: f64,
        /// The configured factor.
        factor: f64,
    },
    /// A particle moved more than the allowed number of kernel spacings in one step: the
    /// time step is too large for its speed (or the run has become unstable).
    #[error(
        "step {step}, particle {particle}: moved {courant:.3} kernel spacings in one step (limit {limit}): the time step is too large for its speed"
    )]
    Unstable {
        /// Step number.
        step: usize,
        /// The fastest particle (its index at construction).
        particle: usize,
        /// Its Courant number |v| Δt / h.
        courant: f64,
        /// The configured limit.
        limit: f64,
    },
    /// The step would be stable at the body's speed, but one particle was kicked far
    /// beyond it (a sliver simplex or a light node of the kernel, not the time step).
    #[error(
        "step {step}, particle {particle}: kicked to |v| = {speed:.4e}, {ratio:.1}× the particles' RMS speed; the step is stable at that speed, not at the kicked particle's (wave Courant number {wave_courant:.3} > the limit): the kick, not Δt, is the cause"
    )]
    ParticleKick {
        /// Step number.
        step: usize,
        /// The kicked particle (its index at construction).
        particle: usize,
        /// Its speed.
        speed: f64,
        /// Its speed over the particles' mass-weighted RMS speed.
        ratio: f64,
        /// The wave Courant number Δt (c + |v|) / h at its speed.
        wave_courant: f64,
    },
    /// The time step exceeds the explicit stability limit.
    #[error(
        "step {step}: Δt = {dt:.4e} exceeds the stable step {stable:.4e} (wave Courant number {wave_courant:.3} > the limit): use a smaller dt or cfl, or an adaptive time step"
    )]
    TimeStepTooLarge {
        /// Step number.
        step: usize,
        /// The time step.
        dt: f64,
        /// The stable step h / (c + |v|_max).
        stable: f64,
        /// Their ratio.
        wave_courant: f64,
    },
    /// The initial stress could not be imposed on a particle.
    #[error("particle {particle}: cannot impose the initial stress: {reason}")]
    InitialStress {
        /// Particle index (at construction: [`crate::Simulation::particle_id`]).
        particle: usize,
        /// Why.
        reason: &'static str,
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
    /// A transfer scheme combined with a kernel or setting it cannot work with.
    #[error("the {transfer} transfer does not work with {setting}: {reason}")]
    Unsupported {
        /// The transfer scheme's name.
        transfer: &'static str,
        /// The kernel or setting.
        setting: &'static str,
        /// Why.
        reason: &'static str,
    },
}

impl EngineError {
    /// The error with the particle it names (a storage slot) given by `id` instead.
    #[cold]
    pub(crate) fn naming_particle_by(self, id: impl Fn(usize) -> usize) -> Self {
        match self {
            Self::Kernel {
                step,
                particle,
                source,
            } => Self::Kernel {
                step,
                particle: id(particle),
                source,
            },
            Self::Material {
                step,
                particle,
                source,
            } => Self::Material {
                step,
                particle: id(particle),
                source,
            },
            Self::NonFinite {
                step,
                field,
                entity: "particle",
                index,
            } => Self::NonFinite {
                step,
                field,
                entity: "particle",
                index: id(index),
            },
            Self::Inverted {
                step,
                particle,
                det,
            } => Self::Inverted {
                step,
                particle: id(particle),
                det,
            },
            Self::Unstable {
                step,
                particle,
                courant,
                limit,
            } => Self::Unstable {
                step,
                particle: id(particle),
                courant,
                limit,
            },
            Self::InitialStress { particle, reason } => Self::InitialStress {
                particle: id(particle),
                reason,
            },
            Self::ParticleKick {
                step,
                particle,
                speed,
                ratio,
                wave_courant,
            } => Self::ParticleKick {
                step,
                particle: id(particle),
                speed,
                ratio,
                wave_courant,
            },
            other => other,
        }
    }

    /// A short name of the kind of failure, for tables and stability maps: `kernel`,
    /// `material`, `non-finite`, `inverted`, `energy-blow-up`, `too-fast`,
    /// `time-step-too-large`, `particle-kick`, `initial-stress`, `invalid-parameter` or `unsupported`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Kernel { .. } | Self::FacePoint { .. } => "kernel",
            Self::Material { .. } => "material",
            Self::NonFinite { .. } => "non-finite",
            Self::Inverted { .. } => "inverted",
            Self::EnergyBlowUp { .. } => "energy-blow-up",
            Self::Unstable { .. } => "too-fast",
            Self::TimeStepTooLarge { .. } => "time-step-too-large",
            Self::ParticleKick { .. } => "particle-kick",
            Self::InitialStress { .. } => "initial-stress",
            Self::InvalidParameter { .. } => "invalid-parameter",
            Self::Unsupported { .. } => "unsupported",
        }
    }
}
