//! Locating 10⁵ slightly moved points: walk from the previous host vs a fresh BVH query.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::SVector;
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};

const POINTS: usize = 100_000;

/// Deterministic pseudo-random numbers in [0, 1) (an LCG is enough to spread points).
fn uniform(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Points inside the mesh with their hosts, and the same points moved by up to 0.2 h.
fn moved_points<const D: usize>(mesh: &SimplexMesh<D>) -> (Vec<u32>, Vec<SVector<f64, D>>) {
    let mut state = 42;
    let h = mesh.max_edge_length();
    let mut hosts = Vec::with_capacity(POINTS);
    let mut moved = Vec::with_capacity(POINTS);
    while hosts.len() < POINTS {
        let x = SVector::<f64, D>::from_fn(|_, _| 0.05 + 0.9 * uniform(&mut state));
        let dx = SVector::<f64, D>::from_fn(|_, _| 0.2 * h * (2.0 * uniform(&mut state) - 1.0));
        if let Some(found) = mesh.locate(&x) {
            hosts.push(found.simplex);
            moved.push(x + dx);
        }
    }
    (hosts, moved)
}

fn bench_dimension<const D: usize>(c: &mut Criterion, name: &str, mesh: &SimplexMesh<D>) {
    let (hosts, moved) = moved_points(mesh);
    let mut group = c.benchmark_group(format!("locate_{name}"));
    group.throughput(Throughput::Elements(POINTS as u64));
    group.sample_size(20);
    group.bench_function(
        BenchmarkId::new("walk_from_previous_host", mesh.simplex_count()),
        |b| {
            b.iter(|| {
                hosts
                    .iter()
                    .zip(&moved)
                    .filter_map(|(&h, x)| mesh.locate_from(x, h))
                    .map(|l| l.simplex as u64)
                    .sum::<u64>()
            })
        },
    );
    group.bench_function(BenchmarkId::new("bvh", mesh.simplex_count()), |b| {
        b.iter(|| {
            moved
                .iter()
                .filter_map(|x| mesh.locate(black_box(x)))
                .map(|l| l.simplex as u64)
                .sum::<u64>()
        })
    });
    group.finish();
}

fn locate(c: &mut Criterion) {
    let tri = Lattice::new([0.0, 0.0], [1.0, 1.0], [100, 100])
        .jitter(0.2, 1)
        .triangles(Diagonal::Alternating)
        .expect("valid mesh");
    bench_dimension(c, "2d", &tri);
    let tet = Lattice::new([0.0; 3], [1.0; 3], [20, 20, 20])
        .jitter(0.2, 1)
        .tetrahedra()
        .expect("valid mesh");
    bench_dimension(c, "3d", &tet);
}

criterion_group!(benches, locate);
criterion_main!(benches);
