//! Samples in Rⁿ with optional values, validated once.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::ManifoldError;

/// Source of [`PointCloud`] identities: a cloud never changes after construction, so an
/// identity names its data exactly and a [`crate::NeighbourIndex`] can refuse a cloud it
/// was not built from in O(1).
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// N samples r_i ∈ Rⁿ stored row after row, each with k values f_i ∈ Rᵏ (k may be 0 when
/// only the manifold itself is of interest).
#[derive(Debug, Clone)]
pub struct PointCloud {
    id: u64,
    ambient: usize,
    points: Vec<f64>,
    value_dim: usize,
    values: Vec<f64>,
}

impl PartialEq for PointCloud {
    /// Equal data (the identity is not compared).
    fn eq(&self, other: &Self) -> bool {
        self.ambient == other.ambient
            && self.value_dim == other.value_dim
            && self.points == other.points
            && self.values == other.values
    }
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
                what: "value of sample",
                index: i / value_dim.max(1),
            });
        }
        Ok(Self {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
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

    /// Diagonal of the samples' bounding box (0 for a single position).
    pub fn extent(&self) -> f64 {
        let n = self.ambient_dim();
        (0..n)
            .map(|c| {
                let (lo, hi) = self
                    .points()
                    .iter()
                    .skip(c)
                    .step_by(n)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                        (lo.min(x), hi.max(x))
                    });
                (hi - lo) * (hi - lo)
            })
            .sum::<f64>()
            .sqrt()
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

    /// The identity shared by this cloud and its clones.
    pub(crate) fn id(&self) -> u64 {
        self.id
    }

    /// Groups of samples at bitwise-equal positions (−0 = +0): one representative per
    /// position, its multiplicity and the mean of the group's values. `None` when every
    /// position is distinct. A repeated sample must count as many times in a fit, but it
    /// must not count as a separate neighbour when the bandwidth is chosen from the
    /// K*-th neighbour distance, or replicated data would shrink σ to zero.
    pub(crate) fn distinct(&self) -> Option<Distinct> {
        let key = |i: usize| self.point(i).iter().map(|x| x + 0.0);
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_unstable_by(|&a, &b| {
            key(a)
                .zip(key(b))
                .map(|(x, y)| x.total_cmp(&y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
                .then(a.cmp(&b))
        });
        let same = |a: usize, b: usize| key(a).zip(key(b)).all(|(x, y)| x == y);
        if order.windows(2).all(|w| !same(w[0], w[1])) {
            return None;
        }
        let k = self.value_dim;
        let mut representatives = Vec::new();
        let mut mass = vec![0.0; self.len()];
        let mut values = vec![0.0; self.len() * k];
        let mut start = 0;
        while start < order.len() {
            let first = order[start];
            let mut end = start + 1;
            while end < order.len() && same(first, order[end]) {
                end += 1;
            }
            let count = (end - start) as f64;
            let rep = first;
            representatives.push(rep);
            mass[rep] = count;
            for &i in &order[start..end] {
                for c in 0..k {
                    values[rep * k + c] += self.values[i * k + c] / count;
                }
            }
            start = end;
        }
        representatives.sort_unstable();
        Some(Distinct {
            representatives,
            mass,
            values,
        })
    }
}

/// Distinct sample positions of a cloud with repeated samples.
#[derive(Debug, Clone)]
pub(crate) struct Distinct {
    /// One sample index per distinct position, ascending.
    pub representatives: Vec<usize>,
    /// Multiplicity of each representative (0 for the others), indexed by sample.
    pub mass: Vec<f64>,
    /// Mean values of each representative's group, indexed by sample (N × k).
    pub values: Vec<f64>,
}
