//! The `fluid-box-3d` scene (Taichi's mpm3d) and the grid kernels' lean background: a
//! B-spline run of a `[mesh.lattice]` scene never splits the lattice into simplices.

use umls_runner::run::run;
use umls_runner::scene::Scene;
use umls_runner::setup::{build, build_for, tetrahedra, triangles};

#[path = "common/runs.rs"]
mod runs;
use runs::{History, options};

/// `edits` and the first and last particle frames only: 64,000 particles take 22 MB a
/// frame, and these tests read the history, not the frames.
fn with_few_frames(mut edits: Vec<(String, String)>) -> Vec<(String, String)> {
    edits.push(("output.frames".into(), "2".into()));
    edits
}

/// The first 25 steps: the block is in free fall (it is 0.1 above the floor plane), so
/// its momentum is −M g t along y to round-off and nothing else moves it; no mesh is
/// built or written.
#[test]
fn fluid_box_falls_freely_at_first_without_a_mesh() {
    let scene = Scene::load_with("fluid-box-3d", &with_few_frames(Vec::new())).unwrap();
    let options = options("fluid-box", None, Some(0.005));
    let report = run(&scene, &options).unwrap();
    let out = options.out.clone().unwrap();
    let s = &report.summary.to_json();
    assert_eq!(s["kernel"], "bspline2");
    assert_eq!(s["particles"], 64_000);
    assert_eq!(s["steps"], 25);
    assert!(
        s["cells"].is_null() && s["outputs"]["mesh"].is_null(),
        "{s}"
    );
    assert!(!out.join("mesh.vtu").exists() && out.join("grid.vtu").exists());
    let history = History::read(&out);
    let column = |name: &str| history.last(name);
    // 64,000 particles of 10⁻⁶ m³ at density 1 (a sum of 64,000 rounded volumes).
    let mass = column("mass");
    assert!((mass - 0.064).abs() < 1e-12 * 0.064, "{mass}");
    // Sums over 64,000 particles for 25 steps carry ~10⁻¹² relative round-off; touching
    // a wall or losing mass would show at 10⁻³.
    let expected = -mass * 9.8 * column("time");
    assert!(
        (column("momentum_y") - expected).abs() < 1e-10 * expected.abs(),
        "{} vs {expected}",
        column("momentum_y")
    );
    assert!(column("momentum_x").abs() < 1e-15 && column("momentum_z").abs() < 1e-15);
}

/// MLS-MPM folds gravity into the momentum P2G spreads (and the force into the affine
/// term): in free fall its momentum is still −M g t along y to round-off, and it is
/// bitwise unchanged by the thread count.
#[test]
fn fluid_box_falls_freely_under_mls_mpm_on_any_thread_count() {
    let edits = with_few_frames(vec![("transfer.kind".into(), "\"mls-mpm\"".into())]);
    let scene = Scene::load_with("fluid-box-3d", &edits).unwrap();
    let mut histories = Vec::new();
    for threads in [1, 2] {
        let mut options = options(&format!("fluid-box-mls-mpm-{threads}"), None, Some(0.005));
        options.threads = Some(threads);
        let report = run(&scene, &options).unwrap();
        assert_eq!(
            report.summary.to_json()["transfer"],
            "mls-mpm",
            "{}",
            report.summary.to_json()
        );
        let history = History::read(options.out.as_deref().unwrap());
        let mass = history.last("mass");
        let expected = -mass * 9.8 * history.last("time");
        let momentum = history.last("momentum_y");
        assert!(
            (momentum - expected).abs() < 1e-10 * expected.abs(),
            "{momentum} vs {expected}"
        );
        histories.push(
            std::fs::read_to_string(options.out.as_deref().unwrap().join("history.csv")).unwrap(),
        );
    }
    assert_eq!(histories[0], histories[1]);
}

/// Without the simplices a grid run seeds the same particles and constrains the same
/// nodes, upright and turned: the lean background changes only what is built.
#[test]
fn lean_background_seeds_what_the_mesh_seeds() {
    for name in ["hydrostatic-column", "hydrostatic-column-tilted"] {
        let scene = Scene::load(name).unwrap();
        let full = build::<2>(&scene, triangles).unwrap();
        let lean = build_for::<2>(&scene, triangles, true).unwrap();
        assert!(full.background.mesh().is_some() && lean.background.mesh().is_none());
        assert_eq!(full.seeds.position, lean.seeds.position, "{name}");
        assert_eq!(full.seeds.volume, lean.seeds.volume, "{name}");
        let (a, b) = (
            full.background.bounding_box(),
            lean.background.bounding_box(),
        );
        assert!(
            (a.0 - b.0).norm() < 1e-14 && (a.1 - b.1).norm() < 1e-14,
            "{name}"
        );
    }
    let scene = Scene::load("hydrostatic-column-3d").unwrap();
    let full = build::<3>(&scene, tetrahedra).unwrap();
    let lean = build_for::<3>(&scene, tetrahedra, true).unwrap();
    assert_eq!(full.seeds.position, lean.seeds.position);
    // A mesh kernel always gets its mesh.
    let meshed = build_for::<3>(&scene, tetrahedra, false).unwrap();
    assert_eq!(meshed.background.cell_count(), Some(5 * 5 * 22 * 6));
}

/// `[kernel] stencils = "factored"`: UMLS keeps each fit's weights and inverse moment
/// matrix instead of its entries, and the run is the stored-stencil run bit for bit, with
/// less than half the stored bytes (8 B per entry and 136 B per particle against 36 B per
/// entry, for about 30 entries).
#[test]
fn factored_umls_stencils_give_the_stored_run_in_less_memory() {
    let mut histories = Vec::new();
    let mut stored_bytes = Vec::new();
    for storage in ["store", "factored"] {
        let scene = Scene::load_with(
            "fluid-box-3d",
            &with_few_frames(vec![
                ("kernel.stencils".into(), format!("\"{storage}\"")),
                ("mesh.lattice.cells".into(), "[16, 16, 16]".into()),
                ("bodies.seeding.lattice".into(), "0.02".into()),
                // Thrown at the floor and a wall: particles cross faces and hit walls.
                ("bodies.velocity".into(), "[2.0, -3.0, 1.0]".into()),
                ("output.history_every".into(), "1".into()),
            ]),
        )
        .unwrap();
        let options = options(
            &format!("fluid-box-umls-{storage}"),
            Some(umls_runner::schema::KernelKind::Umls),
            Some(0.05),
        );
        let report = run(&scene, &options).unwrap();
        let s = &report.summary.to_json();
        assert_eq!(s["stencils"], storage, "{s}");
        assert_eq!(s["status"], "completed", "{s}");
        stored_bytes.push(s["engine_memory"]["stored_stencil_bytes"].as_f64().unwrap());
        histories.push(
            std::fs::read_to_string(options.out.as_deref().unwrap().join("history.csv")).unwrap(),
        );
    }
    assert!(histories[0].lines().count() > 200);
    assert_eq!(histories[0], histories[1]);
    assert!(
        stored_bytes[1] < 0.5 * stored_bytes[0],
        "factored {} B, stored {} B",
        stored_bytes[1],
        stored_bytes[0]
    );
}
