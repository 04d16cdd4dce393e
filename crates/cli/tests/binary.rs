//! The `umls` binary end to end: runs small scenes and reads every file it writes back
//! with independent parsers (vtkio, roxmltree, csv, serde_json).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::umls_within;
use vtkio::model::{Attribute, DataSet, Piece};

mod common;

fn umls(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_umls"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Runs `umls` and requires success, showing its stderr otherwise.
fn umls_ok(args: &[&str]) -> Output {
    let out = umls(args);
    assert!(
        out.status.success(),
        "`umls {}`: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("binary")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// Frames listed in particles.pvd, as (time, file).
fn frames(dir: &Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("DataSet"))
        .map(|n| {
            (
                n.attribute("timestep").unwrap().parse().unwrap(),
                n.attribute("file").unwrap().to_string(),
            )
        })
        .collect()
}

/// Point coordinates (3 per point) of a .vtu file.
fn points(path: &Path) -> Vec<f64> {
    let vtk = vtkio::Vtk::import(path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("not inline")
    };
    piece.points.into_vec::<f64>().unwrap()
}

/// Point count and point arrays (name → values) of a .vtu file.
fn point_arrays(path: &Path) -> (usize, Vec<(String, Vec<f64>)>) {
    let vtk = vtkio::Vtk::import(path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("not inline")
    };
    let n = piece.num_points();
    let arrays = piece
        .data
        .point
        .into_iter()
        .filter_map(|a| match a {
            Attribute::DataArray(d) => {
                let values = d.data.clone().into_vec::<f64>().or_else(|| {
                    d.data
                        .into_vec::<i32>()
                        .map(|v| v.into_iter().map(f64::from).collect())
                });
                values.map(|v| (d.name, v))
            }
            Attribute::Field { .. } => None,
        })
        .collect();
    (n, arrays)
}

fn history(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut reader = csv::Reader::from_path(dir.join("history.csv")).unwrap();
    let header = reader.headers().unwrap().iter().map(String::from).collect();
    let rows = reader
        .records()
        .map(|r| r.unwrap().iter().map(|f| f.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn vibrating_bar_writes_readable_files() {
    let dir = scratch("bar");
    let out = umls_ok(&[
        "run",
        "vibrating-bar",
        "--out",
        dir.to_str().unwrap(),
        "--end-time",
        "2.5",
        "--quiet",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("velocity_rmse"), "{stdout}");

    let s = summary(&dir);
    assert_eq!(s["status"], "completed");
    assert_eq!(s["steps"], 500);
    assert_eq!(s["particles"], 100);
    assert_eq!(s["kernel"], "umls");
    // Two throughputs, each what its name says: stepping alone, and the run loop's
    // wall time with the frames written (41 of them here, so the second is lower).
    let work = 100.0 * 500.0;
    let stepping = s["particle_steps_per_second"].as_f64().unwrap();
    let stage_total = s["stage_seconds"]["total"].as_f64().unwrap();
    assert!(
        (stepping * stage_total / work - 1.0).abs() < 1e-9,
        "{stepping}"
    );
    let walled = s["particle_steps_per_wall_second"].as_f64().unwrap();
    let wall = s["wall_time_s"].as_f64().unwrap();
    assert!((walled * wall / work - 1.0).abs() < 1e-9, "{walled}");
    assert!(walled < stepping, "{walled} ≥ {stepping}");
    let rmse = s["metrics"]["velocity_rmse"].as_f64().unwrap();
    assert!(rmse > 0.0 && rmse < 2e-3, "{rmse}");

    // 41 frames evenly over [0, 2.5], each at the step nearest its time (Δt = 0.005).
    let frames = frames(&dir);
    assert_eq!(frames.len(), 41);
    for (k, (t, _)) in frames.iter().enumerate() {
        assert!(
            (t - 2.5 * k as f64 / 40.0).abs() <= 0.0025 + 1e-9,
            "frame {k} at {t}"
        );
    }
    assert!((frames[40].0 - 2.5).abs() < 1e-9);
    // The last frame's velocities against the analytic solution at the particles'
    // initial positions (position − displacement).
    let (n, arrays) = point_arrays(&dir.join(&frames[40].1));
    assert_eq!(n, 100);
    let get = |name: &str| &arrays.iter().find(|(n, _)| n == name).unwrap().1;
    let (v, u) = (get("velocity"), get("displacement"));
    let x = points(&dir.join(&frames[40].1));
    let t = 2.5;
    for p in 0..n {
        let x0 = x[3 * p] - u[3 * p];
        let exact =
            0.1 * (std::f64::consts::PI * t / 5.0).cos() * (std::f64::consts::PI * x0 / 50.0).sin();
        assert!(
            (v[3 * p] - exact).abs() < 5e-3 * 0.1,
            "particle {p}: {} vs {exact}",
            v[3 * p]
        );
    }
    for field in [
        "cauchy_stress",
        "deformation_gradient",
        "jacobian",
        "mass",
        "material",
        "mean_stress",
    ] {
        assert!(arrays.iter().any(|(n, _)| n == field), "{field}");
    }

    let (header, rows) = history(&dir);
    assert_eq!(
        &header[..6],
        ["step", "time", "kinetic", "elastic", "potential", "total"]
    );
    assert_eq!(header.last().unwrap(), "velocity_error");
    assert_eq!(rows.len(), 501);
    assert!((rows[500][1] - 2.5).abs() < 1e-12);
    // Energy is nearly conserved: kinetic + elastic stays within 1 % of the start.
    let e0 = rows[0][5];
    assert!(rows.iter().all(|r| (r[5] - e0).abs() < 1e-2 * e0));

    // The energy plot is well-formed SVG with the three curves.
    let svg = std::fs::read_to_string(dir.join("energies.svg")).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    for label in ["kinetic", "elastic", "total"] {
        assert!(svg.contains(label), "{label}");
    }
    assert!(!svg.contains("potential"), "no gravity, no potential curve");

    let (nodes, mesh_arrays) = point_arrays(&dir.join("mesh.vtu"));
    assert_eq!(nodes, 109);
    let mass: f64 = mesh_arrays
        .iter()
        .find(|(n, _)| n == "node_mass")
        .unwrap()
        .1
        .iter()
        .sum();
    assert!(
        (mass - 50.0).abs() < 1e-9,
        "nodal mass {mass} = bar mass 50"
    );
}

#[test]
fn kernel_override_and_conservation() {
    for kernel in [
        "linear-fe",
        "bspline2",
        "bspline3",
        "umls-wide",
        "umls-paper",
        "umls-wendland",
        "umls-sharp",
        "umls-full-gradient",
        "umls-frozen-eta",
        "umls-uncorrected",
        "umls-eta4",
        "umls-eta8",
    ] {
        let dir = scratch(&format!("disks-{kernel}"));
        let out = umls(&[
            "run",
            "colliding-disks",
            "--kernel",
            kernel,
            "--out",
            dir.to_str().unwrap(),
            "--end-time",
            "0.02",
            "--threads",
            "1",
        ]);
        assert!(
            out.status.success(),
            "{kernel}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s = summary(&dir);
        assert_eq!(s["kernel"], kernel);
        assert_eq!(s["threads"], 1);
        // Grid kernels write their nodes with the nodal mass: all of the disks' mass.
        if kernel.starts_with("bspline") {
            assert_eq!(s["outputs"]["grid"], "grid.vtu");
            let (_, arrays) = point_arrays(&dir.join("grid.vtu"));
            let mass: f64 = arrays
                .iter()
                .find(|(n, _)| n == "node_mass")
                .unwrap()
                .1
                .iter()
                .sum();
            assert!(
                (mass - 416.0 * 0.025f64.powi(2) * 1000.0).abs() < 1e-9,
                "{kernel}: {mass}"
            );
        } else {
            assert!(s["outputs"]["grid"].is_null());
        }
        assert!(
            s["metrics"]["momentum_change"].as_f64().unwrap() < 1e-12,
            "{kernel}"
        );
        let (_, rows) = history(&dir);
        // Free flight: kinetic energy 2 × ½ · m · |v|² with m = 416/2 · 0.025² · 1000.
        let expected = 416.0 * 0.025f64.powi(2) * 1000.0 * 0.02 / 2.0;
        assert!((rows[0][2] - expected).abs() < 1e-12, "{}", rows[0][2]);
    }
}

#[test]
fn plastic_scene_file_on_a_grid_with_slip() {
    let dir = scratch("column");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("column.toml");
    std::fs::write(
        &file,
        r#"
[scene]
name = "sand-column"
dimension = 2
end_time = 0.05
gravity = [0.0, -9.81]

[mesh.lattice]
lower = [0.0, 0.0]
upper = [1.0, 0.5]
cells = [20, 10]

[kernel]
kind = "bspline2"

[transfer]
kind = "apic"

[time]
cfl = 0.4

[output]
frames = 3
encoding = "ascii"

[[materials]]
name = "sand"
model = "drucker-prager"
density = 1500.0
young = 1e6
poisson = 0.3
cohesion = 0.0
friction_angle = 30.0

[[materials]]
name = "block"
model = "neo-hookean"
density = 1000.0
young = 1e6
poisson = 0.3

[[bodies]]
material = "sand"
region = { box = { lower = [0.0, 0.0], upper = [0.2, 0.4] } }
seeding = { lattice = 0.025 }

[[bodies]]
material = "block"
region = { box = { lower = [0.6, 0.0], upper = [0.8, 0.1] } }
seeding = { lattice = 0.025 }

[[boundaries]]
kind = "slip"
plane = { point = [0.0, 0.0], normal = [0.0, -1.0] }

[[boundaries]]
kind = "slip"
plane = { point = [0.0, 0.0], normal = [-1.0, 0.0] }
"#,
    )
    .unwrap();
    umls_ok(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    let s = summary(&dir.join("out"));
    assert_eq!(s["kernel"], "bspline2");
    assert_eq!(s["materials"], serde_json::json!(["sand", "block"]));
    let frames = frames(&dir.join("out"));
    assert_eq!(frames.len(), 3);
    let (n, arrays) = point_arrays(&dir.join("out").join(&frames[2].1));
    assert_eq!(n, 8 * 16 + 8 * 4);
    let get = |name: &str| &arrays.iter().find(|(n, _)| n == name).unwrap().1;
    let (ids, strain, jp) = (
        get("material"),
        get("plastic_strain"),
        get("plastic_jacobian"),
    );
    // The sand column yields under its own weight; the elastic block never does.
    assert!(ids.iter().zip(strain).any(|(&id, &e)| id == 0.0 && e > 0.0));
    assert!(
        ids.iter()
            .zip(strain)
            .all(|(&id, &e)| id == 0.0 || e == 0.0)
    );
    assert!(ids.iter().zip(jp).all(|(&id, &j)| id == 0.0 || j == 1.0));
    // The column sinks under gravity, but no particle goes through the floor (slip plane
    // y = 0) or the wall (slip plane x = 0).
    assert!(get("displacement").chunks(3).any(|d| d[1] < -1e-4));
    let x = points(&dir.join("out").join(&frames[2].1));
    assert!(
        x.chunks(3).all(|p| p[0] > 0.0 && p[1] > 0.0),
        "a particle left the box"
    );
}

#[test]
fn scenes_and_help() {
    let out = umls(&["scenes"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // Every built-in scene, one line each, the summaries in one column.
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), umls_runner::builtin::BUILTIN.len());
    let mut columns = std::collections::BTreeSet::new();
    for (line, b) in lines.iter().zip(umls_runner::builtin::BUILTIN) {
        assert!(line.starts_with(&format!("{}  ", b.name)), "{text}");
        columns.insert(line.find(b.summary).expect("the summary is listed"));
    }
    assert_eq!(columns.len(), 1, "{text}");
    for args in [
        &["--help"][..],
        &["run", "--help"],
        &["scenes", "--help"],
        &["mesh-info", "--help"],
    ] {
        let out = umls(args);
        assert!(out.status.success(), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("Usage"),
            "{args:?}"
        );
    }
    let help = String::from_utf8_lossy(&umls(&["run", "--help"]).stdout).into_owned();
    for option in [
        "--kernel",
        "--out",
        "--end-time",
        "--threads",
        "linear-fe",
        "bspline3",
    ] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
}

#[test]
fn mesh_info_reports_and_fails_clearly() {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/fixtures/square-v41-binary.msh");
    let out = umls(&["mesh-info", fixture.to_str().unwrap()]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("31 vertices, 44 triangles"), "{text}");
    assert!(text.contains("\"left\""), "{text}");
    assert!(text.contains("total area: 1"), "{text}");

    let dir = scratch("bad-mesh");
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.msh");
    let good = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/fixtures/square-v22.msh"),
    )
    .unwrap();
    std::fs::write(&bad, good.replacen("$EndNodes", "$EndNode", 1)).unwrap();
    let out = umls(&["mesh-info", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line ") && err.contains("$EndNodes"), "{err}");
    assert!(err.contains("bad.msh"), "the file is named: {err}");

    // Two triangles on the unit square with the diagonal's end (1, 1) given twice: read
    // as written they would meet along a crack, so the reader refuses the file.
    let cracked = dir.join("cracked.msh");
    std::fs::write(
        &cracked,
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 1 1 0\n\
         4 0 1 0\n7 1 1 0\n$EndNodes\n$Elements\n2\n1 2 2 1 1 1 2 3\n2 2 2 1 1 1 7 4\n\
         $EndElements\n",
    )
    .unwrap();
    let out = umls(&["mesh-info", cracked.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cracked.msh") && err.contains("nodes 3 and 7 both lie at (1, 1)"),
        "{err}"
    );

    // A scene whose mesh file is missing names the scene, the key and the path.
    let scene = dir.join("scene.toml");
    let text = umls_runner::builtin::BUILTIN[2].toml.replacen(
        "file = \"meshes/cantilever.msh\"",
        "file = \"meshes/missing.msh\"",
        1,
    );
    assert!(text.contains("missing.msh"));
    std::fs::write(&scene, text).unwrap();
    let out = umls(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        dir.join("o").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("scene.toml") && err.contains("mesh.file") && err.contains("missing.msh"),
        "{err}"
    );
}

#[test]
fn bad_scene_names_and_keys_fail_clearly() {
    let out = umls(&["run", "no-such-scene"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("colliding-disks") && err.contains("vibrating-bar"),
        "{err}"
    );

    let dir = scratch("bad-key");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("typo.toml");
    let text = umls_runner::builtin::BUILTIN[0]
        .toml
        .replacen("[output]", "[output]\nframe = 3", 1);
    std::fs::write(&file, text).unwrap();
    let out = umls(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown field `frame`"), "{err}");
}

#[test]
fn an_unstable_run_leaves_its_history_and_says_why() {
    // Pure FLIP with huge time steps blows up; the files written so far stay.
    let dir = scratch("unstable");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("unstable.toml");
    let text = umls_runner::builtin::BUILTIN[0]
        .toml
        .replacen("dt = 1e-3", "dt = 0.2", 1)
        .replacen("alpha = 0.99", "alpha = 1.0", 1);
    std::fs::write(&file, text).unwrap();
    let out = umls(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("simulation stopped: step"), "{err}");
    let s = summary(&dir.join("out"));
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("step"));
    // The kind of failure is named for tables and stability maps: 200 times the stable
    // step is caught by the wave Courant check after the first step.
    assert_eq!(s["failure_kind"], "time-step-too-large");
    // The process measured its own peak memory (Linux reports it).
    if cfg!(target_os = "linux") {
        assert!(s["peak_memory_bytes"].as_u64().unwrap() > 1 << 20);
    }
    let (_, rows) = history(&dir.join("out"));
    assert!(!rows.is_empty());
    // The time step was 0.2 / 1e-3 = 200 times the one the scene is stable with: said
    // before the run, and in the summary.
    assert!(err.contains("warning: time.dt"), "{err}");
    assert_eq!(s["dt_exceeds_stable"], true);
    // The state the run stopped in is the last frame.
    let (time, _) = frames(&dir.join("out")).pop().unwrap();
    let stopped = rows.last().unwrap()[1];
    assert_eq!(time, stopped);
}

/// Starts a long run, sends it `signals` (one `kill` each) once it is stepping, and
/// checks that it stopped after its current step and still wrote the last state, the
/// mesh, the plot, the history and a summary saying "interrupted".
fn interrupted_by(name: &str, signals: &[&str]) {
    let dir = scratch(name);
    let mut child = Command::new(env!("CARGO_BIN_EXE_umls"))
        .args([
            "run",
            "steel-cantilever",
            "--end-time",
            "100",
            "--out",
            dir.to_str().unwrap(),
            "--quiet",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the run is stepping (its first frame is written), then interrupt it.
    let start = std::time::Instant::now();
    while !dir.join("particles_00000.vtu").exists() {
        assert!(
            start.elapsed() < std::time::Duration::from_secs(60),
            "the run never started"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    for signal in signals {
        let status = Command::new("kill")
            .args([*signal, child.id().to_string().as_str()])
            .status()
            .unwrap();
        assert!(status.success());
    }
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            panic!("the interrupted run did not stop");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("interrupted at t ="),
        "{signals:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = summary(&dir);
    assert_eq!(s["status"], "interrupted");
    let steps = s["steps"].as_u64().unwrap();
    assert!(steps > 0);
    for file in ["mesh.vtu", "energies.svg", "history.csv"] {
        assert!(dir.join(file).exists(), "{file}");
    }
    assert!(frames(&dir).len() >= 2);
    // The history reaches the step the run stopped at, one row per recorded step.
    let (_, rows) = history(&dir);
    assert!(!rows.is_empty(), "{signals:?}: empty history");
}

/// Ctrl-C (SIGINT) stops a run after the current step and still writes its output.
#[test]
fn an_interrupted_run_writes_its_output() {
    interrupted_by("interrupted", &["-INT"]);
}

/// SIGTERM, what a scheduler or `kill` sends, is handled like Ctrl-C.
#[test]
fn a_terminated_run_writes_its_output() {
    interrupted_by("terminated", &["-TERM"]);
}

/// An impatient second Ctrl-C still leaves the output and the summary.
#[test]
fn a_double_interrupt_still_writes_its_output() {
    interrupted_by("interrupted-twice", &["-INT", "-INT"]);
}

/// The quasi-static keys: a soft column on slip planes, loaded by a gravity ramp, damped,
/// with an adaptive time step; and the same column started at its geostatic stress.
#[test]
fn quasi_static_column_keys() {
    let column = |extra: &str, ramp: &str| {
        format!(
            r#"
[scene]
name = "column"
dimension = 2
end_time = 0.3
gravity = [0.0, -10.0]
{ramp}

[mesh.lattice]
lower = [0.0, 0.0]
upper = [1.0, 2.2]
cells = [10, 22]

[kernel]
kind = "bspline2"

[transfer]
kind = "pic"

[time]
cfl = 0.3
adaptive = true

[damping]
local = 0.7

[output]
frames = 2

[[materials]]
name = "soil"
model = "linear-elastic"
density = 1000.0
young = 1e6
poisson = 0.3

[[bodies]]
material = "soil"
region = {{ box = {{ lower = [0.0, 0.0], upper = [1.0, 2.0] }} }}
seeding = {{ lattice = 0.05 }}

[[boundaries]]
kind = "slip"
plane = {{ point = [0.0, 0.0], normal = [1.0, 0.0] }}

[[boundaries]]
kind = "slip"
plane = {{ point = [1.0, 0.0], normal = [1.0, 0.0] }}

[[boundaries]]
kind = "slip"
plane = {{ point = [0.0, 0.0], normal = [0.0, 1.0] }}
{extra}
"#
        )
    };
    let dir = scratch("quasi-static");
    std::fs::create_dir_all(&dir).unwrap();
    let run = |name: &str, text: String| {
        let file = dir.join(format!("{name}.toml"));
        std::fs::write(&file, text).unwrap();
        let out_dir = dir.join(name);
        umls_ok(&[
            "run",
            file.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ]);
        (summary(&out_dir), history(&out_dir))
    };
    let (ramped, (header, rows)) = run("ramped", column("", "gravity_ramp = 0.1"));
    assert_eq!(ramped["time_step"], "adaptive");
    assert_eq!(ramped["dt_exceeds_stable"], false);
    let column_of = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (courant, potential) = (column_of("wave_courant"), column_of("potential"));
    // Adaptive Δt keeps the wave Courant number at the requested 0.3 (the history's
    // value uses the speeds after the step, Δt those before it).
    assert!(
        rows.iter().all(|r| r[courant] <= 0.3 * (1.0 + 1e-3)),
        "{rows:?}"
    );
    // (The last step is shortened to end at end_time.)
    assert!(rows[..rows.len() - 1].iter().all(|r| r[courant] >= 0.29));
    // Gravity did work: the column settled (potential is minus that work).
    assert!(rows.last().unwrap()[potential] < 0.0);
    let (geostatic, (_, rows)) = run(
        "geostatic",
        column("[initial_stress]\ngeostatic_k0 = 0.4285714285714286\n", ""),
    );
    assert_eq!(geostatic["status"], "completed");
    let speed = header.iter().position(|h| h == "max_speed").unwrap();
    // Started at its weight's stress, the column barely moves; without it it falls
    // at g t until the base stops it.
    assert!(rows.iter().all(|r| r[speed] < 0.05), "{rows:?}");
}

/// Writes `text` as `name` in a fresh scratch directory whose `meshes/` holds the
/// umls-io Gmsh fixtures, and returns the scene path.
fn scene_with_fixtures(dir: &Path, name: &str, text: &str) -> PathBuf {
    let meshes = dir.join("meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    for f in ["cube-v41-binary.msh", "square-v22.msh"] {
        let from = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../io/tests/fixtures")
            .join(f);
        std::fs::copy(from, meshes.join(f)).unwrap();
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

const BLOCK: &str = r#"
[scene]
name = "block"
dimension = 3
end_time = 0.02
gravity = [0.0, 0.0, -9.81]

[mesh]
file = "meshes/cube-v41-binary.msh"

[time]
cfl = 0.3

[output]
interval = 0.01

[[materials]]
name = "rubber"
model = "neo-hookean"
density = 1000.0
young = 1e7
poisson = 0.3

[[bodies]]
material = "rubber"
region = { box = { lower = [0.25, 0.25, 0.0], upper = [0.75, 0.75, 0.5] } }
seeding = { lattice = 0.125 }

[[boundaries]]
kind = "slip"
group = "base"
"#;

#[test]
fn three_dimensional_gmsh_scene_with_group_slip() {
    // The same block with and without the slip condition on the mesh's `base` group.
    let mut momentum = Vec::new();
    for (name, text) in [
        ("supported", BLOCK.to_string()),
        (
            "falling",
            BLOCK.replace("[[boundaries]]\nkind = \"slip\"\ngroup = \"base\"\n", ""),
        ),
    ] {
        let dir = scratch(&format!("cube-{name}"));
        let file = scene_with_fixtures(&dir, "block.toml", &text);
        umls_ok(&[
            "run",
            file.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        let s = summary(&dir.join("out"));
        assert_eq!(
            (s["dimension"].as_u64(), s["particles"].as_u64()),
            (Some(3), Some(64))
        );
        // `interval = 0.01` over 0.02: three frames.
        assert_eq!(frames(&dir.join("out")).len(), 3);
        let (header, rows) = history(&dir.join("out"));
        assert_eq!(header[8], "momentum_z");
        let last = rows.last().unwrap();
        momentum.push((last[8], rows[0][9] * 9.81 * last[1]));
        let (nodes, arrays) = point_arrays(&dir.join("out").join("mesh.vtu"));
        let base = &arrays.iter().find(|(n, _)| n == "group base").unwrap().1;
        assert_eq!(base.len(), nodes);
        assert!(base.contains(&1.0));
    }
    // Free fall: p_z = −M g t to round-off. On the slip base the block rests; its vertical
    // momentum only oscillates with the elastic vibration (amplitude ≈ M g / ω, ω ≈ πc/2H).
    let (falling, free_fall) = momentum[1];
    assert!(
        (falling + free_fall).abs() < 1e-9 * free_fall,
        "{falling} vs −{free_fall}"
    );
    let (supported, _) = momentum[0];
    assert!(
        supported.abs() < 0.3 * free_fall,
        "p_z = {supported}, free fall −{free_fall}"
    );
}

#[test]
fn group_region_seeds_the_groups_cells() {
    let dir = scratch("square-group");
    let file = scene_with_fixtures(
        &dir,
        "square.toml",
        r#"
[scene]
name = "square"
dimension = 2
end_time = 0.001

[mesh]
file = "meshes/square-v22.msh"

[time]
dt = 1e-4

[output]
frames = 2

[[materials]]
name = "m"
model = "linear-elastic"
density = 2.0
young = 1.0
poisson = 0.2

[[bodies]]
material = "m"
region = { group = "domain" }
seeding = { mesh = "gauss2" }
velocity = ["y", "-x"]
"#,
    );
    umls_ok(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
        "--kernel",
        "linear-fe",
    ]);
    let s = summary(&dir.join("out"));
    // 44 triangles × 3 Gauss points; the mass is density × area.
    assert_eq!(s["particles"], 132);
    let (_, rows) = history(&dir.join("out"));
    assert!((rows[0][8] - 2.0).abs() < 1e-12, "mass {}", rows[0][8]);
    // A rigid rotation v = (y, −x) about the origin: kinetic energy ½ ρ ∫ |x|² = ρ/3 · … on
    // the unit square, ½ · 2 · ∫∫ (x² + y²) = 2/3; the degree-2 rule integrates it exactly.
    assert!(
        (rows[0][2] - 2.0 / 3.0).abs() < 1e-12,
        "kinetic {}",
        rows[0][2]
    );
}

/// Inputs that used to hang or name the wrong key: an infinite initial velocity, an
/// absurd thread count or end time, a Poisson ratio of 0.5, a friction angle in degrees,
/// a jitter too large, a directory given as scene. Each fails within a minute and says
/// what is wrong where.
#[test]
fn bad_values_fail_fast_and_name_their_key() {
    let dir = scratch("bad-values");
    std::fs::create_dir_all(&dir).unwrap();
    let disks = umls_runner::builtin::BUILTIN[0].toml;
    let edit = |find: &str, replace: &str| Some(disks.replacen(find, replace, 1));
    /// Case name, scene text (`None`: the directory itself), extra arguments, what the
    /// message must say, what it must not say.
    type Case<'a> = (
        &'a str,
        Option<String>,
        &'a [&'a str],
        &'a [&'a str],
        &'a [&'a str],
    );
    let cases: [Case; 8] = [
        (
            "infinite-velocity",
            edit("velocity = [0.1, 0.1]", "velocity = [\"1 / 0\", \"0\"]"),
            &[],
            &["bodies[0].velocity", "not finite"],
            &[],
        ),
        (
            "threads",
            Some(disks.to_string()),
            &["--threads", "100000"],
            &["--threads", "100000"],
            &[],
        ),
        (
            "poisson",
            edit("poisson = 0.3", "poisson = 0.5"),
            &[],
            &["materials[0].poisson", "0.5"],
            &["materials[0].young"],
        ),
        (
            "jitter",
            edit("jitter = 0.2", "jitter = 0.5"),
            &[],
            &["jitter", "[0, 0.45]"],
            &["MAX_JITTER"],
        ),
        ("directory", None, &[], &["is a directory"], &[]),
        (
            "end-time",
            edit("end_time = 3.0", "end_time = 1e12"),
            &[],
            &["scene.end_time", "steps"],
            &[],
        ),
        (
            // The angle as given, in degrees, under its own key.
            "friction",
            edit(
                "model = \"linear-elastic\"",
                "model = \"drucker-prager\"\ncohesion = 10.0\nfriction_angle = 95.0",
            ),
            &[],
            &["materials[0].friction_angle", "95", "90°"],
            &["1.658"],
        ),
        (
            // At a particle exactly on x = a the velocity is infinite; a rounding error
            // away it is 10¹⁷ m/s, which the stable-step check stops at once.
            "singular-velocity",
            edit(
                "velocity = [0.1, 0.1]",
                "velocity = [\"1 / (x - 0.2125)\", \"0\"]",
            ),
            &[],
            &[],
            &[],
        ),
    ];
    for (name, text, extra, says, never) in cases {
        let scene = match text {
            Some(text) => {
                let file = dir.join(format!("{name}.toml"));
                std::fs::write(&file, text).unwrap();
                file
            }
            None => dir.clone(),
        };
        let out_dir = dir.join(name);
        let mut args = vec![
            "run",
            scene.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--quiet",
        ];
        args.extend(extra);
        let out = umls_within(&args, std::time::Duration::from_secs(60));
        assert!(!out.status.success(), "{name} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        for s in says {
            assert!(err.contains(s), "{name}: no `{s}` in {err}");
        }
        for s in never {
            assert!(!err.contains(s), "{name}: `{s}` in {err}");
        }
        if name == "singular-velocity" {
            assert!(
                err.contains("bodies[0].velocity") || err.contains("exceeds the stable step"),
                "{err}"
            );
        }
    }
}

/// A body partly outside the mesh is clipped with a warning that says how much.
#[test]
fn a_clipped_body_is_reported() {
    let dir = scratch("clipped");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("clipped.toml");
    let text = umls_runner::builtin::BUILTIN[0].toml.replacen(
        "centre = [0.2, 0.2], radius = 0.2",
        "centre = [0.0, 0.2], radius = 0.2",
        1,
    );
    std::fs::write(&file, text).unwrap();
    let out = umls_ok(&[
        "run",
        file.to_str().unwrap(),
        "--end-time",
        "0.01",
        "--out",
        dir.join("out").to_str().unwrap(),
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning: bodies[0]") && err.contains("outside the mesh"),
        "{err}"
    );
    let s = summary(&dir.join("out"));
    let warnings = s["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("bodies[0]"))
    );
}

/// A run replaces what an earlier run left in its folder (stale frames, a B-spline
/// run's grid.vtu) and nothing else.
#[test]
fn a_run_clears_the_files_of_an_earlier_run() {
    let dir = scratch("stale");
    std::fs::create_dir_all(&dir).unwrap();
    for stale in ["particles_00099.vtu", "grid.vtu", "summary.json"] {
        std::fs::write(dir.join(stale), "stale").unwrap();
    }
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    std::fs::write(dir.join("particles_final.vtu"), "mine too").unwrap();
    umls_ok(&[
        "run",
        "vibrating-bar",
        "--kernel",
        "linear-fe",
        "--end-time",
        "0.05",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!dir.join("particles_00099.vtu").exists());
    assert!(!dir.join("grid.vtu").exists());
    assert_eq!(
        std::fs::read_to_string(dir.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(dir.join("particles_final.vtu").exists());
    let listed = frames(&dir).len();
    let written = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name().into_string().unwrap();
            name.starts_with("particles_0") && name.ends_with(".vtu")
        })
        .count();
    assert_eq!(listed, written);
    assert_eq!(summary(&dir)["status"], "completed");
}

/// 2D output carries the plane-strain state: F_zz = 1, σ_zz = ν (σ_xx + σ_yy) for linear
/// elasticity, and mean_stress = tr σ / 3 with that σ_zz.
#[test]
fn two_dimensional_tensors_are_plane_strain() {
    let dir = scratch("plane-strain");
    umls_ok(&[
        "run",
        "colliding-disks",
        "--end-time",
        "1.0",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ]);
    let (_, last) = frames(&dir).pop().unwrap();
    let (n, arrays) = point_arrays(&dir.join(last));
    let get = |name: &str| &arrays.iter().find(|(a, _)| a == name).unwrap().1;
    let (sigma, f, mean) = (
        get("cauchy_stress"),
        get("deformation_gradient"),
        get("mean_stress"),
    );
    let mut loaded = 0;
    for p in 0..n {
        let s = &sigma[9 * p..9 * p + 9];
        assert_eq!(f[9 * p + 8], 1.0);
        assert_eq!(
            (f[9 * p + 2], f[9 * p + 5], f[9 * p + 6], f[9 * p + 7]),
            (0.0, 0.0, 0.0, 0.0)
        );
        let in_plane = s[0] + s[4];
        assert!(
            (s[8] - 0.3 * in_plane).abs() <= 1e-12 * in_plane.abs().max(1e-300),
            "{s:?}"
        );
        assert!(
            (mean[p] - (s[0] + s[4] + s[8]) / 3.0).abs()
                <= 1e-12 * s[0].abs().max(s[4].abs()).max(1e-300)
        );
        loaded += usize::from(s[8] != 0.0);
    }
    // At t = 1 the disks are in contact: stressed particles exist.
    assert!(loaded > n / 10, "{loaded} of {n}");
}
