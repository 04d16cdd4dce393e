//! The consistent mass matrix (`MassMatrix::Consistent`): fields the transfer reproduces
//! are fixed points of its iterations, it keeps more of a particle field through the
//! round trip the more it iterates, momentum stays conserved, results stay independent
//! of the thread count, and what it cannot do is refused by name.

use nalgebra::{Matrix2, Vector2};
use umls_constitutive::{ElasticParameters, NeoHookean};
use umls_engine::{
    Apic, EngineError, Flip, MassMatrix, MlsMpm, Particles, Pic, Simulation, StepSettings,
    TransferScheme,
};
use umls_kernels::{BSplineKernel, BSplineOrder, Umls2};
use umls_transfer::Kernel;

fn material(young: f64) -> NeoHookean {
    NeoHookean {
        parameters: ElasticParameters::from_young_poisson(young, 0.3).unwrap(),
    }
}

/// Particles on a lattice of spacing 0.025 (four per 0.05-cell) filling
/// [0.2, 0.8]², with velocity `v(x)`.
fn block<C: Copy + Default>(v: impl Fn(&Vector2<f64>) -> Vector2<f64>) -> Particles<2, (), C> {
    let h = 0.025;
    let n = 24;
    let x: Vec<Vector2<f64>> = (0..n * n)
        .map(|k| {
            Vector2::new(
                0.2 + ((k % n) as f64 + 0.5) * h,
                0.2 + ((k / n) as f64 + 0.5) * h,
            )
        })
        .collect();
    let mut p = Particles::at_rest(x, vec![h * h; n * n], 1000.0, ());
    for (velocity, x) in p.velocity.iter_mut().zip(&p.position) {
        *velocity = v(x);
    }
    p
}

#[path = "common/unit_square.rs"]
mod unit_square;
use unit_square::mesh;

/// Quadratic B-splines over the unit square.
fn grid() -> BSplineKernel<2> {
    unit_square::grid(BSplineOrder::Quadratic)
}

fn consistent(iterations: usize, forces: f64) -> MassMatrix {
    MassMatrix::Consistent { iterations, forces }
}

/// With an affine particle field v = a + C x carried by APIC (C_p = C) and no stress,
/// the lumped nodal velocity is the field at the node exactly, and so is every
/// iterate: P2G of the field's own interpolant gives back the lumped momenta.
#[test]
fn affine_fields_are_fixed_points_of_the_iterations() {
    fn check<K: Kernel<2>>(kernel: K, name: &str) {
        let a = Vector2::new(0.3, -0.2);
        let c = Matrix2::new(0.4, -1.1, 0.7, 0.2);
        let mut particles = block(|x| a + c * x);
        particles.affine.iter_mut().for_each(|m| *m = c);
        let mut settings = StepSettings::new(1e-4);
        settings.mass_matrix = consistent(6, 1.0);
        let mut sim = Simulation::new(kernel, material(1e3), Apic, particles, settings).unwrap();
        sim.step().unwrap();
        let (mass, velocity) = sim.grid();
        let heaviest = mass.iter().copied().fold(0.0, f64::max);
        let mut checked = 0;
        for (i, (&m, v)) in mass.iter().zip(velocity).enumerate() {
            if m > 1e-6 * heaviest {
                let exact = a + c * sim.kernel.node_position(i);
                assert!(
                    (v - exact).norm() < 1e-11,
                    "{name}: node {i} (mass {m:.3e}) {v:?} against {exact:?}"
                );
                checked += 1;
            }
        }
        assert!(checked > 100, "{name}: {checked} nodes checked");
    }
    check(Umls2::new(mesh()), "UMLS");
    check(grid(), "bspline2");
}

/// Kinetic energy a PIC step keeps of a shear wave 12 cells long (a soft material, so
/// the forces do next to nothing in one step), and the momentum change.
fn shear_wave_kept<K: Kernel<2>>(kernel: K, mass_matrix: MassMatrix) -> (f64, f64) {
    let k = 2.0 * std::f64::consts::PI / 0.6;
    let particles = block(|x| Vector2::new(0.0, 0.01 * (k * (x.x - 0.2)).sin()));
    let mut settings = StepSettings::new(1e-4);
    settings.mass_matrix = mass_matrix;
    let mut sim = Simulation::new(kernel, material(1e-3), Pic, particles, settings).unwrap();
    let before = sim.diagnostics().unwrap();
    sim.step().unwrap();
    let after = sim.diagnostics().unwrap();
    (
        after.kinetic / before.kinetic,
        (after.momentum - before.momentum).norm() / (before.mass * 0.01),
    )
}

