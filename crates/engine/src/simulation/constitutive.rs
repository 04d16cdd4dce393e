//! Stage 5 of the step and the start of the next: F ← (I + Δt ∇v) F with the material's
//! return map, and the Kirchhoff stresses P2G spreads.

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
    /// decomposition for plastic models); the smallest density m / (V⁰ det F).
    pub(super) fn update_deformation(
        &mut self,
        velocity_gradients: &[SMatrix<f64, D, D>],
        dt: f64,
    ) -> Result<f64, EngineError> {
        let step = self.step;
        let material = &self.material;
        let p = &mut self.particles;
        let (mass, volume) = (&p.mass, &p.volume);
        self.stress_buffer.resize(p.len(), SMatrix::zeros());
        let result = p
            .deformation
            .par_iter_mut()
            .zip(p.state.par_iter_mut())
            .zip(velocity_gradients.par_iter())
            .zip(self.stress_buffer.par_iter_mut())
            .enumerate()
            .map(|(i, (((f, state), gv), stress))| {
                let fail = |e| (i, e);
                *f = (SMatrix::<f64, D, D>::identity() + gv * dt) * *f;
                if !f.iter().all(|c| c.is_finite()) {
                    return Err(fail(EngineError::NonFinite {
                        step,
                        field: "deformation gradient",
                        entity: "particle",
                        index: i,
                    }));
                }
                let det = umls_constitutive::determinant(f);
                if det <= 0.0 {
                    return Err(fail(EngineError::Inverted {
                        step,
                        particle: i,
                        det,
                    }));
                }
                *stress = material.return_map_and_stress(f, state).map_err(|source| {
                    fail(EngineError::Material {
                        step,
                        particle: i,
                        source,
                    })
                })?;
                Ok(mass[i] / (volume[i] * det))
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
