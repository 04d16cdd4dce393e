//! Taichi's `mpm3d` scene, the `fluid-box-3d` built-in (scenes/fluid-box-3d.toml): a
//! weakly compressible fluid block of 64,000 particles in [0.15, 0.55]³ falls in a unit
//! box of slip walls three cells in from its faces, APIC, Δt = 2·10⁻⁴. One step per
//! iteration, in particle-steps per second, with 1 and 2 threads, for quadratic B-splines
//! on the 64³ grid and UMLS on the 64³-cell Kuhn lattice of tetrahedra (1.57 M tets, the
//! same node spacing), both also with MLS-MPM (Taichi's own transfer: the force folded
//! into the affine momentum; UMLS with each particle's own D_p); UMLS once more with its
//! stencils kept as the fits' factors (`StencilStorage::Factored`: half the memory, rebuilt in P2G and G2P).
//! The comparison with Taichi runs the same scene through
//! `umls run fluid-box-3d`; this bench isolates the step from scene set-up and output.

use std::sync::Arc;

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{SVector, Vector3};
use umls::constitutive::WeaklyCompressibleFluid;
use umls::engine::{
    Apic, MlsMpm, Particles, Simulation, StencilStorage, StepSettings, TransferScheme, Wall,
    WallKind, lattice_points,
};
use umls::kernels::{BSplineKernel, BSplineOrder, Umls3};
use umls::mesh::generate::Lattice;
use umls::transfer::Kernel;

/// Cells per axis of the box.
const CELLS: usize = 64;
/// Where the walls stand: three cells in from the box's faces.
const WALL: f64 = 3.0 / CELLS as f64;

fn particles<C: Copy + Default>() -> Particles<3, (), C> {
    let (x, volume): (Vec<Vector3<f64>>, Vec<f64>) =
        lattice_points(Vector3::repeat(0.15), Vector3::repeat(0.55), 0.01).unzip();
    Particles::at_rest(x, volume, 1.0, ())
}

/// A simulation of the scene on `kernel`: slip conditions on the nodes on or beyond each
/// wall, and the walls themselves for the particles.
fn scene<K: Kernel<3>, T: TransferScheme>(
    kernel: K,
    transfer: T,
    storage: StencilStorage,
) -> Simulation<3, K, WeaklyCompressibleFluid, T> {
    let material = WeaklyCompressibleFluid::new(400.0, 1.0).expect("valid");
    let mut settings = StepSettings::new(2e-4);
    settings.stencil_storage = storage;
    settings.gravity = Vector3::new(0.0, -9.8, 0.0);
    // As the scene file: the particles stored in P2G's order every 20 steps.
    settings.particle_sort_interval = 20;
    let mut sim =
        Simulation::new(kernel, material, transfer, particles(), settings).expect("valid");
    for axis in 0..3 {
        for (point, sign) in [(WALL, -1.0), (1.0 - WALL, 1.0)] {
            let normal = SVector::<f64, 3>::from_fn(|k, _| if k == axis { sign } else { 0.0 });
            for node in 0..sim.kernel.node_count() {
                let x = sim.kernel.node_position(node)[axis];
                if (x - point) * sign >= -1e-12 {
                    sim.boundary.slip.push((node as u32, normal));
                }
            }
            sim.boundary.walls.push(Wall {
                kind: WallKind::Slip,
                point: SVector::<f64, 3>::from_fn(|k, _| if k == axis { point } else { 0.5 }),
                normal,
            });
        }
    }
    sim
}

fn bench<K: Kernel<3> + Clone, T: TransferScheme>(
    c: &mut Criterion,
    name: &str,
    kernel: K,
    transfer: T,
    storage: StencilStorage,
) {
    let mut g = c.benchmark_group("fluid_box_3d_64k");
    g.throughput(Throughput::Elements(64_000));
    g.sample_size(10);
    common::step_with_threads(&mut g, name, || scene(kernel.clone(), transfer, storage));
    g.finish();
}

fn fluid_box(c: &mut Criterion) {
    let h = 1.0 / CELLS as f64;
    // Two cells of margin around the box, as `umls run` gives a grid kernel.
    let grid = BSplineKernel::new(
        SVector::repeat(-2.0 * h),
        h,
        [CELLS + 4; 3],
        BSplineOrder::Quadratic,
    )
    .expect("grid");
    let auto = StencilStorage::KernelChoice;
    bench(c, "bspline2", grid.clone(), Apic, auto);
    bench(c, "bspline2_mls_mpm", grid, MlsMpm, auto);
    let mesh = Lattice::new([0.0; 3], [1.0; 3], [CELLS; 3])
        .tetrahedra()
        .expect("mesh");
    let umls = Umls3::new(Arc::new(mesh));
    bench(c, "umls_tet", umls.clone(), Apic, auto);
    // MLS-MPM with each particle's own D_p.
    bench(c, "umls_tet_mls_mpm", umls.clone(), MlsMpm, auto);
    bench(c, "umls_tet_factored", umls, Apic, StencilStorage::Factored);
}

criterion_group!(benches, fluid_box);
criterion_main!(benches);
