//! Step settings: time step control, body loads, stress update, damping, failure checks.

use nalgebra::SVector;

use crate::transfer::StressUpdate;

/// How the time step is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TimeStepControl {
    /// Δt = [`StepSettings::dt`] every step.
    #[default]
    Fixed,
    /// Δt = min(`cfl` · h / (c + |v|_max), [`StepSettings::dt`]) recomputed before every
    /// step from the current wave speed c and the fastest particle (see
    /// [`crate::Simulation::stable_time_step`]).
    Adaptive {
        /// Courant number C < 1.
        cfl: f64,
    },
}

/// Damping for bringing a body to (quasi-)static equilibrium. It acts on the nodal force
/// and removes momentum, so it is off for dynamics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Damping {
    /// No damping.
    #[default]
    None,
    /// Local non-viscous damping (Cundall): f_i ← f_i − α |f_i| sign(v_i), per component.
    /// Independent of the time scale; α ≈ 0.1–0.8 (geomechanics codes use 0.7–0.8 for
    /// quasi-static loading).
    Local {
        /// α ∈ [0, 1).
        alpha: f64,
    },
    /// Mass-proportional viscous damping: f_i ← f_i − β m_i v_i, with β in 1/s
    /// (critical for the mode of angular frequency ω at β = 2ω).
    MassProportional {
        /// β ≥ 0.
        beta: f64,
    },
}

/// Whether the step stores every particle's stencil (its entries, or the kernel's
/// factors of it) or evaluates it again where P2G and G2P use it. All give the same
/// numbers, bit for bit, except for a tensor-product kernel (B-splines) evaluated again:
/// P2G and G2P then sum its stencil row by row (`Kernel::tensor_stencil`), which agrees
/// with its stored entries to round-off. They trade memory against work.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StencilStorage {
    /// As the kernel prefers: recomputed where `Kernel::recompute_stencils` says so
    /// (B-splines), else stored entries (mesh kernels).
    #[default]
    KernelChoice,
    /// Store the entries for the step (memory: ≈ (4 + 8 + 8·D) bytes per entry).
    Store,
    /// Store the kernel's factors for the step where it has them
    /// (`Kernel::factor_layout`; UMLS with the reconstructed gradient: 8 bytes per entry
    /// and (D + 1)² + 1 numbers per particle), rebuilding the entries in P2G and G2P;
    /// the entries where it has none. About half the stored bytes of UMLS in 3D for
    /// 10–17 % more time per step (docs/scenes.md).
    Factored,
    /// Evaluate them in P2G and G2P (two evaluations a step; the ordering pass asks the
    /// kernel for each stencil's node range, which mesh and grid kernels know without
    /// evaluating it).
    Recompute,
}

/// The mass matrix of the grid update. The lumped one (row sums m_i = Σ_p N_ip m_p) makes
/// the velocity v_i = p_i / m_i a weighted mean of the particle velocities, so every
/// P2G → G2P round trip smooths the particle field, the more the wider the stencil. The
/// consistent one, M_ij = Σ_p m_p N_ip N_jp, makes it the mass-weighted least-squares
/// projection onto the nodal basis; its inverse is approximated by Jacobi iterations
/// preconditioned by the lumped matrix (Nairn and Hammerquist's FMPM), each costing one
/// gather and one scatter over the stencils. docs/umls-kernel.md ("Mass matrix") has the
/// measurements.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum MassMatrix {
    /// Lumped: v_i = p_i / m_i, a_i = f_i / m_i (the default).
    #[default]
    Lumped,
    /// The consistent matrix, approximated by `iterations` ≥ 1 Jacobi iterations, for the
    /// velocity and, in the share `forces`, for the acceleration too.
    ///
    /// - For the velocity it keeps what the particles carry through the round trip
    ///   (PIC, APIC and the PIC part of FLIP lose less energy). With an affine transfer
    ///   the round trip carries each particle's affine field, so affine velocity fields
    ///   stay fixed points.
    /// - For the forces it is the equation of motion with the matrix
    ///   (1 − β) M_L + β M_C, β = `forces`. β = 1 is the consistent-mass equation, whose
    ///   frequencies are those of the kernel's basis rather than of its lumping (the
    ///   vibrating bar's error halves). Lumping lowers a smooth mode's frequency and the
    ///   consistent matrix raises it; β = ½, the mixed matrix of finite elements (Krieg
    ///   and Key), cancels their leading terms for linear elements (on the bar, UMLS's
    ///   and bspline2's errors fall by another quarter, cubic B-splines' rise:
    ///   docs/umls-kernel.md, *Mass matrix*). k iterations raise the highest frequency,
    ///   so the stable Δt is divided by √(Σ_{j=1..k} β^j) when that exceeds 1: √k for
    ///   the consistent matrix ([`crate::Simulation::stable_time_step`]).
    ///
    /// Not with MLS-MPM, whose momenta carry the force impulse.
    Consistent {
        /// Jacobi iterations (1 or more).
        iterations: usize,
        /// The consistent matrix's share β ∈ [0, 1] in the forces' mass matrix: 0 leaves
        /// them lumped, 1 solves them with the consistent matrix, ½ with the mixed one.
        forces: f64,
    },
}

impl MassMatrix {
    /// Jacobi iterations for the velocity (0 when lumped).
    pub fn velocity_iterations(&self) -> usize {
        match *self {
            Self::Lumped => 0,
            Self::Consistent { iterations, .. } => iterations,
        }
    }

