//! `cargo xtask compare REV`: the working tree against revision `REV`, on the same
//! machine in the same session, which is the only comparison of speed that means
//! anything here (timings move by 10–30 % between sessions).
//!
//! Both command-line programs are built (the revision in a temporary git worktree with
//! a target directory of its own, kept between invocations so a rebuild is
//! incremental), then a fixed set of short runs alternates between them, round by round,
//! with the order of each pair flipped every round so that drift of the machine's speed
//! during the comparison falls on both alike. For every case the report gives the time
//! per particle-step of the whole step and of each stage (medians over the rounds, with
//! their range), the ratio of the medians, and whether the two runs' `history.csv` are
//! identical byte for byte: an optimisation that should not change the arithmetic is
//! checked to leave the results as they were in the same command that times it.
//!
//! Speed is a benchmark, not a test, so CI does not run this; `--fail-above R` makes the
//! command fail when any case's ratio exceeds R, for use as a guard before merging.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::{cargo, cargo_in, machine, option_value, positive_integer, target_dir, workspace_root};

/// The stages of `summary.json`'s `stage_seconds`, in the step's order.
const STAGES: [&str; 6] = [
    "stencils",
    "particles_to_grid",
    "grid_update",
    "grid_to_particles",
    "constitutive",
    "checks",
];

/// Short names of [`STAGES`] for the report's columns.
const STAGE_LABELS: [&str; 6] = ["stencils", "P2G", "grid", "G2P", "constitutive", "checks"];

/// The default cases: the engine's hot paths at a few seconds each on one thread. Each
/// is the arguments of `umls run` after the scene (built-in names, so each program runs
/// its own definition of the scene).
const DEFAULT_CASES: [&str; 6] = [
    // Taichi's scene with bspline2 and APIC (50 steps of 64,000 particles).
    "fluid-box-3d --end-time 0.01",
    // The same with MLS-MPM, the transfer of the side-by-side measurement.
    "fluid-box-3d --set transfer.kind=mls-mpm --end-time 0.02",
    // The same with UMLS on the 1.57 M-tetrahedron lattice, where memory adds about a
    // quarter to the step (20 steps; the mesh and the integration correction take about
    // 8 s on one thread before them, untimed).
    "fluid-box-3d --kernel umls --end-time 0.004",
    // UMLS in 3D on the Kuhn lattice with its integration correction.
    "hydrostatic-column-3d --kernel umls --end-time 0.1",
    // UMLS in 2D on jittered triangles, the whole scene (FLIP).
    "colliding-disks --kernel umls",
    // Linear elements in 2D.
    "hydrostatic-column --kernel linear-fe --end-time 0.3",
];

/// What `cargo xtask compare` was asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareArgs {
    /// The revision the working tree is compared with.
    pub base: String,
    /// Pairs of runs per case.
    pub rounds: usize,
    /// Worker threads of every run.
    pub threads: usize,
    /// `umls run` arguments after the scene name, one string per case.
    pub cases: Vec<String>,
    /// Fail when a case's median step time rises by more than this ratio.
    pub fail_above: Option<f64>,
}

/// Parses `REV [--rounds N] [--threads N] [--case ARGS]... [--fail-above R]`.
pub fn parse_args(args: &[String]) -> Result<CompareArgs, String> {
    let mut base = None;
    let mut parsed = CompareArgs {
        base: String::new(),
        rounds: 3,
        threads: 1,
        cases: Vec::new(),
        fail_above: None,
    };
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        let mut value =
            |name: &str| option_value(&mut rest, || format!("compare: {name} needs a value"));
        let number = |name: &str, text: String| positive_integer("compare", name, text);
        match arg.as_str() {
            "--rounds" => parsed.rounds = number("--rounds", value("--rounds")?)?,
            "--threads" => parsed.threads = number("--threads", value("--threads")?)?,
            "--case" => parsed.cases.push(value("--case")?),
            "--fail-above" => {
                let text = value("--fail-above")?;
                let ratio = text
                    .parse::<f64>()
                    .ok()
                    .filter(|r| r.is_finite() && *r > 0.0)
                    .ok_or_else(|| {
                        format!("compare: --fail-above takes a positive ratio, not `{text}`")
                    })?;
                parsed.fail_above = Some(ratio);
            }
            other if other.starts_with("--") => {
                return Err(format!("compare: unknown argument `{other}`"));
            }
            other => {
                if base.replace(other.to_string()).is_some() {
                    return Err(format!("compare: a second revision `{other}`"));
                }
            }
        }
    }
    parsed.base = base.ok_or("compare: name the revision to compare with, e.g. HEAD")?;
    if parsed.cases.is_empty() {
        parsed.cases = DEFAULT_CASES.iter().map(|c| c.to_string()).collect();
    }
    Ok(parsed)
}

