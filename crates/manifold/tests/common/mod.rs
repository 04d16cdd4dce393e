//! Sampled manifolds and embeddings for the tests.
#![allow(dead_code)]

use std::f64::consts::{PI, TAU};

/// Deterministic uniform numbers in [0, 1).
pub struct Lcg(pub u64);

impl Lcg {
    /// Next number in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Approximately standard normal (sum of 12 uniforms − 6).
    pub fn normal(&mut self) -> f64 {
        (0..12).map(|_| self.next()).sum::<f64>() - 6.0
    }
}

/// `count` Fibonacci points on the unit sphere.
pub fn fibonacci_sphere(count: usize) -> Vec<[f64; 3]> {
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect()
}

/// The reference function on S²: f = sin 2x + yz.
pub fn sphere_function(p: &[f64]) -> f64 {
    (2.0 * p[0]).sin() + p[1] * p[2]
}

/// Helix (cos t, sin t, t/2), t ∈ [0, 4π], `count` equally spaced samples.
pub fn helix(count: usize) -> Vec<(f64, [f64; 3])> {
    (0..count)
        .map(|i| {
            let t = 2.0 * TAU * i as f64 / (count - 1) as f64;
            (t, [t.cos(), t.sin(), 0.5 * t])
        })
        .collect()
}

/// Flat torus in R⁴: (cos u, sin u, cos v, sin v), on a `k × k` grid.
pub fn flat_torus(k: usize) -> Vec<([f64; 2], [f64; 4])> {
    let mut out = Vec::with_capacity(k * k);
    for i in 0..k {
        for j in 0..k {
            let (u, v) = (TAU * i as f64 / k as f64, TAU * j as f64 / k as f64);
            out.push(([u, v], [u.cos(), u.sin(), v.cos(), v.sin()]));
        }
    }
    out
}

/// An n×3 matrix with orthonormal columns (Gram–Schmidt on pseudo-random vectors), as
/// three column vectors: an isometric embedding R³ → Rⁿ.
pub fn isometric_embedding(n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Lcg(seed);
    let mut columns: Vec<Vec<f64>> = Vec::new();
    while columns.len() < 3 {
        let mut v: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        for c in &columns {
            let dot: f64 = v.iter().zip(c).map(|(a, b)| a * b).sum();
            v.iter_mut().zip(c).for_each(|(a, b)| *a -= dot * b);
        }
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        columns.push(v.into_iter().map(|x| x / norm).collect());
    }
    columns
}

/// Applies the embedding to a point of R³.
pub fn embed(columns: &[Vec<f64>], p: &[f64; 3]) -> Vec<f64> {
    let n = columns[0].len();
    (0..n)
        .map(|j| (0..3).map(|k| columns[k][j] * p[k]).sum())
        .collect()
}

/// Observed orders between successive levels, given errors and spacings.
pub fn orders(errors: &[f64], spacings: &[f64]) -> Vec<f64> {
    errors
        .windows(2)
        .zip(spacings.windows(2))
        .map(|(e, h)| (e[0] / e[1]).ln() / (h[0] / h[1]).ln())
        .collect()
}
