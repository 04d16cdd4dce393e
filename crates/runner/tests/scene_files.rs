//! Scene files: the built-in ones build the same particles and give the same results as
//! the same scenes built by hand from the engine; bad files fail naming the key.

use umls_engine::Apic;
use umls_kernels::{Umls1, Umls2};
use umls_runner::RunError;
use umls_runner::run::{RunOptions, run};
use umls_runner::scene::Scene;
use umls_runner::setup::{build, segments, triangles};

#[path = "common/by_hand.rs"]
mod by_hand;
use by_hand::Bar;

#[path = "common/runs.rs"]
mod runs;
use runs::variant_text;

fn options(name: &str, end_time: Option<f64>) -> RunOptions {
    RunOptions {
        out: Some(std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)),
        end_time,
        threads: Some(2),
        ..RunOptions::default()
    }
}

#[test]
fn disks_file_builds_the_hand_written_scene() {
    let scene = Scene::load("colliding-disks").unwrap();
    let setup = build::<2>(&scene, triangles).unwrap();
    let particles = by_hand::disks_particles::<()>();
    // The same lattice points, from different origins: equal to round-off, same order.
    assert_eq!(setup.seeds.position.len(), particles.position.len());
    let offset = setup
        .seeds
        .position
        .iter()
        .zip(&particles.position)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(offset < 1e-15, "{offset}");
    assert_eq!(setup.seeds.velocity, particles.velocity);
    assert_eq!(setup.seeds.mass, particles.mass);
    let mesh = setup.background.mesh().unwrap();
    let reference = by_hand::disks_mesh();
    assert_eq!(mesh.vertices(), reference.vertices());
    assert_eq!(mesh.connectivity(), reference.connectivity());
}

#[test]
fn disks_file_runs_like_the_hand_written_scene() {
    let scene = Scene::load("colliding-disks").unwrap();
    let report = run(&scene, &options("disks-file", Some(0.05))).unwrap();
    let mut sim = by_hand::disks(
        Umls2::new(by_hand::disks_mesh()),
        umls_engine::Flip { alpha: 0.99 },
    );
    for _ in 0..50 {
        sim.step().unwrap();
    }
    let d = sim.diagnostics().unwrap();
    let s = &report.summary.to_json();
    assert_eq!(s["steps"], 50);
    // Every stage is timed, inside the run's wall time, and the shares add up.
    assert_eq!(sim.stage_times().steps, 50);
    let stages = &s["stage_seconds"];
    let total = stages["total"].as_f64().unwrap();
    assert!(
        total > 0.0 && total <= s["wall_time_s"].as_f64().unwrap(),
        "{stages}"
    );
    let shares: f64 = stages["fractions"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_f64().unwrap())
        .sum();
    assert!((shares - 1.0).abs() < 1e-12, "{stages}");
    assert!(stages["stencils"].as_f64().unwrap() > 0.0);
    let final_energy = s["metrics"]["final_energy"].as_f64().unwrap();
    assert!(
        (final_energy - d.total_energy()).abs() < 1e-12 * d.total_energy(),
        "{final_energy} vs {}",
        d.total_energy()
    );
}

/// The command line runs PIC as FLIP with α = 0 (one simulation type fewer to compile):
/// the energies match the library's own PIC to round-off.
#[test]
fn pic_from_a_file_is_the_library_pic() {
    let text = umls_runner::builtin::BUILTIN[0].toml;
    let flip = "kind = \"flip\"\nalpha = 0.99";
    assert!(text.contains(flip));
    let scene = Scene::parse(&text.replacen(flip, "kind = \"pic\"", 1), "pic.toml", None).unwrap();
    let report = run(&scene, &options("disks-pic", Some(0.05))).unwrap();
    assert_eq!(report.summary.to_json()["transfer"], "pic");
    let mut sim = by_hand::disks(Umls2::new(by_hand::disks_mesh()), umls_engine::Pic);
    for _ in 0..50 {
        sim.step().unwrap();
    }
    let expected = sim.diagnostics().unwrap().total_energy();
    let found = report.summary.to_json()["metrics"]["final_energy"]
        .as_f64()
        .unwrap();
    assert!(
        (found - expected).abs() < 1e-12 * expected,
        "{found} vs {expected}"
    );
}

