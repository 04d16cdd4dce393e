//! The 1D vibrating bar (theory digest §3): L = 25, E = 100, ρ = 1, fixed at x = 0, free
//! at x = L, v(x, 0) = v₀ sin(βx) with β = π/(2L). Analytic: v(X, t) = v₀ cos(ωt) sin(βX),
//! ω = β √(E/ρ). The mesh extends four cells past L so the free end stays inside.

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::SVector;
use umls_constitutive::{ElasticParameters, LinearElastic};
use umls_engine::{Apic, EngineError, Flip, Particles, Simulation, StepSettings, TransferScheme};
use umls_kernels::{HostCache, LinearFeKernel};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::Lattice;
use umls_transfer::Kernel;

const L: f64 = 25.0;
const E: f64 = 100.0;

fn beta() -> f64 {
    PI / (2.0 * L)
}

fn omega() -> f64 {
    beta() * E.sqrt()
}

fn material() -> LinearElastic {
    LinearElastic {
        parameters: ElasticParameters::from_young_poisson(E, 0.0).unwrap(),
    }
}

fn bar_mesh(cells: usize) -> Arc<SimplexMesh<1>> {
    let dx = L / cells as f64;
    Arc::new(
        Lattice::new([0.0], [L + 4.0 * dx], [cells + 4])
            .segments()
            .unwrap(),
    )
}

/// `ppc` particles per cell at sub-cell midpoints, with v(x, 0) = v₀ sin(βx).
fn particles(cells: usize, ppc: usize, v0: f64) -> Particles<1, (), HostCache> {
    let dx = L / cells as f64;
    let x: Vec<SVector<f64, 1>> = (0..cells * ppc)
        .map(|k| SVector::from([(k as f64 + 0.5) * dx / ppc as f64]))
        .collect();
    let mut p = Particles::at_rest(x, vec![dx / ppc as f64; cells * ppc], 1.0, ());
    for (v, x) in p.velocity.iter_mut().zip(&p.position) {
        *v = SVector::from([v0 * (beta() * x[0]).sin()]);
    }
    p
}

/// Relative velocity RMSE over one period and the largest relative energy deviation.
fn run<K: Kernel<1, Cache = HostCache>, T: TransferScheme>(
    kernel: K,
    transfer: T,
    cells: usize,
    v0: f64,
    dt_target: f64,
) -> (f64, f64) {
    let period = 2.0 * PI / omega();
    let steps = (period / dt_target).ceil() as usize;
    let parts = particles(cells, 1, v0);
    let reference: Vec<f64> = parts.position.iter().map(|x| x[0]).collect();
    let mut sim = Simulation::new(
        kernel,
        material(),
        transfer,
        parts,
        StepSettings::new(period / steps as f64),
    )
    .unwrap();
    sim.boundary.fixed = vec![0];
    let e0 = sim.diagnostics().unwrap().total_energy();
    let (mut sq, mut count, mut energy_error) = (0.0, 0.0, 0.0f64);
    for _ in 0..steps {
        sim.step().unwrap();
        energy_error =
            energy_error.max((sim.diagnostics().unwrap().total_energy() - e0).abs() / e0);
        let t = sim.time();
        for (v, x) in sim.particles.velocity.iter().zip(&reference) {
            sq += (v[0] - v0 * (omega() * t).cos() * (beta() * x).sin()).powi(2);
            count += 1.0;
        }
    }
    ((sq / count).sqrt() / v0, energy_error)
}

/// The engine's machinery converges at second order with linear FE shape functions. Small
/// amplitude (v₀ = 10⁻³) keeps geometric nonlinearity below the discretisation error, and
/// one Δt for all levels (0.1 Δx/c of a 256-cell bar) keeps the first-order time error of
/// symplectic Euler below the spatial error.
#[test]
fn linear_fe_apic_converges_at_second_order() {
    let dt = 0.1 * (L / 256.0) / E.sqrt();
    let results: Vec<(f64, f64)> = [8, 16, 32]
        .iter()
        .map(|&cells| run(LinearFeKernel::new(bar_mesh(cells)), Apic, cells, 1e-3, dt))
        .collect();
    let orders: Vec<f64> = results
        .windows(2)
        .map(|w| (w[0].0 / w[1].0).log2())
        .collect();
    eprintln!("linear FE + APIC: (relative RMSE, energy error) {results:?}, orders {orders:?}");
    assert!(orders.iter().all(|&p| p > 1.75), "orders {orders:?}");
    assert!(results[2].1 < 2e-3, "energy error {}", results[2].1);
}

/// Pure FLIP with two particles per cell on linear FE is the textbook unstable case
/// (grid-invisible particle modes ring and grow): the run must stop with a typed error.
#[test]
fn pure_flip_instability_is_detected() {
    let cells = 64;
    let dt = 0.1 * (L / cells as f64) / E.sqrt();
    let parts = particles(cells, 2, 0.1);
    let mut sim = Simulation::new(
        LinearFeKernel::new(bar_mesh(cells)),
        material(),
        Flip { alpha: 1.0 },
        parts,
        StepSettings::new(dt),
    )
    .unwrap();
    sim.boundary.fixed = vec![0];
    let error = (0..5000)
        .find_map(|_| sim.step().err())
        .expect("pure FLIP must go unstable");
    assert!(
        matches!(error, EngineError::EnergyBlowUp { factor, .. } if factor == 10.0),
        "{error}"
    );
}
