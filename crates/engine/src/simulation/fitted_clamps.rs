//! Part of stage 3, the grid update: clamps imposed on the fit ([`FittedClamp`]) set
//! their nodes' velocities from the clamped particles' stencils, and clamps held on
//! their face ([`FaceClamp`]) move the nodes around their face points least to hold
//! those points.
//!
//! [`FittedClamp`]: crate::FittedClamp
//! [`FaceClamp`]: crate::FaceClamp

use umls_constitutive::Constitutive;
use umls_transfer::{Kernel, Stencil};

use super::Simulation;
use crate::error::EngineError;
use crate::fitted_clamp::ClampRow;
use crate::transfer::TransferScheme;

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// Builds this step's systems of the fitted and the face clamps (kept for the MUSL
    /// re-map) and applies them to the grid velocities before and after the update (so a
    /// FLIP increment vanishes where the clamp holds, as well as the velocity).
    pub(super) fn apply_clamps_after_update(&mut self) -> Result<(), EngineError> {
        let rows = self.fitted_clamp_rows()?;
        self.clamp_systems.clear();
        for (clamp, rows) in self.boundary.fitted.iter().zip(rows) {
            let system = clamp.system(rows);
            clamp.fit(&system, &mut self.grid.velocity);
            clamp.fit(&system, &mut self.grid.new_velocity);
            self.clamp_systems.push(system);
        }
        self.face_systems.clear();
        for clamp in &self.boundary.faces {
            if let Some(node) = clamp
                .largest_node()
                .filter(|&n| n as usize >= self.grid.mass.len())
            {
                return Err(EngineError::InvalidParameter {
                    parameter: "face clamp node",
                    value: node as f64,
                    reason: "names a node beyond the kernel's node count (a clamp built with another kernel)",
                });
            }
            if !(clamp.penalty.is_finite() && clamp.penalty > 0.0) {
                // Zero would hold nothing, a negative penalty can leave the normal matrix
                // without a Cholesky factor: either way the face silently unheld.
                return Err(EngineError::InvalidParameter {
                    parameter: "face clamp penalty",
                    value: clamp.penalty,
                    reason: "must be finite and positive",
                });
            }
            let system = clamp.system(&self.grid.mass);
            clamp.hold(&system, &mut self.grid.velocity);
            clamp.hold(&system, &mut self.grid.new_velocity);
            self.face_systems.push(system);
        }
        Ok(())
    }

    /// The clamped particles' stencils of this step, one list per clamp.
    fn fitted_clamp_rows(&self) -> Result<Vec<Vec<ClampRow<D>>>, EngineError> {
        let step = self.step;
        let (p, kernel, stencils) = (&self.particles, &self.kernel, &self.stencils);
        let mut scratch = Stencil::new();
        let mut all = Vec::with_capacity(self.boundary.fitted.len());
        for clamp in &self.boundary.fitted {
            let mut rows = Vec::with_capacity(clamp.particles().len());
            for &i in clamp.particles() {
                let i = i as usize;
                if i >= p.len() {
                    return Err(EngineError::InvalidParameter {
                        parameter: "fitted clamp particle index",
                        value: i as f64,
                        reason: "names a particle beyond the particle count",
                    });
                }
                let entries = stencils
                    .with(i, kernel, &p.position[i], &p.cache[i], &mut scratch, |st| {
                        (0..st.len())
                            .map(|e| (st.nodes[e], st.values[e], st.gradients[e]))
                            .collect::<Vec<_>>()
                    })
                    .map_err(|(particle, source)| EngineError::Kernel {
                        step,
                        particle,
                        source,
                    })?;
                rows.push(ClampRow {
                    mass: p.mass[i],
                    entries,
                });
            }
            all.push(rows);
        }
        Ok(all)
    }
}
