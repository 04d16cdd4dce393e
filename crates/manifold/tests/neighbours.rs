//! Neighbour search is exact: k-nearest and radius queries against brute force, in low
//! dimension (raw k-d tree) and high dimension (projected tree with exact re-ranking),
//! including duplicate samples and data on a coordinate plane.

use proptest::prelude::*;
use umls_manifold::{ManifoldMls, NeighbourIndex, PointCloud, Settings};

mod common;

fn brute(cloud: &PointCloud, q: &[f64]) -> Vec<(usize, f64)> {
    let mut all: Vec<(usize, f64)> = (0..cloud.len())
        .map(|i| {
            (
                i,
                cloud
                    .point(i)
                    .iter()
                    .zip(q)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
                    .sqrt(),
            )
        })
        .collect();
    all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    all
}

fn check(ambient: usize, coords: Vec<f64>, queries: &[f64], k: usize) -> Result<(), TestCaseError> {
    let cloud = PointCloud::from_points(ambient, coords).unwrap();
    let index = NeighbourIndex::new(&cloud);
    for q in queries.chunks_exact(ambient) {
        let expected = brute(&cloud, q);
        let found = index.nearest(&cloud, q, k).unwrap();
        prop_assert_eq!(found.len(), k.min(cloud.len()));
        for (f, e) in found.iter().zip(&expected) {
            // Ties may order differently; distances must match exactly.
            prop_assert!(
                (f.distance - e.1).abs() <= 1e-12 * (1.0 + e.1),
                "k-NN distance {} vs {}",
                f.distance,
                e.1
            );
        }
        let radius = expected[(k / 2).min(expected.len() - 1)].1;
        let within = index.within(&cloud, q, radius).unwrap();
        let count = expected.iter().filter(|e| e.1 <= radius).count();
        prop_assert_eq!(within.len(), count, "radius query");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn exact_in_three_dimensions(coords in prop::collection::vec(-1.0f64..1.0, 3 * 200), queries in prop::collection::vec(-1.2f64..1.2, 3 * 10), k in 1usize..40) {
        check(3, coords, &queries, k)?;
    }

    /// n = 50 > TREE_DIM: data near a curved 2-surface, so the 4-component projection loses
    /// some spread and re-ranking matters.
    #[test]
    fn exact_in_fifty_dimensions(params in prop::collection::vec((0.0f64..6.3, 0.0f64..3.1), 300), seed in any::<u64>(), k in 1usize..30) {
        let n = 50;
        let mut state = seed | 1;
        let mut next = || { state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407); (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5 };
        let directions: Vec<Vec<f64>> = (0..6).map(|_| (0..n).map(|_| next()).collect()).collect();
        let features = |u: f64, v: f64| [u.cos() * v.sin(), u.sin() * v.sin(), v.cos(), (2.0 * u).sin() * 0.3, (3.0 * v).cos() * 0.2, 0.1 * u];
        let mut coords = Vec::new();
        for &(u, v) in &params {
            let f = features(u, v);
            coords.extend((0..n).map(|j| (0..6).map(|c| directions[c][j] * f[c]).sum::<f64>()));
        }
        let queries: Vec<f64> = coords[..n * 5].iter().map(|x| x + 0.01 * next()).collect();
        check(n, coords, &queries, k)?;
    }
}

#[test]
fn duplicates_and_flat_data() {
    // 100 copies of one point plus a grid on the plane z = 0 (a constant coordinate).
    let mut coords: Vec<f64> = (0..100).flat_map(|_| [0.5, 0.5, 0.0]).collect();
    for i in 0..20 {
        for j in 0..20 {
            coords.extend([i as f64 / 19.0, j as f64 / 19.0, 0.0]);
        }
    }
    check(3, coords, &[0.5, 0.5, 0.0, 0.1, 0.9, 0.3], 150).unwrap();
}

/// Queries on samples, and a few units in the last place off them, in high dimension
/// (the projected tree): the true distance is 0 or ~1e-15, below the round-off of the
/// projected one, and the sample must still be found by k-NN and by a radius query, and
/// a manifold fit there must run. (In the benchmark, the helix in R¹⁰⁰⁰, a fit's
/// projected point that close to a sample found no neighbour and panicked.)
#[test]
fn queries_on_samples_find_them_in_high_dimension() {
    let n = 1000;
    let columns = common::isometric_embedding(n, 17);
    let helix = |t: f64| [t.cos(), t.sin(), 0.5 * t];
    let samples: Vec<[f64; 3]> = (0..4000).map(|i| helix(12.0 * i as f64 / 4000.0)).collect();
    let coords: Vec<f64> = samples
        .iter()
        .flat_map(|p| common::embed(&columns, p))
        .collect();
    let values: Vec<f64> = samples.iter().map(|p| p[0] * p[1] + p[2]).collect();
    let cloud = PointCloud::new(n, coords, 1, values).unwrap();
    let index = NeighbourIndex::new(&cloud);
    for sample in (0..4000).step_by(37) {
        // On the sample, and a few units in the last place off it: true distances of
        // 0 and ~1e-15, below the projection's round-off.
        let exact = cloud.point(sample).to_vec();
        let nudged: Vec<f64> = exact
            .iter()
            .enumerate()
            .map(|(j, &x)| {
                if j % 3 == 0 {
                    x.next_up()
                } else {
                    x.next_down()
                }
            })
            .collect();
        for q in [exact, nudged] {
            let nearest = index.nearest(&cloud, &q, 1).unwrap();
            assert_eq!(nearest.len(), 1, "sample {sample}");
            assert!(nearest[0].distance <= 1e-12, "sample {sample}");
            let within = index.within(&cloud, &q, 1e-12).unwrap();
            assert!(within.iter().any(|f| f.index == sample), "sample {sample}");
        }
    }
    let mls = ManifoldMls::new(cloud, Settings::new(1, 1)).unwrap();
    let on_sample = common::embed(&columns, &helix(0.0));
    let fit = mls.evaluate(&on_sample).unwrap();
    assert!(fit.value[0].abs() < 1e-6, "{}", fit.value[0]);
}
