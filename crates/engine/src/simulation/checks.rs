//! Stage 6 of the step: failure detection (non-finite particles, Courant number, energy
//! growth).

use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use super::Simulation;
use crate::error::EngineError;
use crate::transfer::TransferScheme;

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// NaN and Courant checks after a step (from what G2P gathered); records speed and
    /// density for the next Δt.
    pub(super) fn check_particles(
        &mut self,
        step: usize,
        dt: f64,
        min_density: f64,
    ) -> Result<(), EngineError> {
        // G2P gathered the first non-finite particle and the fastest one.
        if let Some(i) = self.totals.first_non_finite {
            return Err(EngineError::NonFinite {
                step,
                field: "velocity or position",
                entity: "particle",
                index: i,
            });
        }
        let (fastest, max_speed) = self.totals.fastest;
        let max_speed = max_speed.max(0.0).sqrt();
        let h = self.kernel.spacing();
        let (mover, moved) = self.totals.longest_move;
        let (particle, courant) = if moved / h > max_speed * dt / h {
            (mover, moved / h)
        } else {
            (fastest, max_speed * dt / h)
        };
        if courant > self.settings.max_courant {
            return Err(EngineError::Unstable {
                step,
                particle,
                courant,
                limit: self.settings.max_courant,
            });
        }
        self.totals.max_speed = max_speed;
        self.totals.min_density = min_density;
        Ok(())
    }

    /// The energy check: kinetic + elastic energy against what was put in.
    pub(super) fn check_energy(&mut self, step: usize) -> Result<(), EngineError> {
        let p = &self.particles;
        let kinetic: f64 = p
            .mass
            .iter()
            .zip(&p.velocity)
            .map(|(m, v)| 0.5 * m * v.norm_squared())
            .sum();
        let energy = kinetic + self.elastic_energy()?;
        let initial = self.totals.initial_energy.unwrap_or(0.0);
        let t = &mut self.totals;
        t.energy_supplied = t.energy_supplied.max(initial + t.external_work);
        if t.energy_supplied > 0.0 && energy > self.settings.energy_growth_limit * t.energy_supplied
        {
            return Err(EngineError::EnergyBlowUp {
                step,
                energy,
                initial: t.energy_supplied,
                factor: self.settings.energy_growth_limit,
            });
        }
        Ok(())
    }
}
