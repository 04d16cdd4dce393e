//! Project automation, run as `cargo xtask <command>`:
//!
//! - `ci`: format check, clippy with `-D warnings`, and the whole test suite in release mode.
//! - `bench [FILTER]`: the criterion benches of every crate, then a Markdown table of the
//!   results in `target/bench-report.md`.
//! - `deny`: `cargo deny check` (needs `cargo install cargo-deny`).

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("ci") => ci(),
        Some("bench") => bench(args.get(1).map(String::as_str)),
        Some("deny") => cargo(&["deny", "check"]),
        _ => {
            eprintln!("usage: cargo xtask <ci | bench [FILTER] | deny>");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask: {message}");
            ExitCode::FAILURE
        }
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

fn cargo(args: &[&str]) -> Result<(), String> {
    eprintln!("xtask: cargo {}", args.join(" "));
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(args)
        .current_dir(workspace_root())
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`cargo {}` failed ({status})", args.join(" ")))
    }
}

fn ci() -> Result<(), String> {
    cargo(&["fmt", "--all", "--", "--check"])?;
    cargo(&[
        "clippy",
        "--workspace",
        "--all-targets",
        "--release",
        "--",
        "-D",
        "warnings",
    ])?;
    // Crates must also build with default features off (the MLS core without the mesh,
    // the mesh without parry).
    cargo(&[
        "check",
        "-p",
        "umls-mesh",
        "-p",
        "umls-mls",
        "--no-default-features",
        "--release",
    ])?;
    cargo(&["test", "--workspace", "--release"])
}

fn bench(filter: Option<&str>) -> Result<(), String> {
    let mut args = vec!["bench", "--workspace"];
    if let Some(f) = filter {
        args.extend(["--", f]);
    }
    cargo(&args)?;
    let report = report::collect(&workspace_root().join("target/criterion"))?;
    let path = workspace_root().join("target/bench-report.md");
    std::fs::write(&path, report).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    eprintln!("xtask: wrote {}", path.display());
    Ok(())
}

mod report;
