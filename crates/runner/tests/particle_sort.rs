//! `[kernel] particle_sort_interval`: the engine stores the particles in P2G's order now
//! and then, and the run follows every particle by its index in the scene. A body force
//! of the reference position (the vortex), a velocity reference and a probe (the
//! cantilever's tip) give what they give unsorted.

use umls_runner::run::run;
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;

#[path = "common/runs.rs"]
mod runs;
use runs::{History, options};

/// `name` run with `kernel` to `end_time`, unsorted and sorted every 2 steps, a history
/// row per step: the two histories.
fn unsorted_and_sorted(name: &str, kernel: KernelKind, end_time: f64) -> (History, History) {
    let mut histories = Vec::new();
    for interval in [0, 2] {
        let edits = vec![
            (
                "kernel.particle_sort_interval".to_string(),
                interval.to_string(),
            ),
            ("output.frames".to_string(), "2".to_string()),
            ("output.history_every".to_string(), "1".to_string()),
        ];
        let scene = Scene::load_with(name, &edits).unwrap();
        let options = options(
            &format!("{name}-sort-{interval}"),
            Some(kernel),
            Some(end_time),
        );
        let report = run(&scene, &options).unwrap();
        let s = &report.summary.to_json();
        assert_eq!(s["status"], "completed", "{s}");
        assert_eq!(s["particle_sort_interval"], interval, "{s}");
        let sorts = s["particle_sorts"].as_u64().unwrap();
        let steps = s["steps"].as_u64().unwrap();
        // A sort before every second step from the second on.
        let expected = if interval == 0 { 0 } else { (steps - 1) / 2 };
        assert_eq!(sorts, expected, "{name}: {steps} steps");
        histories.push(History::read(options.out.as_deref().unwrap()));
    }
    let sorted = histories.pop().unwrap();
    (histories.pop().unwrap(), sorted)
}

/// Column `name` of two histories: equal bit for bit (`exact`), or to the round-off of
/// a sum over the particles taken in another order.
fn assert_same_column(a: &History, b: &History, name: &str, exact: bool) {
    let (i, j) = (a.column(name), b.column(name));
    assert_eq!(a.rows.len(), b.rows.len());
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        let (x, y) = (ra[i], rb[j]);
        if exact {
            assert_eq!(
                x.to_bits(),
                y.to_bits(),
                "{name} at t = {}: {x} vs {y}",
                ra[1]
            );
        } else {
            assert!(
                (x - y).abs() <= 1e-12 * x.abs().max(1e-300),
                "{name} at t = {}: {x} vs {y}",
                ra[1]
            );
        }
    }
}

/// The vortex's body force is a function of each particle's reference position and its
/// error is measured against it: sorted, both follow the particles. UMLS on the mesh.
#[test]
fn the_vortex_follows_its_particles_through_the_sorts() {
    let (unsorted, sorted) = unsorted_and_sorted("vortex", KernelKind::Umls, 0.05);
    assert!(unsorted.rows.len() > 3);
    // Sums of positive terms: their round-off is relative to the sum.
    for column in ["velocity_error", "kinetic", "elastic"] {
        assert_same_column(&unsorted, &sorted, column, false);
    }
    // The error is not zero: a body force at the wrong particles would show here.
    assert!(unsorted.last("velocity_error") > 0.0);
}

/// The cantilever's tip probe is one particle, followed from slot to slot: its
/// displacement is the same bit for bit.
#[test]
fn the_cantilever_probe_follows_its_particle_through_the_sorts() {
    let (unsorted, sorted) = unsorted_and_sorted("cantilever", KernelKind::Bspline2, 0.1);
    for column in ["probe0_ux", "probe0_uy"] {
        assert_same_column(&unsorted, &sorted, column, true);
    }
    assert!(unsorted.last("probe0_uy") < 0.0, "the tip falls");
    assert_same_column(&unsorted, &sorted, "kinetic", false);
}
