//! The local frame of a query: coordinates of its neighbours in a space of dimension
//! at most min(n, K + 1), so the chart and the fits cost nothing per ambient dimension.
//!
//! The frame is centred on the query's nearest sample c. When n ≤ K + 1 it is Rⁿ itself
//! (coordinates r_i − c). When n > K + 1 the K neighbours and the query span at most
//! K + 1 directions: a modified Gram–Schmidt with column pivoting on r_i − c and r − c
//! finds an orthonormal basis Q of that span (stopping at rank r once the residuals are
//! round-off, 10⁻¹² of the largest offset), and the coordinates are Qᵀ(r_i − c), exact
//! to round-off. This is the K × K Gram-space formulation done by orthogonalisation
//! rather than by forming the Gram matrix, which would square its condition. Cost
//! O(n·K·r): for data on a low-dimensional manifold r ≈ d + 2 and the work is a few
//! passes over the neighbours.

use crate::cloud::PointCloud;
use crate::dense::dot;

/// Residuals below this fraction of the largest offset are round-off.
const RANK_TOLERANCE: f64 = 1e-12;

/// A query's neighbours in local coordinates, with the map back to Rⁿ.
#[derive(Debug, Default)]
pub(crate) struct Frame {
    /// Frame dimension r.
    pub dim: usize,
    /// Neighbour i at `coords[i·dim..(i+1)·dim]`.
    pub coords: Vec<f64>,
    /// The query's coordinates.
    pub query: Vec<f64>,
    /// Centre c (the nearest sample).
    centre: Vec<f64>,
    /// Orthonormal basis Q, n × dim column-major; empty when the frame is Rⁿ.
    basis: Vec<f64>,
    /// Residual vectors during the pivoted Gram–Schmidt, n × (K + 1).
    residuals: Vec<f64>,
    norms: Vec<f64>,
    selected: Vec<bool>,
    /// R factor, (K + 1) × (K + 1) column-major, before compaction.
    r: Vec<f64>,
}

impl Frame {
    /// Builds the frame of `query` over the samples `indices`, centred on sample `centre`.
    pub fn build(&mut self, cloud: &PointCloud, indices: &[usize], centre: usize, query: &[f64]) {
        let n = cloud.ambient_dim();
        let k = indices.len();
        self.centre.clear();
        self.centre.extend_from_slice(cloud.point(centre));
        if n <= k + 1 {
            self.dim = n;
            self.basis.clear();
            self.coords.clear();
            for &i in indices {
                let p = cloud.point(i);
                self.coords
                    .extend(p.iter().zip(&self.centre).map(|(x, c)| x - c));
            }
            self.query.clear();
            self.query
                .extend(query.iter().zip(&self.centre).map(|(x, c)| x - c));
            return;
        }
        self.reduce(cloud, indices, query);
    }

    fn reduce(&mut self, cloud: &PointCloud, indices: &[usize], query: &[f64]) {
        let n = cloud.ambient_dim();
        let columns = indices.len() + 1;
        self.residuals.clear();
        for &i in indices {
            let p = cloud.point(i);
            self.residuals
                .extend(p.iter().zip(&self.centre).map(|(x, c)| x - c));
        }
        self.residuals
            .extend(query.iter().zip(&self.centre).map(|(x, c)| x - c));
        self.norms.clear();
        self.norms
            .extend(self.residuals.chunks_exact(n).map(|v| dot(v, v)));
        let largest = self.norms.iter().copied().fold(0.0, f64::max);
        self.selected.clear();
        self.selected.resize(columns, false);
        self.r.clear();
        self.r.resize(columns * columns, 0.0);
        self.basis.clear();
        let mut rank = 0;
        while rank < columns {
            let Some((pivot, _)) = self
                .norms
                .iter()
                .enumerate()
                .filter(|(j, _)| !self.selected[*j])
                .max_by(|a, b| a.1.total_cmp(b.1))
            else {
                break;
            };
            let v = &self.residuals[pivot * n..(pivot + 1) * n];
            // Downdated norms drift; the pivot's is recomputed before it is trusted.
            let norm = dot(v, v).sqrt();
            if norm.is_nan() || norm <= RANK_TOLERANCE * largest.sqrt() {
                break;
            }
            self.selected[pivot] = true;
            self.basis.extend(v.iter().map(|x| x / norm));
            let q = &self.basis[rank * n..(rank + 1) * n];
            self.r[rank + pivot * columns] = norm;
            for j in 0..columns {
                if self.selected[j] {
                    continue;
                }
                let column = &mut self.residuals[j * n..(j + 1) * n];
                let c = dot(q, column);
                column.iter_mut().zip(q).for_each(|(x, q)| *x -= c * q);
                self.r[rank + j * columns] = c;
                self.norms[j] -= c * c;
                if self.norms[j] < 1e-4 * largest {
                    self.norms[j] = dot(column, column);
                }
            }
            rank += 1;
        }
        self.dim = rank;
        self.coords.clear();
        for j in 0..columns - 1 {
            self.coords
                .extend_from_slice(&self.r[j * columns..j * columns + rank]);
        }
        self.query.clear();
        let last = (columns - 1) * columns;
        self.query.extend_from_slice(&self.r[last..last + rank]);
    }

    /// The point of Rⁿ with frame coordinates `y`.
    pub fn point(&self, y: &[f64]) -> Vec<f64> {
        let mut out = self.centre.clone();
        self.add_direction(y, &mut out);
        out
    }

    /// The vector of Rⁿ with frame components `y`.
    pub fn direction(&self, y: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.centre.len()];
        self.add_direction(y, &mut out);
        out
    }

    fn add_direction(&self, y: &[f64], out: &mut [f64]) {
        if self.basis.is_empty() {
            out.iter_mut().zip(y).for_each(|(o, y)| *o += y);
        } else {
            let n = out.len();
            for (k, &yk) in y.iter().enumerate() {
                out.iter_mut()
                    .zip(&self.basis[k * n..(k + 1) * n])
                    .for_each(|(o, q)| *o += yk * q);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reduced_coordinates_keep_every_distance() {
        // 12 points on a 3-dimensional subspace of R⁴⁰ plus an off-subspace query.
        let n = 40;
        let mut state = 3u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let axes: Vec<Vec<f64>> = (0..3).map(|_| (0..n).map(|_| next()).collect()).collect();
        let mut points = Vec::new();
        for _ in 0..12 {
            let c = [next(), next(), next()];
            points.extend((0..n).map(|j| (0..3).map(|a| c[a] * axes[a][j]).sum::<f64>()));
        }
        let cloud = PointCloud::from_points(n, points).unwrap();
        let query: Vec<f64> = (0..n).map(|_| next()).collect();
        let indices: Vec<usize> = (1..12).collect();
        let mut frame = Frame::default();
        frame.build(&cloud, &indices, 0, &query);
        assert_eq!(frame.dim, 4, "3 spanned directions plus the query's own");
        for (a, &i) in indices.iter().enumerate() {
            let y = &frame.coords[a * 4..(a + 1) * 4];
            let back = frame.point(y);
            for (x, p) in back.iter().zip(cloud.point(i)) {
                assert!((x - p).abs() < 1e-14, "{x} vs {p}");
            }
        }
        let back = frame.point(&frame.query);
        for (x, p) in back.iter().zip(&query) {
            assert!((x - p).abs() < 1e-14);
        }
    }
}
