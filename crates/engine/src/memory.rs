//! What a simulation holds in memory, by what it grows with: the particle state, the
//! per-particle scratch of a step, the stored stencils, and the nodal fields.

/// Bytes held by a [`crate::Simulation`]'s arrays (their capacity times the element
/// size; heap data inside a material state is not followed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MemoryUse {
    /// Particle count.
    pub particle_count: usize,
    /// The particle state: positions, velocities, affine matrices and moments,
    /// deformation gradients, volumes, masses, material states, location caches.
    pub particles: usize,
    /// Per-particle scratch of a step: stresses (which also carry the velocity
    /// gradients to the deformation update), stencil node ranges, the P2G ordering.
    pub particle_scratch: usize,
    /// Stored stencils (zero where they are recomputed).
    pub stencils: usize,
    /// Nodal fields and the P2G windows: they grow with the grid or mesh, not with the
    /// particles.
    pub nodes: usize,
}

impl MemoryUse {
    /// Particle state plus per-step scratch, per particle: what a particle costs besides
    /// stored stencils.
    pub fn bytes_per_particle(&self) -> f64 {
        (self.particles + self.particle_scratch) as f64 / self.particle_count.max(1) as f64
    }

    /// The same with the stored stencils.
    pub fn bytes_per_particle_with_stencils(&self) -> f64 {
        (self.particles + self.particle_scratch + self.stencils) as f64
            / self.particle_count.max(1) as f64
    }

    /// Everything.
    pub fn total(&self) -> usize {
        self.particles + self.particle_scratch + self.stencils + self.nodes
    }
}

/// Bytes held by a vector's storage.
pub(crate) fn bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}
