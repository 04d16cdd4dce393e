//! `cargo xtask peers`: the fluid box side by side with Taichi, the measurement behind
//! the engine's speed and memory claims against it.
//!
//! Taichi runs its own `mpm3d` example (`xtask/peers/taichi_mpm3d.py`: the same scene,
//! 64³ grid, f64) and `umls run fluid-box-3d` runs the built-in scene with quadratic
//! B-splines under MLS-MPM (Taichi's transfer) and APIC, and with UMLS on the Kuhn
//! lattice of the same node count under APIC and MLS-MPM (each particle's own D_p).
//! The programs alternate within each round, so drift
//! of the machine's speed falls on all of them alike, and every ratio is taken against
//! the Taichi run of the same round. Taichi is a measuring instrument, not a dependency:
//! it is installed from PyPI into a virtual environment under the target directory on
//! first use (network needed once). The report goes to `target/peers/peers.md`.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::compare::{median, parse_summary, run_summary};
use crate::{cargo, machine, option_value, positive_integer, target_dir, workspace_root};

/// The Taichi release the measurements use (the one the engine's issue measured).
const TAICHI: &str = "taichi==1.7.4";

/// The peer script, written next to the virtual environment when the command runs.
const SCRIPT: &str = include_str!("../peers/taichi_mpm3d.py");

/// Grid cells per axis of both programs' scene.
const GRID: usize = 64;

/// The fluid box's time step (the scene's and Taichi's example at 64³).
const DT: f64 = 2e-4;

/// The `umls run fluid-box-3d` configurations measured, with their labels.
const CONFIGS: [(&str, &[&str]); 4] = [
    (
        "bspline2, MLS-MPM",
        &["--kernel", "bspline2", "--set", "transfer.kind=mls-mpm"],
    ),
    ("bspline2, APIC", &["--kernel", "bspline2"]),
    ("UMLS, Kuhn lattice", &["--kernel", "umls"]),
    (
        "UMLS, Kuhn lattice, MLS-MPM",
        &["--kernel", "umls", "--set", "transfer.kind=mls-mpm"],
    ),
];

/// What `cargo xtask peers` was asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct PeersArgs {
    /// Rounds of one run of every program.
    pub rounds: usize,
    /// Worker threads of every run.
    pub threads: usize,
    /// Steps of every run.
    pub steps: usize,
    /// The Python that creates the virtual environment.
    pub python: String,
}

/// Parses `[--rounds N] [--threads N] [--steps N] [--python PATH]`.
pub fn parse_args(args: &[String]) -> Result<PeersArgs, String> {
    let mut parsed = PeersArgs {
        rounds: 3,
        threads: 2,
        steps: 500,
        python: "python3".into(),
    };
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        let mut value =
            |name: &str| option_value(&mut rest, || format!("peers: {name} needs a value"));
        let number = |name: &str, text: String| positive_integer("peers", name, text);
        match arg.as_str() {
            "--rounds" => parsed.rounds = number("--rounds", value("--rounds")?)?,
            "--threads" => parsed.threads = number("--threads", value("--threads")?)?,
            "--steps" => parsed.steps = number("--steps", value("--steps")?)?,
            "--python" => parsed.python = value("--python")?,
            other => return Err(format!("peers: unknown argument `{other}`")),
        }
    }
    Ok(parsed)
}

/// One run's throughput (particle-steps per second of the timed steps) and peak
/// resident memory (bytes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeerRun {
    /// Particle-steps per second.
    pub throughput: f64,
    /// Peak resident memory of the process, bytes.
    pub peak_bytes: f64,
}

/// Reads the peer script's result line (`n_grid n_particles steps seconds
/// particle_steps_per_s peak_rss_bytes`, the last line of its output).
pub fn parse_taichi_output(text: &str) -> Result<PeerRun, String> {
    let line = text
        .lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .ok_or("peers: the Taichi script printed nothing")?;
    let fields: Vec<&str> = line.split_whitespace().collect();
    let number = |i: usize, name: &str| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| format!("peers: no {name} in the Taichi script's line `{line}`"))
    };
    if fields.len() != 6 {
        return Err(format!(
            "peers: the Taichi script's line `{line}` has {} fields, not 6",
            fields.len()
        ));
    }
    Ok(PeerRun {
        throughput: number(4, "throughput")?,
        peak_bytes: number(5, "peak memory")?,
    })
}

