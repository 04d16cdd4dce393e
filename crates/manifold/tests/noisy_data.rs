//! Noisy and under-sampled data: the adaptive bandwidth, the noise estimates of
//! `FitQuality`, its concerns, and validation of every setting.
mod common;

use std::f64::consts::TAU;

use common::{Lcg, fibonacci_sphere, noisy_sphere, sphere_function};
use proptest::prelude::*;
use umls_manifold::{Bandwidth, ManifoldError, ManifoldMls, PointCloud, Settings};

/// `count` uniformly random points of S², the same for every call.
fn random_sphere(count: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Lcg(seed);
    (0..count)
        .map(|_| {
            let p = [rng.gauss(), rng.gauss(), rng.gauss()];
            let norm = p.iter().map(|x| x * x).sum::<f64>().sqrt();
            p.map(|x| x / norm)
        })
        .collect()
}

/// RMS value error at clean queries, and the number of failed queries.
fn value_rms(mls: &ManifoldMls, queries: &[[f64; 3]]) -> (f64, usize) {
    let mut squares = 0.0;
    let mut failed = 0;
    for q in queries {
        match mls.evaluate(q) {
            Ok(estimate) => squares += (estimate.value[0] - sphere_function(q)).powi(2),
            Err(_) => failed += 1,
        }
    }
    ((squares / (queries.len() - failed) as f64).sqrt(), failed)
}

#[test]
fn at_fixed_noise_the_error_falls_as_samples_grow() {
    // S² with Gaussian noise 0.05 on positions and values, m = 1. The plain rule keeps
    // K* samples whatever N is, so its error stalls at the noise it averages; the
    // adaptive bandwidth widens where that pays and its error keeps falling.
    let queries = random_sphere(300, 3);
    let plain = Settings {
        bandwidth: Bandwidth::Neighbours {
            factor: 3.0,
            scale: 2.0,
        },
        ..Settings::new(2, 1)
    };
    let mut adaptive_errors = Vec::new();
    let mut plain_errors = Vec::new();
    for count in [2000, 8000] {
        let cloud = noisy_sphere(count, 0.05, 11 + count as u64);
        let adaptive = ManifoldMls::new(cloud.clone(), Settings::new(2, 1)).unwrap();
        let (error, failed) = value_rms(&adaptive, &queries);
        assert_eq!(failed, 0);
        assert!(
            adaptive.growth() > 1.0,
            "noise calls for a wider σ at N = {count}"
        );
        adaptive_errors.push(error);
        let (error, failed) = value_rms(&ManifoldMls::new(cloud, plain).unwrap(), &queries);
        assert_eq!(failed, 0);
        plain_errors.push(error);
    }
    assert!(
        adaptive_errors[1] < 0.8 * adaptive_errors[0],
        "adaptive RMS {adaptive_errors:?} must fall with N"
    );
    assert!(
        adaptive_errors[1] < 0.8 * plain_errors[1],
        "adaptive {adaptive_errors:?} against the plain rule {plain_errors:?}"
    );
}

#[test]
fn clean_data_keep_the_rule_bandwidth_and_raise_no_concern() {
    let points = fibonacci_sphere(4000);
    let coords: Vec<f64> = points.iter().flatten().copied().collect();
    let values: Vec<f64> = points.iter().map(|p| sphere_function(p)).collect();
    let cloud = PointCloud::new(3, coords, 1, values).unwrap();
    let mls = ManifoldMls::new(cloud, Settings::new(2, 2)).unwrap();
    assert_eq!(mls.growth(), 1.0);
    for q in random_sphere(100, 5) {
        let estimate = mls.evaluate(&q).unwrap();
        assert!(
            estimate.quality.is_trustworthy(),
            "{:?} at {q:?}",
            estimate.quality
        );
        assert!((estimate.value[0] - sphere_function(&q)).abs() < 1e-4);
    }
}

