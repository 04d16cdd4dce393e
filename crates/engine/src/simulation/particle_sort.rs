//! Before stage 1, every [`StepSettings::particle_sort_interval`] steps: the particles
//! are stored in P2G's order (by the lowest node of their stencils, as the last step's
//! scatter sorted them), so that P2G reads them in storage order instead of through its
//! ordering, and G2P, which walks them in storage order, reads the grid block by block.
//!
//! P2G waits for memory, not for arithmetic (docs/scenes.md, *fluid-box-3d*): reading a
//! particle through the ordering is a jump in every array it touches, while in storage
//! order the hardware prefetches. The particles move, so the storage drifts out of
//! order; sorting again now and then costs one gather of the particle state, which the
//! interval spreads over its steps.
//!
//! Sorting renumbers the particles. [`Simulation::particle_id`] gives the index a stored
//! particle had when the simulation was built (body forces and error reports use it);
//! the boundary's fitted clamps are renumbered with the particles.
//!
//! [`StepSettings::particle_sort_interval`]: crate::StepSettings::particle_sort_interval

use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use super::Simulation;
use crate::transfer::TransferScheme;

/// `values` gathered in `order` (entry k becomes values[order[k]]), through `scratch`,
/// which keeps the old storage for the next gather of the same type.
fn gather<T: Clone + Send + Sync>(values: &mut Vec<T>, order: &[u32], scratch: &mut Vec<T>) {
    scratch.clear();
    scratch.par_extend(order.par_iter().map(|&p| values[p as usize].clone()));
    std::mem::swap(values, scratch);
}

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// Whether this step starts by sorting: sorting is switched on, its interval has
    /// passed, and the last scatter ordered exactly the particles stored now.
    pub(super) fn sort_due(&self) -> bool {
        let interval = self.settings.particle_sort_interval;
        interval > 0
            && self.step % interval == 0
            && self.step > 0
            && self.scatter.order().len() == self.particles.len()
    }

    /// Stores the particles, and everything the simulation keeps per particle across
    /// steps, in the last scatter's order.
    #[inline(never)]
    pub(super) fn sort_particles(&mut self) {
        let n = self.particles.len();
        let order = self.scatter.take_order();
        // Particles added since the last sort keep the ids of the slots they were added in.
        let first_new = self.ids.len().min(n);
        self.ids.truncate(n);
        self.ids.extend(first_new as u32..n as u32);
        gather(&mut self.ids, &order, &mut Vec::new());
        let p = &mut self.particles;
        // One scratch vector per element type: each gather leaves the old storage there
        // for the next array of that type, so a sort allocates one array of each (the
        // peak memory grows by a matrix array for the moment).
        let mut matrices = Vec::new();
        gather(&mut p.affine, &order, &mut matrices);
        gather(&mut p.deformation, &order, &mut matrices);
        if self.stresses_current {
            gather(&mut self.stress_buffer, &order, &mut matrices);
        }
        let mut vectors = Vec::new();
        gather(&mut p.position, &order, &mut vectors);
        gather(&mut p.velocity, &order, &mut vectors);
        if p.quadratic.len() == n {
            gather(&mut p.quadratic, &order, &mut Vec::new());
        }
        let mut scalars = Vec::new();
        gather(&mut p.affine_moment, &order, &mut scalars);
        gather(&mut p.volume, &order, &mut scalars);
        gather(&mut p.mass, &order, &mut scalars);
        gather(&mut p.state, &order, &mut Vec::new());
        gather(&mut p.cache, &order, &mut Vec::new());
        if !self.boundary.fitted.is_empty() {
            let mut slot = vec![0u32; n];
            for (k, &p) in order.iter().enumerate() {
                slot[p as usize] = k as u32;
            }
            for clamp in &mut self.boundary.fitted {
                clamp.renumber(&slot);
            }
        }
        self.scatter.restore_sorted_order(order);
        self.sorts += 1;
    }

    /// How many times the particles have been sorted: when it changes, slots may hold
    /// other particles than before ([`Self::particle_id`]).
    pub fn particle_sorts(&self) -> usize {
        self.sorts
    }

    /// The index particle `slot` had when the simulation was built (or when it was added
    /// through [`Self::particles_mut`]): sorting
    /// ([`crate::StepSettings::particle_sort_interval`]) moves particles between slots.
    pub fn particle_id(&self, slot: usize) -> usize {
        id_in(&self.ids, slot)
    }
}

/// The id of the particle in `slot` given the simulation's `ids` (a slot beyond them,
/// where no sort has run or a particle was added since, is its own id).
pub(crate) fn id_in(ids: &[u32], slot: usize) -> usize {
    ids.get(slot).map_or(slot, |&id| id as usize)
}
