//! Colliding disks with UMLS on a jittered triangle mesh, and the cell-crossing comparison
//! against linear FE on the same mesh.

use umls_engine::{Diagnostics, Flip};
use umls_kernels::{LinearFeKernel, Umls2};
use umls_scenes::colliding_disks::{CollidingDisks, stress_roughness};
use umls_transfer::Kernel;

/// The transfer of the classic runs: FLIP blended with 1 % PIC.
const TRANSFER: Flip = Flip { alpha: 0.99 };

/// UMLS runs through the collision to t = 3 without failure; momentum stays zero; kinetic
/// energy dips in the collision and recovers after the rebound; the disks move apart.
#[test]
fn umls_disks_collide_and_rebound() {
    let scene = CollidingDisks::default();
    let mut sim = scene
        .simulation(Umls2::new(scene.shared_mesh().unwrap()), TRANSFER)
        .unwrap();
    let mut history: Vec<Diagnostics<2>> = vec![sim.diagnostics().unwrap()];
    while sim.time() < scene.end_time - 1e-9 {
        sim.step().unwrap();
        if sim.step_count() % 10 == 0 {
            history.push(sim.diagnostics().unwrap());
        }
    }
    let k0 = history[0].kinetic;
    let at = |t: f64| {
        history
            .iter()
            .min_by(|a, b| (a.time - t).abs().total_cmp(&(b.time - t).abs()))
            .unwrap()
    };
    let min_kinetic = history
        .iter()
        .map(|d| d.kinetic)
        .fold(f64::INFINITY, f64::min);
    let max_momentum = history
        .iter()
        .map(|d| d.momentum.norm())
        .fold(0.0, f64::max);
    let max_energy = history.iter().map(|d| d.total_energy()).fold(0.0, f64::max);
    eprintln!(
        "UMLS disks: K0 {k0:.4}, min K {min_kinetic:.3e}, K(3) {:.4}, max |p| {max_momentum:.2e}, max E {max_energy:.4}",
        at(3.0).kinetic
    );
    assert!((at(0.5).kinetic - k0).abs() < 0.02 * k0, "free flight");
    assert!(
        min_kinetic < 0.1 * k0,
        "collision: min kinetic {min_kinetic}"
    );
    assert!(
        at(3.0).kinetic > 0.5 * k0,
        "rebound: kinetic {}",
        at(3.0).kinetic
    );
    assert!(max_momentum < 1e-12, "momentum {max_momentum}");
    assert!(
        max_energy < 1.0001 * history[0].total_energy(),
        "energy grew to {max_energy}"
    );
    let half = sim.particles().len() / 2;
    let velocity = sim.particles().velocity[..half]
        .iter()
        .sum::<nalgebra::Vector2<f64>>()
        / half as f64;
    assert!(
        velocity.x < 0.0 && velocity.y < 0.0,
        "first disk moves back: {velocity:?}"
    );
}

/// Over the collision (t = 1.3 … 2.7: stresses far from zero, particles crossing facets)
/// linear-FE stress histories are much rougher than UMLS ones.
#[test]
fn linear_fe_stress_is_rougher_than_umls_stress() {
    fn roughness<K: Kernel<2>>(scene: &CollidingDisks, kernel: K) -> f64 {
        let mut sim = scene.simulation(kernel, TRANSFER).unwrap();
        while sim.time() < 1.3 {
            sim.step().unwrap();
        }
        let mut history = Vec::new();
        while sim.time() < 2.7 {
            sim.step().unwrap();
            history.push(sim.stresses().unwrap());
        }
        stress_roughness(&history)
    }
    let scene = CollidingDisks::default();
    let fe = roughness(&scene, LinearFeKernel::new(scene.shared_mesh().unwrap()));
    let umls = roughness(&scene, Umls2::new(scene.shared_mesh().unwrap()));
    eprintln!(
        "collision stress roughness: linear FE {fe:.4e}, UMLS {umls:.4e}, ratio {:.1}",
        fe / umls
    );
    assert!(fe > 3.0 * umls, "FE {fe} vs UMLS {umls}");
}