/// One run's timing: seconds per stage (in [`STAGES`] order) and in all, and the
/// particle-steps they cover.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Seconds of each stage.
    pub stages: [f64; 6],
    /// Seconds of the whole steps.
    pub total: f64,
    /// Particles times steps.
    pub particle_steps: f64,
}

impl Timing {
    /// Nanoseconds per particle-step of the whole step (`None`) or of stage `stage`.
    pub fn ns(&self, stage: Option<usize>) -> f64 {
        let seconds = stage.map_or(self.total, |s| self.stages[s]);
        seconds * 1e9 / self.particle_steps
    }
}

/// Reads a run's timing from its `summary.json` text.
pub fn parse_summary(text: &str) -> Result<Timing, String> {
    let json: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("summary.json: {e}"))?;
    let number = |value: &serde_json::Value, name: &str| {
        value[name]
            .as_f64()
            .ok_or_else(|| format!("summary.json: no number `{name}`"))
    };
    if json["status"].as_str() != Some("completed") {
        return Err(format!(
            "summary.json: the run did not complete (status {}, error {})",
            json["status"], json["error"]
        ));
    }
    let seconds = &json["stage_seconds"];
    let mut stages = [0.0; 6];
    for (slot, name) in stages.iter_mut().zip(STAGES) {
        // A stage an older program did not time counts as zero.
        *slot = seconds[name].as_f64().unwrap_or(0.0);
    }
    let particle_steps = number(&json, "particles")? * number(&json, "steps")?;
    if particle_steps <= 0.0 {
        return Err("summary.json: no particle-steps".into());
    }
    Ok(Timing {
        stages,
        total: number(seconds, "total")?,
        particle_steps,
    })
}

/// The median of `values` (the mean of the middle two for an even count).
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

/// One case's results: the base and current runs' timings, and whether their
/// histories were identical in every round.
#[derive(Debug, Clone, Default)]
pub struct CaseResult {
    /// `umls run` arguments of the case.
    pub case: String,
    /// The base revision's timings, one per round.
    pub base: Vec<Timing>,
    /// The working tree's timings, one per round.
    pub current: Vec<Timing>,
    /// Whether every round's two `history.csv` were the same bytes.
    pub same_history: bool,
}

impl CaseResult {
    /// Median current / median base of the whole step, or of stage `stage`.
    pub fn ratio(&self, stage: Option<usize>) -> f64 {
        let base = median(&self.base.iter().map(|t| t.ns(stage)).collect::<Vec<_>>());
        let current = median(&self.current.iter().map(|t| t.ns(stage)).collect::<Vec<_>>());
        current / base
    }
}

/// "median (min–max)" of ns per particle-step over `timings`.
fn spread(timings: &[Timing], stage: Option<usize>) -> String {
    let values: Vec<f64> = timings.iter().map(|t| t.ns(stage)).collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    format!("{:.1} ({lo:.1}–{hi:.1})", median(&values))
}

/// The report: one table of whole-step times and one of stage ratios.
pub fn render(base: &str, threads: usize, results: &[CaseResult]) -> String {
    let rounds = results.first().map_or(0, |r| r.base.len());
    let mut out = format!(
        "# The working tree against `{base}`\n\n\
         {rounds} alternating rounds, {threads} thread(s); ns per particle-step in the \
         steps, median (range) over the rounds; ratio = working tree / base.\n\n\
         | case | base | working tree | ratio | history.csv |\n|---|---|---|---|---|\n"
    );
    for r in results {
        out += &format!(
            "| `{}` | {} | {} | {:.3} | {} |\n",
            r.case,
            spread(&r.base, None),
            spread(&r.current, None),
            r.ratio(None),
            if r.same_history {
                "identical"
            } else {
                "differs"
            },
        );
    }
    out += "\nStage ratios (working tree / base, medians; – where the base spent no time):\n\n| case |";
    for label in STAGE_LABELS {
        out += &format!(" {label} |");
    }
    out += "\n|---|";
    out += &"---|".repeat(STAGES.len());
    out += "\n";
    for r in results {
        out += &format!("| `{}` |", r.case);
        for s in 0..STAGES.len() {
            let ratio = r.ratio(Some(s));
            if ratio.is_finite() {
                out += &format!(" {ratio:.3} |");
            } else {
                out += " – |";
            }
        }
        out += "\n";
    }
    out
}