/// Reads a `umls run`'s throughput in the steps and its peak memory from its
/// `summary.json` text.
pub fn parse_umls_summary(text: &str) -> Result<PeerRun, String> {
    let timing = parse_summary(text)?;
    let json: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("summary.json: {e}"))?;
    let peak_bytes = json["peak_memory_bytes"]
        .as_f64()
        .filter(|v| *v > 0.0)
        .ok_or("summary.json: no `peak_memory_bytes`")?;
    Ok(PeerRun {
        throughput: timing.particle_steps / timing.total,
        peak_bytes,
    })
}

/// The report: every round's runs and ratios, then per configuration the medians and
/// ranges of its throughput and of its ratio to the same round's Taichi run, its ratio
/// to Taichi's fastest run, and its peak memory against Taichi's.
pub fn render(args: &PeersArgs, taichi: &[PeerRun], umls: &[Vec<PeerRun>]) -> String {
    let million = |r: &PeerRun| r.throughput / 1e6;
    let megabytes = |r: &PeerRun| r.peak_bytes / 1e6;
    let mut out = format!(
        "# The fluid box side by side with Taichi\n\n\
         {} alternating rounds of {} steps, f64, {} thread(s): Taichi's `mpm3d` example at \
         {GRID}³ (`xtask/peers/taichi_mpm3d.py`, {TAICHI}) and `umls run fluid-box-3d`. \
         Throughput in million particle-steps per second of the timed steps (Taichi \
         after compilation, umls without set-up and frames), peak resident memory of \
         the process; ratio = umls / the same round's Taichi run.\n\n| round | Taichi |",
        taichi.len(),
        args.steps,
        args.threads
    );
    for (label, _) in CONFIGS {
        out += &format!(" {label} | ratio |");
    }
    out += "\n|---|---|";
    out += &"---|---|".repeat(CONFIGS.len());
    out += "\n";
    for (round, t) in taichi.iter().enumerate() {
        out += &format!(
            "| {} | {:.2} M/s, {:.0} MB |",
            round + 1,
            million(t),
            megabytes(t)
        );
        for runs in umls {
            let r = &runs[round];
            out += &format!(
                " {:.2} M/s, {:.0} MB | {:.2}× |",
                million(r),
                megabytes(r),
                r.throughput / t.throughput
            );
        }
        out += "\n";
    }
    let throughputs: Vec<f64> = taichi.iter().map(million).collect();
    let fastest = throughputs.iter().copied().fold(f64::NAN, f64::max);
    let taichi_memory = median(&taichi.iter().map(megabytes).collect::<Vec<_>>());
    out += &format!(
        "\nTaichi: median {:.2} M/s ({:.2}–{:.2}), {:.0} MB.\n\n\
         | umls | throughput, median (range) | ratio to the same round's Taichi, median (range) | ratio to Taichi's fastest run | peak memory / Taichi's |\n\
         |---|---|---|---|---|\n",
        median(&throughputs),
        throughputs.iter().copied().fold(f64::NAN, f64::min),
        fastest,
        taichi_memory
    );
    for ((label, _), runs) in CONFIGS.iter().zip(umls) {
        let m: Vec<f64> = runs.iter().map(million).collect();
        let ratios: Vec<f64> = runs
            .iter()
            .zip(taichi)
            .map(|(r, t)| r.throughput / t.throughput)
            .collect();
        let memory = median(&runs.iter().map(megabytes).collect::<Vec<_>>());
        out += &format!(
            "| {label} | {:.2} M/s ({:.2}–{:.2}) | {:.2}× ({:.2}–{:.2}) | {:.2}× | {:.2}× |\n",
            median(&m),
            m.iter().copied().fold(f64::NAN, f64::min),
            m.iter().copied().fold(f64::NAN, f64::max),
            median(&ratios),
            ratios.iter().copied().fold(f64::NAN, f64::min),
            ratios.iter().copied().fold(f64::NAN, f64::max),
            median(&m) / fastest,
            memory / taichi_memory
        );
    }
    out
}

