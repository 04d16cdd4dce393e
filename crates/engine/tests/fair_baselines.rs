//! Every kernel on the classic cases: the same scene, the same settings, and each kernel
//! must run it (linear FE with USL included), hold its walls, conserve momentum, and stop
//! only for a real cause.

use std::sync::Arc;

use nalgebra::{SVector, Vector2, Vector3};
use umls_constitutive::{
    ConeFit, Constitutive, DruckerPrager, ElasticParameters, ElastoPlastic, FixedCorotated,
    LinearElastic, NeoHookean,
};
use umls_engine::{
    Apic, Damping, EngineError, Flip, Particles, Pic, Region, Simulation, StepSettings,
    TimeStepControl, TransferScheme, Wall, WallKind, lattice_samples,
};
use umls_kernels::{BSplineKernel, BSplineOrder, LinearFeKernel, Umls2, Umls3};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mls::{CubicBSpline, SupportRadius, UmlsKernel};
use umls_transfer::Kernel;

fn square_mesh(cells: usize) -> Arc<SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [cells, cells])
            .triangles(Diagonal::Right)
            .unwrap(),
    )
}

fn square_grid(cells: usize, order: BSplineOrder) -> BSplineKernel<2> {
    let h = 1.0 / cells as f64;
    BSplineKernel::new(
        Vector2::new(-2.0 * h, -2.0 * h),
        h,
        [cells + 4, cells + 4],
        order,
    )
    .unwrap()
}

fn elastic(young: f64) -> NeoHookean {
    NeoHookean {
        parameters: ElasticParameters::from_young_poisson(young, 0.3).unwrap(),
    }
}

/// Particles on a lattice of spacing `h` inside `region`, density 1000, velocity `v`.
fn body<const D: usize, C: Copy + Default>(
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    h: f64,
    region: &Region<D>,
    v: SVector<f64, D>,
) -> Particles<D, (), C> {
    Particles::seed(&lattice_samples(lower, upper, h), region, 1000.0, (), |_| v)
}

/// A disk of particles on a lattice of spacing `h` in the unit square, moving at
/// (0.1, 0) m/s.
fn disk<C: Copy + Default>(centre: Vector2<f64>, radius: f64, h: f64) -> Particles<2, (), C> {
    let region = Region::Ball { centre, radius };
    body(
        Vector2::zeros(),
        Vector2::new(1.0, 1.0),
        h,
        &region,
        Vector2::new(0.1, 0.0),
    )
}

/// Runs `steps` steps (or to the first error) and returns the error.
fn run<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme>(
    sim: &mut Simulation<D, K, M, T>,
    steps: usize,
) -> Result<(), EngineError> {
    for _ in 0..steps {
        sim.step()?;
    }
    Ok(())
}

/// A disk translating at 0.1 m/s with one particle per cell (particles on the cell
/// centres, so nodes of the far corners of their triangles get N ≈ 0): linear FE with
/// USL used to invert particles at step 2. Every kernel now translates it rigidly.
#[test]
fn translating_disk_runs_with_every_kernel() {
    fn translate<K: Kernel<2>>(kernel: K, per_cell: f64) {
        let particles = disk(Vector2::new(0.5, 0.5), 0.2, 0.05 / per_cell);
        let mut sim = Simulation::new(
            kernel,
            elastic(1e4),
            Flip { alpha: 1.0 },
            particles,
            StepSettings::new(1.0),
        )
        .unwrap();
        sim.settings.dt = sim.stable_time_step(0.3);
        let before = sim.diagnostics().unwrap();
        run(&mut sim, 150).unwrap();
        let after = sim.diagnostics().unwrap();
        let scale = before.mass * 0.1;
        assert!((after.momentum - before.momentum).norm() < 1e-12 * scale);
        assert!(after.elastic < 1e-3 * before.kinetic, "{after:?}");
        assert!(after.dropped_mass.abs() < 1e-12 * before.mass);
    }
    for per_cell in [1.0, 2.0] {
        translate(LinearFeKernel::new(square_mesh(20)), per_cell);
        translate(Umls2::new(square_mesh(20)), per_cell);
        translate(square_grid(20, BSplineOrder::Quadratic), per_cell);
    }
}

