//! Editing scenes from the command line: `--set KEY=VALUE` on the TOML text, `--refine`
//! and `--particle-refine` on the parsed scene, through the library and the binary.

use std::process::Command;

use umls_runner::edit::{override_text, parse_assignment, refine, refine_particles};
use umls_runner::scene::Scene;
use umls_runner::schema::SeedingSpec;

const TEXT: &str = "[scene]\nname = \"s\"\n[time]\ncfl = 0.3\n[[bodies]]\nmaterial = \"a\"\n[[boundaries]]\nkind = \"fixed\"\n[[boundaries]]\nkind = \"slip\"\n";

fn edit(assignments: &[(&str, &str)]) -> Result<toml::Table, String> {
    let owned: Vec<(String, String)> = assignments
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    override_text(TEXT, "t.toml", &owned)
        .map(|text| text.parse().unwrap())
        .map_err(|e| e.to_string())
}

#[test]
fn sets_nested_values_and_creates_missing_tables() {
    let t = edit(&[
        ("time.cfl", "0.5"),
        ("mesh.transform.rotation", "15"),
        ("kernel.kind", "bspline2"),
        ("bodies.material", "\"b\""),
        ("boundaries.1.kind", "fixed"),
        ("mesh.lattice.cells", "[20, 88]"),
        ("scene.name", ""),
    ])
    .unwrap();
    // An empty value removes the key.
    assert!(t["scene"].get("name").is_none());
    assert_eq!(t["time"]["cfl"].as_float(), Some(0.5));
    assert_eq!(t["mesh"]["transform"]["rotation"].as_integer(), Some(15));
    assert_eq!(t["kernel"]["kind"].as_str(), Some("bspline2"));
    // A one-entry array is entered without an index.
    assert_eq!(t["bodies"][0]["material"].as_str(), Some("b"));
    assert_eq!(t["boundaries"][1]["kind"].as_str(), Some("fixed"));
    assert_eq!(t["boundaries"][0]["kind"].as_str(), Some("fixed"));
    assert_eq!(t["mesh"]["lattice"]["cells"][1].as_integer(), Some(88));
}

#[test]
fn bad_paths_are_errors_naming_the_key() {
    let e = edit(&[("boundaries.kind", "fixed")]).unwrap_err();
    assert!(
        e.contains("`boundaries.kind`") && e.contains("boundaries.0.kind"),
        "{e}"
    );
    let e = edit(&[("time.cfl.x", "1")]).unwrap_err();
    assert!(e.contains("`time.cfl` is a value"), "{e}");
    let e = edit(&[("boundaries.5.kind", "fixed")]).unwrap_err();
    assert!(e.contains("has 2 entries; there is no entry 5"), "{e}");
    assert!(parse_assignment("cfl").is_err() && parse_assignment("=1").is_err());
    assert_eq!(
        parse_assignment("a.b = [1, 2]").unwrap(),
        ("a.b".to_string(), "[1, 2]".to_string())
    );
    // A value the schema rejects is rejected when the scene is read, naming the key.
    let e = Scene::load_with("vortex", &[("time.cfl".into(), "\"fast\"".into())])
        .unwrap_err()
        .to_string();
    assert!(e.contains("cfl"), "{e}");
}

#[test]
fn refinement_scales_cells_particles_grid_and_time_step() {
    let mut bar = Scene::load("vibrating-bar").unwrap();
    let dt = bar.spec.time.dt.unwrap();
    refine(&mut bar, 2.0).unwrap();
    assert_eq!(bar.spec.mesh.lattice.as_ref().unwrap().cells, vec![216]);
    assert_eq!(bar.spec.time.dt, Some(dt / 2.0));

    let mut column = Scene::load_with(
        "hydrostatic-column",
        &[("kernel.grid_spacing".into(), "0.1".into())],
    )
    .unwrap();
    refine(&mut column, 2.0).unwrap();
    assert_eq!(
        column.spec.mesh.lattice.as_ref().unwrap().cells,
        vec![20, 88]
    );
    assert_eq!(column.spec.kernel.grid_spacing, Some(0.05));
    assert!(matches!(column.spec.bodies[0].seeding, SeedingSpec::Lattice(h) if h == 0.025));
    refine_particles(&mut column, 2.0).unwrap();
    assert!(matches!(column.spec.bodies[0].seeding, SeedingSpec::Lattice(h) if h == 0.0125));
    // Cells must stay whole, and a mesh file cannot be refined by a factor.
    let e = refine(&mut column, 1.01).unwrap_err().to_string();
    assert!(e.contains("mesh.lattice.cells[0]"), "{e}");
    let mut gmsh = Scene::load("slope-3d").unwrap();
    let e = refine(&mut gmsh, 2.0).unwrap_err().to_string();
    assert!(
        e.contains("mesh.file") && e.contains("[mesh.lattice]"),
        "{e}"
    );
    assert!(refine(&mut column, -1.0).is_err());
}

