//! Conservation and determinism: with no boundary conditions and no external force,
//! total mass is exact and linear momentum is conserved to round-off for every kernel ×
//! transfer combination; results are bitwise identical for 1 and 2 threads.

use std::sync::Arc;

use nalgebra::{SVector, Vector2};
use umls_constitutive::{ElasticParameters, NeoHookean};
use umls_engine::{
    Apic, ApicFlip, Flip, MlsMpm, Particles, Pic, QuadraticApic, QuadraticApicFlip, Simulation,
    StepSettings, StressUpdate, TransferScheme, VelocityGradientAffine,
};
use umls_kernels::{BSplineOrder, LinearFeKernel, Umls2};
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::Kernel;

/// A disk of particles (4 per 0.05² cell) with a swirling, stretching velocity field.
fn disk<C: Copy + Default>() -> Particles<2, (), C> {
    let mut x = Vec::new();
    let h = 0.025;
    for i in 0..40 {
        for j in 0..40 {
            let p = Vector2::new(
                0.25 + (i as f64 + 0.5) * h * 0.5,
                0.25 + (j as f64 + 0.5) * h * 0.5,
            );
            if (p - Vector2::new(0.5, 0.5)).norm() < 0.22 {
                x.push(p);
            }
        }
    }
    let volumes = vec![h * h / 4.0; x.len()];
    let mut particles = Particles::at_rest(x, volumes, 1000.0, ());
    for (v, p) in particles.velocity.iter_mut().zip(&particles.position) {
        let r = p - Vector2::new(0.5, 0.5);
        *v = Vector2::new(-r.y + 0.3 * r.x + 0.1, r.x + 0.05 * r.y * r.y - 0.2);
    }
    particles
}

fn check<K: Kernel<2>, T: TransferScheme>(kernel: K, transfer: T, update: StressUpdate) {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    let mut settings = StepSettings::new(1e-4);
    settings.stress_update = update;
    let mut sim = Simulation::new(kernel, material, transfer, disk(), settings).unwrap();
    let before = sim.diagnostics().unwrap();
    for _ in 0..20 {
        sim.step().unwrap();
    }
    let after = sim.diagnostics().unwrap();
    let scale = before.mass * before.momentum.norm().max(0.1);
    assert_eq!(after.mass, before.mass, "{}: mass", transfer.name());
    assert!(
        (after.momentum - before.momentum).norm() < 1e-12 * scale,
        "{} {update:?}: momentum {:?} → {:?}",
        transfer.name(),
        before.momentum,
        after.momentum
    );
}

#[path = "common/unit_square.rs"]
mod unit_square;
use unit_square::{grid, mesh};

macro_rules! every_transfer {
    ($kernel:expr) => {
        for update in [StressUpdate::Usl, StressUpdate::Musl] {
            check($kernel, Pic, update);
            check($kernel, Flip { alpha: 0.95 }, update);
            check($kernel, Apic, update);
            check($kernel, ApicFlip { alpha: 0.95 }, update);
            check($kernel, VelocityGradientAffine, update);
            check($kernel, QuadraticApic, update);
            check($kernel, QuadraticApicFlip { alpha: 0.95 }, update);
        }
    };
}

#[test]
fn mass_and_momentum_are_conserved_for_every_kernel_and_transfer() {
    every_transfer!(Umls2::new(mesh()));
    // The integration correction keeps momentum: its ∇N_i + N_i (ξ_i − ξ̄_p) sums to
    // zero over every stencil.
    let corrected = Umls2::new(mesh()).with_integration_correction().unwrap();
    every_transfer!(corrected.clone());
    every_transfer!(LinearFeKernel::new(mesh()));
    every_transfer!(grid(BSplineOrder::Quadratic));
    every_transfer!(grid(BSplineOrder::Cubic));
    // MLS-MPM: B-splines and UMLS (each particle's own D_p), USL only (the combinations
    // it refuses are tested below); its folded force Σ_i N_i (m C − Δt V τ D⁻¹)(x_i − x_p)
    // vanishes with Σ_i N_i r_i.
    check(grid(BSplineOrder::Quadratic), MlsMpm, StressUpdate::Usl);
    check(grid(BSplineOrder::Cubic), MlsMpm, StressUpdate::Usl);
    check(Umls2::new(mesh()), MlsMpm, StressUpdate::Usl);
    check(corrected, MlsMpm, StressUpdate::Usl);
}

