//! Under USL the deformation update runs inside G2P, particle by particle: F ← (I + Δt ∇v) F
//! with the gradient G2P has just made, and a failing update is reported as the separate
//! stage reported it, by the lowest particle, on any number of threads.

use nalgebra::{Matrix2, Vector2};
use umls_constitutive::{ElasticParameters, NeoHookean};
use umls_engine::{EngineError, MlsMpm, Simulation, StepSettings};
use umls_kernels::BSplineKernel;

#[path = "common/moving_square.rs"]
mod moving_square;

/// A square of particles on a quadratic B-spline grid under MLS-MPM (whose velocity
/// gradient is the affine matrix the particles keep), moving with `velocity(x)`.
fn simulation(
    velocity: impl Fn(&Vector2<f64>) -> Vector2<f64>,
    dt: f64,
) -> Simulation<2, BSplineKernel<2>, NeoHookean, MlsMpm> {
    let particles = moving_square::particles(0.0125, (), velocity);
    let mut settings = StepSettings::new(dt);
    // The inversion test moves faster than a stable step allows: it is the update's
    // check that must stop it, not the step's.
    settings.max_wave_courant = 1e6;
    settings.max_courant = 1e6;
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    Simulation::new(moving_square::grid(), material, MlsMpm, particles, settings).unwrap()
}

/// Each step's F is the last one times I + Δt C_p, C_p the affine matrix (MLS-MPM's
/// velocity gradient) G2P left with the particle, bit for bit, for every particle.
#[test]
fn each_particle_is_deformed_by_the_gradient_its_g2p_made() {
    let spin_and_stretch = |x: &Vector2<f64>| {
        Vector2::new(
            -(x[1] - 0.5) + 0.3 * (x[0] - 0.5),
            x[0] - 0.5 - 0.2 * (x[1] - 0.5),
        )
    };
    let mut sim = simulation(spin_and_stretch, 1e-4);
    for _ in 0..4 {
        let before = sim.particles().deformation.clone();
        sim.step().unwrap();
        let p = sim.particles();
        let mut changed = 0;
        for (i, (f, old)) in p.deformation.iter().zip(&before).enumerate() {
            let expected = (Matrix2::identity() + p.affine[i] * sim.last_dt()) * old;
            assert_eq!(*f, expected, "particle {i}");
            changed += usize::from(f != old);
        }
        assert!(changed > p.len() / 2, "{changed} of {} deformed", p.len());
    }
}

/// A compression along x of 1.5 / Δt inverts the particles in one step. The error names
/// the lowest particle whose det (I + Δt C_p) F_p is not positive, recomputed here from
/// what G2P left, and it is the same on one, two and four threads.
#[test]
fn an_inversion_names_the_lowest_particle_on_any_thread_count() {
    let dt = 1e-4;
    let squeeze = move |x: &Vector2<f64>| Vector2::new(-1.5 / dt * (x[0] - 0.5), 0.0);
    let mut reported = Vec::new();
    for threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut sim = simulation(squeeze, dt);
            let before = sim.particles().deformation.clone();
            let error = sim.step().expect_err("an inverting step");
            let EngineError::Inverted { particle, det, .. } = error else {
                panic!("expected an inversion, got {error}");
            };
            assert!(det <= 0.0);
            let p = sim.particles();
            let inverted: Vec<usize> = (0..p.len())
                .filter(|&i| {
                    ((Matrix2::identity() + p.affine[i] * dt) * before[i]).determinant() <= 0.0
                })
                .collect();
            assert!(inverted.len() > 10, "{} particles inverted", inverted.len());
            assert_eq!(particle, inverted[0], "{threads} threads");
            reported.push(particle);
        });
    }
    assert!(reported.windows(2).all(|w| w[0] == w[1]), "{reported:?}");
}
