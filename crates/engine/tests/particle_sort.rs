//! Storing the particles in P2G's order (`StepSettings::particle_sort_interval`) moves
//! them between slots and changes no bit: P2G visits them in the same order either way,
//! the other stages work particle by particle, body forces and fitted clamps follow the
//! particles, and an error names the particle by its index at construction.

use std::sync::Arc;

use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use umls_constitutive::NeoHookean;
use umls_engine::{
    Apic, EngineError, FittedClamp, Flip, MlsMpm, QuadraticApic, Simulation, StepSettings,
    TransferScheme,
};
use umls_kernels::{BSplineKernel, BSplineOrder, Umls2};
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::Kernel;

#[path = "common/spinning_block.rs"]
mod spinning_block;

/// Per particle (by its index at construction): position, velocity, affine matrix,
/// deformation gradient.
type State<const D: usize> = Vec<(
    SVector<f64, D>,
    SVector<f64, D>,
    SMatrix<f64, D, D>,
    SMatrix<f64, D, D>,
)>;

/// The spinning block (three radians per second, so that its particles cross cells and
/// their P2G order drifts from the lattice's) under gravity, with a body force that
/// depends on the particle's index (so a force that followed the slot instead would
/// change the result).
fn simulation<const D: usize, K: Kernel<D>, T: TransferScheme>(
    kernel: K,
    transfer: T,
    h: f64,
    sort_interval: usize,
) -> Simulation<D, K, NeoHookean, T> {
    let mut settings = StepSettings::new(1.0);
    settings.particle_sort_interval = sort_interval;
    let mut sim = spinning_block::simulation(kernel, transfer, (h, 3.0), settings);
    sim.body_force = Some(Arc::new(|p: usize, _: &SVector<f64, D>, _: f64| {
        let mut b = SVector::<f64, D>::zeros();
        b[0] = (p % 7) as f64 - 3.0;
        b
    }));
    sim
}

/// The state by particle index at construction, and how many particles sit in another
/// slot than their own.
fn by_id<const D: usize, K: Kernel<D>, T: TransferScheme>(
    sim: &Simulation<D, K, NeoHookean, T>,
) -> (State<D>, usize) {
    let p = sim.particles();
    let zero = (
        SVector::zeros(),
        SVector::zeros(),
        SMatrix::zeros(),
        SMatrix::zeros(),
    );
    let mut state = vec![zero; p.len()];
    let mut moved = 0;
    let mut seen = vec![false; p.len()];
    for slot in 0..p.len() {
        let id = sim.particle_id(slot);
        assert!(!seen[id], "particle {id} is stored twice");
        seen[id] = true;
        moved += usize::from(id != slot);
        state[id] = (
            p.position[slot],
            p.velocity[slot],
            p.affine[slot],
            p.deformation[slot],
        );
    }
    (state, moved)
}

/// Steps `kernel` unsorted and sorted every 3 steps, in pools of 1 and 4 threads, and
/// asserts the same bits by particle; returns how many particles the sorts moved.
fn assert_sorting_changes_no_bit<const D: usize, K, T>(
    name: &str,
    kernel: K,
    transfer: T,
    h: f64,
    steps: usize,
) -> usize
where
    K: Kernel<D> + Clone + Send + Sync,
    T: TransferScheme + Send + Sync,
{
    let run = |interval: usize, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut sim = simulation(kernel.clone(), transfer, h, interval);
            for _ in 0..steps {
                sim.step().unwrap();
            }
            by_id(&sim)
        })
    };
    let (unsorted, stayed) = run(0, 2);
    assert_eq!(stayed, 0, "{name}: unsorted particles moved between slots");
    let (sorted, moved) = run(3, 1);
    assert!(sorted == unsorted, "{name}: sorting changed the result");
    let (sorted_four, moved_four) = run(3, 4);
    assert!(sorted_four == sorted, "{name}: 4 threads differ from 1");
    assert_eq!(moved, moved_four, "{name}");
    moved
}

/// Quadratic B-splines of spacing 0.025 over [−0.1, 1.1]².
fn quadratic_grid() -> BSplineKernel<2> {
    BSplineKernel::new(
        Vector2::new(-0.1, -0.1),
        0.025,
        [48, 48],
        BSplineOrder::Quadratic,
    )
    .unwrap()
}