/// MLS-MPM's force needs D_p⁻¹ and a nodal force it does not have: linear elements
/// (whose D_p vanishes at the vertices), damping and MUSL are refused by name, at
/// construction and at a step after the public settings changed; UMLS is accepted.
#[test]
fn mls_mpm_refuses_what_it_cannot_do() {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    let unsupported = |e: umls_engine::EngineError, what: &str| match &e {
        umls_engine::EngineError::Unsupported {
            transfer, setting, ..
        } => {
            assert_eq!(*transfer, "MLS-MPM");
            assert!(setting.contains(what), "{e}");
        }
        other => panic!("expected Unsupported, got {other}"),
    };
    let settings = StepSettings::new(1e-4);
    let linear = Simulation::new(
        LinearFeKernel::new(mesh()),
        material,
        MlsMpm,
        disk(),
        settings,
    );
    unsupported(linear.err().unwrap(), "linear elements");
    assert!(Simulation::new(Umls2::new(mesh()), material, MlsMpm, disk(), settings).is_ok());
    let mut musl = settings;
    musl.stress_update = StressUpdate::Musl;
    let refused = Simulation::new(
        grid(BSplineOrder::Quadratic),
        material,
        MlsMpm,
        disk(),
        musl,
    );
    unsupported(refused.err().unwrap(), "MUSL");
    let mut sim = Simulation::new(
        grid(BSplineOrder::Quadratic),
        material,
        MlsMpm,
        disk(),
        settings,
    )
    .unwrap();
    sim.step().unwrap();
    sim.settings.damping = umls_engine::Damping::MassProportional { beta: 1.0 };
    unsupported(sim.step().err().unwrap(), "damping");
}

/// Nearest-node values on the integers of [0, 8] (N = 1 at the nearest node, ∇N = 0),
/// claiming a regular second moment: D_p = 0 everywhere, which MLS-MPM must report.
struct NearestNode;

impl Kernel<1> for NearestNode {
    type Cache = ();
    fn node_count(&self) -> usize {
        9
    }
    fn node_position(&self, node: usize) -> SVector<f64, 1> {
        SVector::from([node as f64])
    }
    fn spacing(&self) -> f64 {
        1.0
    }
    fn stencil(
        &self,
        x: &SVector<f64, 1>,
        _: &mut (),
        out: &mut umls_transfer::Stencil<1>,
    ) -> Result<(), umls_transfer::KernelError> {
        let node = x[0].round().clamp(0.0, 8.0);
        out.clear();
        out.push(
            node as u32,
            1.0,
            SVector::zeros(),
            SVector::from([node - x[0]]),
        );
        Ok(())
    }
    fn regular_second_moment(&self) -> bool {
        true
    }
}

/// A particle whose D_p has no inverse stops an MLS-MPM run with a step error naming
/// it and the cause, whichever way the stencils are kept.
#[test]
fn a_singular_second_moment_stops_mls_mpm_naming_the_particle() {
    for storage in [
        umls_engine::StencilStorage::Store,
        umls_engine::StencilStorage::Recompute,
    ] {
        let particles = Particles::at_rest(
            vec![SVector::from([2.0]), SVector::from([4.25])],
            vec![1.0; 2],
            1.0,
            (),
        );
        let mut settings = StepSettings::new(1e-3);
        settings.stencil_storage = storage;
        let material = umls_constitutive::WeaklyCompressibleFluid::new(400.0, 1.0).unwrap();
        let mut sim = Simulation::new(NearestNode, material, MlsMpm, particles, settings)
            .expect("the kernel claims a regular D_p");
        match sim.step().unwrap_err() {
            umls_engine::EngineError::Kernel {
                step: 0,
                particle: 0,
                source: umls_transfer::KernelError::Evaluation { source, .. },
            } => {
                let cause = source
                    .downcast_ref::<umls_engine::SingularSecondMoment>()
                    .expect("the cause is the singular moment");
                assert_eq!(cause.trace, 0.0, "{storage:?}");
                assert!(source.to_string().contains("MLS-MPM"), "{source}");
            }
            other => panic!("{storage:?}: expected the singular moment, got {other}"),
        }
    }
}

