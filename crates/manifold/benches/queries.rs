//! Queries per second for d = 1, 2 and n = 3, 100, 1000 at m = 1, 2: a helix (d = 1) and
//! the sphere (d = 2), isometrically embedded in Rⁿ. Then the neighbour index against a
//! brute-force scan in R¹⁰⁰, on the embedded sphere (3 directions) and on a 2-torus spread
//! over 16 directions, N = 16,000, 20 nearest.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use umls_manifold::{ManifoldMls, NeighbourIndex, PointCloud, Settings};

/// Orthonormal n×3 embedding columns from a deterministic generator.
fn embedding(n: usize) -> Vec<Vec<f64>> {
    let mut state = 17u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut cols: Vec<Vec<f64>> = Vec::new();
    while cols.len() < 3 {
        let mut v: Vec<f64> = (0..n).map(|_| next()).collect();
        for c in &cols {
            let d: f64 = v.iter().zip(c).map(|(a, b)| a * b).sum();
            v.iter_mut().zip(c).for_each(|(a, b)| *a -= d * b);
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        cols.push(v.into_iter().map(|x| x / norm).collect());
    }
    cols
}

fn embed(cols: &[Vec<f64>], p: [f64; 3], n: usize) -> Vec<f64> {
    if n == 3 {
        return p.to_vec();
    }
    (0..n)
        .map(|j| (0..3).map(|k| cols[k][j] * p[k]).sum())
        .collect()
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
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..count)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
                let r = (1.0 - z * z).sqrt();
                [
                    r * (golden * i as f64).cos(),
                    r * (golden * i as f64).sin(),
                    z,
                ]
            })
            .collect()
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
            let cols = embedding(n);
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

/// A 2-torus in Rⁿ whose 16 Fourier features lie along random directions.
fn spread_torus(n: usize, count: usize) -> Vec<f64> {
    let mut state = 5u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let directions: Vec<Vec<f64>> = (0..16).map(|_| (0..n).map(|_| next()).collect()).collect();
    let mut coords = Vec::with_capacity(n * count);
    for _ in 0..count {
        let (u, v) = (
            std::f64::consts::TAU * next(),
            std::f64::consts::TAU * next(),
        );
        let features: Vec<f64> = (0..16)
            .map(|k| {
                let f = (k / 4 + 1) as f64;
                [(f * u).cos(), (f * u).sin(), (f * v).cos(), (f * v).sin()][k % 4]
            })
            .collect();
        coords.extend((0..n).map(|j| (0..16).map(|k| directions[k][j] * features[k]).sum::<f64>()));
    }
    coords
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
    let cols = embedding(n);
    let sphere: Vec<f64> = samples(2, count)
        .iter()
        .flat_map(|p| embed(&cols, *p, n))
        .collect();
    let mut group = c.benchmark_group("neighbours_n100_N16k");
    group.sample_size(10);
    for (name, coords) in [("sphere", sphere), ("torus16", spread_torus(n, count))] {
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
