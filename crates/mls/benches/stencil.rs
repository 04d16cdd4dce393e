//! UMLS stencil evaluation per point (weights, moment matrix, solve, shape functions and
//! gradients) on jittered meshes, against linear FE shape functions on the same points.
//! The benchmark ids carry the mean stencil size.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::SVector;
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mls::{GradientKind, Linear, PolynomialBasis, Stencil, UmlsKernel};

/// One point per simplex at a fixed interior barycentric position.
fn points<const D: usize>(mesh: &SimplexMesh<D>) -> Vec<(u32, SVector<f64, D>)> {
    let raw = [0.4, 0.3, 0.2, 0.1];
    (0..mesh.simplex_count())
        .map(|s| {
            let total: f64 = raw[..=D].iter().sum();
            let x = mesh
                .simplex(s)
                .iter()
                .zip(raw)
                .fold(SVector::zeros(), |acc, (&v, w)| {
                    acc + mesh.vertex(v as usize) * (w / total)
                });
            (s as u32, x)
        })
        .collect()
}

fn bench_kernel<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    c: &mut Criterion,
    group_name: &str,
    basis: &str,
    mesh: &SimplexMesh<D>,
) {
    let kernel = UmlsKernel::new(mesh);
    let pts = points(mesh);
    let mean_ring = (0..mesh.simplex_count())
        .map(|s| mesh.topology().one_ring(s).len())
        .sum::<usize>() as f64
        / mesh.simplex_count() as f64;
    let mut group = c.benchmark_group(group_name);
    group.throughput(Throughput::Elements(pts.len() as u64));
    group.sample_size(20);
    for kind in [GradientKind::Reconstructed, GradientKind::Full] {
        let id = BenchmarkId::new(
            format!("umls_{basis}_{kind:?}"),
            format!("stencil{mean_ring:.1}"),
        );
        group.bench_function(id, |b| {
            let mut st = Stencil::new();
            b.iter(|| {
                let mut acc = 0.0;
                for (s, x) in &pts {
                    kernel
                        .evaluate::<N, B>(mesh, *s, x, kind, &mut st)
                        .expect("well-conditioned interior stencil");
                    acc += st.values()[0];
                }
                acc
            })
        });
    }
    group.finish();
}

fn bench_linear_fe<const D: usize>(c: &mut Criterion, group_name: &str, mesh: &SimplexMesh<D>) {
    let pts = points(mesh);
    let mut group = c.benchmark_group(group_name);
    group.throughput(Throughput::Elements(pts.len() as u64));
    group.sample_size(20);
    group.bench_function(
        BenchmarkId::new("linear_fe", format!("stencil{}", D + 1)),
        |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for (s, x) in &pts {
                    let lambda = mesh.barycentric(*s as usize, x);
                    let grads = mesh.barycentric_gradients(*s as usize);
                    acc += lambda.as_slice()[0] + grads.as_slice()[0][0];
                }
                acc
            })
        },
    );
    group.finish();
}

fn stencil(c: &mut Criterion) {
    let tri = Lattice::new([0.0, 0.0], [1.0, 1.0], [60, 60])
        .jitter(0.2, 3)
        .triangles(Diagonal::Alternating)
        .expect("mesh");
    bench_kernel::<2, 3, Linear>(c, "stencil_2d", "linear", &tri);
    bench_linear_fe(c, "stencil_2d", &tri);
    let tet = Lattice::new([0.0; 3], [1.0; 3], [12, 12, 12])
        .jitter(0.2, 3)
        .tetrahedra()
        .expect("mesh");
    bench_kernel::<3, 4, Linear>(c, "stencil_3d", "linear", &tet);
    bench_linear_fe(c, "stencil_3d", &tet);
}

criterion_group!(benches, stencil);
criterion_main!(benches);
