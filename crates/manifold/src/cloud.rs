//! Samples in Rⁿ with optional values, validated once.

use crate::error::ManifoldError;

/// N samples r_i ∈ Rⁿ stored row after row, each with k values f_i ∈ Rᵏ (k may be 0 when
/// only the manifold itself is of interest).
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloud {
    ambient: usize,
    points: Vec<f64>,
    value_dim: usize,
    values: Vec<f64>,
}

impl PointCloud {
    /// Samples of dimension `ambient` in `points` (N·n entries) and `value_dim` values per
    /// sample in `values` (N·k entries).
    pub fn new(
        ambient: usize,
        points: Vec<f64>,
        value_dim: usize,
        values: Vec<f64>,
    ) -> Result<Self, ManifoldError> {
        if ambient == 0 || points.is_empty() {
            return Err(ManifoldError::Empty {
                samples: points.len() / ambient.max(1),
                dimension: ambient,
            });
        }
        if points.len() % ambient != 0 {
            return Err(ManifoldError::LengthMismatch {
                what: "points (N × n)",
                expected: points.len() / ambient * ambient,
                found: points.len(),
            });
        }
        let samples = points.len() / ambient;
        if values.len() != samples * value_dim {
            return Err(ManifoldError::LengthMismatch {
                what: "values (N × k)",
                expected: samples * value_dim,
                found: values.len(),
            });
        }
        if let Some(i) = points.iter().position(|x| !x.is_finite()) {
            return Err(ManifoldError::NonFinite {
                what: "sample",
                index: i / ambient,
            });
        }
        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
            return Err(ManifoldError::NonFinite {
                what: "value",
                index: i / value_dim.max(1),
            });
        }
        Ok(Self {
            ambient,
            points,
            value_dim,
            values,
        })
    }

    /// Samples only (no values): for projection onto the manifold.
    pub fn from_points(ambient: usize, points: Vec<f64>) -> Result<Self, ManifoldError> {
        Self::new(ambient, points, 0, Vec::new())
    }

    /// Number of samples N.
    pub fn len(&self) -> usize {
        self.points.len() / self.ambient
    }

    /// Whether there are no samples (never, once constructed).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Ambient dimension n.
    pub fn ambient_dim(&self) -> usize {
        self.ambient
    }

    /// Values per sample k.
    pub fn value_dim(&self) -> usize {
        self.value_dim
    }

    /// Sample i.
    #[inline]
    pub fn point(&self, i: usize) -> &[f64] {
        &self.points[i * self.ambient..(i + 1) * self.ambient]
    }

    /// Values of sample i.
    #[inline]
    pub fn value(&self, i: usize) -> &[f64] {
        &self.values[i * self.value_dim..(i + 1) * self.value_dim]
    }

    /// All coordinates, row after row.
    pub fn points(&self) -> &[f64] {
        &self.points
    }
}

/// Euclidean distance between two points of equal length.
#[inline]
pub(crate) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}
