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
        /// Output directory (default: out/<scene name>-<kernel>); the files of an earlier run
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
        Command::MeshInfo { file } => umls_cli::mesh_info::mesh_info(&file).map(|r| print!("{r}")),
        Command::Run {
            scene,
            kernel,
            out,
            end_time,
            threads,
            quiet,
        } => Scene::load(&scene).and_then(|scene| {
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
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
