//! Slip boundaries and gravity: an elastic block on a frictionless slope. The mesh is a
//! rectangle rotated by θ; its bottom boundary vertices slip along their (mesh-computed)
//! normals. Slip removes only normal velocity components and internal forces sum to zero,
//! so the tangential momentum must grow exactly as M g sinθ t while the block rests on the
//! slope; without the slip condition the same block falls out of the mesh.

use std::sync::Arc;

use nalgebra::{Rotation2, Vector2};
use umls_constitutive::{ElasticParameters, NeoHookean};
use umls_engine::{Particles, Pic, Simulation, StepSettings, Wall, WallKind};
use umls_kernels::{HostCache, LinearFeKernel, Umls2};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::Kernel;

const THETA: f64 = 0.3;
const G: f64 = 10.0;
const CELLS: [usize; 2] = [20, 10];

fn slope() -> Arc<SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [2.0, 1.0], CELLS)
            .rotate_by(THETA)
            .triangles(Diagonal::Right)
            .unwrap(),
    )
}

/// 2×2 particles per cell in the block [0.6, 1.4] × [0, 0.4] of the unrotated rectangle.
fn block() -> Particles<2, (), HostCache<2>> {
    let rotation = Rotation2::new(THETA);
    let centre = Vector2::new(1.0, 0.5);
    let mut x = Vec::new();
    for i in 0..16 {
        for j in 0..8 {
            let local = Vector2::new(0.6 + (i as f64 + 0.5) * 0.05, (j as f64 + 0.5) * 0.05);
            x.push(centre + rotation * (local - centre));
        }
    }
    let n = x.len();
    Particles::at_rest(x, vec![0.05 * 0.05; n], 1000.0, ())
}

/// Tangential momentum over M g sinθ t, and the centroid's normal displacement.
fn slide<K: Kernel<2, Cache = HostCache<2>>>(kernel: K, mesh: &SimplexMesh<2>) -> (f64, f64) {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    let mut settings = StepSettings::new(1e-3);
    settings.gravity = Vector2::new(0.0, -G);
    let mut sim = Simulation::new(kernel, material, Pic, block(), settings).unwrap();
    // Bottom edge vertices of the lattice (corners excluded: their normals mix two sides).
    sim.boundary.slip = (1..CELLS[0] as u32)
        .map(|v| (v, mesh.topology().vertex_normal(v as usize)))
        .collect();
    let tangent = Rotation2::new(THETA) * Vector2::new(1.0, 0.0);
    let normal = Vector2::new(-tangent.y, tangent.x);
    let centroid = |s: &Simulation<2, K, NeoHookean, Pic>| {
        s.particles().position.iter().sum::<Vector2<f64>>() / s.particles().len() as f64
    };
    let start = centroid(&sim);
    for _ in 0..200 {
        sim.step().unwrap();
    }
    let d = sim.diagnostics().unwrap();
    let expected = d.mass * G * THETA.sin() * sim.time();
    // Gravity's tangential component points down the slope: −tangent.
    (
        -d.momentum.dot(&tangent) / expected,
        (centroid(&sim) - start).dot(&normal),
    )
}

#[test]
fn block_slides_down_a_frictionless_slope() {
    let mesh = slope();
    // The mesh's boundary normals on the bottom edge are the rotated (0, −1).
    let expected_normal = Rotation2::new(THETA) * Vector2::new(0.0, -1.0);
    for v in 1..CELLS[0] {
        assert!((mesh.topology().vertex_normal(v) - expected_normal).norm() < 1e-12);
    }
    for (name, (ratio, sink)) in [
        ("UMLS", slide(Umls2::new(mesh.clone()), &mesh)),
        ("linear FE", slide(LinearFeKernel::new(mesh.clone()), &mesh)),
    ] {
        eprintln!(
            "{name}: tangential momentum / (M g sinθ t) = {ratio:.12}, normal displacement {sink:.4e}"
        );
        assert!((ratio - 1.0).abs() < 1e-9, "{name}: {ratio}");
        // Elastic settling under its own weight only: ρgH/E ≈ 0.04 strain over 0.4 height.
        assert!(sink.abs() < 0.03, "{name}: sank by {sink}");
    }
}

/// Control: without the slip condition the block falls through the slope and leaves the
/// mesh (½ g cosθ t² reaches the particles' distance to the boundary within 0.2 time
/// units); the run stops with a typed error naming a particle outside the domain.
#[test]
fn without_slip_the_block_falls_out_of_the_mesh() {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    };
    let mut settings = StepSettings::new(1e-3);
    settings.gravity = Vector2::new(0.0, -G);
    let mut sim = Simulation::new(Umls2::new(slope()), material, Pic, block(), settings).unwrap();
    let error = (0..200)
        .find_map(|_| sim.step().err())
        .expect("the block must fall out");
    assert!(
        matches!(
            error,
            umls_engine::EngineError::Kernel {
                source: umls_transfer::KernelError::OutsideDomain { .. },
                ..
            }
        ),
        "{error}"
    );
}

/// The material of the body-force tests' block.
fn block_material() -> NeoHookean {
    NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).unwrap(),
    }
}

/// The block on the slope's mesh under `force`, without gravity or walls.
fn block_under(force: umls_engine::BodyForce<2>) -> Simulation<2, Umls2, NeoHookean, Pic> {
    let mut sim = Simulation::new(
        Umls2::new(slope()),
        block_material(),
        Pic,
        block(),
        StepSettings::new(1e-3),
    )
    .unwrap();
    sim.body_force = Some(force);
    sim
}

