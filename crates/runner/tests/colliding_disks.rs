//! The colliding disks (`colliding-disks`) through the runner: UMLS takes them through
//! the collision and the rebound, and its stresses are smoother than linear FE's on the
//! same jittered mesh, the cell-crossing error the kernel removes.

use nalgebra::Matrix2;
use umls_runner::run::{RunOptions, prepare, run};
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;

/// UMLS runs through the collision to t = 3 without failure; momentum stays zero; kinetic
/// energy dips in the collision and recovers after the rebound; the disks move apart.
#[test]
fn umls_disks_collide_and_rebound() {
    let scene = Scene::load("colliding-disks").unwrap();
    let report = run(&scene, &RunOptions::default()).unwrap();
    let history = &report.history;
    let (time, kinetic, total) = (
        history.column("time").unwrap(),
        history.column("kinetic").unwrap(),
        history.column("total").unwrap(),
    );
    let momentum: Vec<f64> = history
        .column("momentum_x")
        .unwrap()
        .iter()
        .zip(history.column("momentum_y").unwrap())
        .map(|(x, y)| x.hypot(y))
        .collect();
    let k0 = kinetic[0];
    let at = |t: f64| {
        let row = (0..time.len())
            .min_by(|&a, &b| (time[a] - t).abs().total_cmp(&(time[b] - t).abs()))
            .unwrap();
        kinetic[row]
    };
    let min_kinetic = kinetic.iter().copied().fold(f64::INFINITY, f64::min);
    let max_momentum = momentum.iter().copied().fold(0.0, f64::max);
    let max_energy = total.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "UMLS disks: K0 {k0:.4}, min K {min_kinetic:.3e}, K(3) {:.4}, max |p| {max_momentum:.2e}, max E {max_energy:.4}",
        at(3.0)
    );
    assert!((at(0.5) - k0).abs() < 0.02 * k0, "free flight");
    assert!(
        min_kinetic < 0.1 * k0,
        "collision: min kinetic {min_kinetic}"
    );
    assert!(at(3.0) > 0.5 * k0, "rebound: kinetic {}", at(3.0));
    assert!(max_momentum < 1e-12, "momentum {max_momentum}");
    assert!(
        max_energy < 1.0001 * total[0],
        "energy grew to {max_energy}"
    );
    // The first disk moves back toward its corner after the rebound.
    let velocities = &report.summary.metrics["body_velocities"];
    let first: Vec<f64> = velocities[0]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(first[0] < 0.0 && first[1] < 0.0, "first disk: {first:?}");
}

/// Roughness of a stress history: mean ‖σ_{n+1} − 2σ_n + σ_{n−1}‖ over mean ‖σ_n‖, over
/// all particles (`history[step][particle]`). A smooth history has second differences
/// O(Δt²); a particle whose stress jumps when it crosses a facet (cell-crossing error)
/// has O(jump).
fn stress_roughness(history: &[Vec<Matrix2<f64>>]) -> f64 {
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

/// The stress roughness of the disks with `kernel` over the collision, t = 1.3 … 2.7,
/// where stresses are far from zero and particles cross facets.
fn collision_roughness(kernel: KernelKind) -> f64 {
    let scene = Scene::load("colliding-disks").unwrap();
    let options = RunOptions {
        kernel: Some(kernel),
        ..RunOptions::default()
    };
    let mut prepared = prepare::<2>(&scene, &options).unwrap();
    let sim = prepared.simulation();
    while sim.time() < 1.3 {
        sim.step().unwrap();
    }
    let mut history = Vec::new();
    while sim.time() < 2.7 {
        sim.step().unwrap();
        history.push(sim.cauchy_stresses().unwrap());
    }
    stress_roughness(&history)
}

/// Over the collision linear-FE stress histories are much rougher than UMLS ones.
#[test]
fn linear_fe_stress_is_rougher_than_umls_stress() {
    let fe = collision_roughness(KernelKind::LinearFe);
    let umls = collision_roughness(KernelKind::Umls);
    eprintln!(
        "collision stress roughness: linear FE {fe:.4e}, UMLS {umls:.4e}, ratio {:.1}",
        fe / umls
    );
    assert!(fe > 3.0 * umls, "FE {fe} vs UMLS {umls}");
}
