//! The `umls` binary: see `umls --help`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use umls_cli::builtin::BUILTIN;
use umls_cli::run::{RunOptions, run};
use umls_cli::scene::Scene;
use umls_cli::schema::KernelKind;

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
    Run {
        /// A built-in scene name (see `umls scenes`) or the path of a TOML scene file.
        scene: String,
        /// Shape-function kernel (default: the scene's).
        #[arg(long, value_enum)]
        kernel: Option<KernelKind>,
        /// Output directory (default: out/SCENE-KERNEL); the files of an earlier run
        /// there are replaced.
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
        #[arg(long = "set", value_name = "KEY=VALUE", value_parser = umls_cli::edit::parse_assignment)]
        set: Vec<(String, String)>,
        /// Divide every length of the discretisation by this factor: lattice cells,
        /// particle spacing, B-spline grid spacing and a fixed time step.
        #[arg(long, value_name = "FACTOR")]
        refine: Option<f64>,
        /// Divide the particle spacing alone by this factor (particles per cell × FACTOR^D).
        #[arg(long, value_name = "FACTOR")]
        particle_refine: Option<f64>,
    },
    /// Run a study matrix (scenes × kernels × resolutions, stability sweeps, throughput)
    /// and write a report with charts: report.md, charts/*.svg, results.csv/json.
    Report {
        /// `quick` (coarse levels, minutes), `full`, or the path of a matrix TOML file.
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
        Command::MeshInfo { file } => umls_cli::mesh_info::mesh_info(&file)
            .map(|r| print!("{r}"))
            .map_err(Failure::from),
        Command::Run {
            scene,
            kernel,
            out,
            end_time,
            threads,
            quiet,
            set,
            refine,
            particle_refine,
        } => Scene::load_with(&scene, &set)
            .map_err(Failure::from)
            .and_then(|mut scene| {
                if let Some(factor) = refine {
                    umls_cli::edit::refine(&mut scene, factor)?;
                }
                if let Some(factor) = particle_refine {
                    umls_cli::edit::refine_particles(&mut scene, factor)?;
                }
                // One folder per scene and kernel, so comparisons do not overwrite each other.
                let kernel_name = kernel.unwrap_or(scene.spec.kernel.kind).name();
                let out = out.unwrap_or_else(|| {
                    PathBuf::from("out").join(format!("{}-{kernel_name}", scene.spec.scene.name))
                });
                // Ctrl-C stops the run after the current step and still writes its output
                // and summary; a second Ctrl-C (or a failed handler) ends the process as usual.
                let interrupt = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
                let flag = interrupt.clone();
                let handler = ctrlc::set_handler(move || {
                    if flag.swap(true, std::sync::atomic::Ordering::Relaxed) {
                        std::process::exit(130);
                    }
                });
                let options = RunOptions {
                    kernel,
                    out,
                    end_time,
                    threads,
                    progress: !quiet,
                    interrupt: handler.is_ok().then_some(interrupt),
                };
                let report = run(&scene, &options)?;
                let s = &report.summary;
                println!(
                    "{}: {} steps of {} particles with {} in {:.2} s ({:.3e} particle-steps/s)",
                    s["scene"].as_str().unwrap_or(""),
                    s["steps"],
                    s["particles"],
                    s["kernel"].as_str().unwrap_or(""),
                    s["wall_time_s"].as_f64().unwrap_or(0.0),
                    s["particle_steps_per_second"].as_f64().unwrap_or(0.0),
                );
                if let Some(metrics) = s["metrics"].as_object() {
                    for (k, v) in metrics {
                        println!("  {k}: {v}");
                    }
                }
                let background = if report.summary["outputs"]["mesh"].is_null() {
                    "grid.vtu"
                } else {
                    "mesh.vtu"
                };
                println!(
                    "wrote {} (open particles.pvd and {background} in ParaView)",
                    report.out.display()
                );
                Ok(())
            }),
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

/// Why a command failed: a run or scene, or the report around the runs.
enum Failure {
    Cli(umls_cli::CliError),
    Report(umls_report::ReportError),
}

impl From<umls_cli::CliError> for Failure {
    fn from(e: umls_cli::CliError) -> Self {
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