#[test]
fn bar_file_matches_the_hand_written_scene_error() {
    let scene = Scene::load("vibrating-bar").unwrap();
    let report = run(&scene, &options("bar-file", None)).unwrap();
    let file_rmse = report.summary.to_json()["metrics"]["velocity_rmse"]
        .as_f64()
        .unwrap();
    let bar = Bar {
        cells: 50,
        gradient_start: false,
    };
    let (steps, _) = bar.steps_and_dt();
    assert_eq!(report.summary.to_json()["steps"], steps);
    let expected = bar.velocity_rmse(Umls1::new(bar.mesh()), Apic);
    assert!(
        (file_rmse - expected).abs() < 1e-9 * expected,
        "{file_rmse} vs {expected}"
    );
    // Second-order UMLS on 50 cells: the error is small.
    assert!(file_rmse < 2e-3, "{file_rmse}");
}

/// `affine = "velocity-gradient"` starts a body's C_p at ∇v of its `velocity`: the bar
/// file's matrices are the hand-written scene's `AffineStart::VelocityGradient` ones and
/// its run gives that scene's error; in 2D a polynomial field's gradient comes out exact
/// (fourth-order differences), turned with the scene by `[transform]`, and only on the
/// body that asks; the key is refused without a velocity or with a transfer that has no
/// affine matrices.
#[test]
fn a_body_starts_its_affine_matrices_at_the_velocity_gradient() {
    let sine = r#"velocity = ["0.1 * sin(PI * x / 50)"]"#;
    let scene = with(
        "vibrating-bar",
        sine,
        &format!("{sine}\naffine = \"velocity-gradient\""),
    );
    let seeds = build::<1>(&scene, segments).unwrap().seeds;
    let bar = Bar {
        cells: 50,
        gradient_start: true,
    };
    let expected = bar.particles::<()>();
    let largest = expected.affine.iter().fold(0.0f64, |m, c| m.max(c.amax()));
    assert!(largest > 6e-3, "{largest}");
    // (x, C) pairs sorted by x: the comparison does not depend on the seeding order.
    let by_position = |x: &[nalgebra::Vector1<f64>], c: &[nalgebra::Matrix1<f64>]| {
        let mut pairs: Vec<(f64, f64)> = x.iter().zip(c).map(|(x, c)| (x[0], c[(0, 0)])).collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        pairs
    };
    let pairs = by_position(&seeds.position, &seeds.affine);
    let wanted = by_position(&expected.position, &expected.affine);
    assert_eq!(pairs.len(), wanted.len());
    for (got, want) in pairs.iter().zip(&wanted) {
        assert!((got.0 - want.0).abs() < 1e-12, "{got:?} {want:?}");
        assert!((got.1 - want.1).abs() < 1e-10 * largest, "{got:?} {want:?}");
    }
    let report = run(&scene, &options("bar-file-affine", None)).unwrap();
    let file_rmse = report.summary.to_json()["metrics"]["velocity_rmse"]
        .as_f64()
        .unwrap();
    let started = bar.velocity_rmse(Umls1::new(bar.mesh()), Apic);
    let zero = Bar {
        gradient_start: false,
        ..bar
    }
    .velocity_rmse(Umls1::new(bar.mesh()), Apic);
    assert!(
        (file_rmse - started).abs() < 1e-8 * started,
        "{file_rmse} vs {started}"
    );
    assert!((started - zero).abs() > 1e-3 * zero, "{started} vs {zero}");

    // 2D: a cubic field on the first disk, the scene turned by 90° about (0.5, 0.5).
    let mut text = variant_text(
        "colliding-disks",
        &[
            (r#"kind = "flip""#, r#"kind = "apic""#),
            (
                "velocity = [0.1, 0.1]",
                "velocity = [\"0.1 + x * y - 2 * y^2\", \"0.3 * x^3\"]\naffine = \"velocity-gradient\"",
            ),
        ],
    );
    text.push_str("\n[transform]\nrotation = 90.0\ncentre = [0.5, 0.5]\n");
    let scene = Scene::parse(&text, "affine.toml", None).unwrap();
    let seeds = build::<2>(&scene, triangles).unwrap().seeds;
    let turn = nalgebra::Matrix2::new(0.0, -1.0, 1.0, 0.0);
    let centre = nalgebra::Vector2::new(0.5, 0.5);
    let (mut first, mut second) = (0, 0);
    for (world, c) in seeds.position.iter().zip(&seeds.affine) {
        let x = turn.transpose() * (world - centre) + centre;
        if (x - nalgebra::Vector2::new(0.2, 0.2)).norm() < 0.21 {
            let gradient = nalgebra::Matrix2::new(x[1], x[0] - 4.0 * x[1], 0.9 * x[0] * x[0], 0.0);
            let want = turn * gradient * turn.transpose();
            assert!((c - want).amax() < 1e-9, "at {x}: {c} against {want}");
            first += 1;
        } else {
            assert_eq!(*c, nalgebra::Matrix2::zeros(), "second disk at {x}");
            second += 1;
        }
    }
    assert!(first > 100 && second > 100, "{first} {second}");

    // Refused, naming the key.
    let refused = |scene: Result<Scene, RunError>| {
        let message = match scene.and_then(|s| build::<1>(&s, segments).map(|_| ())) {
            Err(e) => e.to_string(),
            Ok(()) => panic!("accepted"),
        };
        assert!(message.contains("bodies[0].affine"), "{message}");
        message
    };
    let flip = variant_text(
        "vibrating-bar",
        &[
            (sine, &format!("{sine}\naffine = \"velocity-gradient\"")),
            (r#"kind = "apic""#, r#"kind = "flip""#),
        ],
    );
    assert!(refused(Scene::parse(&flip, "flip.toml", None)).contains("pic or flip"));
    let still = variant_text(
        "vibrating-bar",
        &[(sine, r#"affine = "velocity-gradient""#)],
    );
    assert!(refused(Scene::parse(&still, "still.toml", None)).contains("not given"));
}

fn with(text: &str, find: &str, replace: &str) -> Scene {
    Scene::parse(&variant_text(text, &[(find, replace)]), "edited.toml", None).unwrap()
}

fn message(scene_name: &str, find: &str, replace: &str) -> String {
    let builtin = umls_runner::builtin::BUILTIN
        .iter()
        .find(|b| b.name == scene_name)
        .unwrap();
    let text = builtin.toml.replacen(find, replace, 1);
    match Scene::parse(&text, "edited.toml", None) {
        Err(e) => e.to_string(),
        Ok(scene) => run(&scene, &options("bad", Some(0.01)))
            .map(|_| String::from("accepted"))
            .unwrap_or_else(|e| e.to_string()),
    }
}

#[test]
fn unknown_keys_are_named() {
    let m = message("colliding-disks", "young = 1000.0", "youngs = 1000.0");
    assert!(m.contains("unknown field `youngs`"), "{m}");
    assert!(m.starts_with("edited.toml"), "{m}");
    let m = message("colliding-disks", "[time]", "[time]\ndtt = 1");
    assert!(m.contains("unknown field `dtt`"), "{m}");
}

#[test]
fn bad_values_name_their_key() {
    for (scene, find, replace, key) in [
        (
            "vortex",
            "s = \"r - 1\"",
            "s = \"h - 1\"",
            "`definitions.h`",
        ),
        ("vortex", "b_r = \"-r", "b_r = \"q - r", "`definitions.b_r`"),
        (
            "vortex",
            "acceleration = [\"cos_a",
            "acceleration = [\"1 / 0 + cos_a",
            "`body_force.acceleration`",
        ),
        (
            "vortex",
            "displacement = [\"x",
            "displacement = [\"w + x",
            "`reference.displacement`",
        ),
        (
            "cantilever",
            "kind = \"fixed\"",
            "kind = \"slip\"",
            "`boundaries[0].normal`",
        ),
        (
            "cantilever",
            "upper = [0.0, 10.0] } }",
            "upper = [-9.0, -9.0] } }",
            "`boundaries[0].region`",
        ),
        (
            "cantilever",
            "spacing = 0.125,",
            "spacing = 0.0,",
            "`bodies[0].seeding.lattice-from.spacing`",
        ),
        (
            "cantilever",
            "file = \"data/cantilever-tip.csv\"",
            "file = \"data/cantilever-tip.csv\"\nprobe = 1",
            "`reference.probe.probe`",
        ),
        (
            "cantilever",
            "file = \"data/cantilever-tip.csv\"",
            "file = \"data/missing.csv\"",
            "`reference.probe.file`",
        ),
        (
            "cantilever",
            "rotation = 0.0",
            "rotation = 0.0\naxis = [0.0, 0.0, 1.0]",
            "`mesh.transform.axis`",
        ),
        (
            "hydrostatic-column-tilted",
            "rotation = 30.0",
            "rotation = 30.0\naxis = [0.0, 0.0, 1.0]",
            "`transform.axis`",
        ),
        (
            "hydrostatic-column-3d",
            "[reference.hydrostatic]",
            "[transform]\nrotation = 10.0\naxis = [0.0, 0.0, 0.0]\n\n[reference.hydrostatic]",
            "`transform.axis`",
        ),
        (
            "hydrostatic-column",
            "base = 0.0",
            "base = 4.5",
            "`reference.hydrostatic.surface`",
        ),
        (
            "hydrostatic-column",
            "base = 0.0",
            "base = 0.0\nmargin = 2.5",
            "`reference.hydrostatic.margin`",
        ),
        (
            "hydrostatic-column",
            "surface = 4.0",
            "surface = 8.0",
            "`reference.hydrostatic.row`",
        ),
        (
            "hydrostatic-column",
            "model = \"linear-elastic\"\ndensity = 1000.0\nyoung = 1e8\npoisson = 0.3",
            "model = \"drucker-prager\"\ndensity = 1000.0\nyoung = 1e8\npoisson = 0.3\ncohesion = 500.0\nfriction_angle = 20.0",
            "`reference.hydrostatic`",
        ),
        (
            "hydrostatic-column",
            "[reference.hydrostatic]\nsurface = 4.0\nbase = 0.0",
            "[reference]\nscale = 2.0",
            "`reference`",
        ),
        (
            "colliding-disks",
            "material = \"elastic\"",
            "material = \"steel\"",
            "`bodies[0].material`",
        ),
        (
            "colliding-disks",
            "dt = 1e-3",
            "dt = 1e-3\ncfl = 0.5",
            "`time`",
        ),
        (
            "colliding-disks",
            "velocity = [0.1, 0.1]",
            "velocity = [0.1]",
            "`bodies[0].velocity`",
        ),
        (
            "colliding-disks",
            "velocity = [0.1, 0.1]",
            "velocity = [\"q * 2\", 0]",
            "`bodies[0].velocity`",
        ),
        (
            "colliding-disks",
            "young = 1000.0\n",
            "",
            "missing field `young`",
        ),
        (
            "colliding-disks",
            "model = \"linear-elastic\"",
            "model = \"jelly\"",
            "unknown variant `jelly`, expected one of `linear-elastic`",
        ),
        // A key of another model is an error, not ignored.
        (
            "colliding-disks",
            "young = 1000.0",
            "young = 1000.0\nyield_stress = 5.0",
            "unknown field `yield_stress`, expected one of `name`, `density`, `young`, `poisson`",
        ),
        (
            "colliding-disks",
            "diagonal = \"alternating\"",
            "diagonal = \"diagonal\"",
            "unknown variant `diagonal`, expected one of `right`, `left`, `alternating`, `crossed`",
        ),
        (
            "colliding-disks",
            "[time]",
            "[time]\nstress_update = \"usf\"",
            "unknown variant `usf`, expected `usl` or `musl`",
        ),
        (
            "colliding-disks",
            "[output]",
            "[output]\nencoding = \"base64\"",
            "unknown variant `base64`, expected `binary` or `ascii`",
        ),
        (
            "vibrating-bar",
            "seeding = { mesh = \"centroid\" }",
            "seeding = { mesh = \"gauss3\" }",
            "unknown variant `gauss3`, expected `centroid` or `gauss2`",
        ),
        (
            "colliding-disks",
            "poisson = 0.3",
            "poisson = 0.5",
            "`materials[0].poisson`",
        ),
        (
            "colliding-disks",
            "jitter = 0.2",
            "jitter = 0.6",
            "`mesh.lattice`",
        ),
        (
            "colliding-disks",
            "alpha = 0.99",
            "alpha = 1.5",
            "`transfer.alpha`",
        ),
        (
            "colliding-disks",
            "radius = 0.2 } }\nseeding",
            "radius = 0.0 } }\nseeding",
            "`bodies[0].region`",
        ),
        (
            "vibrating-bar",
            "model = \"linear-elastic\"",
            "model = \"von-mises\"\nyield_stress = 1.0",
            "`materials`",
        ),
        (
            "vibrating-bar",
            "scale = 0.1",
            "scale = -1.0",
            "`reference.scale`",
        ),
        (
            "vibrating-bar",
            "velocity_time = \"mid-step\"",
            "velocity_time = \"midstep\"",
            "unknown variant `midstep`, expected `end` or `mid-step`",
        ),
        // The time a velocity is compared at needs the velocity.
        (
            "vibrating-bar",
            "velocity = [\"0.1 * cos(PI * t / 5) * sin(PI * x / 50)\"]\nscale = 0.1",
            "displacement = [\"0\"]",
            "`reference.velocity_time`",
        ),
        (
            "steel-cantilever",
            "group = \"wall\"",
            "group = \"floor\"",
            "`boundaries[0].group`",
        ),
        (
            "colliding-disks",
            "lattice = 0.025",
            "lattice = 1e-9",
            "`bodies[0].seeding.lattice`",
        ),
        (
            "colliding-disks",
            "cells = [20, 20]",
            "cells = [0, 20]",
            "`mesh.lattice`",
        ),
        (
            "colliding-disks",
            "kind = \"umls\"",
            "kind = \"bspline2\"\ngrid_spacing = 1e-9",
            "`kernel.grid_spacing`",
        ),
        (
            "colliding-disks",
            "frames = 61",
            "frames = 61\ninterval = 0.1",
            "`output`",
        ),
        (
            "colliding-disks",
            "seeding = { lattice = 0.025 }",
            "seeding = { lattice = 0.025 }\njitter = { amount = 1.5 }",
            "`bodies[0].jitter.amount`",
        ),
        (
            "vortex",
            "seeding = { lattice = 0.05 }",
            "seeding = { mesh = \"centroid\" }\njitter = { amount = 0.5 }",
            "`bodies[0].jitter`",
        ),
    ] {
        let m = message(scene, find, replace);
        assert!(m.contains(key), "{scene}: `{replace}` gave: {m}");
        // Errors the TOML reader finds also point at the line.
        if key.starts_with("unknown") || key.starts_with("missing") {
            assert!(m.contains("edited.toml: TOML parse error at line"), "{m}");
        }
    }
}

#[test]
fn group_conditions_reach_grid_kernels_as_a_collider() {
    // The clamp is the mesh's edge x = 0: a grid fixes its nodes on or beyond it (the
    // group's signed-distance collider), and particles that cross it are put back. It
    // carries the beam as a clamp: the mean clamp force over the first 0.2 s is upward,
    // the beam's momentum never exceeds a quarter of a free fall's M g t (a rod turning
    // about a frictionless hinge reaches 0.75 of it), and by 0.2 s, past half the first
    // period of 0.37 s, the beam has turned back: its momentum is below a tenth of the
    // free fall's.
    let text = umls_runner::builtin::BUILTIN
        .iter()
        .find(|b| b.name == "steel-cantilever")
        .unwrap()
        .toml
        .replacen("kind = \"umls\"", "kind = \"bspline2\"", 1);
    let scene = Scene::parse(&text, "edited.toml", None).unwrap();
    let report = run(&scene, &options("cantilever-bspline", Some(0.2))).unwrap();
    let text = std::fs::read_to_string(report.out.as_deref().unwrap().join("history.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (force, momentum) = (column("reaction0_y"), column("momentum_y"));
    let mean_force = rows[1..].iter().map(|r| r[force]).sum::<f64>() / (rows.len() - 1) as f64;
    assert!(mean_force > 0.0, "{mean_force}");
    let free_fall = 400.0 * 9.81 * 0.2;
    let deepest = rows.iter().map(|r| r[momentum]).fold(0.0, f64::min);
    assert!(
        deepest < 0.0 && -deepest < 0.25 * free_fall,
        "{deepest} vs {free_fall}"
    );
    let last = rows.last().unwrap()[momentum];
    assert!(last.abs() < 0.1 * free_fall, "{last} vs {free_fall}");
    // A group the mesh does not have is still an error naming the key.
    let scene = with("steel-cantilever", "group = \"wall\"", "group = \"floor\"");
    let err = run(&scene, &options("cantilever-bspline-floor", Some(1e-3))).unwrap_err();
    assert!(
        matches!(&err, RunError::SceneValue { key, .. } if key == "boundaries[0].group"),
        "{err}"
    );
}

/// `jitter` moves each lattice particle within its cell by at most amount × h / 2 per
/// axis, keeps the body's particles, volumes and order, and follows its seed.
#[test]
fn jitter_moves_lattice_particles_within_their_cells() {
    let seeds = |replace: &str| {
        let scene = with("vortex", "seeding = { lattice = 0.05 }", replace);
        build::<2>(&scene, triangles).unwrap().seeds
    };
    let plain = seeds("seeding = { lattice = 0.05 }");
    let jittered = seeds("seeding = { lattice = 0.05 }\njitter = { amount = 0.5, seed = 3 }");
    assert_eq!(plain.position.len(), jittered.position.len());
    assert_eq!(plain.volume, jittered.volume);
    let largest = plain
        .position
        .iter()
        .zip(&jittered.position)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);
    // The bound is 0.5 × 0.05 / 2; 2520 offset components nearly reach it.
    assert!(largest <= 0.0125 && largest > 0.012, "{largest}");
    let other = seeds("seeding = { lattice = 0.05 }\njitter = { amount = 0.5, seed = 4 }");
    assert_ne!(jittered.position, other.position);
    let again = seeds("seeding = { lattice = 0.05 }\njitter = { amount = 0.5, seed = 3 }");
    assert_eq!(jittered.position, again.position);
}