/// The colliding disks at 10 and 20 cells with PIC, FLIP 0.99 and FLIP 1 run to the end
/// with every kernel, conserving momentum to round-off (40 cells and APIC: docs/scenes.md).
#[test]
fn colliding_disks_run_with_every_kernel_and_transfer() {
    fn collide<K: Kernel<2>, T: TransferScheme>(kernel: K, transfer: T, cells: usize) {
        let material = LinearElastic {
            parameters: ElasticParameters::from_young_poisson(1000.0, 0.3).unwrap(),
        };
        collide_with(kernel, material, transfer, cells)
            .unwrap_or_else(|e| panic!("{} at {cells} cells: {e}", transfer.name()));
    }
    for cells in [10, 20] {
        for alpha in [0.99, 1.0] {
            collide(
                LinearFeKernel::new(square_mesh(cells)),
                Flip { alpha },
                cells,
            );
            collide(Umls2::new(square_mesh(cells)), Flip { alpha }, cells);
            collide(
                square_grid(cells, BSplineOrder::Quadratic),
                Flip { alpha },
                cells,
            );
        }
        collide(LinearFeKernel::new(square_mesh(cells)), Pic, cells);
        collide(Umls2::new(square_mesh(cells)), Pic, cells);
        collide(Umls2::new(square_mesh(cells)), Apic, cells);
        collide(square_grid(cells, BSplineOrder::Quadratic), Apic, cells);
        // Linear FE with APIC: see the next test (the material, not the kernel, fails).
    }
}

/// Linear elements with APIC at 10 cells: APIC keeps the spin of particles, and small-
/// strain linear elasticity is not frame-invariant (a rotated particle has strain
/// sym(R) − I ≠ 0), so a spinning particle on the coarsest mesh gains energy until it
/// inverts. The same scene with a frame-invariant material of the same E and ν runs.
#[test]
fn linear_elasticity_under_apic_spin_is_the_cause_not_the_kernel() {
    let linear = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(1000.0, 0.3).unwrap(),
    };
    // The scene's jittered mesh (on the regular one the spin stays small enough).
    let jittered = |cells: usize| {
        Arc::new(
            Lattice::new([0.0, 0.0], [1.0, 1.0], [cells, cells])
                .jitter(0.2, 11)
                .triangles(Diagonal::Alternating)
                .unwrap(),
        )
    };
    let error = collide_with(LinearFeKernel::new(jittered(10)), linear, Apic, 10)
        .expect_err("linear elasticity with APIC at 10 cells");
    assert!(
        matches!(
            error,
            EngineError::Inverted { .. }
                | EngineError::EnergyBlowUp { .. }
                | EngineError::TimeStepTooLarge { .. }
                | EngineError::ParticleKick { .. }
                | EngineError::Unstable { .. }
        ),
        "{error}"
    );
    for cells in [10, 20, 40] {
        collide_with(
            LinearFeKernel::new(square_mesh(cells)),
            elastic(1000.0),
            Apic,
            cells,
        )
        .unwrap_or_else(|e| panic!("neo-Hookean, linear FE, APIC, {cells} cells: {e}"));
        collide_with(
            LinearFeKernel::new(jittered(cells)),
            FixedCorotated {
                parameters: ElasticParameters::from_young_poisson(1000.0, 0.3).unwrap(),
            },
            Apic,
            cells,
        )
        .unwrap_or_else(|e| panic!("corotated, linear FE, APIC, {cells} cells: {e}"));
    }
}

