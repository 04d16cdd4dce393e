//! The simulation as the run loop sees it: the object-safe [`Run`] trait, implemented
//! for every typed simulation, so the loop is compiled once per dimension.

use nalgebra::{SMatrix, SVector};
use umls_constitutive::Constitutive;
use umls_constitutive::table::{MaterialTable, PlasticPart};
use umls_engine::{
    Boundary, Diagnostics, EngineError, FaceClamp, Simulation, StageTimes, StepSettings,
    TransferScheme, Wall,
};
use umls_transfer::Kernel;

use crate::error::Result;
use crate::output::OutputDir;

/// What the run loop needs of a simulation. Object-safe, so [`crate::drive::drive`] is compiled once
/// per dimension; only [`Run::step`] and the output of particle fields are compiled for
/// each kernel, material table and transfer, which is where the time goes.
pub(crate) trait Run<const D: usize> {
    fn step(&mut self) -> std::result::Result<(), EngineError>;
    fn time(&self) -> f64;
    fn step_count(&self) -> usize;
    fn diagnostics(&self) -> std::result::Result<Diagnostics<D>, EngineError>;
    fn settings(&self) -> &StepSettings<D>;
    fn settings_mut(&mut self) -> &mut StepSettings<D>;
    fn stable_time_step(&self, cfl: f64) -> f64;
    fn set_geostatic_stress(&mut self, k0: f64) -> std::result::Result<(), EngineError>;
    fn spacing(&self) -> f64;
    /// Adds a wall; the nodes it constrains.
    fn add_wall(&mut self, wall: Wall<D>, tolerance: f64) -> Vec<u32>;
    /// Adds a clamp held on its face, the region's `nodes` and the face `points`, with
    /// the face points' residuals weighted by `penalty` (else the default); the nodes its
    /// constraint moves (or the face point the kernel cannot evaluate).
    fn add_face_clamp(
        &mut self,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
        penalty: Option<f64>,
    ) -> std::result::Result<Vec<u32>, EngineError>;
    /// The particles' reference volumes.
    fn volumes(&self) -> &[f64];
    /// The constraint forces of the boundary's reaction sets in the last step.
    fn reactions(&self) -> &[umls_engine::Reaction<D>];
    /// Each reaction-set node's reaction, the sets one after the other.
    fn node_reactions(&self) -> &[SVector<f64, D>];
    /// The node sets whose reactions are summed.
    fn reaction_sets(&mut self) -> Vec<Vec<u32>>;
    /// Each material state scalar's name and its largest value over the particles.
    fn state_scalar_maxima(&self) -> Vec<(&'static str, f64)>;
    fn boundary(&mut self) -> &mut Boundary<D>;
    fn positions(&self) -> &[SVector<f64, D>];
    fn velocities(&self) -> &[SVector<f64, D>];
    fn masses(&self) -> &[f64];
    /// The scene's index of the particle stored in `slot` (sorting moves particles).
    fn particle_id(&self, slot: usize) -> usize;
    /// How many times the particles have been sorted.
    fn particle_sorts(&self) -> usize;
    fn write_particles(&self, out: &mut OutputDir, reference: &[SVector<f64, D>]) -> Result<()>;
    fn grid(&self) -> (&[f64], &[SVector<f64, D>]);
    fn node_positions(&self) -> Vec<SVector<f64, D>>;
    fn node_count(&self) -> usize;
    fn last_dt(&self) -> f64;
    fn stage_times(&self) -> StageTimes;
    fn memory_use(&self) -> umls_engine::MemoryUse;
    /// Cauchy stresses σ = τ / det F.
    fn cauchy_stresses(&self) -> std::result::Result<Vec<SMatrix<f64, D, D>>, EngineError>;
}

impl<const D: usize, K: Kernel<D>, P: PlasticPart<D>, T: TransferScheme> Run<D>
    for Simulation<D, K, MaterialTable<P>, T>
{
    fn step(&mut self) -> std::result::Result<(), EngineError> {
        Simulation::step(self)
    }
    fn time(&self) -> f64 {
        Simulation::time(self)
    }
    fn step_count(&self) -> usize {
        Simulation::step_count(self)
    }
    fn diagnostics(&self) -> std::result::Result<Diagnostics<D>, EngineError> {
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
    fn set_geostatic_stress(&mut self, k0: f64) -> std::result::Result<(), EngineError> {
        Simulation::set_geostatic_stress(self, k0)
    }
    fn spacing(&self) -> f64 {
        self.kernel.spacing()
    }
    fn reactions(&self) -> &[umls_engine::Reaction<D>] {
        Simulation::reactions(self)
    }
    fn node_reactions(&self) -> &[SVector<f64, D>] {
        Simulation::node_reactions(self)
    }
    fn reaction_sets(&mut self) -> Vec<Vec<u32>> {
        self.boundary.reaction_sets.clone()
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
    fn add_wall(&mut self, wall: Wall<D>, tolerance: f64) -> Vec<u32> {
        self.boundary.add_wall(&self.kernel, wall, tolerance)
    }
    fn add_face_clamp(
        &mut self,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
        penalty: Option<f64>,
    ) -> std::result::Result<Vec<u32>, EngineError> {
        let mut clamp = FaceClamp::new(&self.kernel, nodes, points)?;
        if let Some(w) = penalty {
            clamp.penalty = w;
        }
        Ok(self.boundary.add_face_clamp(clamp))
    }
    fn volumes(&self) -> &[f64] {
        &self.particles().volume
    }
    fn boundary(&mut self) -> &mut Boundary<D> {
        &mut self.boundary
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
    fn particle_id(&self, slot: usize) -> usize {
        Simulation::particle_id(self, slot)
    }
    fn particle_sorts(&self) -> usize {
        Simulation::particle_sorts(self)
    }
    fn write_particles(&self, out: &mut OutputDir, reference: &[SVector<f64, D>]) -> Result<()> {
        out.write_particles(self, reference)
    }
    fn grid(&self) -> (&[f64], &[SVector<f64, D>]) {
        Simulation::grid(self)
    }
    fn node_positions(&self) -> Vec<SVector<f64, D>> {
        (0..self.kernel.node_count())
            .map(|n| self.kernel.node_position(n))
            .collect()
    }
    fn node_count(&self) -> usize {
        self.kernel.node_count()
    }
    fn last_dt(&self) -> f64 {
        Simulation::last_dt(self)
    }
    fn stage_times(&self) -> StageTimes {
        *Simulation::stage_times(self)
    }
    fn memory_use(&self) -> umls_engine::MemoryUse {
        Simulation::memory_use(self)
    }
    fn cauchy_stresses(&self) -> std::result::Result<Vec<SMatrix<f64, D, D>>, EngineError> {
        let mut stresses = self.stresses()?;
        for (tau, f) in stresses.iter_mut().zip(&self.particles().deformation) {
            *tau /= umls_constitutive::determinant(f);
        }
        Ok(stresses)
    }
}
