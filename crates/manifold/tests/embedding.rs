//! Independence of the ambient dimension, noise, a torus in R⁴, errors, and batch
//! determinism.

mod common;

use umls_manifold::{Bandwidth, ManifoldError, ManifoldMls, PointCloud, Settings};

/// Errors on a d = 2 sphere embedded isometrically in Rⁿ for n = 3 (identity), 10, 100, 1000.
#[test]
fn error_does_not_depend_on_the_ambient_dimension() {
    let pts = common::fibonacci_sphere(1500);
    let values: Vec<f64> = pts.iter().map(|p| common::sphere_function(p)).collect();
    let queries = common::fibonacci_sphere(23);
    let error_in = |n: usize| -> f64 {
        let (coords, embedded_queries): (Vec<f64>, Vec<Vec<f64>>) = if n == 3 {
            (
                pts.iter().flatten().copied().collect(),
                queries.iter().map(|q| q.to_vec()).collect(),
            )
        } else {
            let e = common::isometric_embedding(n, 99);
            (
                pts.iter().flat_map(|p| common::embed(&e, p)).collect(),
                queries.iter().map(|q| common::embed(&e, q)).collect(),
            )
        };
        let mls = ManifoldMls::new(
            PointCloud::new(n, coords, 1, values.clone()).unwrap(),
            Settings::new(2, 2),
        )
        .unwrap();
        embedded_queries
            .iter()
            .zip(&queries)
            .map(|(r, q)| (mls.evaluate(r).unwrap().value[0] - common::sphere_function(q)).abs())
            .fold(0.0, f64::max)
    };
    let reference = error_in(3);
    for n in [10, 100, 1000] {
        let e = error_in(n);
        eprintln!("n = {n}: max error {e:.3e} (R³: {reference:.3e})");
        assert!(
            (e - reference).abs() <= 1e-3 * reference + 1e-12,
            "n = {n}: {e} vs {reference}"
        );
    }
}

