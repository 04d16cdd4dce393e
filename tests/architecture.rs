//! The layering of docs/ARCHITECTURE.md, enforced: `cargo metadata` lists every workspace
//! crate's normal dependencies, and no crate may depend on a crate of an outer ring, or
//! on a crate of its own ring other than the ones the architecture names.

use std::process::Command;

/// Rings from the inside out.
const RINGS: [&[&str]; 4] = [
    // Pure numerics.
    &[
        "umls-mesh",
        "umls-mls",
        "umls-constitutive",
        "umls-manifold",
    ],
    // Ports and wiring.
    &["umls-transfer", "umls-kernels", "umls-ugimp", "umls-engine"],
    // Adapters.
    &["umls-io", "umls-runner", "umls-report", "umls-cli", "xtask"],
    // The facade.
    &["umls"],
];

/// Dependencies inside one ring that the architecture allows.
const SAME_RING: [(&str, &str); 9] = [
    ("umls-mls", "umls-mesh"),
    ("umls-kernels", "umls-transfer"),
    ("umls-ugimp", "umls-transfer"),
    ("umls-engine", "umls-transfer"),
    ("umls-cli", "umls-io"),
    // The runner writes its output through io; the command line is thin over it.
    ("umls-runner", "umls-io"),
    ("umls-cli", "umls-runner"),
    // The report draws with the chart helper and runs cases through the binary.
    ("umls-report", "umls-io"),
    ("umls-cli", "umls-report"),
];

fn ring(name: &str) -> Option<usize> {
    RINGS.iter().position(|r| r.contains(&name))
}

/// The workspace's packages, from `cargo metadata`.
fn metadata() -> serde_json::Value {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn dependencies_point_inward() {
    let metadata = metadata();
    let mut checked = 0;
    for package in metadata["packages"].as_array().unwrap() {
        let name = package["name"].as_str().unwrap();
        let own = ring(name).unwrap_or_else(|| panic!("{name} is in no ring of the architecture"));
        for dependency in package["dependencies"].as_array().unwrap() {
            let target = dependency["name"].as_str().unwrap();
            // Dev-dependencies (tests, benches) may reach anywhere.
            if !dependency["kind"].is_null() {
                continue;
            }
            let Some(theirs) = ring(target) else { continue };
            checked += 1;
            assert!(
                theirs < own || (theirs == own && SAME_RING.contains(&(name, target))),
                "{name} (ring {own}) depends on {target} (ring {theirs})"
            );
        }
    }
    // The workspace's own edges were seen (a metadata change would otherwise pass).
    assert!(
        checked >= 20,
        "only {checked} workspace dependencies checked"
    );
}

/// The workspace's normal dependencies of `package`, from `cargo metadata`.
fn normal_dependencies(package: &str) -> Vec<String> {
    let metadata = metadata();
    let packages = metadata["packages"].as_array().unwrap();
    let found = packages
        .iter()
        .find(|p| p["name"] == package)
        .unwrap_or_else(|| panic!("no package {package}"));
    found["dependencies"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["kind"].is_null())
        .map(|d| d["name"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn the_command_line_runs_scenes_through_the_runner_and_nothing_names_it() {
    assert!(normal_dependencies("umls-cli").contains(&"umls-runner".to_string()));
    for package in [
        "umls-runner",
        "umls-engine",
        "umls-kernels",
        "umls-report",
        "umls-io",
        "umls",
    ] {
        let deps = normal_dependencies(package);
        assert!(
            !deps.iter().any(|d| d == "umls-cli"),
            "{package} depends on the command line"
        );
    }
}

#[test]
fn the_ugimp_kernel_comes_through_the_port_alone() {
    let deps = normal_dependencies("umls-ugimp");
    assert!(deps.contains(&"umls-transfer".to_string()), "{deps:?}");
    assert!(
        !deps.iter().any(|d| d == "umls-kernels" || d == "umls-mls"),
        "{deps:?}"
    );
}

#[test]
fn the_engine_names_no_concrete_kernel() {
    assert!(!normal_dependencies("umls-engine").contains(&"umls-kernels".to_string()));
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/engine/src");
    let mut files = vec![src];
    let mut read = 0;
    while let Some(path) = files.pop() {
        if path.is_dir() {
            files.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        read += 1;
        // Code lines only: the crate's doc examples may show it driven by a kernel.
        for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
            for name in [
                "umls_kernels",
                "UmlsMeshKernel",
                "BSplineKernel",
                "LinearFeKernel",
            ] {
                assert!(
                    !line.contains(name),
                    "{} names {name}: {line}",
                    path.display()
                );
            }
        }
    }
    assert!(read > 10, "only {read} engine files read");
}

/// The runner's modules and the modules each one imports with `use crate::…` or names
/// as `crate::…`.
fn runner_imports() -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/runner/src");
    let mut graph = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        let module = path.file_stem().unwrap().to_string_lossy().to_string();
        if module == "lib" {
            continue;
        }
        // A module in a folder (`setup/`) is all its files, its submodules' imports
        // counted as its own.
        let text = if path.is_dir() {
            let mut files: Vec<_> = std::fs::read_dir(&path)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            files.sort();
            assert!(
                files
                    .iter()
                    .all(|f| f.extension().is_some_and(|e| e == "rs")),
                "{}: one level of submodules is read",
                path.display()
            );
            files
                .iter()
                .map(|f| std::fs::read_to_string(f).unwrap())
                .collect::<Vec<_>>()
                .join("\n")
        } else {
            std::fs::read_to_string(&path).unwrap()
        };
        let code: String = text
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let mut uses = std::collections::BTreeSet::new();
        for (k, _) in code.match_indices("crate::") {
            let rest = &code[k + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() && name != module {
                uses.insert(name);
            }
        }
        // `use crate::{a, b::C}` lists several modules.
        for (k, _) in code.match_indices("crate::{") {
            let rest = &code[k + "crate::{".len()..];
            let list = &rest[..rest.find('}').unwrap_or(0)];
            for item in list.split(',') {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() && name != module {
                    uses.insert(name);
                }
            }
        }
        graph.insert(module, uses);
    }
    graph
}

#[test]
fn the_runner_has_no_import_circle() {
    let graph = runner_imports();
    assert!(graph.len() > 15, "only {} modules read", graph.len());
    // Depth-first search for a back edge, naming the circle it closes.
    fn visit(
        module: &str,
        graph: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut std::collections::BTreeSet<String>,
    ) {
        if let Some(k) = path.iter().position(|m| m == module) {
            panic!("import circle: {} -> {module}", path[k..].join(" -> "));
        }
        if done.contains(module) {
            return;
        }
        path.push(module.to_string());
        for next in graph.get(module).into_iter().flatten() {
            if graph.contains_key(next) {
                visit(next, graph, path, done);
            }
        }
        path.pop();
        done.insert(module.to_string());
    }
    let mut done = std::collections::BTreeSet::new();
    for module in graph.keys() {
        visit(module, &graph, &mut Vec::new(), &mut done);
    }
}
