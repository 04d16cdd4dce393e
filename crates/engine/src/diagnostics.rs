//! What a run reports about itself: energies, momentum, speeds, Courant numbers, and
//! what the grid update and the walls set aside.

use nalgebra::SVector;

/// Energies, momentum and stability indicators of the particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diagnostics<const D: usize> {
    /// Step number.
    pub step: usize,
    /// Time.
    pub time: f64,
    /// Time step of the last step (the next one's, before the first).
    pub dt: f64,
    /// Σ ½ m |v|².
    pub kinetic: f64,
    /// Σ V⁰ ψ(F).
    pub elastic: f64,
    /// Work done on the particles by gravity and body forces since the start,
    /// ∫ Σ m_p b(x_p, t)·v_p dt (the negative change of the gravitational potential for
    /// constant gravity).
    pub external_work: f64,
    /// Σ m v.
    pub momentum: SVector<f64, D>,
    /// Σ m.
    pub mass: f64,
    /// max |v|.
    pub max_speed: f64,
    /// Particle Courant number max|v| Δt / h (h the kernel's effective spacing).
    pub courant: f64,
    /// Wave Courant number Δt (c + max|v|) / h, c the largest p-wave speed: above 1 the
    /// explicit step is unstable.
    pub wave_courant: f64,
    /// Mass of empty nodes (cancelled by negative shape functions, or reached only by
    /// round-off), summed over the steps.
    pub dropped_mass: f64,
    /// Momentum the grid update handed on to the active nodes in proportion to their
    /// mass, summed over the steps: that of empty nodes (cancelled, or reached only by
    /// round-off) and the impulse mass-scaled nodes did not absorb. Momentum is conserved;
    /// this says how much was moved.
    pub redistributed_momentum: SVector<f64, D>,
    /// How many times a particle was put back from beyond a wall.
    pub wall_corrections: usize,
    /// Node updates that were mass-scaled (nodes beyond their own stability limit),
    /// summed over the steps: a large count says the results near those nodes are
    /// slowed by added inertia.
    pub mass_scaled_nodes: usize,
}

impl<const D: usize> Diagnostics<D> {
    /// Kinetic plus elastic energy.
    pub fn total_energy(&self) -> f64 {
        self.kinetic + self.elastic
    }

    /// Kinetic plus elastic energy minus the external work: constant for a conservative
    /// system, also under gravity and body forces.
    pub fn energy_balance(&self) -> f64 {
        self.kinetic + self.elastic - self.external_work
    }
}

/// Running totals the step keeps for [`Diagnostics`] and the energy check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Totals<const D: usize> {
    pub external_work: f64,
    pub dropped_mass: f64,
    pub redistributed_momentum: SVector<f64, D>,
    pub wall_corrections: usize,
    pub mass_scaled_nodes: usize,
    /// Kinetic plus elastic energy at the start (set before the first step).
    pub initial_energy: Option<f64>,
    /// The largest energy put in so far: initial energy plus external work.
    pub energy_supplied: f64,
    /// Fastest particle and smallest density after the last step.
    pub max_speed: f64,
    pub min_density: f64,
    /// The particle that moved farthest in the last step, and how far.
    pub longest_move: (usize, f64),
    /// The fastest particle after the last G2P (the first among equals) and its speed².
    pub fastest: (usize, f64),
    /// The first particle whose velocity or position G2P left non-finite.
    pub first_non_finite: Option<usize>,
    /// The largest wave Courant number Δt / Δt_stable a step was asked to take, the one
    /// the guard refused included.
    pub max_wave_courant: f64,
}

impl<const D: usize> Default for Totals<D> {
    fn default() -> Self {
        Self {
            external_work: 0.0,
            dropped_mass: 0.0,
            redistributed_momentum: SVector::zeros(),
            wall_corrections: 0,
            mass_scaled_nodes: 0,
            initial_energy: None,
            energy_supplied: 0.0,
            max_speed: 0.0,
            min_density: f64::INFINITY,
            longest_move: (0, 0.0),
            fastest: (0, 0.0),
            first_non_finite: None,
            max_wave_courant: 0.0,
        }
    }
}