#[test]
fn noise_gives_order_delta_error_and_projection_denoises() {
    let pts = common::fibonacci_sphere(3000);
    let clean_values: Vec<f64> = pts.iter().map(|p| common::sphere_function(p)).collect();
    let queries = common::fibonacci_sphere(41);
    let noiseless = {
        let mls = ManifoldMls::new(
            PointCloud::new(
                3,
                pts.iter().flatten().copied().collect(),
                1,
                clean_values.clone(),
            )
            .unwrap(),
            Settings::new(2, 2),
        )
        .unwrap();
        queries
            .iter()
            .map(|q| (mls.evaluate(q).unwrap().value[0] - common::sphere_function(q)).abs())
            .fold(0.0, f64::max)
    };
    for delta in [1e-3, 1e-2] {
        let mut rng = common::Lcg(5);
        let noisy: Vec<f64> = pts
            .iter()
            .flat_map(|p| p.map(|x| x + delta * (2.0 * rng.next() - 1.0)))
            .collect();
        let values: Vec<f64> = clean_values
            .iter()
            .map(|v| v + delta * (2.0 * rng.next() - 1.0))
            .collect();
        let mls = ManifoldMls::new(
            PointCloud::new(3, noisy.clone(), 1, values).unwrap(),
            Settings::new(2, 2),
        )
        .unwrap();
        let err = queries
            .iter()
            .map(|q| (mls.evaluate(q).unwrap().value[0] - common::sphere_function(q)).abs())
            .fold(0.0, f64::max);
        eprintln!("δ = {delta:e}: error {err:.3e}, noiseless {noiseless:.3e}");
        assert!(
            err <= 3.0 * delta + 2.0 * noiseless,
            "δ = {delta}: error {err}"
        );
        // Projecting the noisy samples moves them towards the sphere.
        let before: f64 = noisy
            .chunks_exact(3)
            .take(200)
            .map(|p| (p.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs())
            .sum::<f64>();
        let after: f64 = noisy
            .chunks_exact(3)
            .take(200)
            .map(|p| {
                let q = mls.project(p).unwrap();
                (q.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs()
            })
            .sum();
        eprintln!(
            "   mean distance to S²: before {:.3e}, after projection {:.3e}",
            before / 200.0,
            after / 200.0
        );
        // The constant term of a 6-parameter fit over ~30 effective samples keeps about
        // √(4/30) ≈ 0.4 of the noise: measured 0.42 at both δ.
        assert!(after < 0.5 * before, "projection: {before} → {after}");
    }
}

/// The flat torus in R⁴ (non-trivial topology), m = 2: values converge at third order or
/// better, gradients (as tangent vectors in R⁴) at second order.
#[test]
fn flat_torus_in_r4() {
    let f = |u: f64, v: f64| u.sin() * (2.0 * v).cos();
    let errors: Vec<(f64, f64)> = [24usize, 48, 96]
        .iter()
        .map(|&k| {
            let samples = common::flat_torus(k);
            let coords: Vec<f64> = samples.iter().flat_map(|(_, p)| *p).collect();
            let values: Vec<f64> = samples.iter().map(|([u, v], _)| f(*u, *v)).collect();
            let mls = ManifoldMls::new(
                PointCloud::new(4, coords, 1, values).unwrap(),
                Settings::new(2, 2),
            )
            .unwrap();
            (0..30).fold((0.0f64, 0.0f64), |(ev, eg), i| {
                let (u, v) = (0.3 + 0.2 * i as f64, 1.1 + 0.37 * i as f64);
                let r = [u.cos(), u.sin(), v.cos(), v.sin()];
                let est = mls.evaluate(&r).unwrap();
                // ∇f = f_u ∂r/∂u + f_v ∂r/∂v (u and v are arc lengths).
                let (fu, fv) = (u.cos() * (2.0 * v).cos(), -2.0 * u.sin() * (2.0 * v).sin());
                let exact = [-fu * u.sin(), fu * u.cos(), -fv * v.sin(), fv * v.cos()];
                let g = est.ambient_gradient();
                let grad_err = (0..4)
                    .map(|j| (g[(j, 0)] - exact[j]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                (ev.max((est.value[0] - f(u, v)).abs()), eg.max(grad_err))
            })
        })
        .collect();
    let value_orders: Vec<f64> = errors
        .windows(2)
        .map(|w| (w[0].0 / w[1].0).log2())
        .collect();
    let gradient_orders: Vec<f64> = errors
        .windows(2)
        .map(|w| (w[0].1 / w[1].1).log2())
        .collect();
    eprintln!(
        "torus m = 2: errors {errors:?}, value orders {value_orders:?}, gradient orders {gradient_orders:?}"
    );
    assert!(
        value_orders.iter().all(|&p| p >= 2.7),
        "value orders {value_orders:?}"
    );
    assert!(
        gradient_orders.iter().all(|&p| p >= 1.7),
        "gradient orders {gradient_orders:?}"
    );
}

#[test]
fn typed_errors() {
    let pts = common::fibonacci_sphere(200);
    let coords: Vec<f64> = pts.iter().flatten().copied().collect();
    let cloud = PointCloud::new(3, coords.clone(), 1, vec![0.0; 200]).unwrap();
    assert!(matches!(
        ManifoldMls::new(cloud.clone(), Settings::new(3, 1)),
        Err(ManifoldError::IntrinsicDimension {
            intrinsic: 3,
            ambient: 3
        })
    ));
    assert!(matches!(
        PointCloud::new(3, coords.clone(), 1, vec![0.0; 3]),
        Err(ManifoldError::LengthMismatch { .. })
    ));
    assert!(matches!(
        PointCloud::from_points(3, vec![f64::NAN; 3]),
        Err(ManifoldError::NonFinite {
            what: "sample",
            index: 0
        })
    ));
    // σ fixed so small that the query has no chart, then just too small for 6 samples.
    let tiny = Settings {
        bandwidth: Bandwidth::Fixed(1e-3),
        ..Settings::new(2, 2)
    };
    let mls = ManifoldMls::new(cloud.clone(), tiny).unwrap();
    let err = mls
        .evaluate(&[0.3, 0.4, (1.0f64 - 0.25).sqrt()])
        .unwrap_err();
    assert!(matches!(err, ManifoldError::QueryTooFar { .. }), "{err}");
    let narrow = Settings {
        bandwidth: Bandwidth::Fixed(0.3),
        ..Settings::new(2, 2)
    };
    let err = ManifoldMls::new(cloud.clone(), narrow)
        .unwrap()
        .evaluate(&pts[7])
        .unwrap_err();
    assert_eq!(
        err,
        ManifoldError::TooFewNeighbours {
            found: 5,
            needed: 6,
            degree: 2,
            intrinsic: 2
        }
    );
    assert_eq!(
        err.to_string(),
        "only 5 samples have positive weight within the bandwidth, but a degree-2 polynomial in 2 variables has 6 coefficients"
    );
    let capped = Settings {
        max_iterations: 1,
        tolerance: 1e-300,
        ..Settings::new(2, 1)
    };
    let mls = ManifoldMls::new(cloud.clone(), capped).unwrap();
    assert!(matches!(
        mls.evaluate(&pts[7]),
        Err(ManifoldError::NotConverged { iterations: 1, .. })
    ));
    let mls = ManifoldMls::new(cloud, Settings::new(2, 1)).unwrap();
    assert!(matches!(
        mls.evaluate(&[0.0, 1.0]),
        Err(ManifoldError::LengthMismatch { what: "query", .. })
    ));
    assert!(matches!(
        mls.evaluate(&[0.0, f64::INFINITY, 0.0]),
        Err(ManifoldError::NonFinite { .. })
    ));
}

#[test]
fn batch_is_deterministic_and_order_independent() {
    let pts = common::fibonacci_sphere(800);
    let values: Vec<f64> = pts.iter().map(|p| common::sphere_function(p)).collect();
    let mls = ManifoldMls::new(
        PointCloud::new(3, pts.iter().flatten().copied().collect(), 1, values).unwrap(),
        Settings::new(2, 2),
    )
    .unwrap();
    let queries = common::fibonacci_sphere(64);
    let batch = mls.evaluate_batch(&queries);
    let reversed: Vec<[f64; 3]> = queries.iter().rev().copied().collect();
    let batch_reversed = mls.evaluate_batch(&reversed);
    for (i, r) in queries.iter().enumerate() {
        let single = mls.evaluate(r).unwrap();
        assert_eq!(batch[i].as_ref().unwrap(), &single);
        assert_eq!(batch_reversed[63 - i].as_ref().unwrap(), &single);
    }
    // Slices of a flat buffer work as queries too, and a bad one fails alone.
    let flat: Vec<f64> = queries.iter().flatten().copied().collect();
    let mut rows: Vec<&[f64]> = flat.chunks_exact(3).collect();
    rows.push(&flat[..2]);
    let projections = mls.project_batch(&rows);
    assert_eq!(
        projections[5].as_ref().unwrap(),
        &mls.evaluate(&queries[5]).unwrap().projection
    );
    assert!(matches!(
        projections[64],
        Err(ManifoldError::LengthMismatch { what: "query", .. })
    ));
}
