//! The colliding disks and the vibrating bar built by hand from the engine, the mesh and
//! the material crates: the independent computation the scene files' set-up and results
//! are checked against.
#![allow(dead_code)] // each test file uses its own subset

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{SMatrix, SVector, Vector2};
use umls_constitutive::{ElasticParameters, LinearElastic};
use umls_engine::{Particles, Region, Simulation, StepSettings, TransferScheme, lattice_samples};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::Kernel;

/// The disks' mesh: the unit square, 20 × 20 cells jittered by 0.2 (seed 11),
/// alternating diagonals.
pub fn disks_mesh() -> Arc<SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [20, 20])
            .jitter(0.2, 11)
            .triangles(Diagonal::Alternating)
            .unwrap(),
    )
}

/// The two disks of radius 0.2 at (0.2, 0.2) and (0.8, 0.8), on a lattice of spacing
/// 0.025, moving at ±(0.1, 0.1); ρ = 1000.
pub fn disks_particles<C: Copy + Default>() -> Particles<2, (), C> {
    let mut particles = Particles::at_rest(Vec::new(), Vec::new(), 1000.0, ());
    for (centre, sign) in [
        (Vector2::new(0.2, 0.2), 1.0),
        (Vector2::new(0.8, 0.8), -1.0),
    ] {
        let lattice = lattice_samples(centre.add_scalar(-0.2), centre.add_scalar(0.2), 0.025);
        let disk = Region::Ball {
            centre,
            radius: 0.2,
        };
        let velocity = Vector2::new(0.1, 0.1) * sign;
        particles.append(Particles::seed(&lattice, &disk, 1000.0, (), |_| velocity));
    }
    particles
}

/// The disks with `kernel` and `transfer`: E = 1000, ν = 0.3, Δt = 10⁻³.
pub fn disks<K: Kernel<2>, T: TransferScheme>(
    kernel: K,
    transfer: T,
) -> Simulation<2, K, LinearElastic, T> {
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(1000.0, 0.3).unwrap(),
    };
    Simulation::new(
        kernel,
        material,
        transfer,
        disks_particles(),
        StepSettings::new(1e-3),
    )
    .unwrap()
}

/// The bar of `vibrating-bar`: L = 25, E = 100, ρ = 1, v₀ = 0.1, mirrored about x = 0,
/// `cells` cells on [0, L], one particle at each cell's centre, Δt = 0.1 Δx / c rounded
/// to end at one period.
#[derive(Debug, Clone, Copy)]
pub struct Bar {
    /// Cells on [0, L].
    pub cells: usize,
    /// C_p starts at ∂v/∂x instead of zero.
    pub gradient_start: bool,
}

impl Bar {
    const LENGTH: f64 = 25.0;
    const AMPLITUDE: f64 = 0.1;

    fn beta(&self) -> f64 {
        PI / (2.0 * Self::LENGTH)
    }

    fn omega(&self) -> f64 {
        self.beta() * 10.0
    }

    fn dx(&self) -> f64 {
        Self::LENGTH / self.cells as f64
    }

    /// v(x, t) = v₀ cos(ωt) sin(βx).
    fn velocity(&self, x: f64, t: f64) -> f64 {
        Self::AMPLITUDE * (self.omega() * t).cos() * (self.beta() * x).sin()
    }

    /// Cells of Δx on [−L − 4Δx, L + 4Δx].
    pub fn mesh(&self) -> Arc<SimplexMesh<1>> {
        let end = Self::LENGTH + 4.0 * self.dx();
        Arc::new(
            Lattice::new([-end], [end], [2 * (self.cells + 4)])
                .segments()
                .unwrap(),
        )
    }

    /// One particle per cell centre on [0, L] and their mirror images.
    pub fn particles<C: Copy + Default>(&self) -> Particles<1, (), C> {
        let h = self.dx();
        let mut x: Vec<SVector<f64, 1>> = (0..self.cells)
            .map(|k| SVector::from([(k as f64 + 0.5) * h]))
            .collect();
        let mirrored: Vec<SVector<f64, 1>> = x.iter().map(|p| -p).collect();
        x.extend(mirrored);
        let n = x.len();
        let mut p = Particles::at_rest(x, vec![h; n], 1.0, ());
        for i in 0..n {
            let x = p.position[i][0];
            p.velocity[i] = SVector::from([self.velocity(x, 0.0)]);
            if self.gradient_start {
                let gradient = Self::AMPLITUDE * self.beta() * (self.beta() * x).cos();
                p.affine[i] = SMatrix::from([[gradient]]);
            }
        }
        p
    }

    /// Steps and Δt: 0.1 Δx / c, rounded so that the run ends at one period.
    pub fn steps_and_dt(&self) -> (usize, f64) {
        let end = 2.0 * PI / self.omega();
        let steps = (end / (0.1 * self.dx() / 10.0)).ceil() as usize;
        (steps, end / steps as f64)
    }

    /// RMS over particles and steps of v − v_exact at each step's midpoint, over v₀.
    pub fn velocity_rmse<K: Kernel<1>, T: TransferScheme>(&self, kernel: K, transfer: T) -> f64 {
        let material = LinearElastic {
            parameters: ElasticParameters::from_young_poisson(100.0, 0.0).unwrap(),
        };
        let (steps, dt) = self.steps_and_dt();
        let particles = self.particles();
        let reference: Vec<f64> = particles.position.iter().map(|x| x[0]).collect();
        let mut sim =
            Simulation::new(kernel, material, transfer, particles, StepSettings::new(dt)).unwrap();
        let (mut sq, mut count) = (0.0, 0.0);
        for _ in 0..steps {
            sim.step().unwrap();
            let t = sim.time() - 0.5 * sim.last_dt();
            for (v, x) in sim.particles().velocity.iter().zip(&reference) {
                sq += (v[0] - self.velocity(*x, t)).powi(2);
                count += 1.0;
            }
        }
        (sq / count).sqrt() / Self::AMPLITUDE
    }
}
