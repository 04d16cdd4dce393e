//! Colliding disks (Sulsky, Chen & Schreyer 1994): unit square, disks of radius 0.2 at
//! (0.2, 0.2) and (0.8, 0.8) moving at ±(0.1, 0.1), linear elastic E = 1000, ν = 0.3,
//! ρ = 1000, no gravity, Δt = 10⁻³, T = 3.

use std::sync::Arc;

use nalgebra::{Matrix2, Vector2};
use umls_constitutive::{ConstitutiveError, ElasticParameters, LinearElastic};
use umls_engine::{
    EngineError, Particles, Region, Simulation, StepSettings, TransferScheme, lattice_samples,
};
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mesh::{MeshError, SimplexMesh};
use umls_transfer::Kernel;

/// Parameters of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollidingDisks {
    /// Mesh cells per side of the unit square (20 in the textbook run).
    pub cells: usize,
    /// Interior vertex jitter of the triangle mesh, as a fraction of the cell size.
    pub jitter: f64,
    /// Particles per cell side (2 → 4 per cell).
    pub particles_per_side: usize,
    /// Young's modulus.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Density.
    pub density: f64,
    /// Disk speed along each axis.
    pub speed: f64,
    /// Time step.
    pub dt: f64,
    /// End time.
    pub end_time: f64,
}

impl Default for CollidingDisks {
    /// The textbook run on a jittered (0.2) triangle mesh.
    fn default() -> Self {
        Self {
            cells: 20,
            jitter: 0.2,
            particles_per_side: 2,
            young: 1000.0,
            poisson: 0.3,
            density: 1000.0,
            speed: 0.1,
            dt: 1e-3,
            end_time: 3.0,
        }
    }
}

impl CollidingDisks {
    /// The background mesh: the unit square, `cells` × `cells` jittered cells, alternating diagonals.
    pub fn mesh(&self) -> Result<SimplexMesh<2>, MeshError> {
        Lattice::new([0.0, 0.0], [1.0, 1.0], [self.cells, self.cells])
            .jitter(self.jitter, 11)
            .triangles(Diagonal::Alternating)
    }

    /// The two disks' particles on a regular lattice, moving towards each other.
    pub fn particles<C: Copy + Default>(&self) -> Particles<2, (), C> {
        let spacing = 1.0 / (self.cells * self.particles_per_side) as f64;
        let mut particles = Particles::at_rest(Vec::new(), Vec::new(), self.density, ());
        for (centre, sign) in [
            (Vector2::new(0.2, 0.2), 1.0),
            (Vector2::new(0.8, 0.8), -1.0),
        ] {
            let lattice = lattice_samples(centre.add_scalar(-0.2), centre.add_scalar(0.2), spacing);
            let disk = Region::Ball {
                centre,
                radius: 0.2,
            };
            let velocity = Vector2::new(self.speed, self.speed) * sign;
            particles.append(Particles::seed(&lattice, &disk, self.density, (), |_| {
                velocity
            }));
        }
        particles
    }

    /// The material.
    pub fn material(&self) -> Result<LinearElastic, ConstitutiveError> {
        Ok(LinearElastic {
            parameters: ElasticParameters::from_young_poisson(self.young, self.poisson)?,
        })
    }

    /// A ready simulation with `kernel` and `transfer`.
    pub fn simulation<K: Kernel<2>, T: TransferScheme>(
        &self,
        kernel: K,
        transfer: T,
    ) -> Result<Simulation<2, K, LinearElastic, T>, EngineError> {
        let material = self.material().map_err(|source| EngineError::Material {
            step: 0,
            particle: 0,
            source,
        })?;
        Simulation::new(
            kernel,
            material,
            transfer,
            self.particles(),
            StepSettings::new(self.dt),
        )
    }

    /// The mesh in an `Arc`, for mesh kernels.
    pub fn shared_mesh(&self) -> Result<Arc<SimplexMesh<2>>, MeshError> {
        self.mesh().map(Arc::new)
    }
}

/// Roughness of a stress history: mean ‖τ_{n+1} − 2τ_n + τ_{n−1}‖ over mean ‖τ_n‖, over all
/// particles (`history[step][particle]`). A smooth history has second differences O(Δt²);
/// a particle whose stress jumps when it crosses a facet (cell-crossing error) has O(jump).
pub fn stress_roughness(history: &[Vec<Matrix2<f64>>]) -> f64 {
    let (mut second, mut magnitude, mut count) = (0.0, 0.0, 0.0);
    for w in history.windows(3) {
        for ((a, b), c) in w[0].iter().zip(&w[1]).zip(&w[2]) {
            second += (c - b * 2.0 + a).norm();
            magnitude += b.norm();
            count += 1.0;
        }
    }
    (second / count) / (magnitude / count)
}