/// The unit square in `cells` × `cells` cells, alternating diagonals.
fn triangles(cells: usize) -> Arc<SimplexMesh<2>> {
    Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [cells, cells])
            .triangles(Diagonal::Alternating)
            .unwrap(),
    )
}

#[test]
fn sorted_particles_give_the_unsorted_bits() {
    let grid = quadratic_grid();
    // 10,000 particles: P2G scatters in several parallel blocks.
    let moved = assert_sorting_changes_no_bit("bspline2, APIC", grid, Apic, 0.004, 12);
    assert!(
        moved > 5000,
        "bspline2: the sorts moved only {moved} particles"
    );
    let grid3 = BSplineKernel::new(
        Vector3::new(-0.1, -0.1, -0.1),
        0.05,
        [24, 24, 24],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    let moved = assert_sorting_changes_no_bit("bspline2 3D, MLS-MPM", grid3, MlsMpm, 0.02, 9);
    assert!(
        moved > 4000,
        "bspline2 3D: the sorts moved only {moved} particles"
    );
    let mesh = triangles(40);
    let moved = assert_sorting_changes_no_bit(
        "umls, FLIP",
        Umls2::new(mesh),
        Flip { alpha: 0.99 },
        0.004,
        9,
    );
    assert!(moved > 5000, "umls: the sorts moved only {moved} particles");
    // The quadratic modes are particle state the sorts must carry along.
    let moved = assert_sorting_changes_no_bit(
        "umls, quadratic APIC",
        Umls2::new(triangles(40)),
        QuadraticApic,
        0.004,
        9,
    );
    assert!(
        moved > 5000,
        "umls, quadratic APIC: the sorts moved only {moved} particles"
    );
}

/// A fitted clamp names its particles by slot: the sort renumbers it, so it holds the
/// same particles and the run keeps its bits.
#[test]
fn a_fitted_clamp_follows_its_particles_through_the_sorts() {
    let mesh = triangles(20);
    let run = |interval: usize| {
        let mut sim = simulation(
            Umls2::new(mesh.clone()),
            Flip { alpha: 0.99 },
            0.01,
            interval,
        );
        let x = sim.particles().position.clone();
        let held: Vec<u32> = (0..x.len() as u32)
            .filter(|&p| x[p as usize].x < 0.35)
            .collect();
        let nodes: Vec<u32> = (0..sim.kernel.node_count() as u32)
            .filter(|&n| sim.kernel.node_position(n as usize).x <= 0.35)
            .collect();
        let mut clamp = FittedClamp::new(nodes, held.clone());
        clamp.reach = sim.kernel.spacing();
        sim.boundary.fitted.push(clamp);
        for _ in 0..10 {
            sim.step().unwrap();
        }
        let clamped: Vec<usize> = sim.boundary.fitted[0]
            .particles()
            .iter()
            .map(|&slot| sim.particle_id(slot as usize))
            .collect();
        let held: Vec<usize> = held.iter().map(|&p| p as usize).collect();
        assert_eq!(
            clamped, held,
            "interval {interval}: the clamp lost its particles"
        );
        by_id(&sim)
    };
    let (unsorted, _) = run(0);
    let (sorted, moved) = run(2);
    assert!(moved > 100, "the sorts moved only {moved} particles");
    assert!(sorted == unsorted, "sorting changed the clamped run");
}

/// After the particles have been sorted, a failing particle is reported by its index at
/// construction, not by the slot it sits in.
#[test]
fn an_error_names_the_particle_by_its_index_at_construction() {
    let grid = quadratic_grid();
    let mut sim = simulation(grid, Apic, 0.004, 2);
    for _ in 0..4 {
        sim.step().unwrap();
    }
    let n = sim.particles().len();
    let (slot, id) = (0..n)
        .map(|slot| (slot, sim.particle_id(slot)))
        .find(|&(slot, id)| id != slot && id > 0)
        .expect("a particle the sorts moved");
    // Outside the grid: the kernel cannot place its stencil.
    sim.particles_mut().position[slot] = Vector2::new(5.0, 5.0);
    match sim.step() {
        Err(EngineError::Kernel { particle, .. }) => {
            assert_eq!(particle, id, "slot {slot} holds particle {id}")
        }
        other => panic!("expected the kernel to stop the step, got {other:?}"),
    }
}
