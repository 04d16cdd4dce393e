//! Results do not depend on the number of threads: the same scene stepped in pools of
//! 1, 2 and 4 threads gives bit-identical particles (the parallel sums run over a fixed
//! split of the particles and are reduced in a fixed order), both below the particle
//! count from which P2G scatters in parallel blocks and above it.

use std::sync::Arc;

use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use umls_engine::{
    Apic, ApicFlip, Flip, MlsMpm, Pic, StencilStorage, StepSettings, TransferScheme,
    VelocityGradientAffine,
};
use umls_kernels::{BSplineKernel, BSplineOrder, Umls2, Umls3};
use umls_mesh::generate::{Diagonal, Lattice};
use umls_transfer::Kernel;

#[path = "common/spinning_block.rs"]
mod spinning_block;

/// Positions, velocities and deformation gradients.
type State<const D: usize> = (
    Vec<SVector<f64, D>>,
    Vec<SVector<f64, D>>,
    Vec<SMatrix<f64, D, D>>,
);

/// Positions, velocities and deformation gradients after `steps` steps in a pool of
/// `threads` threads, with APIC.
fn state<const D: usize, K: Kernel<D> + Clone + Send + Sync>(
    kernel: &K,
    h: f64,
    steps: usize,
    threads: usize,
    storage: StencilStorage,
) -> State<D> {
    state_with(kernel, Apic, h, steps, threads, storage)
}

/// [`state`] with the transfer scheme `transfer`.
fn state_with<const D: usize, K: Kernel<D> + Clone + Send + Sync, T: TransferScheme>(
    kernel: &K,
    transfer: T,
    h: f64,
    steps: usize,
    threads: usize,
    storage: StencilStorage,
) -> State<D> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut settings = StepSettings::new(1.0);
        settings.stencil_storage = storage;
        let mut sim = spinning_block::simulation(kernel.clone(), transfer, (h, 1.0), settings);
        for _ in 0..steps {
            sim.step().unwrap();
        }
        let p = &sim.particles();
        (
            p.position.clone(),
            p.velocity.clone(),
            p.deformation.clone(),
        )
    })
}

/// The particles per P2G block: beyond this many, P2G scatters in several blocks in
/// parallel and merges their windows.
const PARALLEL_SCATTER: usize = 4096;

/// Steps `kernel` in pools of 1, 2 and 4 threads; `parallel_scatter` says on which side
/// of the P2G block threshold the particle count must lie.
fn assert_thread_independent<const D: usize, K: Kernel<D> + Clone + Send + Sync>(
    name: &str,
    kernel: K,
    h: f64,
    steps: usize,
    parallel_scatter: bool,
) {
    let one = state(&kernel, h, steps, 1, StencilStorage::KernelChoice);
    let count = one.0.len();
    assert_eq!(
        count > PARALLEL_SCATTER,
        parallel_scatter,
        "{name}: {count} particles"
    );
    for threads in [2, 4] {
        assert!(
            state(&kernel, h, steps, threads, StencilStorage::KernelChoice) == one,
            "{name}: {threads} threads differ from 1"
        );
    }
}

#[test]
fn two_dimensional_runs_are_bitwise_independent_of_the_thread_count() {
    let grid = BSplineKernel::new(
        Vector2::new(-0.1, -0.1),
        0.025,
        [48, 48],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    assert_thread_independent("bspline2", grid, 0.004, 20, true);
    let mesh = Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [40, 40])
            .triangles(Diagonal::Alternating)
            .unwrap(),
    );
    assert_thread_independent("umls", Umls2::new(mesh), 0.004, 20, true);
    // A jittered mesh, and few enough particles that P2G scatters as one block while the
    // stencils, stresses and G2P still run in parallel.
    let jittered = Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [20, 20])
            .jitter(0.2, 3)
            .triangles(Diagonal::Alternating)
            .unwrap(),
    );
    assert_thread_independent(
        "umls, serial scatter",
        Umls2::new(jittered),
        0.0125,
        10,
        false,
    );
}

