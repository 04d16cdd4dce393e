//! Queries per second for d = 1, 2 and n = 3, 100, 1000 at m = 1, 2: a helix (d = 1) and
//! the sphere (d = 2), isometrically embedded in Rⁿ.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use umls_manifold::{ManifoldMls, PointCloud, Settings};

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

criterion_group!(benches, queries);
criterion_main!(benches);
