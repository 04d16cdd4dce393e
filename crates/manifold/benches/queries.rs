//! Queries per second for d = 1, 2 and n = 3, 100, 1000 at m = 1, 2: a helix (d = 1) and
//! the sphere (d = 2), isometrically embedded in Rⁿ. Then the neighbour index against a
//! brute-force scan in R¹⁰⁰, on the embedded sphere (3 directions) and on a 2-torus spread
//! over 16 directions, N = 16,000, 20 nearest.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use umls_manifold::{ManifoldMls, NeighbourIndex, PointCloud, Settings};

// The samplings of the crate's tests.
#[path = "../tests/common/mod.rs"]
mod common;

fn embed(cols: &[Vec<f64>], p: [f64; 3], n: usize) -> Vec<f64> {
    if n == 3 {
        p.to_vec()
    } else {
        common::embed(cols, &p)
    }
}

fn samples(d: usize, count: usize) -> Vec<[f64; 3]> {
    if d == 1 {
        (0..count)
            .map(|i| {
                let t = 12.0 * i as f64 / count as f64;
                [t.cos(), t.sin(), 0.5 * t]
            })
            .collect()
    } else {
        common::fibonacci_sphere(count)
    }
}

fn queries(c: &mut Criterion) {
    for d in [1usize, 2] {
        let base = samples(d, 4000);
        let probe = samples(d, 64);
        let mut group = c.benchmark_group(format!("manifold_d{d}"));
        group.throughput(Throughput::Elements(probe.len() as u64));
        group.sample_size(10);
        for n in [3usize, 100, 1000] {
            let cols = common::isometric_embedding(n, 17);
            let coords: Vec<f64> = base.iter().flat_map(|p| embed(&cols, *p, n)).collect();
            let values: Vec<f64> = base.iter().map(|p| p[0] * p[1] + p[2]).collect();
            let query_coords: Vec<Vec<f64>> = probe.iter().map(|p| embed(&cols, *p, n)).collect();
            for m in [1usize, 2] {
                let mls = ManifoldMls::new(
                    PointCloud::new(n, coords.clone(), 1, values.clone()).expect("valid"),
                    Settings::new(d, m),
                )
                .expect("valid");
                group.bench_function(BenchmarkId::new(format!("m{m}"), format!("n{n}")), |b| {
                    b.iter(|| {
                        query_coords
                            .iter()
                            .map(|r| mls.evaluate(r).expect("interior query").value[0])
                            .sum::<f64>()
                    })
                });
            }
        }
        group.finish();
    }
}

/// The 20 nearest by computing every distance.
fn brute_force(cloud: &PointCloud, query: &[f64], k: usize) -> usize {
    let mut all: Vec<(f64, usize)> = (0..cloud.len())
        .map(|i| {
            let d: f64 = cloud
                .point(i)
                .iter()
                .zip(query)
                .map(|(a, b)| (a - b) * (a - b))
                .sum();
            (d, i)
        })
        .collect();
    all.select_nth_unstable_by(k, |a, b| a.0.total_cmp(&b.0));
    all[..k].iter().map(|a| a.1).sum()
}

fn neighbours(c: &mut Criterion) {
    let n = 100;
    let count = 16_000;
    let cols = common::isometric_embedding(n, 17);
    let sphere: Vec<f64> = samples(2, count)
        .iter()
        .flat_map(|p| embed(&cols, *p, n))
        .collect();
    let mut group = c.benchmark_group("neighbours_n100_N16k");
    group.sample_size(10);
    for (name, coords) in [
        ("sphere", sphere),
        ("torus16", common::spread_torus(n, count, 5)),
    ] {
        let cloud = PointCloud::from_points(n, coords).expect("valid");
        let index = NeighbourIndex::new(&cloud);
        let queries: Vec<Vec<f64>> = (0..32)
            .map(|q| cloud.point(q * 499).iter().map(|x| x + 1e-3).collect())
            .collect();
        group.throughput(Throughput::Elements(queries.len() as u64));
        group.bench_function(BenchmarkId::new("index", name), |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|q| index.nearest(&cloud, q, 20).expect("valid")[0].index)
                    .sum::<usize>()
            })
        });
        group.bench_function(BenchmarkId::new("brute_force", name), |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|q| brute_force(&cloud, q, 20))
                    .sum::<usize>()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, queries, neighbours);
criterion_main!(benches);