/// Builds both programs, runs the cases and writes `target/compare/compare.md`.
pub fn compare(args: &[String]) -> Result<(), String> {
    let args = parse_args(args)?;
    let root = workspace_root();
    let dir = target_dir().join("compare");
    let fail = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    std::fs::create_dir_all(&dir).map_err(|e| fail(&dir, e))?;
    let current = dir.join("umls-current");
    cargo(&["build", "--release", "-p", "umls-cli"])?;
    let built = target_dir().join("release/umls");
    std::fs::copy(&built, &current).map_err(|e| fail(&built, e))?;
    let base = build_revision(&root, &dir, &args.base)?;
    let mut results: Vec<CaseResult> = args
        .cases
        .iter()
        .map(|c| CaseResult {
            case: c.clone(),
            same_history: true,
            ..CaseResult::default()
        })
        .collect();
    for round in 0..args.rounds {
        for (c, result) in results.iter_mut().enumerate() {
            // Flipped every round, so the first run's cold caches and any drift of the
            // machine's speed fall on both programs alike.
            let order = if round % 2 == 0 {
                [(&base, "base"), (&current, "current")]
            } else {
                [(&current, "current"), (&base, "base")]
            };
            let mut histories = Vec::new();
            for (program, which) in order {
                let out = dir.join(format!("runs/case{c}-{which}"));
                let timing = run_case(program, &result.case, args.threads, &out)?;
                eprintln!(
                    "xtask: round {}, `{}`, {which}: {:.1} ns per particle-step",
                    round + 1,
                    result.case,
                    timing.ns(None)
                );
                match which {
                    "base" => result.base.push(timing),
                    _ => result.current.push(timing),
                }
                let history = out.join("history.csv");
                histories.push(std::fs::read(&history).map_err(|e| fail(&history, e))?);
            }
            result.same_history &= histories[0] == histories[1];
        }
    }
    let report = machine::after_title(
        &render(&args.base, args.threads, &results),
        &machine::machine_line(&root),
    );
    let path = dir.join("compare.md");
    std::fs::write(&path, &report).map_err(|e| fail(&path, e))?;
    println!("{report}");
    eprintln!("xtask: wrote {}", path.display());
    if let Some(limit) = args.fail_above {
        let slower: Vec<String> = results
            .iter()
            .filter(|r| r.ratio(None) > limit)
            .map(|r| format!("`{}` ({:.3})", r.case, r.ratio(None)))
            .collect();
        if !slower.is_empty() {
            return Err(format!(
                "slower than {} × the base: {}",
                limit,
                slower.join(", ")
            ));
        }
    }
    Ok(())
}

/// One run of `program` on `case` into `out`, with two frames only (frames are not
/// timed, but writing them would lengthen the comparison).
fn run_case(program: &Path, case: &str, threads: usize, out: &Path) -> Result<Timing, String> {
    let text = run_summary(program, case, threads, out)?;
    parse_summary(&text).map_err(|e| format!("{}: {e}", out.join("summary.json").display()))
}

/// Runs `program run CASE` (the scene and its arguments, split at white space) on
/// `threads` threads into `out`, two frames only, and returns its `summary.json` text.
pub fn run_summary(
    program: &Path,
    case: &str,
    threads: usize,
    out: &Path,
) -> Result<String, String> {
    let mut words = case.split_whitespace();
    let scene = words.next().ok_or("an empty case")?;
    let status = Command::new(program)
        .arg("run")
        .arg(scene)
        .args(words)
        .args(["--set", "output.frames=2", "--quiet", "--threads"])
        .arg(threads.to_string())
        .arg("--out")
        .arg(out)
        .stdout(std::process::Stdio::null())
        .status()
        .map_err(|e| format!("cannot run {}: {e}", program.display()))?;
    if !status.success() {
        return Err(format!(
            "`{} run {case}` failed ({status})",
            program.display()
        ));
    }
    let summary = out.join("summary.json");
    std::fs::read_to_string(&summary).map_err(|e| format!("{}: {e}", summary.display()))
}

