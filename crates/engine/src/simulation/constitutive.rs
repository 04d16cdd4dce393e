//! Stage 5 of the step and the start of the next: F ← (I + Δt ∇v) F with the material's
//! return map, and the Kirchhoff stresses P2G spreads. Under USL G2P calls the
//! per-particle update ([`update_one`]) itself, right after each particle's gather.

use nalgebra::SMatrix;
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use super::Simulation;
use crate::error::EngineError;
use crate::parallel::lowest_failure;
use crate::transfer::TransferScheme;

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// Kirchhoff stresses into the reused buffer, unless the last step's deformation
    /// update left them there for the current particles and material; among failures
    /// the lowest particle index wins, so the report does not depend on the thread
    /// count.
    pub(super) fn compute_stresses(&mut self) -> Result<(), EngineError> {
        if self.stresses_current {
            return Ok(());
        }
        let (material, step, p) = (&self.material, self.step, &self.particles);
        self.stress_buffer.resize(p.len(), SMatrix::zeros());
        self.stress_buffer
            .par_iter_mut()
            .enumerate()
            .map(|(i, stress)| -> Result<(), (usize, EngineError)> {
                *stress = material
                    .kirchhoff_stress(&p.deformation[i], &p.state[i])
                    .map_err(|source| {
                        (
                            i,
                            EngineError::Material {
                                step,
                                particle: i,
                                source,
                            },
                        )
                    })?;
                Ok(())
            })
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))
            .map_err(|(_, e)| e)?;
        self.stresses_current = true;
        Ok(())
    }

    /// F ← (I + Δt ∇v) F, the return map, and the stress of the returned state for the
    /// next step's P2G, in one call of the material (`return_map_and_stress`: one
    /// decomposition for plastic models); the smallest density m / (V⁰ det F). Each
    /// particle's velocity gradient is read from its slot of the stress buffer (where
    /// MUSL's re-map left it) and replaced there by its stress. Under USL G2P makes the
    /// same update per particle instead.
    pub(super) fn update_deformation(&mut self, dt: f64) -> Result<f64, EngineError> {
        let step = self.step;
        let material = &self.material;
        let p = &mut self.particles;
        let (mass, volume) = (&p.mass, &p.volume);
        debug_assert_eq!(self.stress_buffer.len(), p.len());
        // In fixed chunks, each folding its particles in a plain loop (a per-particle
        // `Result` carried through the parallel reduction cost as much as a fluid's
        // whole stress update); the chunks' minima and first failures are joined in
        // chunk order, so the report does not depend on the thread count.
        let chunk = crate::stencils::CHUNK;
        let result = p
            .deformation
            .par_chunks_mut(chunk)
            .zip(p.state.par_chunks_mut(chunk))
            .zip(self.stress_buffer.par_chunks_mut(chunk))
            .enumerate()
            .map(|(c, ((fs, states), stresses))| {
                let mut min_density = f64::INFINITY;
                // A failing particle does not stop its chunk: every particle is updated
                // as far as it gets, whichever fails, and the first failure is reported.
                let mut first_failure = None;
                for (k, ((f, state), stress)) in fs
                    .iter_mut()
                    .zip(states.iter_mut())
                    .zip(stresses.iter_mut())
                    .enumerate()
                {
                    let i = c * chunk + k;
                    let gv = *stress;
                    match update_one(material, f, state, &gv, stress, dt, step, i) {
                        Ok(det) => min_density = min_density.min(mass[i] / (volume[i] * det)),
                        Err(e) => {
                            first_failure.get_or_insert((i, e));
                        }
                    }
                }
                first_failure.map_or(Ok(min_density), Err)
            })
            // Among failures the lowest particle index wins, so the report does not
            // depend on the thread count.
            .reduce(|| Ok(f64::INFINITY), |a, b| lowest_failure(a, b, f64::min))
            .map_err(|(_, e)| e);
        // Whole only if every particle got its stress.
        self.stresses_current = result.is_ok();
        result
    }
}

/// One particle's F ← (I + Δt ∇v) F, return map and stress; det F on success. G2P
/// calls it under USL ([`Simulation::grid_to_particles`]), the stage below under MUSL.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn update_one<const D: usize, M: Constitutive<D>>(
    material: &M,
    f: &mut SMatrix<f64, D, D>,
    state: &mut M::State,
    gv: &SMatrix<f64, D, D>,
    stress: &mut SMatrix<f64, D, D>,
    dt: f64,
    step: usize,
    i: usize,
) -> Result<f64, EngineError> {
    *f = (SMatrix::<f64, D, D>::identity() + gv * dt) * *f;
    if !f.iter().all(|c| c.is_finite()) {
        return Err(EngineError::NonFinite {
            step,
            field: "deformation gradient",
            entity: "particle",
            index: i,
        });
    }
    let det = umls_constitutive::determinant(f);
    if det <= 0.0 {
        return Err(EngineError::Inverted {
            step,
            particle: i,
            det,
        });
    }
    *stress = material
        .return_map_and_stress(f, state)
        .map_err(|source| EngineError::Material {
            step,
            particle: i,
            source,
        })?;
    Ok(det)
}
