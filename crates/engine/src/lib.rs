//! Explicit material point method, generic over dimension, shape-function kernel
//! ([`umls_transfer::Kernel`]), transfer scheme ([`TransferScheme`]: PIC, FLIP, APIC,
//! APIC-FLIP, quadratic APIC ([`quadratic_modes`]), velocity-gradient affine, MLS-MPM,
//! each a type of its own or any of them chosen at run time as an [`AnyTransfer`]) and
//! material ([`umls_constitutive::Constitutive`]).
//!
//! One [`Simulation::step`]: evaluate every particle's stencil (in parallel, walking from
//! its cached host), P2G of mass, momentum (with the affine term, and the quadratic
//! modes, for the schemes that carry them) and
//! force (−Σ V⁰ τ ∇N + gravity and body forces), grid update (empty and mass-scaled nodes,
//! damping, boundary conditions: node sets, walls, clamps imposed on the fit
//! ([`FittedClamp`])), G2P of velocity, affine matrix and position, walls that
//! hold the particles, then F ← (I + Δt∇v)F and the material's return map (USL: inside
//! G2P, each particle right after its gather; or MUSL with re-mapped momenta, as a stage
//! of its own). The time step is fixed or adaptive
//! ([`Simulation::stable_time_step`]: one definition for every kernel). Failures stop the
//! run with a typed [`EngineError`] naming the step and particle or node: kernel errors,
//! NaN, det F ≤ 0, a Δt above the stable step, a particle moving more than a spacing per
//! step, energy growing beyond what gravity and body forces put in.
//!
//! Parallel work is split into fixed chunks and every sum is taken in particle order, so
//! results are bitwise identical for any number of threads. With
//! [`StepSettings::particle_sort_interval`] the engine stores the particles in P2G's
//! order now and then (faster transfers as the particles mix); that moves particles
//! between slots, not the results: [`Simulation::particle_id`] names a slot's particle
//! by its index at construction, and body forces and errors use that index.
//!
//! ```
//! use nalgebra::SVector;
//! use umls_constitutive::{ElasticParameters, LinearElastic};
//! use umls_engine::{Apic, Particles, Simulation, StepSettings};
//! use umls_kernels::{BSplineKernel, BSplineOrder};
//!
//! // A 1D bar of 20 particles on a quadratic B-spline grid, pulled apart at its ends.
//! let grid = BSplineKernel::new(SVector::from([-0.2]), 0.1, [14], BSplineOrder::Quadratic).unwrap();
//! let x = (0..20).map(|i| SVector::from([0.025 + 0.05 * i as f64])).collect();
//! let mut particles = Particles::at_rest(x, vec![0.05; 20], 1.0, ());
//! for (v, x) in particles.velocity.iter_mut().zip(&particles.position) {
//!     *v = SVector::from([x[0] - 0.5]);
//! }
//! let material = LinearElastic { parameters: ElasticParameters::from_young_poisson(10.0, 0.0)? };
//! let mut sim = Simulation::new(grid, material, Apic, particles, StepSettings::new(1e-3))?;
//! let before = sim.diagnostics()?;
//! for _ in 0..100 {
//!     sim.step()?;
//! }
//! let after = sim.diagnostics()?;
//! // No boundary conditions, no gravity: momentum is conserved, kinetic energy turned
//! // into strain energy.
//! assert!((after.momentum - before.momentum).norm() < 1e-12);
//! assert!(after.elastic > 0.0 && after.kinetic < before.kinetic);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod boundary;
mod collider;
mod diagnostics;
mod dyn_simulation;
mod error;
mod face_clamp;
mod fitted_clamp;
pub mod geostatic;
mod grid;
mod memory;
mod moving_collider;
mod parallel;
mod particles;
pub mod quadratic_modes;
mod sampled_distance;
mod scatter;
mod seeding;
mod settings;
mod simulation;
mod stencils;
mod time_plan;
mod timing;
mod transfer;

pub use boundary::{Boundary, Reaction, Wall, WallKind};
pub use collider::{Collider, NodeCondition};
pub use diagnostics::Diagnostics;
pub use dyn_simulation::DynSimulation;
pub use error::EngineError;
pub use face_clamp::{FACE_CLAMP_PENALTY, FACE_CLAMP_REGULARISATION, FaceClamp, face_points};
pub use fitted_clamp::{FITTED_CLAMP_REGULARISATION, FittedClamp};
pub use memory::MemoryUse;
pub use moving_collider::MovingCollider;
pub use particles::Particles;
pub use quadratic_modes::{MAX_QUADRATIC_MODES, QUADRATIC_RIDGE, QuadraticModes};
pub use sampled_distance::{MAX_SAMPLES, SampledDistance, SampledDistanceError};
pub use seeding::{Inside, Region, lattice_points, lattice_samples};
pub use settings::{Damping, MassMatrix, StencilStorage, StepSettings, TimeStepControl};
pub use simulation::{BodyForce, Simulation};
pub use time_plan::{MAX_PLANNED_STEPS, TimePlan};
pub use timing::StageTimes;
pub use transfer::{
    AnyTransfer, Apic, ApicFlip, Flip, MlsMpm, Pic, QuadraticApic, QuadraticApicFlip,
    SingularSecondMoment, StressUpdate, TransferScheme, TransferShape, VelocityGradientAffine,
};
