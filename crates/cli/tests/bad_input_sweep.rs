//! A sweep of bad input through the same paths a user takes: broken TOML, bad
//! expressions, bad command-line arguments, hostile mesh files and unwritable output
//! folders (every number of the built-in scenes replaced by hostile values is in
//! `scene_fuzz.rs`). Nothing may panic or
//! hang (every binary run has a time limit), and every message names where the problem
//! is: the file and line, or the key.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Duration;

use umls_runner::builtin::BUILTIN;

mod common;

const LIMIT: Duration = Duration::from_secs(60);

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("sweep")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `umls` with the sweep's time limit.
fn umls(args: &[&str]) -> Output {
    common::umls_within(args, LIMIT)
}

/// A failed run: non-zero status, no panic, and the message of stderr.
fn failure(args: &[&str]) -> String {
    let out = umls(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "`umls {}` succeeded", args.join(" "));
    assert!(
        !err.contains("panicked"),
        "`umls {}` panicked: {err}",
        args.join(" ")
    );
    assert!(
        err.starts_with("error:") || err.contains("\nerror:"),
        "{err}"
    );
    err
}

fn disks() -> &'static str {
    BUILTIN
        .iter()
        .find(|b| b.name == "colliding-disks")
        .unwrap()
        .toml
}

fn run_scene(dir: &Path, name: &str, text: &str, extra: &[&str]) -> String {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let out = dir.join(format!("{name}-out"));
    let mut args = vec![
        "run",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--end-time",
        "0.01",
    ];
    args.extend(extra);
    failure(&args)
}

#[test]
fn broken_toml_names_file_and_line() {
    let dir = scratch("toml");
    // The parser names the line of the broken header.
    let line_of = |header: &str| {
        let line = disks()
            .lines()
            .position(|l| l == header)
            .expect("the header")
            + 1;
        format!("line {line}")
    };
    let (unclosed, not_toml) = (line_of("[time]"), line_of("[scene]"));
    for (name, find, replace, says) in [
        ("unclosed", "[time]", "[time", unclosed.as_str()),
        (
            "duplicate",
            "dt = 1e-3",
            "dt = 1e-3\ndt = 2e-3",
            "duplicate key",
        ),
        (
            "type",
            "end_time = 3.0",
            "end_time = \"long\"",
            "invalid type",
        ),
        (
            "missing-table",
            "[time]\ndt = 1e-3",
            "",
            "missing field `time`",
        ),
        ("not-toml", "[scene]", "\u{0}\u{1}binary", not_toml.as_str()),
        ("array", "cells = [20, 20]", "cells = 20", "invalid type"),
    ] {
        assert!(disks().contains(find), "{find}");
        let err = run_scene(&dir, name, &disks().replacen(find, replace, 1), &[]);
        assert!(err.contains(&format!("{name}.toml")), "{name}: {err}");
        assert!(err.contains(says), "{name}: no `{says}` in {err}");
        assert!(err.contains("line"), "{name}: no line in {err}");
    }
}

#[test]
fn bad_expressions_name_the_body() {
    let dir = scratch("expressions");
    for (name, expression) in [
        ("division", "1 / 0"),
        ("root", "sqrt(-1 - x)"),
        ("syntax", "x +"),
        ("function", "foo(x)"),
        ("variable", "t * 2"),
        ("overflow", "1e400"),
        ("parens", "((x)"),
    ] {
        let text = disks().replacen(
            "velocity = [0.1, 0.1]",
            &format!("velocity = [\"{expression}\", 0]"),
            1,
        );
        let err = run_scene(&dir, name, &text, &[]);
        assert!(err.contains("bodies[0].velocity"), "{name}: {err}");
    }
}

