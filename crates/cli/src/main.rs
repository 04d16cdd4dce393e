//! The `umls` binary: see `umls --help`.

use std::path::PathBuf;
use std::process::ExitCode;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use clap::{Parser, Subcommand};
use umls_runner::builtin::BUILTIN;
use umls_runner::schema::KernelKind;
use umls_runner::{RunOptions, RunReport, Scene, run};

mod mesh_info;
mod progress;

/// UMLS-MPM: material point methods on unstructured simplicial meshes.
#[derive(Debug, Parser)]
#[command(name = "umls", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a built-in scene or a TOML scene file and write ParaView and CSV output.
    Run(RunArgs),
    /// Run a study matrix (scenes × kernels × resolutions, stability sweeps, throughput)
    /// and write a report with charts: report.md, charts/*.svg, results.csv/json.
    Report {
        /// `quick` (coarse levels, about 4 minutes on 2 cores), `full` (about 1¼ hours), or
        /// the path of a matrix TOML file.
        #[arg(long, default_value = "quick")]
        matrix: String,
        /// Output directory.
        #[arg(long, default_value = "out/report")]
        out: PathBuf,
        /// Directory of criterion results (`target/criterion`) to include.
        #[arg(long)]
        criterion: Option<PathBuf>,
        /// The criterion result set to report (`new`, or a name saved with
        /// `--save-baseline`).
        #[arg(long, default_value = "new")]
        criterion_current: String,
        /// A saved criterion baseline to compare with.
        #[arg(long)]
        baseline: Option<String>,
        /// Keep every run's ParaView frames (by default only summaries and histories).
        #[arg(long)]
        keep_frames: bool,
    },
    /// List the built-in scenes.
    Scenes,
    /// Describe a Gmsh mesh: counts, bounding box, quality, physical groups.
    MeshInfo {
        /// The .msh file (format 4.1 ASCII or binary, or 2.2 ASCII).
        file: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Scenes => {
            let width = BUILTIN.iter().map(|b| b.name.len()).max().unwrap_or(0);
            for b in BUILTIN {
                println!("{:<width$}  {}", b.name, b.summary);
            }
            Ok(())
        }
        Command::Report {
            matrix,
            out,
            criterion,
            criterion_current,
            baseline,
            keep_frames,
        } => report(
            &matrix,
            out,
            criterion,
            criterion_current,
            baseline,
            keep_frames,
        ),
        Command::MeshInfo { file } => mesh_info::mesh_info(&file)
            .map(|r| print!("{r}"))
            .map_err(Failure::from),
        Command::Run(args) => run_scene(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Report(e)) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
        Err(Failure::Cli(e)) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The kernel names `--kernel` accepts.
fn kernel_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(KernelKind::ALL.map(KernelKind::name))
}

/// `umls run`'s arguments.
#[derive(Debug, clap::Args)]
struct RunArgs {
    /// A built-in scene name (see `umls scenes`) or the path of a TOML scene file.
    scene: String,
    /// Shape-function kernel (default: the scene's).
    #[arg(long, value_parser = kernel_names())]
    kernel: Option<String>,
    /// Output directory (default: out/SCENE-KERNEL, with a short tag of the edits
    /// when `--set`, `--refine` or `--particle-refine` change the scene); the files
    /// of an earlier run there are replaced.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Simulated time (default: the scene's).
    #[arg(long)]
    end_time: Option<f64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Do not draw the progress bar.
    #[arg(long)]
    quiet: bool,
    /// Replace a value of the scene before it is read, e.g. `--set time.cfl=0.5`,
    /// `--set mesh.lattice.jitter=0.3`, `--set bodies.0.seeding.lattice=0.025`
    /// (repeatable; the value is TOML, or else a string).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = umls_runner::edit::parse_assignment)]
    set: Vec<(String, String)>,
    /// Divide every length of the discretisation by this factor: lattice cells,
    /// particle spacing, B-spline grid spacing and a fixed time step.
    #[arg(long, value_name = "FACTOR")]
    refine: Option<f64>,
    /// Divide the particle spacing alone by this factor (particles per cell × FACTOR^D).
    #[arg(long, value_name = "FACTOR")]
    particle_refine: Option<f64>,
}

/// `umls run`: loads and edits the scene, runs it with output, prints what it measured.
fn run_scene(args: RunArgs) -> Result<(), Failure> {
    let mut scene = Scene::load_with(&args.scene, &args.set)?;
    if let Some(factor) = args.refine {
        umls_runner::edit::refine(&mut scene, factor)?;
    }
    if let Some(factor) = args.particle_refine {
        umls_runner::edit::refine_particles(&mut scene, factor)?;
    }
    // clap accepts only the presets' names, so the lookup finds one.
    let kernel = args.kernel.as_deref().and_then(KernelKind::from_name);
    let kernel_name = kernel.unwrap_or(scene.spec.kernel.kind).name();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_out(&scene.spec.scene.name, kernel_name, &args));
    let options = RunOptions {
        kernel,
        out: Some(out),
        end_time: args.end_time,
        threads: args.threads,
        progress: Some(Arc::new(progress::Bar::new(!args.quiet))),
        interrupt: interrupt_on_signals(),
    };
    let report = run(&scene, &options)?;
    print_report(&report);
    Ok(())
}