/// A mesh numbered without locality: every P2G window spans most of the nodes, so the
/// scatter merges neighbouring blocks until the windows span at most 4× the node count.
/// The result still does not depend on the thread count, and it is the run on the
/// well-numbered mesh up to round-off (only the order of the sums differs).
#[test]
fn a_scrambled_numbering_changes_only_the_summation_order() {
    let ordered = Lattice::new([0.0, 0.0], [1.0, 1.0], [40, 40])
        .triangles(Diagonal::Alternating)
        .unwrap();
    // Vertex k of the ordered mesh becomes vertex perm[k] (a fixed pseudo-random order).
    let n = ordered.vertices().len();
    let mut perm: Vec<u32> = (0..n as u32).collect();
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    for i in (1..n).rev() {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        perm.swap(i, (seed % (i as u64 + 1)) as usize);
    }
    let mut vertices = vec![Vector2::zeros(); n];
    for (k, v) in ordered.vertices().iter().enumerate() {
        vertices[perm[k] as usize] = *v;
    }
    let simplices: Vec<u32> = ordered
        .simplices()
        .flat_map(|s| s.iter().map(|&v| perm[v as usize]).collect::<Vec<_>>())
        .collect();
    let scrambled =
        umls_mesh::SimplexMesh::new(vertices, simplices, umls_mesh::Orientation::Fix).unwrap();
    let h = 0.002;
    assert!(spinning_block::particles::<2, ()>(h, 1.0).len() > 8 * PARALLEL_SCATTER);
    assert_thread_independent(
        "umls, scrambled",
        Umls2::new(Arc::new(scrambled.clone())),
        h,
        3,
        true,
    );
    let a = state(
        &Umls2::new(Arc::new(ordered)),
        h,
        3,
        2,
        StencilStorage::KernelChoice,
    );
    let b = state(
        &Umls2::new(Arc::new(scrambled)),
        h,
        3,
        2,
        StencilStorage::KernelChoice,
    );
    let largest = a.1.iter().map(|v| v.norm()).fold(0.0, f64::max);
    for (va, vb) in a.1.iter().zip(&b.1) {
        assert!((va - vb).norm() <= 1e-12 * largest, "{va} vs {vb}");
    }
}

#[test]
fn three_dimensional_runs_are_bitwise_independent_of_the_thread_count() {
    let mesh = Arc::new(
        Lattice::new([0.0; 3], [1.0; 3], [10, 10, 10])
            .tetrahedra()
            .unwrap(),
    );
    assert_thread_independent("umls 3D", Umls3::new(mesh.clone()), 0.0195, 5, true);
    let corrected = Umls3::new(mesh).with_integration_correction().unwrap();
    assert_thread_independent(
        "umls 3D, integration correction",
        corrected,
        0.0195,
        5,
        true,
    );
    let grid = BSplineKernel::new(
        Vector3::from_element(-0.2),
        0.1,
        [14, 14, 14],
        BSplineOrder::Cubic,
    )
    .unwrap();
    assert_thread_independent("bspline3 3D", grid, 0.0195, 5, true);
}

/// Recomputing a stencil where P2G and G2P use it, or rebuilding it from stored factors
/// (UMLS; the others store entries then), gives the stored stencil's numbers, bit for bit
/// (APIC reads the offsets x_i − x_p too), for mesh kernels, on 1 and 2 threads.
/// B-spline stencils that are not stored are summed row by row
/// (`Kernel::tensor_stencil`), grouped otherwise than the stored entries: see
/// [`recomputed_b_spline_stencils_agree_with_stored_ones_under_every_transfer`].
#[test]
fn stored_factored_and_recomputed_stencils_give_the_same_bits() {
    fn same<const D: usize, K: Kernel<D> + Clone + Send + Sync>(name: &str, kernel: K, h: f64) {
        let stored = state(&kernel, h, 12, 1, StencilStorage::Store);
        for threads in [1, 2] {
            assert!(
                state(&kernel, h, 12, threads, StencilStorage::Recompute) == stored,
                "{name}: recomputed stencils on {threads} threads differ from stored ones"
            );
            assert!(
                state(&kernel, h, 12, threads, StencilStorage::Factored) == stored,
                "{name}: factored stencils on {threads} threads differ from stored ones"
            );
        }
        // The runs moved the particles: the comparison is not between two rest states.
        assert!(stored.1.iter().any(|v| v.norm() > 0.1), "{name}");
    }
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [16, 16]).jitter(0.2, 5);
    let triangles = Arc::new(mesh.triangles(Diagonal::Alternating).unwrap());
    assert!(Umls2::new(triangles.clone()).factor_layout().is_some());
    same("umls", Umls2::new(triangles.clone()), 0.0125);
    same(
        "umls full gradient (entries)",
        Umls2::new(triangles.clone()).with_gradient(umls_mls::GradientKind::Full),
        0.0125,
    );
    // ξ̄_p of the integration correction: stored with the entries, or summed by P2G over
    // the same evaluation as the entries (factored and recomputed stencils).
    same(
        "umls with the integration correction",
        Umls2::new(triangles).with_integration_correction().unwrap(),
        0.0125,
    );
    let tets = Lattice::new([0.0; 3], [1.0; 3], [6; 3]).jitter(0.2, 3);
    same(
        "umls 3D",
        Umls3::new(Arc::new(tets.tetrahedra().unwrap())),
        0.05,
    );
}

