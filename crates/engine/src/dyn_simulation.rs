//! The simulation as a trait object: [`DynSimulation`], implemented for every typed
//! [`Simulation`], so a driver (the scene runner, a bench, a researcher's loop) is
//! compiled once per dimension and steps any kernel, material and transfer through one
//! virtual call per step.

use nalgebra::{SMatrix, SVector};
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use crate::boundary::{Boundary, Reaction, Wall};
use crate::collider::Collider;
use crate::diagnostics::Diagnostics;
use crate::error::EngineError;
use crate::face_clamp::FaceClamp;
use crate::memory::MemoryUse;
use crate::settings::StepSettings;
use crate::simulation::Simulation;
use crate::time_plan::TimePlan;
use crate::timing::StageTimes;
use crate::transfer::TransferScheme;

/// What a driver needs of a simulation, without its kernel, material and transfer types.
/// Each method is the [`Simulation`] method of the same name, or says what it reads.
///
/// ```
/// use nalgebra::SVector;
/// use umls_constitutive::{ElasticParameters, LinearElastic};
/// use umls_engine::{Apic, DynSimulation, Particles, Simulation, StepSettings};
/// use umls_kernels::{BSplineKernel, BSplineOrder};
///
/// let grid = BSplineKernel::new(SVector::from([-0.2]), 0.1, [14], BSplineOrder::Quadratic)
///     .ok_or("a valid grid")?;
/// let x = (0..20).map(|i| SVector::from([0.025 + 0.05 * i as f64])).collect();
/// let particles = Particles::at_rest(x, vec![0.05; 20], 1.0, ());
/// let material = LinearElastic { parameters: ElasticParameters::from_young_poisson(10.0, 0.0)? };
/// let sim = Simulation::new(grid, material, Apic, particles, StepSettings::new(1.0))?;
/// let mut sim: Box<dyn DynSimulation<1>> = Box::new(sim);
/// let plan = sim.plan_until(0.1, 3e-3)?;
/// assert_eq!(plan.steps, 34);
/// while !sim.reached(0.1) {
///     sim.step_until(0.1)?;
/// }
/// assert!((sim.time() - 0.1).abs() < 1e-15 && sim.step_count() == 34);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait DynSimulation<const D: usize> {
    /// One explicit step ([`Simulation::step`]).
    fn step(&mut self) -> Result<(), EngineError>;
    /// One step toward `end_time` ([`Simulation::step_until`]).
    fn step_until(&mut self, end_time: f64) -> Result<(), EngineError>;
    /// Plans the steps to `end_time` ([`Simulation::plan_until`]).
    fn plan_until(&mut self, end_time: f64, target_dt: f64) -> Result<TimePlan, EngineError>;
    /// Whether `end_time` is reached ([`Simulation::reached`]).
    fn reached(&self, end_time: f64) -> bool;
    /// Simulated time.
    fn time(&self) -> f64;
    /// Steps taken.
    fn step_count(&self) -> usize;
    /// The last step's Δt.
    fn last_dt(&self) -> f64;
    /// The largest wave Courant number of the steps so far, a refused one included.
    fn max_wave_courant(&self) -> f64;
    /// Energies, momentum, speeds and Courant numbers now.
    fn diagnostics(&self) -> Result<Diagnostics<D>, EngineError>;
    /// The step settings.
    fn settings(&self) -> &StepSettings<D>;
    /// The step settings, to change between steps.
    fn settings_mut(&mut self) -> &mut StepSettings<D>;
    /// The stable time step for Courant number `cfl`.
    fn stable_time_step(&self, cfl: f64) -> f64;
    /// Sets the particles' stresses to the geostatic state of coefficient `k0`.
    fn set_geostatic_stress(&mut self, k0: f64) -> Result<(), EngineError>;
    /// The kernel's effective node spacing.
    fn spacing(&self) -> f64;
    /// The boundary conditions, to change between steps.
    fn boundary_mut(&mut self) -> &mut Boundary<D>;
    /// Adds a wall; the nodes it constrains ([`Boundary::add_wall`]).
    fn add_wall(&mut self, wall: Wall<D>, tolerance: f64) -> Vec<u32>;
    /// Adds a wall of any shape; the nodes it holds ([`Boundary::add_collider`]).
    fn add_collider(&mut self, collider: Collider<D>, tolerance: f64, reach: f64) -> Vec<u32>;
    /// Adds an obstacle in prescribed motion; the nodes it may reach
    /// ([`Boundary::add_moving_collider`]).
    fn add_moving_collider(
        &mut self,
        collider: Collider<D>,
        velocity: SVector<f64, D>,
        tolerance: f64,
        reach: f64,
        until: f64,
    ) -> Vec<u32>;
    /// Adds a clamp held on its face: the region's `nodes` and the face `points`, the
    /// face points' residuals weighted by `penalty` (else the default); the nodes its
    /// constraint moves.
    fn add_face_clamp(
        &mut self,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
        penalty: Option<f64>,
    ) -> Result<Vec<u32>, EngineError>;
    /// The constraint forces of the boundary's reaction sets in the last step.
    fn reactions(&self) -> &[Reaction<D>];
    /// Each reaction-set node's reaction, the sets one after the other.
    fn node_reactions(&self) -> &[SVector<f64, D>];
    /// Particle positions.
    fn positions(&self) -> &[SVector<f64, D>];
    /// Particle velocities.
    fn velocities(&self) -> &[SVector<f64, D>];
    /// Particle masses.
    fn masses(&self) -> &[f64];
    /// Particle reference volumes.
    fn volumes(&self) -> &[f64];
    /// The index at construction of the particle stored in `slot`.
    fn particle_id(&self, slot: usize) -> usize;
    /// How many times the particles have been sorted.
    fn particle_sorts(&self) -> usize;
    /// Cauchy stresses σ = τ / det F of the particles.
    fn cauchy_stresses(&self) -> Result<Vec<SMatrix<f64, D, D>>, EngineError>;
    /// Each material state scalar's name and its largest value over the particles.
    fn state_scalar_maxima(&self) -> Vec<(&'static str, f64)>;
    /// Nodal masses and velocities of the last step.
    fn grid(&self) -> (&[f64], &[SVector<f64, D>]);
    /// The kernel's nodes.
    fn node_count(&self) -> usize;
    /// The kernel's node positions.
    fn node_positions(&self) -> Vec<SVector<f64, D>>;
    /// Wall time per stage so far.
    fn stage_times(&self) -> StageTimes;
    /// The bytes the simulation holds.
    fn memory_use(&self) -> MemoryUse;
}

