//! Convergence on noiseless data: helix in R³ (d = 1) and the sphere S² ⊂ R³ (d = 2),
//! m = 1, 2, 3, with the measured order asserted ≥ m + 1 − 0.3.

mod common;

use umls_manifold::{ManifoldMls, PointCloud, Settings};

/// The approximation of f = sin 2x + yz from N Fibonacci samples of the sphere.
fn sphere_mls(samples: usize, degree: usize) -> ManifoldMls {
    let pts = common::fibonacci_sphere(samples);
    let values: Vec<f64> = pts.iter().map(|p| common::sphere_function(p)).collect();
    let cloud = PointCloud::new(3, pts.iter().flatten().copied().collect(), 1, values).unwrap();
    ManifoldMls::new(cloud, Settings::new(2, degree)).unwrap()
}

/// 97 query points on the sphere, rotated off the sample lattice.
fn sphere_queries() -> Vec<[f64; 3]> {
    common::fibonacci_sphere(97)
        .iter()
        .map(|q| [q[0] * 0.8 - q[1] * 0.6, q[0] * 0.6 + q[1] * 0.8, q[2]])
        .collect()
}

/// Max error of f̃ at query points on the sphere, for N Fibonacci samples.
fn sphere_error(samples: usize, degree: usize) -> f64 {
    let mls = sphere_mls(samples, degree);
    sphere_queries()
        .iter()
        .map(|r| (mls.evaluate(r).unwrap().value[0] - common::sphere_function(r)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn sphere_orders_2_3_4() {
    let levels = [500usize, 2000, 8000];
    // Spacing h ∝ N^(-1/2) on a 2-manifold.
    let spacings: Vec<f64> = levels.iter().map(|&n| (n as f64).powf(-0.5)).collect();
    for degree in 1..=3 {
        let errors: Vec<f64> = levels.iter().map(|&n| sphere_error(n, degree)).collect();
        let orders = common::orders(&errors, &spacings);
        eprintln!("sphere m = {degree}: errors {errors:?}, orders {orders:.2?}");
        for p in &orders {
            assert!(
                *p >= degree as f64 + 1.0 - 0.3,
                "m = {degree}: orders {orders:?}"
            );
        }
    }
}

fn helix_error(samples: usize, degree: usize) -> f64 {
    let pts = common::helix(samples);
    let f = |t: f64| (1.3 * t).sin() + 0.1 * t;
    let values: Vec<f64> = pts.iter().map(|(t, _)| f(*t)).collect();
    let cloud = PointCloud::new(3, pts.iter().flat_map(|(_, p)| *p).collect(), 1, values).unwrap();
    let mls = ManifoldMls::new(cloud, Settings::new(1, degree)).unwrap();
    // Interior parameters, off the sample grid.
    (0..60)
        .map(|k| {
            let t = 1.0 + k as f64 * 0.17;
            let r = [t.cos(), t.sin(), 0.5 * t];
            (mls.evaluate(&r).unwrap().value[0] - f(t)).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn helix_orders_2_3_4() {
    let levels = [200usize, 400, 800];
    let spacings: Vec<f64> = levels.iter().map(|&n| 1.0 / (n - 1) as f64).collect();
    for degree in 1..=3 {
        let errors: Vec<f64> = levels.iter().map(|&n| helix_error(n, degree)).collect();
        let orders = common::orders(&errors, &spacings);
        eprintln!("helix m = {degree}: errors {errors:?}, orders {orders:.2?}");
        for p in &orders {
            assert!(
                *p >= degree as f64 + 1.0 - 0.3,
                "m = {degree}: orders {orders:?}"
            );
        }
    }
}

/// Max error of the ambient gradient on the sphere against the surface gradient of
/// f = sin 2x + yz, (I − ppᵀ) ∇F with ∇F = (2 cos 2x, z, y).
fn sphere_gradient_error(samples: usize, degree: usize) -> f64 {
    let mls = sphere_mls(samples, degree);
    sphere_queries()
        .iter()
        .map(|r| {
            let full = [(2.0 * r[0]).cos() * 2.0, r[2], r[1]];
            let along: f64 = (0..3).map(|i| full[i] * r[i]).sum();
            let gradient = mls.evaluate(r).unwrap().ambient_gradient();
            (0..3)
                .map(|i| (gradient[(i, 0)] - (full[i] - along * r[i])).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn sphere_gradient_orders_1_2_3() {
    // A degree-m fit differentiates to order m: the gradient's error falls as h^m, the
    // tangent plane included.
    let levels = [2000usize, 8000, 32000];
    let spacings: Vec<f64> = levels.iter().map(|&n| (n as f64).powf(-0.5)).collect();
    for degree in 1..=3 {
        let errors: Vec<f64> = levels
            .iter()
            .map(|&n| sphere_gradient_error(n, degree))
            .collect();
        let orders = common::orders(&errors, &spacings);
        eprintln!("sphere gradient m = {degree}: errors {errors:?}, orders {orders:.2?}");
        for p in &orders {
            assert!(*p >= degree as f64 - 0.3, "m = {degree}: orders {orders:?}");
        }
    }
}