#[test]
fn noise_estimates_match_the_noise_put_in() {
    // The plane z = 0 with f = x + 2y exactly linear: every residual is noise. Positions
    // get normal noise 0.004 (a tenth of σ: weights fall with the distance in Rⁿ, so
    // noise near σ would weigh its own outliers down), values noise 0.05.
    let mut rng = Lcg(21);
    let (mut coords, mut values) = (Vec::new(), Vec::new());
    for _ in 0..20_000 {
        let (x, y) = (rng.next(), rng.next());
        coords.extend([x, y, 0.004 * rng.gauss()]);
        values.push(x + 2.0 * y + 0.05 * rng.gauss());
    }
    let settings = Settings {
        bandwidth: Bandwidth::Neighbours {
            factor: 10.0,
            scale: 2.0,
        },
        ..Settings::new(2, 1)
    };
    let coords_only = coords.clone();
    let mls = ManifoldMls::new(PointCloud::new(3, coords, 1, values).unwrap(), settings).unwrap();
    let (mut noise, mut position, mut predicted, mut squares) = (0.0, 0.0, 0.0, 0.0);
    let count = 400;
    for _ in 0..count {
        let (x, y) = (0.2 + 0.6 * rng.next(), 0.2 + 0.6 * rng.next());
        let estimate = mls.evaluate(&[x, y, 0.0]).unwrap();
        noise += estimate.quality.noise / count as f64;
        position += estimate.quality.position_noise / count as f64;
        predicted += estimate.quality.standard_error.powi(2) / count as f64;
        squares += (estimate.value[0] - x - 2.0 * y).powi(2) / count as f64;
    }
    assert!((noise / 0.05 - 1.0).abs() < 0.1, "value noise {noise}");
    // Positions alone: no value noise, the same position noise.
    let positions = ManifoldMls::new(PointCloud::from_points(3, coords_only).unwrap(), settings)
        .unwrap()
        .evaluate(&[0.5, 0.5, 0.0])
        .unwrap()
        .quality;
    assert_eq!(positions.noise, 0.0);
    assert_eq!(positions.standard_error, 0.0);
    assert!((positions.position_noise / 0.004 - 1.0).abs() < 0.3);
    assert!(
        (position / 0.004 - 1.0).abs() < 0.1,
        "position noise {position}"
    );
    // The standard error predicts the spread of the answers around the truth.
    let ratio = (squares / predicted).sqrt();
    assert!(
        (ratio - 1.0).abs() < 0.25,
        "observed over predicted error {ratio}"
    );
}

#[test]
fn an_under_sampled_sphere_is_flagged_and_can_be_refused() {
    for (count, degree) in [(40, 2), (40, 1), (24, 1)] {
        let points = fibonacci_sphere(count);
        let coords: Vec<f64> = points.iter().flatten().copied().collect();
        let values: Vec<f64> = points.iter().map(|p| sphere_function(p)).collect();
        let cloud = PointCloud::new(3, coords, 1, values).unwrap();
        let lenient = ManifoldMls::new(cloud.clone(), Settings::new(2, degree)).unwrap();
        let strict = ManifoldMls::new(
            cloud,
            Settings {
                refuse_untrustworthy: true,
                ..Settings::new(2, degree)
            },
        )
        .unwrap();
        for q in random_sphere(50, 8) {
            if let Ok(estimate) = lenient.evaluate(&q) {
                assert!(
                    estimate.quality.concerns.beyond_reach,
                    "N = {count}, m = {degree}: σ {} reach {}",
                    estimate.chart.sigma, estimate.quality.reach
                );
            }
            assert!(
                matches!(
                    strict.evaluate(&q),
                    Err(ManifoldError::Untrustworthy { .. } | ManifoldError::IllConditioned { .. })
                ),
                "N = {count}, m = {degree} at {q:?}"
            );
        }
    }
}