/// A body-force field enters like gravity: a constant field reproduces the gravity run
/// bit for bit, and with no boundary conditions the momentum changes by exactly
/// Δt Σ m_p b(x_p) per step (internal forces cancel).
#[test]
fn body_force_fields() {
    let mut with_gravity = StepSettings::new(1e-3);
    with_gravity.gravity = Vector2::new(0.0, -G);
    let mut a = Simulation::new(
        Umls2::new(slope()),
        block_material(),
        Pic,
        block(),
        with_gravity,
    )
    .unwrap();
    let mut b = block_under(Arc::new(|_, _, _| Vector2::new(0.0, -G)));
    for _ in 0..5 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert_eq!(a.particles().position, b.particles().position);
    // The work of the force G2P sums is gravity's, bit for bit: both read one acceleration.
    assert_eq!(
        a.diagnostics().unwrap().external_work,
        b.diagnostics().unwrap().external_work
    );
    // A step changes the momentum by exactly `impulse`, what the force gave this step.
    fn step_gives<K: umls_transfer::Kernel<2>, M: umls_constitutive::Constitutive<2>>(
        sim: &mut Simulation<2, K, M, Pic>,
        impulse: Vector2<f64>,
    ) {
        let before = sim.diagnostics().unwrap().momentum;
        sim.step().unwrap();
        let after = sim.diagnostics().unwrap().momentum;
        assert!(
            (after - before - impulse).norm() < 1e-12 * impulse.norm().max(1e-3),
            "{:?} vs {impulse:?}",
            after - before
        );
    }
    // A harmonic trap b(x) = −k (x − c), at the current positions.
    let centre = Vector2::new(1.0, 0.5);
    let k = 40.0;
    let trap_at = move |x: Vector2<f64>| (x - centre) * -k;
    let mut trap = block_under(Arc::new(move |_, x, _| trap_at(*x)));
    // Δt Σ m_p b(x_p) of the particles' masses at these positions.
    let impulse_at = |positions: &[Vector2<f64>], masses: &[f64]| -> Vector2<f64> {
        positions
            .iter()
            .zip(masses)
            .map(|(x, m)| trap_at(*x) * (m * 1e-3))
            .sum()
    };
    for _ in 0..5 {
        let impulse = impulse_at(&trap.particles().position, &trap.particles().mass);
        step_gives(&mut trap, impulse);
    }
    // The same trap as a field of where each particle started, through its index: the
    // impulse is Δt Σ m_p b(X_p) every step however far the particles have moved.
    let start = block().position;
    let at_start = start.clone();
    let mut reference = block_under(Arc::new(move |p, _, _| trap_at(at_start[p])));
    let impulse = impulse_at(&start, &reference.particles().mass);
    for _ in 0..5 {
        step_gives(&mut reference, impulse);
    }
    // The particles have moved, so the field at their current positions would have
    // given another impulse: the index is what made the difference.
    let p = reference.particles();
    let current = impulse_at(&p.position, &p.mass);
    assert!(
        (current - impulse).norm() > 1e-9 * impulse.norm(),
        "{current:?} vs {impulse:?}"
    );
}

/// A step evaluates the body force once per particle: P2G's force and G2P's work of
/// external forces read the same value (a scene's expression can cost more than the
/// rest of the step).
#[test]
fn a_body_force_is_evaluated_once_per_particle_and_step() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = calls.clone();
    let mut sim = block_under(Arc::new(move |_, _, _| {
        counter.fetch_add(1, Ordering::Relaxed);
        Vector2::new(0.5, -G)
    }));
    let steps = 4;
    for _ in 0..steps {
        sim.step().unwrap();
    }
    assert_eq!(calls.load(Ordering::Relaxed), steps * sim.particles().len());
}

/// Boundary conditions on planes select the nodes on the plane and use its normal.
#[test]
fn conditions_on_planes() {
    let mesh = Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4])
            .triangles(Diagonal::Right)
            .unwrap(),
    );
    let kernel = LinearFeKernel::new(mesh);
    let bottom = umls_engine::Boundary::<2>::nodes_on_plane(
        &kernel,
        &Vector2::zeros(),
        &Vector2::new(0.0, -3.0),
        1e-9,
    );
    assert_eq!(bottom, vec![0, 1, 2, 3, 4]);
    // Walls: oriented away from the material, they take the nodes on and beyond them.
    let material = [Vector2::new(0.5, 0.5)];
    let left = Wall::facing(
        WallKind::Fixed,
        Vector2::new(0.0, 0.0),
        Vector2::new(3.0, 0.0),
        &material,
    )
    .unwrap();
    assert_eq!(left.normal, Vector2::new(-1.0, 0.0));
    let top = Wall::facing(
        WallKind::Slip,
        Vector2::new(1.0, 0.75),
        Vector2::new(0.0, -2.0),
        &material,
    )
    .unwrap();
    assert_eq!(top.normal, Vector2::new(0.0, 1.0));
    let mut boundary = umls_engine::Boundary::<2>::default();
    assert_eq!(boundary.add_wall(&kernel, left, 1e-9).len(), 5);
    assert_eq!(boundary.add_wall(&kernel, top, 1e-9).len(), 10);
    assert_eq!(boundary.fixed, vec![0, 5, 10, 15, 20]);
    assert_eq!(boundary.slip.len(), 10);
    assert!(
        boundary
            .slip
            .iter()
            .all(|(n, normal)| *n >= 15 && *normal == Vector2::new(0.0, 1.0))
    );
}