/// Each iteration keeps more of the wave through the round trip, and momentum is
/// conserved whatever the count.
#[test]
fn iterations_keep_more_of_the_particle_field() {
    fn check<K: Kernel<2> + Clone>(kernel: K, name: &str) {
        let lumped = shear_wave_kept(kernel.clone(), MassMatrix::Lumped);
        eprintln!("{name}: lumped keeps {:.4}", lumped.0);
        let mut last = lumped;
        for iterations in [1, 2, 4, 8] {
            let now = shear_wave_kept(kernel.clone(), consistent(iterations, 0.0));
            eprintln!("{name}: {iterations} iterations keep {:.4}", now.0);
            assert!(
                now.0 > last.0 && now.0 <= 1.0 + 1e-9,
                "{name}: {iterations} iterations keep {} after {}",
                now.0,
                last.0
            );
            assert!(now.1 < 1e-12, "{name}: momentum change {}", now.1);
            last = now;
        }
        // At least half of what the lumped round trip loses is recovered.
        assert!(
            1.0 - last.0 < 0.5 * (1.0 - lumped.0),
            "{name}: lumped keeps {}, 8 iterations {}",
            lumped.0,
            last.0
        );
    }
    check(Umls2::new(mesh()), "UMLS");
    check(grid(), "bspline2");
}

/// The nodal velocities after one step of a moving block whose deformation varies from
/// particle to particle (so its stress has a divergence and the forces a rough part),
/// with k iterations and the forces' share β.
fn sheared_grid_velocity(iterations: usize, share: f64) -> Vec<Vector2<f64>> {
    let mut particles = block(|x| Vector2::new(0.5 * (x.y - 0.5), 0.2 * (6.0 * x.x).sin()));
    for (f, x) in particles.deformation.iter_mut().zip(&particles.position) {
        *f = Matrix2::new(1.0 + 0.01 * (9.0 * x.y).sin(), 0.02 * x.x, 0.0, 1.0);
    }
    let mut settings = StepSettings::new(1e-4);
    settings.mass_matrix = consistent(iterations, share);
    let mut sim = Simulation::new(grid(), material(1e6), Apic, particles, settings).unwrap();
    sim.step().unwrap();
    sim.grid().1.to_vec()
}

/// The forces' matrix (1 − β) M_L + β M_C: the Jacobi update a ← a + β (f − M_C a)/m +
/// (1 − β)(f/m − a) from the lumped a⁰ = f/m gives a¹ = a⁰ + β d, d = (f − M_C a⁰)/m,
/// and a² = a⁰ + β d + β² (d − M_C d / m), so the change from β = 0 (the velocity's
/// iterations alone) is linear in β after one iteration and quadratic after two:
/// measured at β = ¼, predicted from β = ½ and 1.
#[test]
fn the_forces_share_enters_the_iterates_as_the_update_says() {
    // β = 0, the base of each iteration count, run once.
    let bases = [1, 2].map(|iterations| sheared_grid_velocity(iterations, 0.0));
    let change = |iterations: usize, share| -> Vec<Vector2<f64>> {
        sheared_grid_velocity(iterations, share)
            .iter()
            .zip(&bases[iterations - 1])
            .map(|(v, b)| v - b)
            .collect()
    };
    let largest = |field: &[Vector2<f64>]| field.iter().map(|v| v.norm()).fold(0.0, f64::max);
    // A field that should vanish to round-off against the size of the change.
    let round_off = |misfit: Vec<Vector2<f64>>, change: &[Vector2<f64>], what: &str| {
        assert!(
            largest(&misfit) < 1e-12 * largest(change).max(1.0),
            "{what}: {:e} off (change {:e})",
            largest(&misfit),
            largest(change)
        );
    };
    // One iteration: linear.
    let (d, quarter) = (change(1, 1.0), change(1, 0.25));
    assert!(largest(&d) > 1e-6, "the forces' iterations change nothing");
    let linear = quarter.iter().zip(&d).map(|(q, w)| q - w * 0.25).collect();
    round_off(linear, &d, "one iteration, linear prediction");
    // Two iterations: β X + β² Y through β = ½ and 1 predicts β = ¼, and X is the one
    // iteration's d (the (1 − β) term cancels the second iteration's β d).
    // X + Y = whole, X/2 + Y/4 = half  =>  X = 4 half − whole, Y = 2 whole − 4 half.
    let (whole, half, quarter) = (change(2, 1.0), change(2, 0.5), change(2, 0.25));
    let x: Vec<_> = (0..d.len()).map(|i| half[i] * 4.0 - whole[i]).collect();
    let y: Vec<_> = (0..d.len())
        .map(|i| whole[i] * 2.0 - half[i] * 4.0)
        .collect();
    round_off(
        (0..d.len()).map(|i| x[i] - d[i]).collect(),
        &d,
        "first-order term",
    );
    let quadratic = (0..d.len())
        .map(|i| quarter[i] - (x[i] * 0.25 + y[i] * 0.0625))
        .collect();
    round_off(quadratic, &whole, "two iterations, quadratic prediction");
    // And the quadratic term is there: the mixed matrix is not a blend of the results.
    assert!(largest(&y) > 1e-3 * largest(&whole), "no quadratic term");
}

