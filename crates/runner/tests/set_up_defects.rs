//! Set-up and summary defects found by trying scenes as a user would, each held fixed:
//! a lattice refused alike whatever the kernel, the warning for linear elements with
//! one particle per simplex, the largest wave Courant number counting the step the
//! guard refused, the guard as a scene key, and a failed run's energy error on the scale
//! of the energy put in.

use umls_engine::EngineError;
use umls_runner::RunError;
use umls_runner::run::{RunOptions, run};
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;
use umls_runner::setup::{build, triangles};

fn edited(name: &str, edits: &[(&str, &str)]) -> Scene {
    let edits: Vec<(String, String)> = edits
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    Scene::load_with(name, &edits).unwrap()
}

fn options(kernel: KernelKind) -> RunOptions {
    RunOptions {
        kernel: Some(kernel),
        end_time: Some(0.01),
        threads: Some(1),
        ..RunOptions::default()
    }
}

/// `summary.json` of a run written to `out`.
fn summary_in(out: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// A jitter beyond the generator's bound was accepted with a grid kernel (which takes
/// the lattice's box without splitting it) and refused with a mesh kernel: now both
/// refuse it with the same message, and both accept 0.2 and the 2D bound, 0.45.
#[test]
fn a_lattice_is_refused_alike_whatever_the_kernel() {
    let too_much = edited("colliding-disks", &[("mesh.lattice.jitter", "0.5")]);
    let messages: Vec<String> = [KernelKind::Umls, KernelKind::Bspline2, KernelKind::Ugimp]
        .into_iter()
        .map(|kernel| match run(&too_much, &options(kernel)) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{} accepted jitter 0.5", kernel.name()),
        })
        .collect();
    assert!(messages[0].contains("mesh.lattice") && messages[0].contains("jitter"));
    assert!(messages.iter().all(|m| *m == messages[0]), "{messages:?}");
    let allowed = edited("colliding-disks", &[("mesh.lattice.jitter", "0.2")]);
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        run(&allowed, &options(kernel)).unwrap();
    }
    // At 0.45 the lattice is accepted alike; slivers may then make the scene's Δt exceed
    // a mesh kernel's stable step, which the run reports as such, not as the lattice.
    let slivers = edited("colliding-disks", &[("mesh.lattice.jitter", "0.45")]);
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        if let Err(e) = run(&slivers, &options(kernel)) {
            let e = e.to_string();
            assert!(!e.contains("mesh.lattice"), "{}: {e}", kernel.name());
        }
    }
}

/// The disks' lattice of 0.025 puts two particles in each triangle of 0.05 cells; at
/// 0.05 it puts half of one. Linear elements are warned about there, and only there;
/// the warning reaches the summary.
#[test]
fn linear_elements_with_one_particle_per_simplex_are_warned_about() {
    let warned = |scene: &Scene, kernel: KernelKind| {
        let report = run(scene, &options(kernel)).unwrap();
        report
            .summary
            .warnings
            .iter()
            .any(|w| w.contains("particles per simplex"))
    };
    let sparse = edited(
        "colliding-disks",
        &[
            ("bodies.0.seeding", "{ lattice = 0.05 }"),
            ("bodies.1.seeding", "{ lattice = 0.05 }"),
        ],
    );
    let setup = build::<2>(&sparse, triangles).unwrap();
    assert!(!setup.warnings.iter().any(|w| w.contains("per simplex")));
    assert!(warned(&sparse, KernelKind::LinearFe));
    assert!(!warned(&sparse, KernelKind::Umls));
    let dense = Scene::load("colliding-disks").unwrap();
    assert!(!warned(&dense, KernelKind::LinearFe));
}