/// The colliding disks (Sulsky et al. 1994) with `material`: runs 3000 steps and checks
/// momentum to round-off and energy against growth.
fn collide_with<K: Kernel<2>, M: Constitutive<2, State = ()>, T: TransferScheme>(
    kernel: K,
    material: M,
    transfer: T,
    cells: usize,
) -> Result<(), EngineError> {
    let h = 0.5 / cells as f64;
    let mut particles = Particles::<2, (), K::Cache>::at_rest(vec![], vec![], 1000.0, ());
    for (centre, v) in [((0.2, 0.2), 0.1), ((0.8, 0.8), -0.1)] {
        let disk = Region::Ball {
            centre: Vector2::new(centre.0, centre.1),
            radius: 0.2,
        };
        particles.append(body(
            Vector2::zeros(),
            Vector2::new(1.0, 1.0),
            h,
            &disk,
            Vector2::new(v, v),
        ));
    }
    let mut sim = Simulation::new(
        kernel,
        material,
        transfer,
        particles,
        StepSettings::new(1e-3),
    )
    .unwrap();
    let before = sim.diagnostics().unwrap();
    run(&mut sim, 3000)?;
    let after = sim.diagnostics().unwrap();
    let scale: f64 = sim.particles().mass.iter().sum::<f64>() * 0.1;
    assert!(
        (after.momentum - before.momentum).norm() < 1e-12 * scale,
        "{} {} at {cells} cells: momentum {:?}, dropped mass {}",
        std::any::type_name::<K>(),
        transfer.name(),
        after.momentum,
        after.dropped_mass
    );
    // Pure FLIP does not dissipate: its transfer noise may add a little energy
    // (linear FE at 10 cells: +1.6 %), an instability adds orders of magnitude.
    assert!(
        after.total_energy() < before.total_energy() * 1.05,
        "{} {} at {cells} cells: energy {} → {}",
        std::any::type_name::<K>(),
        transfer.name(),
        before.total_energy(),
        after.total_energy()
    );
    Ok(())
}

/// Hydrostatic column (width 1, height 4, ρ 1000, g 10, E 10⁶, ν 0.3) between slip walls
/// on a slip base, each wall one plane, brought to rest by local damping. Returns the
/// mean σ_yy of the particles whose initial height lies in `band` over the exact
/// −ρg(H − y).
fn column<K: Kernel<2>>(kernel: K, geostatic: bool, band: (f64, f64)) -> f64 {
    let height = 4.0;
    let region = Region::Box {
        lower: Vector2::zeros(),
        upper: Vector2::new(1.0, height),
    };
    let particles = body(
        Vector2::zeros(),
        Vector2::new(1.0, height),
        0.05,
        &region,
        Vector2::zeros(),
    );
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(1e6, 0.3).unwrap(),
    };
    let mut settings = StepSettings::new(1.0);
    settings.gravity = Vector2::new(0.0, -10.0);
    settings.damping = Damping::Local { alpha: 0.7 };
    let mut sim = Simulation::new(kernel, material, Pic, particles, settings).unwrap();
    sim.settings.dt = sim.stable_time_step(0.3);
    let positions = sim.particles().position.clone();
    for (point, normal) in [
        ((0.0, 0.0), (1.0, 0.0)),
        ((1.0, 0.0), (1.0, 0.0)),
        ((0.0, 0.0), (0.0, 1.0)),
    ] {
        let wall = Wall::facing(
            WallKind::Slip,
            Vector2::new(point.0, point.1),
            Vector2::new(normal.0, normal.1),
            &positions,
        )
        .unwrap();
        assert!(!sim.boundary.add_wall(&sim.kernel, wall, 1e-9).is_empty());
    }
    let end = if geostatic {
        sim.set_geostatic_stress(0.3 / 0.7).unwrap();
        0.05
    } else {
        1.5
    };
    let steps = (end / sim.settings.dt).ceil() as usize;
    run(&mut sim, steps).unwrap();
    let d = sim.diagnostics().unwrap();
    assert!(d.max_speed < 0.02, "column not at rest: {d:?}");
    // Particles may not leave through the walls.
    assert!(
        sim.particles()
            .position
            .iter()
            .all(|x| x.x >= 0.0 && x.x <= 1.0 && x.y >= 0.0)
    );
    let stresses = sim.stresses().unwrap();
    let row = |(bottom, top): (f64, f64)| {
        let (mut sum, mut exact) = (0.0, 0.0);
        for (x0, tau) in positions.iter().zip(&stresses) {
            if bottom <= x0.y && x0.y < top {
                sum += tau[(1, 1)];
                exact += -1000.0 * 10.0 * (height - x0.y);
            }
        }
        sum / exact
    };
    row(band)
}

