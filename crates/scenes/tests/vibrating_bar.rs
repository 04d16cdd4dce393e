//! The vibrating bar: the engine converges at second order with linear FE, and a pure-FLIP
//! run with two particles per cell is stopped as unstable.

use std::sync::Arc;

use umls_engine::{Apic, EngineError, Flip, Simulation, StepSettings};
use umls_kernels::{HostCache, LinearFeKernel};
use umls_scenes::vibrating_bar::VibratingBar;

/// Small amplitude (v₀ = 10⁻³) keeps geometric nonlinearity below the discretisation
/// error; one Δt for all levels (0.1 Δx/c of a 256-cell bar) keeps the first-order time
/// error of symplectic Euler below the spatial error.
#[test]
fn linear_fe_apic_converges_at_second_order() {
    let results: Vec<_> = [8usize, 16, 32]
        .iter()
        .map(|&cells| {
            let bar = VibratingBar {
                cells,
                amplitude: 1e-3,
                courant: 0.1 * cells as f64 / 256.0,
                ..VibratingBar::default()
            };
            bar.run(LinearFeKernel::new(Arc::new(bar.mesh().unwrap())), Apic)
                .unwrap()
        })
        .collect();
    let orders: Vec<f64> = results
        .windows(2)
        .map(|w| (w[0].velocity_rmse / w[1].velocity_rmse).log2())
        .collect();
    eprintln!("linear FE + APIC: {results:?}, orders {orders:?}");
    assert!(orders.iter().all(|&p| p > 1.75), "orders {orders:?}");
    assert!(
        results[2].energy_error < 2e-3,
        "energy error {}",
        results[2].energy_error
    );
}

/// Pure FLIP with two particles per cell on linear FE is the textbook unstable case
/// (grid-invisible particle modes ring and grow): the run must stop with a typed error.
#[test]
fn pure_flip_instability_is_detected() {
    let bar = VibratingBar {
        cells: 64,
        particles_per_cell: 2,
        ..VibratingBar::default()
    };
    let (_, dt) = bar.steps_and_dt();
    let kernel = LinearFeKernel::new(Arc::new(bar.mesh().unwrap()));
    let mut sim = Simulation::new(
        kernel,
        bar.material().unwrap(),
        Flip { alpha: 1.0 },
        bar.particles::<HostCache>(),
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

#[test]
fn analytic_reference_and_time_step() {
    let bar = VibratingBar::default();
    assert!((bar.omega() - std::f64::consts::PI / 50.0 * 10.0).abs() < 1e-15);
    let (steps, dt) = bar.steps_and_dt();
    assert!((steps as f64 * dt - 2.0 * std::f64::consts::PI / bar.omega()).abs() < 1e-9);
    assert!(dt <= 0.1 * bar.dx() / 10.0);
    assert_eq!(bar.particles::<HostCache>().len(), 13);
    assert!((bar.velocity(25.0, 0.0) - 0.1).abs() < 1e-15);
}
