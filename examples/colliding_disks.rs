//! Kernel comparison on the colliding-disks benchmark (Sulsky et al. 1994) on an unstructured,
//! jittered triangle mesh, run with the UMLS kernel and with linear finite elements.
//!
//! `cargo run --release --example colliding_disks [OUT_DIR]` (default `out/kernel-comparison`)
//! prints the energy history and the cell-crossing comparison, and writes
//! - `energies.svg`: kinetic, strain and total energy against time for both kernels;
//! - `stress.svg`: the mean-stress history of one particle whose path crosses many
//!   facets: a staircase with linear FE, smooth with UMLS;
//! - `history_umls.csv`, `history_linear_fe.csv`: step, time, energies, momentum.
//!
//! The scene is the built-in `colliding-disks` (scenes/colliding-disks.toml), set up by
//! the runner ([`umls::runner::prepare`]) and stepped here: unit square meshed with
//! 20 × 20 jittered cells (800 triangles), disks of radius 0.2 at (0.2, 0.2) and
//! (0.8, 0.8) moving at ±(0.1, 0.1), linear elastic E = 1000, ν = 0.3, ρ = 1000, 4
//! particles per 0.05² cell, FLIP 0.99, Δt = 10⁻³, T = 3.

use nalgebra::Vector2;
use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use umls::engine::Diagnostics;
use umls::io::chart::{Axis, LineChart, Series};
use umls::runner::schema::KernelKind;
use umls::runner::{RunOptions, Scene, prepare};

/// Energy history every 10 steps and the mean-stress history of one particle.
struct Run {
    history: Vec<Diagnostics<2>>,
    tracer: Vec<(f64, f64)>,
    wall: f64,
    particles: usize,
    steps: usize,
}

fn run(scene: &Scene, kernel: KernelKind, tracer: usize) -> Result<Run, Box<dyn Error>> {
    let options = RunOptions {
        kernel: Some(kernel),
        ..RunOptions::default()
    };
    let mut prepared = prepare::<2>(scene, &options)?;
    let end_time = prepared.end_time();
    let sim = prepared.simulation();
    let start = std::time::Instant::now();
    let mut history = vec![sim.diagnostics()?];
    let mut trace = Vec::new();
    while !sim.reached(end_time) {
        sim.step_until(end_time)?;
        let sigma = sim.cauchy_stresses()?[tracer];
        trace.push((sim.time(), 0.5 * sigma.trace()));
        if sim.step_count() % 10 == 0 {
            history.push(sim.diagnostics()?);
        }
    }
    Ok(Run {
        history,
        tracer: trace,
        wall: start.elapsed().as_secs_f64(),
        particles: sim.positions().len(),
        steps: sim.step_count(),
    })
}

fn csv(path: &Path, history: &[Diagnostics<2>]) -> Result<(), Box<dyn Error>> {
    let mut out = String::from("step,time,kinetic,strain,total,momentum_x,momentum_y\n");
    for d in history {
        writeln!(
            out,
            "{},{},{},{},{},{},{}",
            d.step,
            d.time,
            d.kinetic,
            d.elastic,
            d.total_energy(),
            d.momentum.x,
            d.momentum.y
        )?;
    }
    std::fs::write(path, out)?;
    Ok(())
}