/// MLS-MPM with UMLS, whose D_p is each particle's own (summed with the stored entries,
/// or from the stencil where factored or recomputed): the same bits on 1, 2 and 4
/// threads and with every storage, in 2D with more particles than one P2G block holds
/// (the blocks are scattered in parallel) and in 3D.
#[test]
fn mls_mpm_with_umls_is_independent_of_threads_and_storage() {
    fn same<const D: usize, K: Kernel<D> + Clone + Send + Sync>(name: &str, kernel: K, h: f64) {
        let stored = state_with(&kernel, MlsMpm, h, 12, 1, StencilStorage::Store);
        assert!(stored.1.iter().any(|v| v.norm() > 0.1), "{name}");
        for threads in [1, 2, 4] {
            for storage in [
                StencilStorage::Store,
                StencilStorage::Factored,
                StencilStorage::Recompute,
            ] {
                assert!(
                    state_with(&kernel, MlsMpm, h, 12, threads, storage) == stored,
                    "{name}: {storage:?} on {threads} threads differs from stored on 1"
                );
            }
        }
        // Not APIC's bits: the force's gradient is another.
        assert!(state_with(&kernel, Apic, h, 12, 1, StencilStorage::Store) != stored);
    }
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [40, 40]).jitter(0.2, 5);
    let triangles = Arc::new(mesh.triangles(Diagonal::Alternating).unwrap());
    let kernel = Umls2::new(triangles).with_integration_correction().unwrap();
    let count = spinning_block::particles::<2, ()>(0.005, 1.0)
        .position
        .len();
    assert!(count > PARALLEL_SCATTER, "{count} particles");
    same("umls 2D", kernel, 0.005);
    let tets = Lattice::new([0.0; 3], [1.0; 3], [6; 3]).jitter(0.2, 3);
    same(
        "umls 3D",
        Umls3::new(Arc::new(tets.tetrahedra().unwrap())),
        0.05,
    );
}

/// B-spline stencils that are not stored are summed row by row along axis 0
/// (`Kernel::tensor_stencil`): under every transfer scheme, in 2D and 3D, quadratic and
/// cubic, the particles come out as with the stored entries summed one by one, to
/// round-off (the sums are grouped otherwise; a wrong factor or gradient component
/// would show at the size of the motion), and the stored entries still equal the
/// factored setting's (B-splines have no factors, so it stores entries) bit for bit.
#[test]
fn recomputed_b_spline_stencils_agree_with_stored_ones_under_every_transfer() {
    fn agree<const D: usize, T: TransferScheme + Copy>(
        name: &str,
        kernel: &BSplineKernel<D>,
        transfer: T,
        h: f64,
    ) {
        let stored = state_with(kernel, transfer, h, 12, 1, StencilStorage::Store);
        let largest = |values: &[f64]| values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let flat = |s: &State<D>| -> [Vec<f64>; 3] {
            [
                s.0.iter().flat_map(|v| v.iter().copied()).collect(),
                s.1.iter().flat_map(|v| v.iter().copied()).collect(),
                s.2.iter().flat_map(|m| m.iter().copied()).collect(),
            ]
        };
        let reference = flat(&stored);
        // The runs moved the particles: the comparison is not between two rest states.
        assert!(stored.1.iter().any(|v| v.norm() > 0.1), "{name}");
        for threads in [1, 2] {
            let rows = flat(&state_with(
                kernel,
                transfer,
                h,
                12,
                threads,
                StencilStorage::Recompute,
            ));
            for (field, (a, b)) in ["position", "velocity", "deformation"]
                .iter()
                .zip(reference.iter().zip(&rows))
            {
                let scale = largest(a);
                let difference = a
                    .iter()
                    .zip(b)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                assert!(
                    difference <= 1e-12 * scale,
                    "{name}, {threads} threads: {field} differs by {difference:e} (scale {scale:e})"
                );
            }
            assert!(
                state_with(kernel, transfer, h, 12, threads, StencilStorage::Factored) == stored,
                "{name}: factored stencils on {threads} threads differ from stored ones"
            );
        }
    }
    fn every_transfer<const D: usize>(name: &str, kernel: &BSplineKernel<D>, h: f64) {
        agree(&format!("{name}, PIC"), kernel, Pic, h);
        agree(&format!("{name}, FLIP"), kernel, Flip { alpha: 0.99 }, h);
        agree(&format!("{name}, APIC"), kernel, Apic, h);
        agree(&format!("{name}, MLS-MPM"), kernel, MlsMpm, h);
        agree(
            &format!("{name}, APIC-FLIP"),
            kernel,
            ApicFlip { alpha: 0.99 },
            h,
        );
        agree(
            &format!("{name}, velocity-gradient"),
            kernel,
            VelocityGradientAffine,
            h,
        );
    }
    for order in [BSplineOrder::Quadratic, BSplineOrder::Cubic] {
        let grid2 = BSplineKernel::new(Vector2::new(-0.1, -0.1), 0.05, [24, 24], order);
        every_transfer(&format!("{order:?} 2D"), &grid2.unwrap(), 0.0125);
        let grid3 = BSplineKernel::new(Vector3::from_element(-0.2), 0.1, [14, 14, 14], order);
        every_transfer(&format!("{order:?} 3D"), &grid3.unwrap(), 0.05);
    }
}
