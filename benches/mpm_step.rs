//! One full explicit MPM step (stencils, P2G, grid, G2P, stress update) in particle-steps
//! per second, for UMLS on triangles and tetrahedra, linear FE on the same meshes and
//! quadratic B-splines on a grid covering the same box, with 1 and 2 threads. Neo-Hookean
//! material, PIC transfer and USL (the transfer costs about the same for every scheme),
//! about 2·10⁴ particles.

use std::sync::Arc;

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::SVector;
use umls::constitutive::{ElasticParameters, NeoHookean};
use umls::engine::{Particles, Pic, Simulation, StepSettings};
use umls::kernels::{BSplineKernel, BSplineOrder, LinearFeKernel, Umls2, Umls3};
use umls::mesh::generate::{Diagonal, Lattice};
use umls::transfer::Kernel;

/// Particles on a regular lattice of `per_axis`^D points inside [0.2, 0.8]^D, swirling.
fn particles<const D: usize, C: Copy + Default>(per_axis: usize) -> Particles<D, (), C> {
    let count = per_axis.pow(D as u32);
    let spacing = 0.6 / per_axis as f64;
    let x: Vec<SVector<f64, D>> = (0..count)
        .map(|mut i| {
            SVector::<f64, D>::from_fn(|_, _| {
                let k = i % per_axis;
                i /= per_axis;
                0.2 + (k as f64 + 0.5) * spacing
            })
        })
        .collect();
    let mut p = Particles::at_rest(x, vec![spacing.powi(D as i32); count], 1000.0, ());
    for (v, x) in p.velocity.iter_mut().zip(&p.position) {
        *v = SVector::<f64, D>::from_fn(|k, _| 0.1 * (x[(k + 1) % D] - 0.5));
    }
    p
}

fn bench_kernel<const D: usize, K: Kernel<D> + Clone>(
    c: &mut Criterion,
    group: &str,
    name: &str,
    kernel: K,
    per_axis: usize,
) {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e5, 0.3).expect("valid"),
    };
    let count = per_axis.pow(D as u32);
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(count as u64));
    g.sample_size(10);
    // USL, the engine's default, for every kernel: the grid update's mass scaling
    // keeps nodes barely covered by material (tiny mass, large f/m) stable.
    common::step_with_threads(&mut g, name, || {
        Simulation::new(
            kernel.clone(),
            material,
            Pic,
            particles::<D, K::Cache>(per_axis),
            StepSettings::new(1e-5),
        )
        .expect("valid")
    });
    g.finish();
}

fn mpm_step(c: &mut Criterion) {
    let tri = Arc::new(
        Lattice::new([0.0, 0.0], [1.0, 1.0], [50, 50])
            .jitter(0.2, 1)
            .triangles(Diagonal::Alternating)
            .expect("mesh"),
    );
    bench_kernel(
        c,
        "mpm_step_2d_20k",
        "umls_tri",
        Umls2::new(tri.clone()),
        140,
    );
    bench_kernel(
        c,
        "mpm_step_2d_20k",
        "linear_fe_tri",
        LinearFeKernel::new(tri),
        140,
    );
    bench_kernel(
        c,
        "mpm_step_2d_20k",
        "bspline2",
        BSplineKernel::new(
            SVector::from([0.0, 0.0]),
            0.02,
            [50, 50],
            BSplineOrder::Quadratic,
        )
        .expect("grid"),
        140,
    );
    let tet = Arc::new(
        Lattice::new([0.0; 3], [1.0; 3], [14, 14, 14])
            .jitter(0.2, 1)
            .tetrahedra()
            .expect("mesh"),
    );
    bench_kernel(
        c,
        "mpm_step_3d_22k",
        "umls_tet",
        Umls3::new(tet.clone()),
        28,
    );
    bench_kernel(
        c,
        "mpm_step_3d_22k",
        "linear_fe_tet",
        LinearFeKernel::new(tet),
        28,
    );
    bench_kernel(
        c,
        "mpm_step_3d_22k",
        "bspline2",
        BSplineKernel::new(
            SVector::from([0.0, 0.0, 0.0]),
            1.0 / 14.0,
            [14, 14, 14],
            BSplineOrder::Quadratic,
        )
        .expect("grid"),
        28,
    );
}

criterion_group!(benches, mpm_step);
criterion_main!(benches);
