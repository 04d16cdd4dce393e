//! Wall time spent in each stage of the step, summed over the steps taken, so a run (and
//! the bench report) can say where its time goes.

use std::time::Instant;

/// Seconds spent per stage since the simulation was created.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Locating particles and evaluating shape functions.
    pub stencils: f64,
    /// Kirchhoff stresses for P2G, and the deformation update with return mapping
    /// where it is a stage of its own (MUSL; under USL G2P makes it, in its time).
    pub constitutive: f64,
    /// The particle-to-grid scatter and its reduction.
    pub particles_to_grid: f64,
    /// Nodal velocities, boundary conditions, damping, mass scaling.
    pub grid_update: f64,
    /// Grid-to-particle gather, MUSL re-map and walls, and under USL the deformation
    /// update.
    pub grid_to_particles: f64,
    /// Non-finite, inversion and energy checks.
    pub checks: f64,
    /// Steps timed.
    pub steps: usize,
}

impl StageTimes {
    /// Sum over the stages.
    pub fn total(&self) -> f64 {
        self.stencils
            + self.constitutive
            + self.particles_to_grid
            + self.grid_update
            + self.grid_to_particles
            + self.checks
    }

    /// (name, seconds) per stage, in step order.
    pub fn stages(&self) -> [(&'static str, f64); 6] {
        [
            ("stencils", self.stencils),
            ("constitutive", self.constitutive),
            ("particles_to_grid", self.particles_to_grid),
            ("grid_update", self.grid_update),
            ("grid_to_particles", self.grid_to_particles),
            ("checks", self.checks),
        ]
    }
}

/// Adds the time since the last lap to a stage.
pub(crate) struct Lap(Instant);

impl Lap {
    pub(crate) fn start() -> Self {
        Self(Instant::now())
    }

    /// Seconds since the previous lap (or the start); restarts the clock.
    pub(crate) fn lap(&mut self) -> f64 {
        let now = Instant::now();
        let seconds = (now - self.0).as_secs_f64();
        self.0 = now;
        seconds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totals_and_stage_order() {
        let times = StageTimes {
            stencils: 1.0,
            constitutive: 2.0,
            particles_to_grid: 3.0,
            grid_update: 4.0,
            grid_to_particles: 5.0,
            checks: 6.0,
            steps: 2,
        };
        assert_eq!(times.total(), 21.0);
        assert_eq!(times.stages()[2], ("particles_to_grid", 3.0));
        let mut lap = Lap::start();
        let first = lap.lap();
        assert!(first >= 0.0 && lap.lap() >= 0.0);
    }
}