/// `max_wave_courant` in the summary used to be the largest of the recorded rows, which
/// leave out the step the guard refused: a run stopped at 1.003 reported 0.955. It is now
/// what the guard measured, the refused step included.
#[test]
fn the_largest_wave_courant_number_counts_the_refused_step() {
    // The bar's stable step is about h / c = 0.5 / 10 = 0.05; Δt = 1/17.
    let scene = edited("vibrating-bar", &[("time.dt", "0.06")]);
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("refused-step");
    let options = RunOptions {
        out: Some(out.clone()),
        end_time: Some(1.0),
        ..options(KernelKind::LinearFe)
    };
    let refused = match run(&scene, &options) {
        Err(RunError::Engine(EngineError::TimeStepTooLarge { wave_courant, .. })) => wave_courant,
        other => panic!("expected the guard to stop the run: {other:?}"),
    };
    assert!(refused > 1.0, "{refused}");
    let summary = summary_in(&out);
    let reported = summary["max_wave_courant"].as_f64().unwrap();
    assert_eq!(reported, refused, "{summary}");
}

/// The guard is a scene key: the step the default refuses runs with
/// `time.max_wave_courant` raised, and a non-positive limit is refused by name.
#[test]
fn the_guard_is_a_scene_key() {
    let short = RunOptions {
        end_time: Some(0.3),
        ..options(KernelKind::LinearFe)
    };
    let refused = edited("vibrating-bar", &[("time.dt", "0.06")]);
    assert!(matches!(
        run(&refused, &short),
        Err(RunError::Engine(EngineError::TimeStepTooLarge { .. }))
    ));
    for limit in ["2.0", "inf"] {
        let raised = edited(
            "vibrating-bar",
            &[("time.dt", "0.06"), ("time.max_wave_courant", limit)],
        );
        let report = run(&raised, &short).unwrap();
        assert_eq!(report.summary.steps, 5, "{limit}");
        assert!(report.summary.max_wave_courant > 1.0, "{limit}");
    }
    let zero = edited("vibrating-bar", &[("time.max_wave_courant", "0.0")]);
    let message = run(&zero, &short).unwrap_err().to_string();
    assert!(message.contains("time.max_wave_courant"), "{message}");
}

/// A run that blows up: its energy error is on the scale of the energy put in, as the
/// engine's blow-up check measures it. On the largest mechanical energy, the blown-up
/// state's own, it read 0.715 for an energy 34 times the initial.
#[test]
fn a_failed_run_reports_its_energy_error_on_the_scale_of_the_energy_put_in() {
    // The guard switched off and Δt 6 times the stable step: the bar's highest mode
    // grows until the energy check stops the run (at step 19, past 10 times the energy
    // put in; on the blown-up scale the error read 0.91).
    let scene = edited(
        "vibrating-bar",
        &[("time.dt", "0.3"), ("time.max_wave_courant", "inf")],
    );
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("blown-up");
    let options = RunOptions {
        out: Some(out.clone()),
        end_time: Some(10.0),
        ..options(KernelKind::LinearFe)
    };
    let error = run(&scene, &options).unwrap_err();
    assert!(
        matches!(error, RunError::Engine(EngineError::EnergyBlowUp { .. })),
        "{error}"
    );
    let summary = summary_in(&out);
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let (kinetic, elastic, total) = (column("kinetic"), column("elastic"), column("total"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let stopped = rows.last().unwrap();
    // The bar has no external forces: the energy put in is the initial energy.
    let supplied = rows[0][kinetic] + rows[0][elastic];
    let change = rows
        .iter()
        .map(|r| (r[total] - rows[0][total]).abs())
        .fold(0.0, f64::max);
    let reported = summary["metrics"]["energy_error"].as_f64().unwrap();
    assert!(stopped[total] > 10.0 * rows[0][total], "{stopped:?}");
    assert!(
        (reported - change / supplied).abs() < 1e-12 * reported,
        "{reported}"
    );
    assert!(reported > 9.0, "{reported}");
    // The final change is on the same scale.
    let final_change = summary["metrics"]["energy_change_final"].as_f64().unwrap();
    let expected = (stopped[total] - rows[0][total]) / supplied;
    assert!(
        (final_change - expected).abs() < 1e-12 * expected,
        "{final_change}"
    );
}