#[test]
fn leaving_the_mesh_names_the_particle() {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    let mut particles = disk::<umls_kernels::HostCache<2>>();
    particles
        .velocity
        .iter_mut()
        .for_each(|v| *v = Vector2::new(4.0, 0.0));
    let mut sim = Simulation::new(
        LinearFeKernel::new(mesh()),
        material,
        Pic,
        particles,
        StepSettings::new(5e-4),
    )
    .unwrap();
    let error = (0..1000)
        .find_map(|_| sim.step().err())
        .expect("particles leave the unit square");
    match error {
        umls_engine::EngineError::Kernel {
            particle,
            source: umls_transfer::KernelError::OutsideDomain { point },
            ..
        } => {
            assert!(point[0] > 1.0, "particle {particle} at {point:?}");
        }
        other => panic!("unexpected {other}"),
    }
    assert!(
        Simulation::new(
            LinearFeKernel::new(mesh()),
            material,
            Pic,
            disk::<umls_kernels::HostCache<2>>(),
            StepSettings::new(-1.0)
        )
        .is_err()
    );
}

/// Beyond one P2G block (4096 particles) the scatter runs in blocks whose node windows
/// overlap, here on two threads: momentum is still conserved to round-off (that the
/// results do not depend on the thread count is `determinism.rs`).
#[test]
fn blocked_scatter_conserves_momentum() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| {
        let samples = umls_engine::lattice_samples(
            SVector::from([0.1, 0.1]),
            SVector::from([0.9, 0.9]),
            0.0075,
        );
        let swirl = |x: &Vector2<f64>| {
            Vector2::new(-(x.y - 0.5), x.x - 0.5) * 0.5 + Vector2::new(0.05, -0.02)
        };
        let particles = Particles::seed(
            &samples,
            &umls_engine::Region::Everywhere,
            1000.0,
            (),
            swirl,
        );
        assert!(particles.len() > 2 * 4096);
        let material = NeoHookean {
            parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
        };
        let mut sim = Simulation::new(
            Umls2::new(mesh()),
            material,
            Apic,
            particles,
            StepSettings::new(1e-4),
        )
        .unwrap();
        let before = sim.diagnostics().unwrap().momentum;
        for _ in 0..3 {
            sim.step().unwrap();
        }
        let after = sim.diagnostics().unwrap().momentum;
        assert!(
            (after - before).norm() < 1e-12 * before.norm() * 1e3,
            "{before:?} → {after:?}"
        );
    });
}

/// An ill-conditioned MLS system (sliver mesh of aspect 10⁷) stops the run with the
/// kernel's typed error naming the simplex, wrapped with the step and particle.
#[test]
fn ill_conditioned_mls_stops_the_run() {
    let mesh = Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1e-7], [8, 2])
            .triangles(Diagonal::Right)
            .unwrap(),
    );
    let positions = (0..4)
        .map(|k| Vector2::new(0.3 + 0.1 * k as f64, 5e-8))
        .collect();
    let particles = Particles::at_rest(positions, vec![1e-9; 4], 1000.0, ());
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    let mut settings = StepSettings::new(1e-4);
    // The sliver's height (5·10⁻⁸) makes any Δt too large; this test is about the kernel.
    settings.max_wave_courant = f64::INFINITY;
    let mut sim = Simulation::new(Umls2::new(mesh), material, Pic, particles, settings).unwrap();
    let error = sim.step().unwrap_err();
    match &error {
        umls_engine::EngineError::Kernel {
            step: 0,
            source: umls_transfer::KernelError::Evaluation { kernel, source },
            ..
        } => {
            assert_eq!(*kernel, "UMLS");
            // The kernel's own error type comes through, typed.
            assert!(matches!(
                source.downcast_ref::<umls_mls::MlsError>(),
                Some(umls_mls::MlsError::IllConditioned {
                    simplex: Some(_),
                    ..
                })
            ));
        }
        other => panic!("unexpected {other}"),
    }
    assert!(
        error
            .to_string()
            .contains("ill-conditioned moment matrix in simplex"),
        "{error}"
    );
}

/// The integration correction acts (the test above would hold for a correction that
/// never reached the forces): the same disk moves differently with it.
#[test]
fn the_integration_correction_changes_the_forces() {
    let run = |kernel: Umls2| {
        let material = NeoHookean {
            parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
        };
        let mut sim =
            Simulation::new(kernel, material, Apic, disk(), StepSettings::new(1e-4)).unwrap();
        for _ in 0..20 {
            sim.step().unwrap();
        }
        sim.particles().velocity.clone()
    };
    let plain = run(Umls2::new(mesh()));
    let corrected = run(Umls2::new(mesh()).with_integration_correction().unwrap());
    let largest = plain
        .iter()
        .zip(&corrected)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(largest > 1e-6, "{largest}");
}