#[test]
fn bspline_column_with_one_plane_per_wall_carries_its_weight() {
    // The bottom row: the lowest row of particles.
    let ratio = column(
        square_grid_column(BSplineOrder::Quadratic),
        false,
        BOTTOM_ROW,
    );
    assert!(
        (ratio - 1.0).abs() < 0.1,
        "bspline2 bottom row σ_yy / exact = {ratio}"
    );
    // The cubic stencil reaches two cells into the wall: 1.10 measured, reported in
    // docs/scenes.md; guarded here against getting worse.
    let ratio = column(square_grid_column(BSplineOrder::Cubic), false, BOTTOM_ROW);
    assert!(
        (ratio - 1.0).abs() < 0.12,
        "bspline3 bottom row σ_yy / exact = {ratio}"
    );
}

#[test]
fn mesh_kernels_bring_the_soft_column_to_rest() {
    let mesh = Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 4.4], [10, 44])
            .triangles(Diagonal::Alternating)
            .unwrap(),
    );
    let fe = column(LinearFeKernel::new(mesh.clone()), false, BOTTOM_ROW);
    let umls = column(Umls2::new(mesh), false, BOTTOM_ROW);
    eprintln!("soft column, bottom row σ_yy / exact: linear FE {fe:.3}, UMLS {umls:.3}");
    // The mesh kernels' boundary accuracy is the subject of their own study; here they
    // must settle, with a bottom row of the right sign and magnitude.
    assert!(fe > 0.5 && fe < 1.5, "linear FE {fe}");
    assert!(umls > 0.5 && umls < 2.5, "UMLS {umls}");
}

#[test]
fn geostatic_initial_stress_starts_the_column_at_rest() {
    // Without it the column drops: after 0.05 s it moves at about g t = 0.5 m/s (the
    // check inside `column` asks for less than 0.02 m/s).
    // And it keeps its stress away from the base, where the kernel's own equilibrium
    // differs from the exact one.
    let ratio = column(
        square_grid_column(BSplineOrder::Quadratic),
        true,
        (1.0, 3.0),
    );
    assert!((ratio - 1.0).abs() < 0.05, "{ratio}");
}

const BOTTOM_ROW: (f64, f64) = (0.0, 0.05);

fn square_grid_column(order: BSplineOrder) -> BSplineKernel<2> {
    BSplineKernel::new(Vector2::new(-0.2, -0.2), 0.1, [14, 48], order).unwrap()
}