/// The binary's `--set` and `--refine` change the run: twice the cells in each direction
/// give four times the particles of the 2D column.
#[test]
fn the_binary_applies_set_and_refine() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scene_edit");
    let run = |extra: &[&str], name: &str| {
        let out = dir.join(name);
        let status = Command::new(env!("CARGO_BIN_EXE_umls"))
            .args(["run", "hydrostatic-column", "--quiet", "--threads", "1"])
            .args(["--end-time", "0.002", "--out", out.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert!(
            status.status.success(),
            "{}",
            String::from_utf8_lossy(&status.stderr)
        );
        let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()
    };
    let base = run(&["--set", "kernel.kind=bspline2"], "base");
    let fine = run(
        &[
            "--set",
            "kernel.kind=bspline2",
            "--set",
            "transfer.kind=apic",
            "--refine",
            "2",
        ],
        "fine",
    );
    assert_eq!(base["kernel"], "bspline2");
    assert!(fine["transfer"].as_str().unwrap().starts_with("apic"));
    assert_eq!(
        fine["particles"].as_u64().unwrap(),
        4 * base["particles"].as_u64().unwrap()
    );
}

/// Without `--out`, an edited run writes beside the plain run, in a folder tagged by its
/// edits, instead of over it; the same edits find the same folder again.
#[test]
fn an_edited_run_does_not_overwrite_the_plain_one() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("edit_folders");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_umls"))
            .current_dir(&dir)
            .args(["run", "vibrating-bar", "--quiet", "--end-time", "0.01"])
            .args(extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let folders = || {
        let mut names: Vec<String> = std::fs::read_dir(dir.join("out"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    run(&[]);
    run(&["--set", "transfer.kind=flip"]);
    run(&["--set", "transfer.kind=flip"]);
    let names = folders();
    assert_eq!(names.len(), 2, "{names:?}");
    let plain = &names[0];
    assert!(plain.starts_with("vibrating-bar-"), "{plain}");
    let tag = names[1].strip_prefix(&format!("{plain}-")).unwrap();
    assert!(
        tag.len() == 8 && tag.chars().all(|c| c.is_ascii_hexdigit()),
        "{names:?}"
    );
    for name in &names {
        assert!(dir.join("out").join(name).join("summary.json").is_file());
    }
}

/// A `--set` that breaks the scene names the key, the assignment and the user's file,
/// not a line of the edited text the user never saw.
#[test]
fn a_bad_assignment_names_its_key_and_the_file() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/colliding-disks.toml"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_umls"))
        .args([
            "run",
            file,
            "--set",
            "material.young=abc",
            "--set",
            "time.dt=2e-4",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("colliding-disks.toml: `material.young`"),
        "{stderr}"
    );
    assert!(stderr.contains("`--set material.young=abc`"), "{stderr}");
    assert!(stderr.contains("unknown field `material`"), "{stderr}");
    assert!(!stderr.contains("line "), "{stderr}");
    // A wrong type is blamed on its assignment too, the good ones before it are not.
    let out = Command::new(env!("CARGO_BIN_EXE_umls"))
        .args(["run", file, "--set", "time.dt=2e-4", "--set", "time.dt=[1"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("`--set time.dt=[1`"), "{stderr}");
    assert!(stderr.contains("invalid type: string \"[1\""), "{stderr}");
}
