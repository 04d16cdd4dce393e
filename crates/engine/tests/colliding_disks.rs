//! 2D colliding disks (Sulsky et al. 1994): unit square, disks of radius 0.2 at (0.2, 0.2)
//! and (0.8, 0.8) moving at ±(0.1, 0.1), linear elastic E = 1000, ν = 0.3, ρ = 1000,
//! no gravity, Δt = 10⁻³. The disks meet at t ≈ 0.9 and separate.

use std::sync::Arc;

use nalgebra::Vector2;
use umls_constitutive::{ElasticParameters, LinearElastic};
use umls_engine::{Diagnostics, Flip, Particles, Simulation, StepSettings, TransferScheme};
use umls_kernels::{HostCache, LinearFeKernel, Umls2};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::Kernel;

fn mesh() -> Arc<SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [20, 20])
            .jitter(0.2, 11)
            .triangles(Diagonal::Alternating)
            .unwrap(),
    )
}

/// Particles on a 0.025 lattice (4 per 0.05² cell) inside the two disks.
fn disks() -> Particles<2, (), HostCache> {
    let spacing = 0.025;
    let mut x = Vec::new();
    let mut v = Vec::new();
    for (centre, velocity) in [
        (Vector2::new(0.2, 0.2), Vector2::new(0.1, 0.1)),
        (Vector2::new(0.8, 0.8), Vector2::new(-0.1, -0.1)),
    ] {
        for i in 0..16 {
            for j in 0..16 {
                let p = centre
                    + Vector2::new(
                        -0.2 + (i as f64 + 0.5) * spacing,
                        -0.2 + (j as f64 + 0.5) * spacing,
                    );
                if (p - centre).norm() < 0.2 {
                    x.push(p);
                    v.push(velocity);
                }
            }
        }
    }
    let n = x.len();
    let mut particles = Particles::at_rest(x, vec![spacing * spacing; n], 1000.0, ());
    particles.velocity = v;
    particles
}

fn run<K: Kernel<2, Cache = HostCache>, T: TransferScheme>(
    kernel: K,
    transfer: T,
    end: f64,
) -> (Vec<Diagnostics<2>>, Simulation<2, K, LinearElastic, T>) {
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(1000.0, 0.3).unwrap(),
    };
    let mut sim =
        Simulation::new(kernel, material, transfer, disks(), StepSettings::new(1e-3)).unwrap();
    let mut history = vec![sim.diagnostics().unwrap()];
    while sim.time() < end - 1e-9 {
        sim.step().unwrap();
        if sim.step_count() % 10 == 0 {
            history.push(sim.diagnostics().unwrap());
        }
    }
    (history, sim)
}

/// The transfer of the classic runs: FLIP blended with 1 % PIC.
const TRANSFER: Flip = Flip { alpha: 0.99 };

/// UMLS on a jittered triangle mesh runs through the collision to t = 3 without failure;
/// momentum stays zero; kinetic energy dips in the collision and recovers after the rebound.
#[test]
fn umls_disks_collide_and_rebound() {
    let (history, sim) = run(Umls2::new(mesh()), TRANSFER, 3.0);
    let k0 = history[0].kinetic;
    let min_kinetic = history
        .iter()
        .map(|d| d.kinetic)
        .fold(f64::INFINITY, f64::min);
    let at = |t: f64| {
        history
            .iter()
            .min_by(|a, b| (a.time - t).abs().total_cmp(&(b.time - t).abs()))
            .unwrap()
    };
    let max_momentum = history
        .iter()
        .map(|d| d.momentum.norm())
        .fold(0.0, f64::max);
    let max_energy = history.iter().map(|d| d.total_energy()).fold(0.0, f64::max);
    eprintln!(
        "UMLS disks: K0 {k0:.4e}, min K {min_kinetic:.4e} at collision, K(3) {:.4e}, elastic(3) {:.4e}, max |momentum| {max_momentum:.2e}, max total energy {max_energy:.4e}",
        at(3.0).kinetic,
        at(3.0).elastic
    );
    // Before contact the disks fly freely.
    assert!((at(0.5).kinetic - k0).abs() < 0.02 * k0);
    // The collision converts almost all kinetic energy into strain energy ...
    assert!(min_kinetic < 0.1 * k0, "min kinetic {min_kinetic}");
    // ... and the disks separate again with most kinetic energy back (elastic rebound;
    // the rest stays in vibration and in FLIP-PIC blending).
    assert!(
        at(3.0).kinetic > 0.5 * k0,
        "kinetic after rebound {}",
        at(3.0).kinetic
    );
    // Momentum: zero initially (opposite velocities) and conserved.
    assert!(max_momentum < 1e-10 * history[0].mass * 0.1 * 2f64.sqrt());
    // No energy growth beyond the initial.
    assert!(max_energy < 1.01 * (k0 + history[0].elastic));
    // After the rebound the disks move apart: centroid of the first disk moves back.
    let half = sim.particles.len() / 2;
    let centroid: Vector2<f64> =
        sim.particles.position[..half].iter().sum::<Vector2<f64>>() / half as f64;
    let velocity: Vector2<f64> =
        sim.particles.velocity[..half].iter().sum::<Vector2<f64>>() / half as f64;
    assert!(
        velocity.x < 0.0 && velocity.y < 0.0,
        "first disk velocity after rebound {velocity:?} at {centroid:?}"
    );
}

/// The cell-crossing error: particles crossing facets see the jump of linear-FE gradients,
/// so their stress jumps from one step to the next; UMLS gradients are continuous. Over
/// the collision (t = 1.3 … 2.7, stresses far from zero, particles moving across
/// facets), roughness = mean ‖τ_{n+1} − 2τ_n + τ_{n−1}‖ / mean ‖τ_n‖ over all particles:
/// a smooth history has second differences O(Δt²), a jumping one O(jump).
#[test]
fn linear_fe_stress_is_rougher_than_umls_stress() {
    fn roughness<K: Kernel<2, Cache = HostCache>>(kernel: K) -> f64 {
        let material = LinearElastic {
            parameters: ElasticParameters::from_young_poisson(1000.0, 0.3).unwrap(),
        };
        let mut sim =
            Simulation::new(kernel, material, TRANSFER, disks(), StepSettings::new(1e-3)).unwrap();
        while sim.time() < 1.3 {
            sim.step().unwrap();
        }
        let mut history: Vec<Vec<nalgebra::Matrix2<f64>>> = Vec::new();
        while sim.time() < 2.7 {
            sim.step().unwrap();
            history.push(sim.stresses().unwrap());
        }
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
    let fe = roughness(LinearFeKernel::new(mesh()));
    let umls = roughness(Umls2::new(mesh()));
    eprintln!(
        "collision stress roughness: linear FE {fe:.4e}, UMLS {umls:.4e}, ratio {:.1}",
        fe / umls
    );
    assert!(fe > 3.0 * umls, "FE {fe} vs UMLS {umls}");
}