/// A block thrown into the corner of a fixed floor and a slip wall: no particle ends
/// up beyond either plane, for every kernel, in 2D and 3D.
#[test]
fn walls_hold_for_every_kernel() {
    fn throw<const D: usize, K: Kernel<D>>(kernel: K, name: &str, cell: f64) {
        let lower = SVector::<f64, D>::from_element(0.25);
        let upper = SVector::<f64, D>::from_element(0.65);
        let region = Region::Box { lower, upper };
        let mut velocity = SVector::<f64, D>::zeros();
        velocity[0] = -2.0;
        velocity[D - 1] = -3.0;
        let particles = body(lower, upper, 0.05, &region, velocity);
        let mut settings = StepSettings::new(1.0);
        settings.time_step = TimeStepControl::Adaptive { cfl: 0.3 };
        let mut sim = Simulation::new(kernel, elastic(2e5), Pic, particles, settings).unwrap();
        sim.settings.dt = 1e-3;
        let positions = sim.particles().position.clone();
        let mut floor = SVector::<f64, D>::zeros();
        floor[D - 1] = 1.0;
        let mut side = SVector::<f64, D>::zeros();
        side[0] = 1.0;
        for (kind, normal) in [(WallKind::Fixed, floor), (WallKind::Slip, side)] {
            let wall = Wall::facing(kind, SVector::zeros(), normal, &positions).unwrap();
            assert_eq!(wall.normal, -normal);
            sim.boundary.add_wall(&sim.kernel, wall, 1e-9);
        }
        let mut lowest = f64::INFINITY;
        while sim.time() < 0.4 {
            sim.step().unwrap_or_else(|e| panic!("{name} {D}D: {e}"));
            for x in &sim.particles().position {
                assert!(
                    x[0] >= 0.0 && x[D - 1] >= 0.0,
                    "{name} {D}D: {x:?} beyond a wall"
                );
                lowest = lowest.min(x[D - 1]);
            }
        }
        // Pressed into the floor: within 1.5 cells of it. (Fixed wall nodes slow the
        // particles within a stencil of the wall: UMLS keeps them 1.0 cell away in 2D
        // and 1.15 in 3D, linear FE 0.64 in 2D.)
        assert!(
            lowest < 1.5 * cell,
            "{name} {D}D never reached the floor: {lowest}"
        );
    }
    throw(LinearFeKernel::new(square_mesh(10)), "linear FE", 0.1);
    throw(Umls2::new(square_mesh(10)), "UMLS", 0.1);
    throw(square_grid(10, BSplineOrder::Quadratic), "bspline2", 0.1);
    let cube = Arc::new(
        Lattice::new([0.0; 3], [1.0; 3], [6, 6, 6])
            .tetrahedra()
            .unwrap(),
    );
    throw(LinearFeKernel::new(cube.clone()), "linear FE", 1.0 / 6.0);
    throw(Umls3::new(cube), "UMLS", 1.0 / 6.0);
    let h = 1.0 / 6.0;
    let grid = BSplineKernel::new(
        Vector3::from_element(-2.0 * h),
        h,
        [10, 10, 10],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    throw(grid, "bspline2", 1.0 / 6.0);
}

/// A disk thrown sideways under gravity: the energy check counts the work of gravity, so
/// the fall runs to the end (it stopped after 11 steps), and kinetic + elastic energy
/// minus that work stays constant.
#[test]
fn free_fall_with_initial_velocity_runs_to_the_end() {
    let particles = disk(Vector2::new(0.3, 0.8), 0.1, 0.025);
    let mut settings = StepSettings::new(1e-3);
    settings.gravity = Vector2::new(0.0, -10.0);
    let mut sim = Simulation::new(
        square_grid(20, BSplineOrder::Quadratic),
        elastic(1e5),
        Flip { alpha: 1.0 },
        particles,
        settings,
    )
    .unwrap();
    let before = sim.diagnostics().unwrap();
    run(&mut sim, 300).unwrap();
    let after = sim.diagnostics().unwrap();
    let fallen = 0.5 * 10.0 * 0.3f64.powi(2);
    assert!((after.external_work - before.mass * 10.0 * fallen).abs() < 0.02 * after.external_work);
    assert!(
        (after.energy_balance() - before.energy_balance()).abs() < 1e-6 * after.external_work,
        "{} → {}",
        before.energy_balance(),
        after.energy_balance()
    );
}

/// A fixed Δt four times the stable step: the wave Courant number says so before the
/// first step, and the run stops with a typed instability instead of completing.
#[test]
fn unstable_time_step_is_reported() {
    let particles = disk(Vector2::new(0.5, 0.5), 0.2, 0.025);
    let mut sim = Simulation::new(
        square_grid(20, BSplineOrder::Quadratic),
        elastic(1e4),
        Flip { alpha: 1.0 },
        particles,
        StepSettings::new(1.0),
    )
    .unwrap();
    sim.settings.dt = 4.0 * sim.stable_time_step(1.0);
    let d = sim.diagnostics().unwrap();
    assert!((d.wave_courant - 4.0).abs() < 1e-9, "{}", d.wave_courant);
    let error = run(&mut sim, 400).unwrap_err();
    assert!(
        matches!(error, EngineError::TimeStepTooLarge { wave_courant, .. } if (wave_courant - 4.0).abs() < 0.1),
        "{error}"
    );
}

/// One particle far faster than the rest (the kick a sliver or a light node gives) makes
/// the step unstable at its speed alone: the guard names the kick and the particle, not
/// Δt. The whole body at that speed is a time step too large.
#[test]
fn a_kicked_particle_is_named_not_the_time_step() {
    let grid = BSplineKernel::new(SVector::from([-0.2]), 0.1, [14], BSplineOrder::Quadratic)
        .expect("grid");
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(10.0, 0.0).unwrap(),
    };
    // c = √10, h = 0.1, Δt = 0.01: stable at the RMS speed √20 of one particle at 20
    // among 20 at rest (Δt_stable 0.013), not at 20 (0.0043).
    let refused = |speed: &dyn Fn(usize) -> f64| {
        let x = (0..20)
            .map(|i| SVector::from([0.025 + 0.05 * i as f64]))
            .collect();
        let mut particles = Particles::at_rest(x, vec![0.05; 20], 1.0, ());
        for (i, v) in particles.velocity.iter_mut().enumerate() {
            *v = SVector::from([speed(i)]);
        }
        let settings = StepSettings::new(0.01);
        let mut sim = Simulation::new(grid.clone(), material, Pic, particles, settings).unwrap();
        sim.step().unwrap_err()
    };
    match refused(&|i| if i == 7 { 20.0 } else { 0.0 }) {
        EngineError::ParticleKick {
            particle,
            speed,
            ratio,
            ..
        } => {
            assert_eq!(particle, 7);
            assert!((speed - 20.0).abs() < 1e-12 && (ratio - 20f64.sqrt()).abs() < 1e-9);
        }
        other => panic!("expected a kick: {other}"),
    }
    let error = refused(&|_| 20.0);
    assert!(
        matches!(error, EngineError::TimeStepTooLarge { .. }),
        "{error}"
    );
}

