//! `[reference.pressure]`: the pressure a body exerts on a closed wall (a container),
//! from the reaction forces of the wall's boundary condition, and how smooth it is in
//! time and around the wall.
//!
//! At each history row the wall pressure is the sum of the magnitudes of the nodal
//! reactions over the wall's area. Around the wall the nodes are sorted into bins of
//! about equal area by their direction from `centre` (24 sectors in 2D; in 3D the
//! Voronoi cells of 24 points of a Fibonacci lattice on the sphere), and the angular
//! roughness is the coefficient of variation of the bins' summed reactions: 0 for a
//! uniform pressure. In time, the roughness is the RMS of the pressure's second
//! difference between rows, over the largest pressure: what a smooth pressure history
//! does not have.

use nalgebra::SVector;
use serde_json::{Map, Value, json};

/// Angular bins around the wall.
const BINS: usize = 24;

/// The wall pressure's samples and their reduction to metrics.
#[derive(Debug, Clone)]
pub struct WallPressure<const D: usize> {
    /// Index of the boundary whose reactions are read.
    pub boundary: usize,
    centre: SVector<f64, D>,
    area: f64,
    directions: Vec<SVector<f64, D>>,
    history: Vec<f64>,
    /// The largest pressure so far, and the angular roughness at its row.
    peak: f64,
    peak_roughness: f64,
}

impl<const D: usize> WallPressure<D> {
    /// A wall of `area` around `centre` (world frame), read from boundary `boundary`.
    pub fn new(boundary: usize, centre: SVector<f64, D>, area: f64) -> Self {
        let directions = (0..BINS)
            .map(|k| {
                let mut d = SVector::<f64, D>::zeros();
                match D {
                    2 => {
                        let a = std::f64::consts::TAU * (k as f64 + 0.5) / BINS as f64;
                        d[0] = a.cos();
                        d[1] = a.sin();
                    }
                    3 => {
                        // Fibonacci lattice: z uniform in (−1, 1), golden-angle turns.
                        let z = 1.0 - (2.0 * k as f64 + 1.0) / BINS as f64;
                        let r = (1.0 - z * z).sqrt();
                        let a = k as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
                        d[0] = r * a.cos();
                        d[1] = r * a.sin();
                        d[2] = z;
                    }
                    _ => d[0] = if k % 2 == 0 { 1.0 } else { -1.0 },
                }
                d
            })
            .collect();
        Self {
            boundary,
            centre,
            area,
            directions,
            history: Vec::new(),
            peak: 0.0,
            peak_roughness: 0.0,
        }
    }

    /// Records one history row: the wall's nodes (world positions) and their reactions.
    /// Returns the pressure.
    pub fn record(&mut self, nodes: &[SVector<f64, D>], reactions: &[SVector<f64, D>]) -> f64 {
        let mut bins = [0.0; BINS];
        let mut total = 0.0;
        for (x, r) in nodes.iter().zip(reactions) {
            let magnitude = r.norm();
            total += magnitude;
            let direction = x - self.centre;
            let bin = (0..BINS)
                .max_by(|&a, &b| {
                    direction
                        .dot(&self.directions[a])
                        .total_cmp(&direction.dot(&self.directions[b]))
                })
                .unwrap_or(0);
            bins[bin] += magnitude;
        }
        let pressure = total / self.area;
        if pressure > self.peak {
            self.peak = pressure;
            let mean = total / BINS as f64;
            let variance = bins.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / BINS as f64;
            self.peak_roughness = variance.sqrt() / mean;
        }
        self.history.push(pressure);
        pressure
    }

    /// `pressure_max`, `pressure_time_roughness`, `pressure_angular_roughness`.
    pub fn metrics(&self) -> Map<String, Value> {
        let max = self.peak;
        let second: Vec<f64> = self
            .history
            .windows(3)
            .map(|w| w[0] - 2.0 * w[1] + w[2])
            .collect();
        let rms = (second.iter().map(|s| s * s).sum::<f64>() / second.len().max(1) as f64).sqrt();
        let mut m = Map::new();
        m.insert("pressure_max".into(), json!(max));
        m.insert(
            "pressure_time_roughness".into(),
            json!(if max > 0.0 { rms / max } else { 0.0 }),
        );
        m.insert(
            "pressure_angular_roughness".into(),
            json!(self.peak_roughness),
        );
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// A uniform pressure on a finely sampled sphere has a small angular roughness (the
    /// bins' areas are only nearly equal), one pressing on a cap a large one; a linear
    /// ramp in time has no time roughness.
    #[test]
    fn uniform_pressure_is_smooth_and_a_cap_is_not() {
        let n = 4000;
        let nodes: Vec<Vector3<f64>> = (0..n)
            .map(|k| {
                let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let a = k as f64 * 2.399963229728653;
                Vector3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect();
        let area = 4.0 * std::f64::consts::PI;
        let mut wall = WallPressure::<3>::new(0, Vector3::zeros(), area);
        for step in 1..=5 {
            let push: Vec<Vector3<f64>> = nodes.iter().map(|x| -x * step as f64).collect();
            let p = wall.record(&nodes, &push);
            assert!((p - step as f64 * n as f64 / area).abs() < 1e-9);
        }
        let m = wall.metrics();
        assert!(m["pressure_time_roughness"].as_f64().unwrap() < 1e-12);
        let uniform = m["pressure_angular_roughness"].as_f64().unwrap();
        assert!(uniform < 0.2, "{uniform}");
        let mut cap = WallPressure::<3>::new(0, Vector3::zeros(), area);
        let push: Vec<Vector3<f64>> = nodes
            .iter()
            .map(|x| if x.z > 0.5 { -x } else { Vector3::zeros() })
            .collect();
        cap.record(&nodes, &push);
        assert!(
            cap.metrics()["pressure_angular_roughness"]
                .as_f64()
                .unwrap()
                > 1.0
        );
    }
}