impl<const D: usize, K, M, T> DynSimulation<D> for Simulation<D, K, M, T>
where
    K: Kernel<D>,
    M: Constitutive<D>,
    T: TransferScheme,
{
    fn step(&mut self) -> Result<(), EngineError> {
        Simulation::step(self)
    }
    fn step_until(&mut self, end_time: f64) -> Result<(), EngineError> {
        Simulation::step_until(self, end_time)
    }
    fn plan_until(&mut self, end_time: f64, target_dt: f64) -> Result<TimePlan, EngineError> {
        Simulation::plan_until(self, end_time, target_dt)
    }
    fn reached(&self, end_time: f64) -> bool {
        Simulation::reached(self, end_time)
    }
    fn time(&self) -> f64 {
        Simulation::time(self)
    }
    fn step_count(&self) -> usize {
        Simulation::step_count(self)
    }
    fn last_dt(&self) -> f64 {
        Simulation::last_dt(self)
    }
    fn max_wave_courant(&self) -> f64 {
        Simulation::max_wave_courant(self)
    }
    fn diagnostics(&self) -> Result<Diagnostics<D>, EngineError> {
        Simulation::diagnostics(self)
    }
    fn settings(&self) -> &StepSettings<D> {
        &self.settings
    }
    fn settings_mut(&mut self) -> &mut StepSettings<D> {
        &mut self.settings
    }
    fn stable_time_step(&self, cfl: f64) -> f64 {
        Simulation::stable_time_step(self, cfl)
    }
    fn set_geostatic_stress(&mut self, k0: f64) -> Result<(), EngineError> {
        Simulation::set_geostatic_stress(self, k0)
    }
    fn spacing(&self) -> f64 {
        self.kernel.spacing()
    }
    fn boundary_mut(&mut self) -> &mut Boundary<D> {
        &mut self.boundary
    }
    fn add_wall(&mut self, wall: Wall<D>, tolerance: f64) -> Vec<u32> {
        self.boundary.add_wall(&self.kernel, wall, tolerance)
    }
    fn add_collider(&mut self, collider: Collider<D>, tolerance: f64, reach: f64) -> Vec<u32> {
        self.boundary
            .add_collider(&self.kernel, collider, tolerance, reach)
    }
    fn add_moving_collider(
        &mut self,
        collider: Collider<D>,
        velocity: SVector<f64, D>,
        tolerance: f64,
        reach: f64,
        until: f64,
    ) -> Vec<u32> {
        self.boundary
            .add_moving_collider(&self.kernel, collider, velocity, tolerance, reach, until)
    }
    fn add_face_clamp(
        &mut self,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
        penalty: Option<f64>,
    ) -> Result<Vec<u32>, EngineError> {
        let mut clamp = FaceClamp::new(&self.kernel, nodes, points)?;
        if let Some(w) = penalty {
            clamp.penalty = w;
        }
        Ok(self.boundary.add_face_clamp(clamp))
    }
    fn reactions(&self) -> &[Reaction<D>] {
        Simulation::reactions(self)
    }
    fn node_reactions(&self) -> &[SVector<f64, D>] {
        Simulation::node_reactions(self)
    }
    fn positions(&self) -> &[SVector<f64, D>] {
        &self.particles().position
    }
    fn velocities(&self) -> &[SVector<f64, D>] {
        &self.particles().velocity
    }
    fn masses(&self) -> &[f64] {
        &self.particles().mass
    }
    fn volumes(&self) -> &[f64] {
        &self.particles().volume
    }
    fn particle_id(&self, slot: usize) -> usize {
        Simulation::particle_id(self, slot)
    }
    fn particle_sorts(&self) -> usize {
        Simulation::particle_sorts(self)
    }
    fn cauchy_stresses(&self) -> Result<Vec<SMatrix<f64, D, D>>, EngineError> {
        let mut stresses = self.stresses()?;
        for (tau, f) in stresses.iter_mut().zip(&self.particles().deformation) {
            *tau /= umls_constitutive::determinant(f);
        }
        Ok(stresses)
    }
    fn state_scalar_maxima(&self) -> Vec<(&'static str, f64)> {
        let names = self.material().state_scalar_names();
        let mut maxima = vec![f64::NEG_INFINITY; names.len()];
        let mut values = Vec::with_capacity(names.len());
        for s in &self.particles().state {
            values.clear();
            self.material().state_scalars(s, &mut values);
            for (m, v) in maxima.iter_mut().zip(&values) {
                *m = m.max(*v);
            }
        }
        names.iter().copied().zip(maxima).collect()
    }
    fn grid(&self) -> (&[f64], &[SVector<f64, D>]) {
        Simulation::grid(self)
    }
    fn node_count(&self) -> usize {
        self.kernel.node_count()
    }
    fn node_positions(&self) -> Vec<SVector<f64, D>> {
        (0..self.kernel.node_count())
            .map(|n| self.kernel.node_position(n))
            .collect()
    }
    fn stage_times(&self) -> StageTimes {
        *Simulation::stage_times(self)
    }
    fn memory_use(&self) -> MemoryUse {
        Simulation::memory_use(self)
    }
}