/// A swirling, falling block on 1 and 2 threads, consistent mass on velocity and
/// forces, FLIP and APIC: the same bits.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    fn run<T: TransferScheme>(transfer: T, threads: usize) -> Vec<Vector2<f64>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let particles = block(|x| Vector2::new(-(x.y - 0.5), x.x - 0.5));
            let mut settings = StepSettings::new(1e-4);
            settings.mass_matrix = consistent(3, 1.0);
            settings.gravity = Vector2::new(0.0, -9.81);
            let mut sim = Simulation::new(
                Umls2::new(mesh()),
                material(1e4),
                transfer,
                particles,
                settings,
            )
            .unwrap();
            for _ in 0..5 {
                sim.step().unwrap();
            }
            let p = sim.particles();
            p.position.iter().chain(&p.velocity).copied().collect()
        })
    }
    assert_eq!(run(Apic, 1), run(Apic, 2));
    assert_eq!(run(Flip { alpha: 0.99 }, 1), run(Flip { alpha: 0.99 }, 2));
}

/// MLS-MPM's momenta carry the force impulse, so it refuses the consistent matrix;
/// zero iterations and a forces' share outside [0, 1] are refused by name; with forces
/// solved the stable step shrinks by √k, with a share β by √(Σ_{j=1..k} β^j) when above
/// 1.
#[test]
fn what_cannot_be_done_is_refused_and_the_stable_step_shrinks() {
    let particles = || block(|_| Vector2::zeros());
    let mut settings = StepSettings::new(1e-4);
    settings.mass_matrix = consistent(2, 0.0);
    match Simulation::new(grid(), material(1e4), MlsMpm, particles(), settings) {
        Err(EngineError::Unsupported { setting, .. }) => {
            assert!(setting.contains("mass"), "{setting}")
        }
        other => panic!("expected Unsupported, got {:?}", other.err()),
    }
    let refused_by_name = |mass_matrix, parameter: &str| {
        let mut settings = StepSettings::new(1e-4);
        settings.mass_matrix = mass_matrix;
        match Simulation::new(grid(), material(1e4), Apic, particles(), settings) {
            Err(e @ EngineError::InvalidParameter { .. }) => {
                assert!(e.to_string().contains(parameter), "{e}")
            }
            other => panic!("expected InvalidParameter, got {:?}", other.err()),
        }
    };
    refused_by_name(consistent(0, 1.0), "mass_matrix.iterations");
    refused_by_name(consistent(2, 1.5), "mass_matrix.forces");
    let stable = |mass_matrix| {
        let mut settings = StepSettings::new(1e-4);
        settings.mass_matrix = mass_matrix;
        Simulation::new(grid(), material(1e4), Apic, particles(), settings)
            .unwrap()
            .stable_time_step(1.0)
    };
    let lumped = stable(MassMatrix::Lumped);
    assert_eq!(stable(consistent(4, 0.0)), lumped);
    assert!((stable(consistent(4, 1.0)) - lumped / 2.0).abs() < 1e-15 * lumped);
    // A share β divides by √(Σ_{j=1..k} β^j) when above 1: not at all for ½ with four
    // iterations (0.9375), by 1.2 for 0.8 with two (1.44).
    assert_eq!(stable(consistent(4, 0.5)), lumped);
    assert!((stable(consistent(2, 0.8)) - lumped / 1.2).abs() < 1e-15 * lumped);
}