    /// Jacobi iterations for the forces (0 when they stay lumped).
    pub fn force_iterations(&self) -> usize {
        match *self {
            Self::Consistent { iterations, forces } if forces > 0.0 => iterations,
            _ => 0,
        }
    }

    /// The consistent matrix's share β in the forces' mass matrix (0 when lumped).
    pub fn force_share(&self) -> f64 {
        match *self {
            Self::Consistent { forces, .. } if self.force_iterations() > 0 => forces,
            _ => 0.0,
        }
    }

    /// The factor the force iterations divide the stable time step by:
    /// √(Σ_{j=1..k} β^j), at least 1 (√k for the consistent matrix, the rule this
    /// generalises). The k-th iterate multiplies a mode whose consistent mass is μ times
    /// its lumped one by Σ_{j=0..k} (β (1 − μ))^j, which for the roughest modes exceeds
    /// the rule's Σ_{j=1..k} β^j: at k = 2, β = 1 their frequency is 3 % above the rule's
    /// for linear elements (μ = 1/3) and 14 % for quadratic B-splines (μ = 2/15), a
    /// margin a Courant number below 1 has to leave.
    pub fn force_step_factor(&self) -> f64 {
        let (k, beta) = (self.force_iterations(), self.force_share());
        let gain: f64 = (1..=k).map(|j| beta.powi(j as i32)).sum();
        gain.max(1.0).sqrt()
    }
}

/// Step settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSettings<const D: usize> {
    /// Time step Δt (the largest one with [`TimeStepControl::Adaptive`]).
    pub dt: f64,
    /// Fixed or adaptive time step.
    pub time_step: TimeStepControl,
    /// Body acceleration (gravity).
    pub gravity: SVector<f64, D>,
    /// Gravity grows linearly from 0 to its full value over this time (0: applied at once),
    /// for bringing a body to rest under its own weight.
    pub gravity_ramp: f64,
    /// Where the stress is updated.
    pub stress_update: StressUpdate,
    /// Damping of the nodal forces.
    pub damping: Damping,
    /// Stop with [`crate::EngineError::EnergyBlowUp`] when kinetic plus elastic energy
    /// exceeds this factor times the energy put into the body (initial energy plus the
    /// largest work of gravity and body forces so far).
    pub energy_growth_limit: f64,
    /// Steps between energy checks (they evaluate every particle's energy density).
    pub energy_check_interval: usize,
    /// Stop with [`crate::EngineError::Unstable`] when a particle moves more than this many
    /// kernel spacings in one step.
    pub max_courant: f64,
    /// Stop with [`crate::EngineError::TimeStepTooLarge`] when Δt exceeds this many stable
    /// steps h / (c + |v|_max) (checked after every step; `f64::INFINITY` switches it
    /// off). Beyond 1 the explicit step is unstable; the grid update's mass scaling would
    /// then slow the whole body down instead of letting it blow up, so the run is stopped.
    pub max_wave_courant: f64,
    /// A node whose mass m_i = Σ N m_p is at most this fraction of Σ |N| m_p has lost its
    /// mass to cancelling (negative) MLS values: it carries no velocity, and its mass and
    /// momentum are reported as dropped.
    pub cancellation_fraction: f64,
    /// Whether the next step sums the forces of `Boundary::reaction_sets` (on by
    /// default). A run that reads them only now and then switches it off for the steps
    /// in between; an unmeasured step leaves no reactions to read.
    pub measure_reactions: bool,
    /// Stored or recomputed stencils.
    pub stencil_storage: StencilStorage,
    /// The mass matrix that turns P2G's nodal momenta (and forces) into velocities (and
    /// accelerations).
    pub mass_matrix: MassMatrix,
    /// Every this many steps, store the particles in P2G's order (by the lowest node of
    /// their stencils) before the step, so that the transfers read them nearly in
    /// storage order; 0 (the default) keeps them where they were given. Sorting
    /// renumbers the particles: [`crate::Simulation::particle_id`] maps a slot to the
    /// particle's index at construction. The results are the same bit for bit (P2G
    /// sums in the same order either way); only the time per step changes.
    pub particle_sort_interval: usize,
}

impl<const D: usize> StepSettings<D> {
    /// Time step `dt` (fixed), no gravity, USL, no damping, energy limit 10× checked every
    /// 10 steps, Courant and wave Courant limits 1, cancellation fraction 10⁻³, stencils
    /// stored or recomputed as the kernel prefers, lumped mass matrix, particles never sorted.
    pub fn new(dt: f64) -> Self {
        Self {
            dt,
            time_step: TimeStepControl::Fixed,
            gravity: SVector::zeros(),
            gravity_ramp: 0.0,
            stress_update: StressUpdate::Usl,
            damping: Damping::None,
            energy_growth_limit: 10.0,
            energy_check_interval: 10,
            max_courant: 1.0,
            max_wave_courant: 1.0,
            cancellation_fraction: 1e-3,
            measure_reactions: true,
            stencil_storage: StencilStorage::KernelChoice,
            mass_matrix: MassMatrix::Lumped,
            particle_sort_interval: 0,
        }
    }

    /// Gravity at time `t` (with the ramp).
    pub fn gravity_at(&self, t: f64) -> SVector<f64, D> {
        if self.gravity_ramp > 0.0 && t < self.gravity_ramp {
            self.gravity * (t / self.gravity_ramp)
        } else {
            self.gravity
        }
    }
}