/// Builds `umls-cli` at `revision` in a detached worktree under `dir` (its target
/// directory kept for the next comparison) and returns the program's copy.
fn build_revision(root: &Path, dir: &Path, revision: &str) -> Result<PathBuf, String> {
    let git = |args: &[&str]| -> Result<String, String> {
        let output = Command::new("git")
            .args(args)
            .current_dir(root)
            .output()
            .map_err(|e| format!("cannot run git: {e}"))?;
        if output.status.success() {
            Ok(String::from_utf8_lossy(&output.stdout).trim().to_string())
        } else {
            Err(format!(
                "`git {}` failed: {}",
                args.join(" "),
                String::from_utf8_lossy(&output.stderr).trim()
            ))
        }
    };
    let commit = git(&["rev-parse", "--verify", &format!("{revision}^{{commit}}")])?;
    let tree = dir.join("worktree");
    let tree_arg = tree.to_string_lossy().to_string();
    if tree.exists() {
        git(&["worktree", "remove", "--force", &tree_arg])?;
    }
    git(&["worktree", "prune"])?;
    git(&["worktree", "add", "--detach", &tree_arg, &commit])?;
    eprintln!(
        "xtask: building {revision} ({commit}) in {}",
        tree.display()
    );
    let target = dir.join("base-target").to_string_lossy().to_string();
    let built = cargo_in(
        &tree,
        &[
            "build",
            "--release",
            "-p",
            "umls-cli",
            "--target-dir",
            &target,
        ],
    );
    // The worktree goes whether or not the build succeeded.
    let removed = git(&["worktree", "remove", "--force", &tree_arg]);
    built.map_err(|e| format!("building {revision}: {e}"))?;
    removed?;
    let program = dir.join("umls-base");
    let built = dir.join("base-target/release/umls");
    std::fs::copy(&built, &program).map_err(|e| format!("{}: {e}", built.display()))?;
    Ok(program)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strings;

    #[test]
    fn arguments_are_read_and_checked() {
        let parsed = parse_args(&strings(&[
            "HEAD~2",
            "--rounds",
            "5",
            "--fail-above",
            "1.05",
        ]))
        .expect("valid");
        assert_eq!(parsed.base, "HEAD~2");
        assert_eq!(parsed.rounds, 5);
        assert_eq!(parsed.threads, 1);
        assert_eq!(parsed.fail_above, Some(1.05));
        assert_eq!(parsed.cases.len(), DEFAULT_CASES.len());
        let custom =
            parse_args(&strings(&["main", "--case", "vortex --kernel umls"])).expect("valid");
        assert_eq!(custom.cases, vec!["vortex --kernel umls".to_string()]);
        for (bad, needle) in [
            (vec!["--rounds", "2"], "name the revision"),
            (vec!["a", "b"], "a second revision `b`"),
            (
                vec!["a", "--rounds", "0"],
                "--rounds takes a positive integer",
            ),
            (vec!["a", "--threads"], "--threads needs a value"),
            (
                vec!["a", "--fail-above", "-1"],
                "--fail-above takes a positive ratio",
            ),
            (vec!["a", "--fast"], "unknown argument `--fast`"),
        ] {
            let error = parse_args(&strings(&bad)).expect_err("invalid");
            assert!(error.contains(needle), "{error}");
        }
    }

    fn summary(status: &str, total: f64, particles: u32, steps: u32) -> String {
        format!(
            r#"{{"status": "{status}", "error": null, "particles": {particles}, "steps": {steps},
               "stage_seconds": {{"stencils": 0.5, "particles_to_grid": 1.0, "grid_update": 0.25,
               "grid_to_particles": 0.75, "constitutive": 0.125, "total": {total},
               "fractions": {{"stencils": 0.2}}}}}}"#
        )
    }

    #[test]
    fn summaries_give_nanoseconds_per_particle_step() {
        let timing = parse_summary(&summary("completed", 2.625, 1000, 500)).expect("valid");
        // 2.625 s over 5·10⁵ particle-steps.
        assert_eq!(timing.ns(None), 5250.0);
        assert_eq!(timing.ns(Some(1)), 2000.0);
        // `checks` is missing: an older program's summary, counted as zero.
        assert_eq!(timing.ns(Some(5)), 0.0);
        let failed = parse_summary(&summary("failed", 1.0, 10, 10)).expect_err("failed run");
        assert!(failed.contains("did not complete"), "{failed}");
        let empty = parse_summary(&summary("completed", 1.0, 0, 10)).expect_err("no particles");
        assert!(empty.contains("no particle-steps"), "{empty}");
    }

    #[test]
    fn ratios_are_of_medians_and_the_report_names_differing_histories() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        let timing = |total: f64| Timing {
            stages: [total, 0.0, 0.0, 0.0, 0.0, 0.0],
            total,
            particle_steps: 1e9,
        };
        let result = CaseResult {
            case: "fluid-box-3d".into(),
            base: vec![timing(1.0), timing(1.2), timing(10.0)],
            current: vec![timing(0.9), timing(0.6), timing(0.8)],
            same_history: false,
        };
        // Medians 1.2 and 0.8: the outlier of 10 does not move the ratio.
        assert!((result.ratio(None) - 0.8 / 1.2).abs() < 1e-12);
        let report = render("HEAD", 1, &[result]);
        assert!(
            report
                .contains("| `fluid-box-3d` | 1.2 (1.0–10.0) | 0.8 (0.6–0.9) | 0.667 | differs |"),
            "{report}"
        );
        // A stage the base never ran has no ratio.
        assert!(report.contains("| 0.667 | – |"), "{report}");
    }
}
