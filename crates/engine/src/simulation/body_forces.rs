//! The body accelerations of a step, evaluated once per particle before P2G: P2G spreads
//! them as nodal forces and G2P reads them again for the work of external forces, at the
//! same particle, position and time, so one evaluation serves both. A scene's field can
//! be an expression of many definitions (a manufactured solution's), which made the
//! second evaluation a measurable part of such a step.

use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use super::Simulation;
use crate::transfer::TransferScheme;

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// Fills `body_accelerations` with b(p, x_p, t) at this step's positions and time,
    /// or empties it when the simulation has no body force.
    pub(super) fn evaluate_body_forces(&mut self) {
        let Some(body_force) = self.body_force.as_ref() else {
            self.body_accelerations.clear();
            return;
        };
        let (position, time, ids) = (&self.particles.position, self.time, &self.ids);
        let chunk = crate::stencils::CHUNK;
        self.body_accelerations
            .resize(position.len(), nalgebra::SVector::zeros());
        self.body_accelerations
            .par_chunks_mut(chunk)
            .enumerate()
            .for_each(|(c, accelerations)| {
                for (k, a) in accelerations.iter_mut().enumerate() {
                    let i = c * chunk + k;
                    // b is a function of the particle's index at construction.
                    *a = body_force(super::id_in(ids, i), &position[i], time);
                }
            });
    }
}
