//! The MUSL re-map (Sulsky et al. 1995): after G2P, the updated particle momenta go back
//! to the grid, and the deformation update uses that grid velocity's gradient.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::{Kernel, Stencil};

use super::Simulation;
use crate::error::EngineError;
use crate::transfer::TransferScheme;

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// Re-maps the particle momenta with the stencils of the start of the step (stored:
    /// the particles have moved since, so they could not be recomputed) and puts the
    /// velocity gradients of the re-mapped grid velocity into the stress buffer, over
    /// G2P's (the deformation update reads them there).
    pub(super) fn musl_velocity_gradients(&mut self) -> Result<(), EngineError> {
        let step = self.step;
        let fail = |(particle, source)| EngineError::Kernel {
            step,
            particle,
            source,
        };
        let g = &mut self.grid;
        g.momentum.iter_mut().for_each(|m| *m = SVector::zeros());
        let (p, kernel, stencils) = (&self.particles, &self.kernel, &self.stencils);
        let mut scratch = Stencil::new();
        for i in 0..p.len() {
            stencils
                .with(i, kernel, &p.position[i], &p.cache[i], &mut scratch, |st| {
                    for e in 0..st.len() {
                        let node = st.nodes[e] as usize;
                        g.momentum[node] += p.velocity[i] * (st.values[e] * p.mass[i]);
                    }
                })
                .map_err(fail)?;
        }
        let fraction = self.settings.cancellation_fraction;
        for node in 0..g.mass.len() {
            g.velocity[node] = if g.is_active(node, fraction) {
                g.momentum[node] / g.mass[node]
            } else {
                SVector::zeros()
            };
        }
        self.boundary.apply(&mut g.velocity);
        // The re-map reads the start-of-step stencils, as the grid update's clamp
        // systems did: the same systems serve.
        for (clamp, system) in self.boundary.fitted.iter().zip(&self.clamp_systems) {
            clamp.fit(system, &mut g.velocity);
        }
        for (clamp, system) in self.boundary.faces.iter().zip(&self.face_systems) {
            clamp.hold(system, &mut g.velocity);
        }
        let v = &g.velocity;
        self.stress_buffer
            .par_iter_mut()
            .enumerate()
            .map(|(i, gradient)| {
                let mut scratch = Stencil::new();
                stencils.with(i, kernel, &p.position[i], &p.cache[i], &mut scratch, |st| {
                    *gradient = (0..st.len()).fold(SMatrix::zeros(), |acc, e| {
                        acc + v[st.nodes[e] as usize] * st.gradients[e].transpose()
                    });
                })
            })
            .reduce(
                || Ok(()),
                |a, b| crate::parallel::lowest_failure(a, b, |(), ()| ()),
            )
            .map_err(fail)
    }
}
