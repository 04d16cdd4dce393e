//! Sampled manifolds and embeddings for the tests.
#![allow(dead_code)]

use std::f64::consts::{PI, TAU};

use umls_manifold::PointCloud;

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

    /// Standard normal by Box–Muller.
    pub fn gauss(&mut self) -> f64 {
        let (a, b) = (self.next().max(1e-300), self.next());
        (-2.0 * a.ln()).sqrt() * (TAU * b).cos()
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

/// Fibonacci samples of S² with Gaussian noise of standard deviation `s` on every
/// coordinate and on the values of f = sin 2x + yz.
pub fn noisy_sphere(count: usize, s: f64, seed: u64) -> PointCloud {
    let mut rng = Lcg(seed);
    let pts = fibonacci_sphere(count);
    let coords: Vec<f64> = pts
        .iter()
        .flat_map(|p| p.map(|x| x + s * rng.gauss()))
        .collect();
    let values: Vec<f64> = pts
        .iter()
        .map(|p| sphere_function(p) + s * rng.gauss())
        .collect();
    PointCloud::new(3, coords, 1, values).unwrap()
}

/// The flat torus (cos u, sin u, cos v, sin v) isometrically in R⁶, sampled on a
/// `ku × kv` grid, with f = sin u cos v.
pub struct Torus {
    basis: Vec<Vec<f64>>,
}

impl Torus {
    /// A fixed random isometric embedding.
    pub fn new() -> Self {
        let mut rng = Lcg(9);
        let mut basis: Vec<Vec<f64>> = Vec::new();
        while basis.len() < 4 {
            let mut v: Vec<f64> = (0..6).map(|_| rng.normal()).collect();
            for c in &basis {
                let d: f64 = v.iter().zip(c).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(c).for_each(|(a, b)| *a -= d * b);
            }
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            basis.push(v.into_iter().map(|x| x / norm).collect());
        }
        Self { basis }
    }

    /// The point with parameters (u, v).
    pub fn point(&self, u: f64, v: f64) -> Vec<f64> {
        let p = [u.cos(), u.sin(), v.cos(), v.sin()];
        (0..6)
            .map(|j| (0..4).map(|k| self.basis[k][j] * p[k]).sum())
            .collect()
    }

    /// f = sin u cos v.
    pub fn value(u: f64, v: f64) -> f64 {
        u.sin() * v.cos()
    }

    /// Samples on a `ku × kv` parameter grid with their values.
    pub fn cloud(&self, ku: usize, kv: usize) -> PointCloud {
        let mut coords = Vec::new();
        let mut values = Vec::new();
        for i in 0..ku {
            for j in 0..kv {
                let (u, v) = (TAU * i as f64 / ku as f64, TAU * j as f64 / kv as f64);
                coords.extend(self.point(u, v));
                values.push(Self::value(u, v));
            }
        }
        PointCloud::new(6, coords, 1, values).unwrap()
    }

    /// `count` random parameter pairs, the same for every call.
    pub fn queries(&self, count: usize) -> Vec<(f64, f64)> {
        let mut rng = Lcg(77);
        (0..count)
            .map(|_| (TAU * rng.next(), TAU * rng.next()))
            .collect()
    }
}

/// `count` random points of a 2-torus in Rⁿ whose 16 Fourier features (cos and sin of
/// u, v, 2u, …, 4v) lie along random directions: data spread over many more directions
/// than a 4-dimensional projection keeps.
pub fn spread_torus(n: usize, count: usize, seed: u64) -> Vec<f64> {
    let mut rng = Lcg(seed);
    let directions: Vec<Vec<f64>> = (0..16)
        .map(|_| (0..n).map(|_| rng.normal()).collect())
        .collect();
    let mut coords = Vec::with_capacity(n * count);
    for _ in 0..count {
        let (u, v) = (TAU * rng.next(), TAU * rng.next());
        let features: Vec<f64> = (0..16)
            .map(|k| {
                let f = (k / 4 + 1) as f64;
                match k % 4 {
                    0 => (f * u).cos(),
                    1 => (f * u).sin(),
                    2 => (f * v).cos(),
                    _ => (f * v).sin(),
                }
            })
            .collect();
        coords.extend((0..n).map(|j| (0..16).map(|k| directions[k][j] * features[k]).sum::<f64>()));
    }
    coords
}
