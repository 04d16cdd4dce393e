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
    &["umls-transfer", "umls-kernels", "umls-engine"],
    // Adapters.
    &["umls-scenes", "umls-io", "umls-report", "umls-cli", "xtask"],
    // The facade.
    &["umls"],
];

/// Dependencies inside one ring that the architecture allows.
const SAME_RING: [(&str, &str); 6] = [
    ("umls-mls", "umls-mesh"),
    ("umls-kernels", "umls-transfer"),
    ("umls-engine", "umls-transfer"),
    ("umls-cli", "umls-io"),
    // The report draws with the chart helper and runs cases through the binary.
    ("umls-report", "umls-io"),
    ("umls-cli", "umls-report"),
];

fn ring(name: &str) -> Option<usize> {
    RINGS.iter().position(|r| r.contains(&name))
}

#[test]
fn dependencies_point_inward() {
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
    let metadata: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
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
