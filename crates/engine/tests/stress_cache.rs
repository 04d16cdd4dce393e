//! The stress a step's deformation update computes is the next step's P2G stress: the
//! material is asked once per particle per step (`return_map_and_stress`, one SVD for
//! plastic models), and asked again from scratch only after the particles or the material
//! were edited between steps, with the same numbers as a fresh simulation.

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Matrix2, Vector2};
use umls_constitutive::{Constitutive, ConstitutiveError, ElasticParameters, NeoHookean};
use umls_engine::{Apic, Simulation, StepSettings};
use umls_kernels::BSplineKernel;

#[path = "common/moving_square.rs"]
mod moving_square;

/// Neo-Hookean, counting how often each stress entry point is called.
#[derive(Debug)]
struct Counting {
    inner: NeoHookean,
    stress: AtomicUsize,
    fused: AtomicUsize,
}

impl Counting {
    fn new(young: f64) -> Self {
        Self {
            inner: NeoHookean {
                parameters: ElasticParameters::from_young_poisson(young, 0.3).unwrap(),
            },
            stress: AtomicUsize::new(0),
            fused: AtomicUsize::new(0),
        }
    }
    fn counts(&self) -> (usize, usize) {
        (
            self.stress.load(Ordering::Relaxed),
            self.fused.load(Ordering::Relaxed),
        )
    }
}

impl Constitutive<2> for Counting {
    type State = ();
    fn name(&self) -> &'static str {
        "counting neo-Hookean"
    }
    fn initial_state(&self) {}
    fn kirchhoff_stress(
        &self,
        f: &Matrix2<f64>,
        s: &(),
    ) -> Result<Matrix2<f64>, ConstitutiveError> {
        self.stress.fetch_add(1, Ordering::Relaxed);
        self.inner.kirchhoff_stress(f, s)
    }
    fn return_map_and_stress(
        &self,
        f: &Matrix2<f64>,
        s: &mut (),
    ) -> Result<Matrix2<f64>, ConstitutiveError> {
        self.fused.fetch_add(1, Ordering::Relaxed);
        self.inner.kirchhoff_stress(f, s)
    }
    fn energy_density(&self, f: &Matrix2<f64>, s: &()) -> Result<f64, ConstitutiveError> {
        Constitutive::<2>::energy_density(&self.inner, f, s)
    }
    fn p_wave_modulus(&self) -> f64 {
        Constitutive::<2>::p_wave_modulus(&self.inner)
    }
}

/// A spinning, stretched square of particles on a quadratic B-spline grid.
fn simulation(young: f64) -> Simulation<2, BSplineKernel<2>, Counting, Apic> {
    let particles = moving_square::particles(0.025, (), |x| {
        Vector2::new(-(x[1] - 0.5) + 0.3 * (x[0] - 0.5), x[0] - 0.5)
    });
    Simulation::new(
        moving_square::grid(),
        Counting::new(young),
        Apic,
        particles,
        StepSettings::new(1e-4),
    )
    .unwrap()
}

#[test]
fn the_material_is_asked_once_per_particle_and_step() {
    let mut sim = simulation(1e5);
    let n = sim.particles().len();
    for _ in 0..5 {
        sim.step().unwrap();
    }
    // The first step's stresses from scratch, then one fused call per particle and step.
    assert_eq!(sim.material().counts(), (n, 5 * n));
    // Reading changes nothing; an edit between steps makes the next step start over.
    let _ = sim.particles().velocity[0];
    sim.step().unwrap();
    assert_eq!(sim.material().counts(), (n, 6 * n));
    sim.particles_mut().deformation[0] *= 1.01;
    sim.step().unwrap();
    assert_eq!(sim.material().counts(), (2 * n, 7 * n));
    sim.material_mut().inner.parameters = ElasticParameters::from_young_poisson(2e5, 0.3).unwrap();
    sim.step().unwrap();
    assert_eq!(sim.material().counts(), (3 * n, 8 * n));
}

/// An edit between steps gives the numbers of a new simulation started from the edited
/// particles: no stress of the old particles or material is used.
#[test]
fn edits_between_steps_use_fresh_stresses() {
    for edit_material in [false, true] {
        let mut edited = simulation(1e5);
        for _ in 0..5 {
            edited.step().unwrap();
        }
        let mut particles = edited.particles().clone();
        let stiffer = ElasticParameters::from_young_poisson(3e5, 0.3).unwrap();
        let mut fresh = simulation(if edit_material { 3e5 } else { 1e5 });
        if edit_material {
            edited.material_mut().inner.parameters = stiffer;
        } else {
            for f in &mut edited.particles_mut().deformation {
                *f *= 1.002;
            }
            for f in &mut particles.deformation {
                *f *= 1.002;
            }
        }
        *fresh.particles_mut() = particles;
        for _ in 0..5 {
            edited.step().unwrap();
            fresh.step().unwrap();
        }
        assert!(
            edited.particles().velocity == fresh.particles().velocity,
            "material edited: {edit_material}"
        );
        assert!(edited.particles().deformation == fresh.particles().deformation);
    }
}