/// The virtual environment's Python with Taichi importable, created and filled on first
/// use.
fn taichi_python(dir: &Path, python: &str) -> Result<PathBuf, String> {
    let venv = dir.join("venv");
    let bin = venv.join("bin/python");
    let importable = |bin: &Path| {
        Command::new(bin)
            .args(["-c", "import taichi"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if importable(&bin) {
        return Ok(bin);
    }
    let run = |program: &Path, args: &[&str]| -> Result<(), String> {
        eprintln!("xtask: {} {}", program.display(), args.join(" "));
        let status = Command::new(program)
            .args(args)
            .status()
            .map_err(|e| format!("cannot run {}: {e}", program.display()))?;
        status.success().then_some(()).ok_or_else(|| {
            format!(
                "`{} {}` failed ({status})",
                program.display(),
                args.join(" ")
            )
        })
    };
    let venv_text = venv.display().to_string();
    run(Path::new(python), &["-m", "venv", &venv_text])?;
    run(&bin, &["-m", "pip", "install", "--quiet", TAICHI])?;
    if importable(&bin) {
        Ok(bin)
    } else {
        Err(format!("taichi does not import in {}", venv.display()))
    }
}

/// One Taichi run.
fn run_taichi(python: &Path, script: &Path, args: &PeersArgs) -> Result<PeerRun, String> {
    let output = Command::new(python)
        .arg(script)
        .args([GRID.to_string(), args.steps.to_string(), "f64".into()])
        .arg(args.threads.to_string())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", python.display()))?;
    if !output.status.success() {
        return Err(format!(
            "the Taichi script failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    parse_taichi_output(&String::from_utf8_lossy(&output.stdout))
}

/// One `umls run fluid-box-3d` with `extra` arguments into `out`.
fn run_umls(
    program: &Path,
    extra: &[&str],
    args: &PeersArgs,
    out: &Path,
) -> Result<PeerRun, String> {
    let case = format!(
        "fluid-box-3d {} --end-time {}",
        extra.join(" "),
        args.steps as f64 * DT
    );
    let text = run_summary(program, &case, args.threads, out)?;
    parse_umls_summary(&text).map_err(|e| format!("{}: {e}", out.join("summary.json").display()))
}

/// Sets up Taichi, builds `umls`, runs the rounds and writes `target/peers/peers.md`.
pub fn peers(args: &[String]) -> Result<(), String> {
    let args = parse_args(args)?;
    let dir = target_dir().join("peers");
    let fail = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    std::fs::create_dir_all(&dir).map_err(|e| fail(&dir, e))?;
    let python = taichi_python(&dir, &args.python)?;
    let script = dir.join("taichi_mpm3d.py");
    std::fs::write(&script, SCRIPT).map_err(|e| fail(&script, e))?;
    cargo(&["build", "--release", "-p", "umls-cli"])?;
    let program = target_dir().join("release/umls");
    let mut taichi = Vec::new();
    let mut umls = vec![Vec::new(); CONFIGS.len()];
    for round in 0..args.rounds {
        let t = run_taichi(&python, &script, &args)?;
        eprintln!(
            "xtask: round {}, Taichi: {:.2} M particle-steps/s, {:.0} MB",
            round + 1,
            t.throughput / 1e6,
            t.peak_bytes / 1e6
        );
        taichi.push(t);
        for (c, (label, extra)) in CONFIGS.iter().enumerate() {
            let r = run_umls(&program, extra, &args, &dir.join(format!("runs/config{c}")))?;
            eprintln!(
                "xtask: round {}, {label}: {:.2} M particle-steps/s, {:.0} MB",
                round + 1,
                r.throughput / 1e6,
                r.peak_bytes / 1e6
            );
            umls[c].push(r);
        }
    }
    let report = machine::after_title(
        &render(&args, &taichi, &umls),
        &machine::machine_line(&workspace_root()),
    );
    let path = dir.join("peers.md");
    std::fs::write(&path, &report).map_err(|e| fail(&path, e))?;
    println!("{report}");
    eprintln!("xtask: wrote {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strings;

    #[test]
    fn arguments_are_read_and_checked() {
        let parsed = parse_args(&strings(&["--rounds", "5", "--steps", "100"])).expect("valid");
        assert_eq!((parsed.rounds, parsed.threads, parsed.steps), (5, 2, 100));
        assert_eq!(parsed.python, "python3");
        let err = parse_args(&strings(&["--threads", "0"])).expect_err("zero threads");
        assert!(err.contains("--threads") && err.contains("`0`"), "{err}");
        let err = parse_args(&strings(&["--steps"])).expect_err("no value");
        assert!(err.contains("--steps needs a value"), "{err}");
        let err = parse_args(&strings(&["--fast"])).expect_err("unknown");
        assert!(err.contains("`--fast`"), "{err}");
    }

    #[test]
    fn the_taichi_line_gives_throughput_and_memory() {
        let text = "[Taichi] version 1.7.4\n64 65536 500 10.3815 3.156400e+06 142548992\n";
        let run = parse_taichi_output(text).expect("valid line");
        assert_eq!(run.throughput, 3.1564e6);
        assert_eq!(run.peak_bytes, 142548992.0);
        let err = parse_taichi_output("64 65536 500 10.3\n").expect_err("short line");
        assert!(err.contains("4 fields"), "{err}");
        let err = parse_taichi_output("64 65536 500 10.3 nan 1\n").expect_err("not a number");
        assert!(err.contains("throughput"), "{err}");
        assert!(parse_taichi_output("\n").is_err());
    }

    fn summary(total: f64, peak: Option<f64>) -> String {
        let peak = peak.map_or(String::new(), |p| format!(r#""peak_memory_bytes": {p},"#));
        format!(
            r#"{{"status": "completed", "particles": 64000, "steps": 500, {peak}
               "stage_seconds": {{"stencils": 0.5, "particles_to_grid": 1.0, "grid_update": 0.25,
               "grid_to_particles": 0.5, "constitutive": 0.25, "checks": 0.1, "total": {total}}}}}"#
        )
    }

    #[test]
    fn a_summary_gives_the_throughput_in_the_steps_and_the_peak() {
        let run = parse_umls_summary(&summary(4.0, Some(1.5e8))).expect("valid");
        assert_eq!(run.throughput, 64000.0 * 500.0 / 4.0);
        assert_eq!(run.peak_bytes, 1.5e8);
        let err = parse_umls_summary(&summary(4.0, None)).expect_err("no peak");
        assert!(err.contains("peak_memory_bytes"), "{err}");
    }

    #[test]
    fn ratios_pair_each_run_with_the_same_rounds_taichi() {
        let args = parse_args(&[]).expect("defaults");
        let run = |m: f64, mb: f64| PeerRun {
            throughput: m * 1e6,
            peak_bytes: mb * 1e6,
        };
        let taichi = [run(2.0, 140.0), run(4.0, 140.0)];
        // Each configuration three times Taichi in its own round; against Taichi's
        // fastest run the median 9 M/s is 2.25×.
        let umls: Vec<Vec<PeerRun>> = (0..CONFIGS.len())
            .map(|_| vec![run(6.0, 140.0), run(12.0, 280.0)])
            .collect();
        let report = render(&args, &taichi, &umls);
        assert!(
            report.contains("| 1 | 2.00 M/s, 140 MB | 6.00 M/s, 140 MB | 3.00× |"),
            "{report}"
        );
        assert!(
            report.contains("| 2 | 4.00 M/s, 140 MB | 12.00 M/s, 280 MB | 3.00× |"),
            "{report}"
        );
        assert!(
            report.contains(
                "| bspline2, MLS-MPM | 9.00 M/s (6.00–12.00) | 3.00× (3.00–3.00) | 2.25× | 1.50× |"
            ),
            "{report}"
        );
        assert!(
            report.contains("Taichi: median 3.00 M/s (2.00–4.00), 140 MB."),
            "{report}"
        );
    }
}
