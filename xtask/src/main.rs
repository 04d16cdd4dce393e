//! Project automation, run as `cargo xtask <command>`:
//!
//! - `ci`: format check, clippy with `-D warnings`, the whole test suite in release mode,
//!   and the custom-kernel example.
//! - `bench [--quick] [--no-criterion] [--save-baseline NAME | --baseline NAME] [--docs]`:
//!   the comparison report in `target/report/` (`umls report`: the study matrix of
//!   scenes × kernels × resolutions, charts, raw results), after the criterion benches of
//!   every crate (skipped by `--quick`, whose matrix has coarse levels only, and by
//!   `--no-criterion`, which reports the criterion results already there); `--docs`
//!   copies the report to `docs/report/`.
//! - `compare REV [--rounds N] [--threads N] [--case ARGS]... [--fail-above R]`: the
//!   working tree's speed against revision `REV` on the same machine, alternating short
//!   runs of both builds, with stage times, ratios and whether the results stayed bit
//!   for bit the same (`compare.rs`; report in `target/compare/compare.md`).
//! - `peers [--rounds N] [--threads N] [--steps N] [--python PATH]`: the fluid box side
//!   by side with Taichi's own example of the scene, alternating runs, throughput and
//!   peak memory with ratios to the same round's Taichi run (`peers.rs`; Taichi installed
//!   from PyPI into `target/peers/venv` on first use; report in `target/peers/peers.md`).
//! - `deny`: `cargo deny check` (needs `cargo install cargo-deny`).
//!
//! Both speed reports open with the machine they were measured on (`machine.rs`: the
//! processor with its family, model and vector extensions, the hardware threads, the
//! revision and the date), since their ratios depend on the CPU.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

mod compare;
// The comparison report's reading of /proc/cpuinfo, shared as source so that xtask
// stays free of the workspace's crates.
#[path = "../../crates/report/src/cpu.rs"]
mod cpu;
mod machine;
mod peers;

/// What `cargo xtask --help` prints: each task, its options and what it produces.
const USAGE: &str = "\
Project automation for the umls workspace.

Usage: cargo xtask <TASK> [OPTIONS]

Tasks:
  ci         Format check, clippy with -D warnings, a build with default features off,
             the whole test suite in release mode, and the custom-kernel example:
             what .ci/run runs.
  bench      The comparison report (scenes x kernels x resolutions: tables, charts,
             raw results) in target/report/, after the criterion benches of every crate.
               --quick                 coarse levels only, no criterion benches (about 4
                                       minutes on 2 cores)
               --no-criterion          reuse the criterion results already there
               --save-baseline NAME    save the criterion results as NAME
               --baseline NAME         compare the criterion results with NAME
               --docs                  copy the report to docs/report/
  compare    The working tree's speed against revision REV on this machine: short runs
             of both builds alternated, stage times, ratios, and whether the results
             stayed bit for bit the same (target/compare/compare.md).
               REV                     the revision to compare with (required)
               --rounds N              alternating rounds
               --threads N             worker threads of each run
               --case ARGS             `umls run` arguments of a case (repeatable)
               --fail-above R          fail if a stage is slower than R times REV
  peers      The fluid box beside Taichi's own example of the scene: throughput and
             peak memory, ratios to the same round's Taichi run
             (target/peers/peers.md; Taichi from PyPI into target/peers/venv).
               --rounds N  --threads N  --steps N  --python PATH
  deny       cargo deny check (needs `cargo install cargo-deny`).
  help       This text.";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("ci") => ci(),
        Some("bench") => bench(&args[1..]),
        Some("compare") => compare::compare(&args[1..]),
        Some("peers") => peers::peers(&args[1..]),
        Some("deny") => cargo(&["deny", "check"]),
        Some("help" | "--help" | "-h") => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Some(other) => {
            eprintln!("xtask: unknown task `{other}`\n\n{USAGE}");
            return ExitCode::from(2);
        }
        None => {
            eprintln!("{USAGE}");
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

/// Cargo's target directory: `CARGO_TARGET_DIR` where set (relative to the workspace,
/// as cargo reads it), else the workspace's `target`.
fn target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) if !dir.is_empty() => workspace_root().join(dir),
        _ => workspace_root().join("target"),
    }
}

fn cargo(args: &[&str]) -> Result<(), String> {
    cargo_in(&workspace_root(), args)
}