/// Mean |second difference| of a history relative to its mean magnitude.
fn roughness(trace: &[(f64, f64)]) -> f64 {
    let second: f64 = trace
        .windows(3)
        .map(|w| (w[2].1 - 2.0 * w[1].1 + w[0].1).abs())
        .sum();
    let magnitude: f64 = trace.iter().map(|t| t.1.abs()).sum();
    second / magnitude
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "out/kernel-comparison".into()),
    );
    std::fs::create_dir_all(&out)?;
    let scene = Scene::load("colliding-disks")?;
    // The particle nearest the contact point of the first disk: it crosses facets while
    // carrying the largest stresses.
    let mut probe = prepare::<2>(&scene, &RunOptions::default())?;
    let positions = probe.simulation().positions().to_vec();
    let tracer = (0..positions.len() / 2)
        .min_by(|&a, &b| {
            (positions[a] - Vector2::new(0.33, 0.33))
                .norm()
                .total_cmp(&(positions[b] - Vector2::new(0.33, 0.33)).norm())
        })
        .ok_or("no particles")?;
    let (dt, end_time) = (probe.simulation().settings().dt, probe.end_time());
    println!(
        "colliding disks: {} particles, Δt = {dt}, T = {end_time}",
        positions.len()
    );
    let umls = run(&scene, KernelKind::Umls, tracer)?;
    let fe = run(&scene, KernelKind::LinearFe, tracer)?;
    let k0 = umls.history[0].kinetic;
    println!("\n  time   UMLS kinetic  strain   total  | linear FE kinetic  strain   total");
    for (a, b) in umls.history.iter().zip(&fe.history).step_by(25) {
        println!(
            "  {:4.2}   {:9.4}  {:7.4}  {:7.4}  | {:13.4}  {:7.4}  {:7.4}",
            a.time,
            a.kinetic,
            a.elastic,
            a.total_energy(),
            b.kinetic,
            b.elastic,
            b.total_energy()
        );
    }
    let last = |h: &[Diagnostics<2>]| *h.last().expect("non-empty");
    println!(
        "\nkinetic energy after the rebound: UMLS {:.1} %, linear FE {:.1} % of the initial",
        100.0 * last(&umls.history).kinetic / k0,
        100.0 * last(&fe.history).kinetic / k0
    );
    let max_p = |h: &[Diagnostics<2>]| h.iter().map(|d| d.momentum.norm()).fold(0.0, f64::max);
    println!(
        "largest |total momentum| (exactly 0 initially): UMLS {:.1e}, linear FE {:.1e}",
        max_p(&umls.history),
        max_p(&fe.history)
    );
    let (ru, rf) = (roughness(&umls.tracer), roughness(&fe.tracer));
    println!(
        "stress roughness of the traced particle: UMLS {ru:.2e}, linear FE {rf:.2e} ({:.0}× rougher)",
        rf / ru
    );
    println!(
        "wall time: UMLS {:.2} s ({:.2e} particle-steps/s), linear FE {:.2} s",
        umls.wall,
        (umls.steps * umls.particles) as f64 / umls.wall,
        fe.wall
    );

    csv(&out.join("history_umls.csv"), &umls.history)?;
    csv(&out.join("history_linear_fe.csv"), &fe.history)?;
    plot_energies(&out.join("energies.svg"), &umls.history, &fe.history)?;
    plot_stress(&out.join("stress.svg"), &umls.tracer, &fe.tracer)?;
    println!(
        "\nwrote {0}/energies.svg, {0}/stress.svg and the CSV histories",
        out.display()
    );
    Ok(())
}

fn plot_energies(
    path: &Path,
    umls: &[Diagnostics<2>],
    fe: &[Diagnostics<2>],
) -> Result<(), Box<dyn Error>> {
    type Pick = fn(&Diagnostics<2>) -> f64;
    let curves: [(&str, Pick); 3] = [
        ("kinetic", |d| d.kinetic),
        ("strain", |d| d.elastic),
        ("total", |d| d.total_energy()),
    ];
    let mut series = Vec::new();
    for (kernel, history) in [("UMLS", umls), ("linear FE", fe)] {
        for (label, pick) in curves {
            series.push(Series::new(
                format!("{label}, {kernel}"),
                history.iter().map(|d| (d.time, pick(d))).collect(),
            ));
        }
    }
    LineChart {
        title: "Colliding disks: energies".into(),
        x: Axis::linear("time t [s]"),
        y: Axis::linear("energy per unit thickness [J/m]"),
        series,
    }
    .write_svg(path)?;
    Ok(())
}

fn plot_stress(path: &Path, umls: &[(f64, f64)], fe: &[(f64, f64)]) -> Result<(), Box<dyn Error>> {
    LineChart {
        title: "Mean stress of one particle crossing facets: cell-crossing noise".into(),
        x: Axis::linear("time t [s]"),
        y: Axis::linear("mean Cauchy stress tr σ / 2 [Pa]"),
        series: vec![
            Series::new("linear FE", fe.to_vec()),
            Series::new("UMLS", umls.to_vec()),
        ],
    }
    .write_svg(path)?;
    Ok(())
}