/// A Drucker–Prager block (c = 100 Pa, φ = 30°) collapsing under gravity on a fixed base
/// against a slip wall, in 2D and 3D: linear FE used to stop at step 5, UMLS particles
/// went through the fixed base. Every kernel runs it, no particle crosses a wall, and the
/// block spreads (its toe moves out along the base).
#[test]
fn drucker_prager_collapse_runs_with_every_kernel() {
    fn collapse<const D: usize, K: Kernel<D>>(kernel: K, name: &str) -> f64
    where
        ElastoPlastic<DruckerPrager>: Constitutive<D>,
    {
        let material = ElastoPlastic::new(
            ElasticParameters::from_young_poisson(1e6, 0.3).unwrap(),
            DruckerPrager::from_mohr_coulomb(100.0, 30f64.to_radians(), 0.0, ConeFit::Compression)
                .unwrap(),
        );
        let lower = SVector::<f64, D>::zeros();
        let mut upper = SVector::<f64, D>::from_element(0.2);
        upper[0] = 0.5;
        upper[D - 1] = 0.4;
        let region = Region::Box { lower, upper };
        let samples = lattice_samples(lower, upper, 0.025);
        let state = <ElastoPlastic<DruckerPrager> as Constitutive<D>>::initial_state(&material);
        let particles = Particles::seed(&samples, &region, 2000.0, state, |_| SVector::zeros());
        let mut settings = StepSettings::new(1.0);
        settings.gravity[D - 1] = -9.81;
        settings.time_step = TimeStepControl::Adaptive { cfl: 0.3 };
        let mut sim =
            Simulation::new(kernel, material, Flip { alpha: 0.99 }, particles, settings).unwrap();
        sim.settings.dt = 1e-3;
        let positions = sim.particles().position.clone();
        let mut up = SVector::<f64, D>::zeros();
        up[D - 1] = 1.0;
        let mut side = SVector::<f64, D>::zeros();
        side[0] = 1.0;
        let mut walls = vec![
            (WallKind::Fixed, SVector::zeros(), up),
            (WallKind::Slip, SVector::zeros(), side),
        ];
        if D == 3 {
            // Slip on the front and back faces: a slice of the plane-strain problem.
            let mut across = SVector::<f64, D>::zeros();
            across[1] = 1.0;
            walls.push((WallKind::Slip, SVector::zeros(), across));
            walls.push((WallKind::Slip, across * 0.2, across));
        }
        for (kind, point, normal) in walls {
            let wall = Wall::facing(kind, point, normal, &positions).unwrap();
            sim.boundary.add_wall(&sim.kernel, wall, 1e-9);
        }
        while sim.time() < 0.3 {
            sim.step().unwrap_or_else(|e| panic!("{name} {D}D: {e}"));
        }
        let x = &sim.particles().position;
        assert!(
            x.iter().all(|x| x[0] >= 0.0 && x[D - 1] >= 0.0),
            "{name} {D}D"
        );
        x.iter().map(|x| x[0]).fold(0.0, f64::max)
    }
    let square = Arc::new(
        Lattice::new([0.0, 0.0], [1.2, 0.6], [24, 12])
            .triangles(Diagonal::Alternating)
            .unwrap(),
    );
    let h = 0.05;
    let grid2 = BSplineKernel::new(
        Vector2::new(-2.0 * h, -2.0 * h),
        h,
        [28, 16],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    let runout = [
        collapse(LinearFeKernel::new(square.clone()), "linear FE"),
        collapse(Umls2::new(square), "UMLS"),
        collapse(grid2, "bspline2"),
    ];
    let cube = Arc::new(
        Lattice::new([0.0; 3], [1.2, 0.2, 0.6], [24, 4, 12])
            .tetrahedra()
            .unwrap(),
    );
    let grid3 = BSplineKernel::new(
        Vector3::from_element(-2.0 * h),
        h,
        [28, 8, 16],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    let runout3 = [
        collapse(LinearFeKernel::new(cube.clone()), "linear FE"),
        collapse(Umls3::new(cube), "UMLS"),
        collapse(grid3, "bspline2"),
    ];
    for toe in runout.iter().chain(&runout3) {
        assert!(
            *toe > 0.5,
            "the block did not spread: {runout:?} {runout3:?}"
        );
    }
}

/// Walls given as node sets (as a mesh's physical groups are): a block thrown at the
/// base of a mesh, whose base vertices are fixed or slip along their normals, stays in
/// the mesh with UMLS and linear FE, in 2D on an inclined mesh and in 3D — particles
/// that cross the base facets are put back on them.
#[test]
fn node_set_walls_hold() {
    fn throw<const D: usize, K: Kernel<D>>(
        kernel: K,
        mesh: &SimplexMesh<D>,
        samples: Vec<(SVector<f64, D>, f64)>,
        velocity: SVector<f64, D>,
        base: Vec<u32>,
        fixed: bool,
        name: &str,
    ) {
        let particles = Particles::seed(&samples, &Region::Everywhere, 1000.0, (), |_| velocity);
        let mut settings = StepSettings::new(1.0);
        settings.time_step = TimeStepControl::Adaptive { cfl: 0.3 };
        let mut sim = Simulation::new(
            kernel,
            elastic(2e5),
            Flip { alpha: 0.99 },
            particles,
            settings,
        )
        .unwrap();
        sim.settings.dt = 1e-3;
        if fixed {
            sim.boundary.fixed = base;
        } else {
            sim.boundary.slip = base
                .iter()
                .map(|&v| (v, mesh.topology().vertex_normal(v as usize)))
                .collect();
        }
        // Until the block has hit the base and before its rebound carries it out of the
        // (open) top of the mesh.
        while sim.time() < 0.12 {
            sim.step().unwrap_or_else(|e| panic!("{name} {D}D: {e}"));
        }
        for x in &sim.particles().position {
            assert!(mesh.locate(x).is_some(), "{name} {D}D: {x:?} left the mesh");
        }
    }
    // 2D: a 2 × 1 rectangle rotated by 0.5 rad; its base is vertices 0..=20.
    let rotation = nalgebra::Rotation2::new(0.5);
    let centre = Vector2::new(1.0, 0.5);
    let block = Region::Box {
        lower: Vector2::new(0.7, 0.1),
        upper: Vector2::new(1.3, 0.5),
    };
    let samples: Vec<_> = lattice_samples(Vector2::zeros(), Vector2::new(2.0, 1.0), 0.05)
        .into_iter()
        .filter(|(x, _)| block.contains(x))
        .map(|(x, v)| (centre + rotation * (x - centre), v))
        .collect();
    let down = rotation * Vector2::new(0.3, -3.0);
    let mesh = Arc::new(
        Lattice::new([0.0, 0.0], [2.0, 1.0], [20, 10])
            .rotate_by(0.5)
            .triangles(Diagonal::Right)
            .unwrap(),
    );
    let base: Vec<u32> = (0..=20).collect();
    for fixed in [true, false] {
        throw(
            Umls2::new(mesh.clone()),
            &mesh,
            samples.clone(),
            down,
            base.clone(),
            fixed,
            "UMLS",
        );
        throw(
            LinearFeKernel::new(mesh.clone()),
            &mesh,
            samples.clone(),
            down,
            base.clone(),
            fixed,
            "linear FE",
        );
    }
    // 3D: the unit cube in 6³ cells; its base is the vertices with z = 0.
    let cube = Arc::new(
        Lattice::new([0.0; 3], [1.0; 3], [6, 6, 6])
            .tetrahedra()
            .unwrap(),
    );
    let base3: Vec<u32> = (0..cube.vertex_count() as u32)
        .filter(|&v| cube.vertex(v as usize).z == 0.0)
        .collect();
    assert_eq!(base3.len(), 49);
    let lower = Vector3::from_element(0.25);
    let upper = Vector3::new(0.75, 0.75, 0.65);
    let samples3 = Particles::<3, (), ()>::seed(
        &lattice_samples(lower, upper, 1.0 / 24.0),
        &Region::Everywhere,
        1.0,
        (),
        |_| Vector3::zeros(),
    );
    let samples3: Vec<_> = samples3.position.into_iter().zip(samples3.volume).collect();
    for fixed in [true, false] {
        throw(
            Umls3::new(cube.clone()),
            &cube,
            samples3.clone(),
            Vector3::new(0.5, 0.0, -6.0),
            base3.clone(),
            fixed,
            "UMLS",
        );
        throw(
            LinearFeKernel::new(cube.clone()),
            &cube,
            samples3.clone(),
            Vector3::new(0.5, 0.0, -6.0),
            base3.clone(),
            fixed,
            "linear FE",
        );
    }
}

/// UMLS particles pressed onto a fixed node-set base by a strong body force. With the
/// wide per-vertex support, the kernel's velocity at the wall is not zero (wall nodes at
/// rest do not stop a non-interpolating kernel), so G2P carries particles across the base
/// facets; the wall puts them back on the facets, and the run goes on. The default
/// (incident-edge) support lets the wall nodes dominate at the wall: no particle needs
/// putting back.
#[test]
fn particles_carried_across_a_node_set_wall_are_put_back() {
    let mesh = square_mesh(10);
    let wide = UmlsKernel::with_weight(
        &mesh,
        CubicBSpline,
        SupportRadius::PerVertex { factor: 1.0 },
    )
    .unwrap();
    let first = first_wall_correction(Umls2::with_kernel(mesh.clone(), wide));
    assert!(
        first.is_some_and(|s| s < 1600),
        "wide: first hold at {first:?}"
    );
    let first = first_wall_correction(Umls2::new(mesh));
    assert!(first.is_none(), "default: first hold at {first:?}");
}

/// The step of the first wall correction while a soft block is crushed onto a fixed
/// base; asserts that no particle is ever below the base.
fn first_wall_correction(kernel: Umls2) -> Option<usize> {
    let region = Region::Box {
        lower: Vector2::new(0.3, 0.0),
        upper: Vector2::new(0.7, 0.2),
    };
    let particles = body(
        Vector2::zeros(),
        Vector2::new(1.0, 1.0),
        0.05,
        &region,
        Vector2::zeros(),
    );
    let mut settings = StepSettings::new(1e-4);
    settings.gravity = Vector2::new(0.0, -2000.0);
    let mut sim = Simulation::new(
        kernel,
        elastic(1e5),
        Flip { alpha: 1.0 },
        particles,
        settings,
    )
    .unwrap();
    sim.boundary.fixed = (0..=10).collect();
    // Soft material under a strong load: the block is crushed onto the base (it inverts
    // after ~1800 steps); the first crossings come well before.
    let mut first = None;
    for step in 0..1700 {
        sim.step().unwrap();
        let lowest = sim
            .particles()
            .position
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        assert!(lowest >= 0.0, "{lowest}");
        if first.is_none() && sim.diagnostics().unwrap().wall_corrections > 0 {
            first = Some(step);
        }
    }
    first
}