/// Runs cargo with `args` in `dir` (another checkout's root, for `compare`).
fn cargo_in(dir: &Path, args: &[&str]) -> Result<(), String> {
    eprintln!("xtask: cargo {} (in {})", args.join(" "), dir.display());
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(args)
        .current_dir(dir)
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
    // the mesh without parry, the B-spline kernels without either).
    cargo(&[
        "check",
        "-p",
        "umls-mesh",
        "-p",
        "umls-mls",
        "-p",
        "umls-kernels",
        "--no-default-features",
        "--release",
    ])?;
    cargo(&["test", "--workspace", "--release"])?;
    // A kernel from outside the workspace runs built-in scenes through the runner.
    cargo(&["run", "--release", "--example", "custom_kernel"])
}

/// What `cargo xtask bench` was asked for.
#[derive(Debug, Default)]
struct BenchArgs {
    quick: bool,
    no_criterion: bool,
    save_baseline: Option<String>,
    baseline: Option<String>,
    docs: bool,
}

/// The value after an option, or `missing()` as the error where the arguments end.
fn option_value(
    rest: &mut std::slice::Iter<'_, String>,
    missing: impl FnOnce() -> String,
) -> Result<String, String> {
    rest.next().cloned().ok_or_else(missing)
}

/// Owned copies of `args`, as the commands' parsers take them (tests).
#[cfg(test)]
fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// `text` as a positive integer, or an error naming `command`'s option `name`.
fn positive_integer(command: &str, name: &str, text: String) -> Result<usize, String> {
    text.parse::<usize>()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("{command}: {name} takes a positive integer, not `{text}`"))
}

fn bench_args(args: &[String]) -> Result<BenchArgs, String> {
    let mut parsed = BenchArgs::default();
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        let mut value =
            |name: &str| option_value(&mut rest, || format!("{name} needs a baseline name"));
        match arg.as_str() {
            "--quick" => parsed.quick = true,
            "--no-criterion" => parsed.no_criterion = true,
            "--docs" => parsed.docs = true,
            "--save-baseline" => parsed.save_baseline = Some(value("--save-baseline")?),
            "--baseline" => parsed.baseline = Some(value("--baseline")?),
            other => return Err(format!("bench: unknown argument `{other}`")),
        }
    }
    Ok(parsed)
}

fn bench(args: &[String]) -> Result<(), String> {
    let args = bench_args(args)?;
    let root = workspace_root();
    if !args.quick && !args.no_criterion {
        let mut criterion = vec!["bench", "--workspace", "--"];
        if let Some(name) = &args.save_baseline {
            criterion.extend(["--save-baseline", name]);
        }
        if let Some(name) = &args.baseline {
            criterion.extend(["--baseline", name]);
        }
        cargo(&criterion)?;
    }
    cargo(&["build", "--release", "-p", "umls-cli"])?;
    let target = target_dir();
    let out = target.join("report");
    let exe = target.join("release/umls");
    let mut command = Command::new(&exe);
    command
        .current_dir(&root)
        .args([
            "report",
            "--matrix",
            if args.quick { "quick" } else { "full" },
        ])
        .arg("--out")
        .arg(&out)
        .arg("--criterion")
        .arg(target.join("criterion"))
        .args([
            "--criterion-current",
            args.save_baseline.as_deref().unwrap_or("new"),
        ]);
    if let Some(name) = &args.baseline {
        command.args(["--baseline", name]);
    }
    eprintln!("xtask: {} report ...", exe.display());
    let status = command
        .status()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if !status.success() {
        return Err(format!("`umls report` failed ({status})"));
    }
    if args.docs {
        publish(&out, &root.join("docs/report"))?;
    }
    Ok(())
}

/// Copies the report (not the runs' directories) to `docs`, replacing what was there.
fn publish(report: &Path, docs: &Path) -> Result<(), String> {
    let fail = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    if docs.exists() {
        std::fs::remove_dir_all(docs).map_err(|e| fail(docs, e))?;
    }
    for sub in ["charts", "histories"] {
        let (from, to) = (report.join(sub), docs.join(sub));
        std::fs::create_dir_all(&to).map_err(|e| fail(&to, e))?;
        for entry in std::fs::read_dir(&from).map_err(|e| fail(&from, e))? {
            let path = entry.map_err(|e| fail(&from, e))?.path();
            let target = to.join(path.file_name().unwrap_or_default());
            std::fs::copy(&path, &target).map_err(|e| fail(&path, e))?;
        }
    }
    for file in ["report.md", "results.csv", "results.json"] {
        let target = docs.join(file);
        std::fs::copy(report.join(file), &target).map_err(|e| fail(&target, e))?;
    }
    eprintln!("xtask: copied the report to {}", docs.display());
    Ok(())
}