/// One folder per scene, kernel and set of edits, so that comparisons and edited runs
/// do not overwrite each other: `out/SCENE-KERNEL`, and `-EDITS` with a short tag of the
/// edits (`--set`, `--refine`, `--particle-refine`, in the order given) when there are
/// any.
fn default_out(scene: &str, kernel: &str, args: &RunArgs) -> PathBuf {
    let mut edits: Vec<String> = args.set.iter().map(|(k, v)| format!("{k}={v}")).collect();
    edits.extend(args.refine.map(|f| format!("refine={f}")));
    edits.extend(args.particle_refine.map(|f| format!("particle-refine={f}")));
    let name = if edits.is_empty() {
        format!("{scene}-{kernel}")
    } else {
        format!(
            "{scene}-{kernel}-{:08x}",
            fnv1a(edits.join("\n").as_bytes()) as u32
        )
    };
    PathBuf::from("out").join(name)
}

/// The 64-bit FNV-1a hash: a stable tag for a folder name, the same on every platform
/// and release (the standard library's hasher promises neither).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// SIGINT (Ctrl-C) and SIGTERM (a scheduler's or `kill`'s) stop the run after the
/// current step, and its output and summary are still written. A second signal changes
/// nothing, so a summary is written however impatient the user is; a third ends the
/// process at once, for a step that does not finish. `None` where no handler could be
/// installed.
fn interrupt_on_signals() -> Option<Arc<AtomicBool>> {
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = interrupt.clone();
    let signals = AtomicUsize::new(0);
    let handler = ctrlc::set_handler(move || {
        flag.store(true, Ordering::Relaxed);
        if signals.fetch_add(1, Ordering::Relaxed) >= 2 {
            std::process::exit(130);
        }
    });
    handler.is_ok().then_some(interrupt)
}

/// What a finished run prints: the warnings, the throughput, the metrics, the folder.
fn print_report(report: &RunReport) {
    let s = &report.summary;
    println!(
        "{}: {} steps of {} particles with {} in {:.2} s ({:.3e} particle-steps/s stepping, {:.3e} with output)",
        s.scene,
        s.steps,
        s.particles,
        s.kernel,
        s.wall_time_s,
        s.particle_steps_per_second,
        s.particle_steps_per_wall_second,
    );
    for (k, v) in &s.metrics {
        println!("  {k}: {v}");
    }
    if let Some(out) = &report.out {
        let background = if s.outputs.as_ref().is_some_and(|o| o.mesh.is_none()) {
            "grid.vtu"
        } else {
            "mesh.vtu"
        };
        println!(
            "wrote {} (open particles.pvd and {background} in ParaView)",
            out.display()
        );
    }
}

/// Why a command failed: a run or scene, or the report around the runs.
enum Failure {
    Cli(umls_runner::RunError),
    Report(umls_report::ReportError),
}

impl From<umls_runner::RunError> for Failure {
    fn from(e: umls_runner::RunError) -> Self {
        Failure::Cli(e)
    }
}

/// `umls report`: every case runs in a child process of this executable.
fn report(
    matrix_name: &str,
    out: PathBuf,
    criterion: Option<PathBuf>,
    current: String,
    baseline: Option<String>,
    keep_frames: bool,
) -> Result<(), Failure> {
    use umls_report::report::{CriterionSource, Options, generate};
    let matrix = umls_report::matrix::Matrix::load(matrix_name).map_err(Failure::Report)?;
    let exe = std::env::current_exe().map_err(|source| {
        Failure::Report(umls_report::ReportError::Spawn {
            exe: PathBuf::from("umls"),
            source,
        })
    })?;
    let options = Options {
        exe,
        out,
        work: None,
        keep_frames,
        matrix_name: matrix_name.to_string(),
        workspace: PathBuf::from("."),
        criterion: criterion.map(|root| CriterionSource {
            root,
            current,
            baseline,
        }),
    };
    let report = generate(&matrix, &options, &mut |p| {
        let r = p.record;
        eprintln!(
            "[{}/{}] {} {} refine {}{}: {} in {:.1} s{}",
            p.done,
            p.total,
            r.study,
            r.series(),
            r.refine,
            if r.x.is_empty() {
                String::new()
            } else {
                format!(" at {} × {}", r.x, r.y)
            },
            r.outcome,
            r.process_time_s,
            r.metric
                .map_or(String::new(), |m| format!(", {} = {m:.4e}", r.metric_name)),
        );
    })
    .map_err(Failure::Report)?;
    println!(
        "wrote {} ({} runs, {} charts)",
        report.path.display(),
        report.records.len(),
        report.charts.len()
    );
    Ok(())
}