#[test]
fn bad_command_lines_fail_with_usage() {
    let dir = scratch("arguments");
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    for (args, says) in [
        (vec!["run"], "SCENE"),
        (
            vec!["run", "colliding-disks", "--threads", "0"],
            "--threads",
        ),
        (vec!["run", "colliding-disks", "--threads", "-2"], "-2"),
        (
            vec!["run", "colliding-disks", "--threads", "100000"],
            "--threads",
        ),
        (
            vec!["run", "colliding-disks", "--end-time=-1", "--out", out],
            "end",
        ),
        (
            vec!["run", "colliding-disks", "--end-time", "nan", "--out", out],
            "end",
        ),
        (
            vec!["run", "colliding-disks", "--kernel", "quartic"],
            "quartic",
        ),
        (
            vec!["run", "colliding-disks", "--frobnicate"],
            "--frobnicate",
        ),
        (vec!["run", "no-such-scene"], "no-such-scene"),
        (
            vec![
                "run",
                "colliding-disks",
                "--set",
                "transfer.alpha=1.5",
                "--out",
                out,
            ],
            "transfer.alpha",
        ),
        (
            // MLS-MPM needs D_p⁻¹, which linear elements do not have at their vertices.
            vec![
                "run",
                "colliding-disks",
                "--kernel",
                "linear-fe",
                "--set",
                "transfer.kind=mls-mpm",
                "--out",
                out,
            ],
            "transfer.kind",
        ),
        (
            vec![
                "run",
                "colliding-disks",
                "--set",
                "transfer.kind=apic-flip",
                "--set",
                "transfer.alpha=-0.5",
                "--out",
                out,
            ],
            "transfer.alpha",
        ),
        (
            vec![
                "run",
                "cantilever",
                "--set",
                "boundaries.0.kind=\"slip\"",
                "--set",
                "boundaries.0.normal=[1.0, 0.0]",
                "--set",
                "boundaries.0.imposed=\"fit\"",
                "--out",
                out,
            ],
            "boundaries[0].imposed",
        ),
        (
            vec![
                "run",
                "hydrostatic-column",
                "--set",
                "boundaries.0.imposed=\"fit\"",
                "--out",
                out,
            ],
            "boundaries[0].imposed",
        ),
        (
            vec![
                "run",
                "cantilever",
                "--set",
                "boundaries.0.penalty=1e4",
                "--out",
                out,
            ],
            "boundaries[0].penalty",
        ),
        (
            vec![
                "run",
                "cantilever",
                "--set",
                "boundaries.0.imposed=\"face\"",
                "--set",
                "boundaries.0.penalty=-1.0",
                "--out",
                out,
            ],
            "boundaries[0].penalty",
        ),
        (
            vec![
                "run",
                "cantilever",
                "--set",
                "boundaries.0.imposed=\"face\"",
                "--set",
                "boundaries.0.region.box.upper=[-2.0, 10.0]",
                "--out",
                out,
            ],
            "boundaries[0].imposed",
        ),
        (vec!["mesh-info"], "FILE"),
        (vec!["mesh-info", "/no/such/file.msh"], "/no/such/file.msh"),
        (vec!["launch"], "launch"),
    ] {
        let err = failure(&args);
        assert!(err.contains(says), "{args:?}: no `{says}` in {err}");
    }
}

/// Mesh files a user (or an attacker) might hand over: each fails at once with the file
/// and the line, and none makes the reader allocate what the file claims.
#[test]
fn hostile_mesh_files_name_file_and_line() {
    let dir = scratch("meshes");
    let header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    let triangle_elements = "$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n";
    for (name, text, line) in [
        ("empty", String::new(), "line 1"),
        ("binary", "garbage\u{0}\u{7f}\u{1b}".to_string(), "line 1"),
        (
            "version",
            "$MeshFormat\n5.0 0 8\n$EndMeshFormat\n".to_string(),
            "line 2",
        ),
        (
            "huge-count",
            format!("{header}$Nodes\n99999999999\n1 0 0 0\n$EndNodes\n"),
            "line 5",
        ),
        (
            "negative-count",
            format!("{header}$Nodes\n-3\n$EndNodes\n"),
            "line 5",
        ),
        (
            "truncated",
            format!("{header}$Nodes\n3\n1 0 0 0\n2 1 0"),
            "line 5",
        ),
        (
            "missing-node",
            format!(
                "{header}$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n1 2 2 0 1 1 2 7\n$EndElements\n"
            ),
            "line 12",
        ),
        (
            "nan-coordinate",
            format!(
                "{header}$Nodes\n3\n1 nan 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n{triangle_elements}"
            ),
            "line",
        ),
        (
            "no-elements",
            format!("{header}$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"),
            "$Elements",
        ),
    ] {
        let file = dir.join(format!("{name}.msh"));
        std::fs::write(&file, &text).unwrap();
        let err = failure(&["mesh-info", file.to_str().unwrap()]);
        assert!(err.contains(&format!("{name}.msh")), "{name}: {err}");
        assert!(err.contains(line), "{name}: no `{line}` in {err}");
        // The same file as a scene's mesh: the message adds the scene and its key.
        let scene = format!(
            "[scene]\nname = \"m\"\ndimension = 2\nend_time = 0.01\n[mesh]\nfile = \"{name}.msh\"\n[time]\ndt = 1e-3\n[[materials]]\nname = \"a\"\nmodel = \"linear-elastic\"\ndensity = 1.0\nyoung = 1.0\npoisson = 0.3\n[[bodies]]\nmaterial = \"a\"\nseeding = {{ mesh = \"centroid\" }}\n"
        );
        let err = run_scene(&dir, &format!("scene-{name}"), &scene, &[]);
        assert!(
            err.contains(&format!("{name}.msh")),
            "scene with {name}: {err}"
        );
        assert!(err.contains("mesh.file"), "scene with {name}: {err}");
    }
}

#[test]
fn unwritable_output_is_named() {
    let dir = scratch("unwritable");
    let file = dir.join("a-file");
    std::fs::write(&file, "not a folder").unwrap();
    // A folder inside a regular file cannot be created.
    let out = file.join("out");
    let err = failure(&[
        "run",
        "colliding-disks",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--end-time",
        "0.01",
    ]);
    assert!(err.contains("a-file"), "{err}");
    // The output path is an existing regular file.
    let err = failure(&[
        "run",
        "colliding-disks",
        "--out",
        file.to_str().unwrap(),
        "--quiet",
        "--end-time",
        "0.01",
    ]);
    assert!(err.contains("a-file"), "{err}");
}