#[test]
fn settings_beyond_what_the_cloud_supports_are_named() {
    let cloud = noisy_sphere(2000, 0.0, 1);
    let refused = |settings: Settings| match ManifoldMls::new(cloud.clone(), settings) {
        Err(ManifoldError::InvalidParameter { parameter, .. }) => parameter,
        other => panic!("{settings:?} gave {other:?}"),
    };
    // Degree 40 in two variables: 861 coefficients, a fit of minutes per query.
    assert_eq!(
        refused(Settings {
            bandwidth: Bandwidth::Fixed(0.5),
            ..Settings::new(2, 40)
        }),
        "degree"
    );
    assert_eq!(refused(Settings::new(2, 40)), "degree");
    // σ = 10³⁰⁰ would make every chart coordinate vanish.
    assert_eq!(
        refused(Settings {
            bandwidth: Bandwidth::Fixed(1e300),
            ..Settings::new(2, 1)
        }),
        "σ"
    );
    assert_eq!(
        refused(Settings {
            bandwidth: Bandwidth::Adaptive {
                factor: 1e19,
                scale: 2.0,
                max_growth: 5.0
            },
            ..Settings::new(2, 1)
        }),
        "bandwidth factor c"
    );
    assert_eq!(
        refused(Settings {
            bandwidth: Bandwidth::Adaptive {
                factor: 3.0,
                scale: 2.0,
                max_growth: 0.5
            },
            ..Settings::new(2, 1)
        }),
        "bandwidth max_growth"
    );
    // A σ as wide as the whole sphere is a global fit, and allowed.
    let global = Settings {
        bandwidth: Bandwidth::Fixed(10.0),
        ..Settings::new(2, 1)
    };
    assert!(ManifoldMls::new(cloud.clone(), global).is_ok());
}

/// 300 samples of the unit circle with f = cos 3t.
fn circle() -> PointCloud {
    let (mut coords, mut values) = (Vec::new(), Vec::new());
    for i in 0..300 {
        let t = TAU * i as f64 / 300.0;
        coords.extend([t.cos(), t.sin()]);
        values.push((3.0 * t).cos());
    }
    PointCloud::new(2, coords, 1, values).unwrap()
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..hi).prop_map(|e: f64| 10f64.powf(e))
}

fn any_bandwidth() -> impl Strategy<Value = Bandwidth> {
    prop_oneof![
        (log_uniform(-3.0, 19.5), log_uniform(-3.0, 3.0))
            .prop_map(|(factor, scale)| Bandwidth::Neighbours { factor, scale }),
        (
            log_uniform(-3.0, 19.5),
            log_uniform(-3.0, 3.0),
            log_uniform(-1.0, 3.0)
        )
            .prop_map(|(factor, scale, max_growth)| Bandwidth::Adaptive {
                factor,
                scale,
                max_growth
            }),
        log_uniform(-300.0, 300.0).prop_map(Bandwidth::Fixed),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Every setting is either refused when the approximation is built or answers a
    /// query with a value or an error: never a panic, and this crate's release builds
    /// check overflow.
    #[test]
    fn no_setting_panics(
        bandwidth in any_bandwidth(),
        degree in 0usize..70,
        tolerance in log_uniform(-300.0, 3.0),
        max_iterations in 1usize..300,
        max_condition in log_uniform(0.0, 300.0),
        max_widening in log_uniform(0.0, 3.0),
        max_offset in log_uniform(-3.0, 3.0),
        refuse_untrustworthy in any::<bool>(),
    ) {
        let settings = Settings {
            intrinsic_dim: 1,
            degree,
            bandwidth,
            tolerance,
            max_iterations,
            max_condition,
            max_widening,
            max_offset,
            refuse_untrustworthy,
        };
        if let Ok(mls) = ManifoldMls::new(circle(), settings) {
            if let Ok(estimate) = mls.evaluate(&[0.6, 0.8]) {
                prop_assert!(estimate.value[0].is_finite());
            }
        }
    }
}
