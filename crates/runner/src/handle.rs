//! The simulation as the run loop sees it: the engine's object-safe
//! [`DynSimulation`] and the output of its particle fields, implemented for every typed
//! simulation, so the loop is compiled once per dimension.

use nalgebra::SVector;
use umls_constitutive::table::{MaterialTable, PlasticPart};
use umls_engine::{DynSimulation, Simulation, TransferScheme};
use umls_transfer::Kernel;

use crate::error::Result;
use crate::output::OutputDir;

/// What the run loop needs of a simulation: the engine's [`DynSimulation`], and the
/// particle frames, whose fields depend on the material table's state. Only the step
/// and the frames are compiled for each kernel and material table, which is where the
/// time goes.
pub(crate) trait Run<const D: usize>: DynSimulation<D> + Send {
    /// Writes a particle frame, with displacements from `reference`.
    fn write_particles(&self, out: &mut OutputDir, reference: &[SVector<f64, D>]) -> Result<()>;
    /// The simulation as the engine's trait object.
    fn as_dyn(&mut self) -> &mut (dyn DynSimulation<D> + Send);
}

impl<const D: usize, K: Kernel<D>, P: PlasticPart<D>, T: TransferScheme> Run<D>
    for Simulation<D, K, MaterialTable<P>, T>
{
    fn write_particles(&self, out: &mut OutputDir, reference: &[SVector<f64, D>]) -> Result<()> {
        out.write_particles(self, reference)
    }
    fn as_dyn(&mut self) -> &mut (dyn DynSimulation<D> + Send) {
        self
    }
}
