//! A structured lattice of vertices with per-axis spacing, interior jitter and rotation.

use nalgebra::SMatrix;

use super::rng::SplitMix64;
use crate::error::MeshError;
use crate::mesh::Point;

/// Spacing of lattice lines along one axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Spacing {
    /// Equal cells.
    #[default]
    Uniform,
    /// Geometric grading: each cell is a constant factor larger than the previous one, so
    /// that the last cell is `ratio` times the first (ratio < 1 refines towards the upper end).
    Graded {
        /// Last cell width over first cell width; positive.
        ratio: f64,
    },
}

impl Spacing {
    /// Lattice line positions in [0, 1] for `cells` cells.
    fn fractions(self, cells: usize) -> Vec<f64> {
        let widths: Vec<f64> = match self {
            Spacing::Uniform => vec![1.0; cells],
            Spacing::Graded { ratio } => {
                let growth = if cells > 1 {
                    ratio.powf(1.0 / (cells - 1) as f64)
                } else {
                    1.0
                };
                (0..cells).map(|k| growth.powi(k as i32)).collect()
            }
        };
        let total: f64 = widths.iter().sum();
        let mut acc = 0.0;
        let mut out = vec![0.0];
        for w in widths {
            acc += w;
            out.push(acc / total);
        }
        *out.last_mut().expect("non-empty") = 1.0;
        out
    }
}

/// Largest accepted jitter amplitude, as a fraction of the local cell width.
///
/// A first-order bound (a vertex moves at most 2√2·a towards the opposite facet, whose
/// distance is at least h/√2 in a Kuhn tetrahedron) gives 0.25, but the volume is cubic
/// in the displacements: in 2·10⁴ random 4³ lattices per amplitude, inverted tetrahedra
/// appeared from a = 0.23 (none at 0.22; none in 2D up to 0.249). 0.2 keeps a margin;
/// should a lattice still invert a simplex, the generator returns
/// [`crate::MeshError::InvertedSimplex`] naming it, never a broken mesh. This bound is
/// the 3D one; 1D and 2D lattices take up to [`MAX_JITTER_PLANAR`].
pub const MAX_JITTER: f64 = 0.2;

/// Largest accepted jitter amplitude of a 1D or 2D lattice. Below ½ the vertices of one
/// row (column) stay in a band of their own, so every jittered cell is a simple polygon:
/// a segment keeps its direction, and a quadrilateral, convex or not, always has a
/// diagonal inside it, which [`Lattice::triangles`] takes where the chosen one would
/// invert a triangle. 0.45 reaches slivers (triangles with an angle near 180°) for
/// stability studies; the crossed split, whose centre vertex may fall outside a
/// non-convex cell, can still be refused with [`crate::MeshError::InvertedSimplex`].
pub const MAX_JITTER_PLANAR: f64 = 0.45;

/// A D-dimensional lattice of `cells[k] + 1` vertices per axis over the box `[lower, upper]`.
///
/// Vertex `(i₀, …, i_{D−1})` has index `i₀ + (n₀+1)·(i₁ + (n₁+1)·i₂)`. Interior vertices
/// can be jittered by up to `jitter` times the adjacent cell width per axis
/// (boundary vertices stay on the box so the domain is exact), and the whole lattice can be
/// rotated about the box centre.
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice<const D: usize> {
    pub(crate) lower: [f64; D],
    pub(crate) upper: [f64; D],
    pub(crate) cells: [usize; D],
    pub(crate) spacing: [Spacing; D],
    pub(crate) jitter: f64,
    pub(crate) seed: u64,
    pub(crate) rotation: SMatrix<f64, D, D>,
}

impl<const D: usize> Lattice<D> {
    /// A uniform, unjittered, unrotated lattice.
    pub fn new(lower: [f64; D], upper: [f64; D], cells: [usize; D]) -> Self {
        Self {
            lower,
            upper,
            cells,
            spacing: [Spacing::Uniform; D],
            jitter: 0.0,
            seed: 0,
            rotation: SMatrix::identity(),
        }
    }

    /// Sets the spacing along every axis.
    pub fn spacing(mut self, spacing: [Spacing; D]) -> Self {
        self.spacing = spacing;
        self
    }

    /// Jitters interior vertices by up to `amount` (≤ [`Lattice::max_jitter`]) times the
    /// local cell width per axis, reproducibly from `seed`.
    pub fn jitter(mut self, amount: f64, seed: u64) -> Self {
        self.jitter = amount;
        self.seed = seed;
        self
    }

    /// Rotates the whole lattice about the box centre by the rotation matrix `rotation`.
    pub fn rotate(mut self, rotation: SMatrix<f64, D, D>) -> Self {
        self.rotation = rotation;
        self
    }

    /// The largest jitter this dimension accepts: [`MAX_JITTER_PLANAR`] in 1D and 2D,
    /// [`MAX_JITTER`] in 3D.
    pub fn max_jitter() -> f64 {
        if D <= 2 {
            MAX_JITTER_PLANAR
        } else {
            MAX_JITTER
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.cells.iter().map(|n| n + 1).product()
    }

    /// Index of lattice vertex `ijk`.
    pub(crate) fn vertex_index(&self, ijk: [usize; D]) -> u32 {
        let mut index = 0;
        for k in (0..D).rev() {
            index = index * (self.cells[k] + 1) + ijk[k];
        }
        index as u32
    }

    /// Checks the parameters as the generators do before building: cells, bounds,
    /// spacing ratios, jitter (≤ [`Lattice::max_jitter`]) and rotation. For a caller that uses the
    /// lattice's box without building its simplices, so that it refuses what they refuse.
    pub fn validate(&self) -> Result<(), MeshError> {
        let bad = |parameter, value: String, reason| {
            Err(MeshError::InvalidParameter {
                parameter,
                value,
                reason,
            })
        };
        for k in 0..D {
            if self.cells[k] == 0 {
                return bad(
                    "cells",
                    format!("{:?}", self.cells),
                    "need at least one cell per axis",
                );
            }
            if !(self.lower[k].is_finite()
                && self.upper[k].is_finite()
                && self.lower[k] < self.upper[k])
            {
                return bad(
                    "lower/upper",
                    format!("{:?} / {:?}", self.lower, self.upper),
                    "need finite lower < upper on every axis",
                );
            }
            if let Spacing::Graded { ratio } = self.spacing[k] {
                if !(ratio.is_finite() && ratio > 0.0) {
                    return bad(
                        "spacing ratio",
                        ratio.to_string(),
                        "must be finite and positive",
                    );
                }
            }
        }
        if !(0.0..=Self::max_jitter()).contains(&self.jitter) {
            return bad(
                "jitter",
                self.jitter.to_string(),
                if D <= 2 {
                    "must lie in [0, 0.45] in 1D and 2D (a fraction of the cell width; ½ folds cells)"
                } else {
                    "must lie in [0, 0.2] in 3D (a fraction of the cell width; more can invert cells)"
                },
            );
        }
        let r = &self.rotation;
        let orthogonality = (r.transpose() * r - SMatrix::<f64, D, D>::identity()).norm();
        if !(orthogonality < 1e-9 && crate::geometry::determinant(r) > 0.0) {
            return bad(
                "rotation",
                format!("{r:?}"),
                "must be a proper rotation (orthogonal, det = +1)",
            );
        }
        Ok(())
    }

    /// Unjittered, unrotated vertex coordinates (used to orient the generated simplices).
    pub(crate) fn reference_coordinates(&self) -> Result<Vec<Point<D>>, MeshError> {
        self.validate()?;
        let lines: Vec<Vec<f64>> = (0..D)
            .map(|k| {
                self.spacing[k]
                    .fractions(self.cells[k])
                    .into_iter()
                    .map(|t| self.lower[k] + t * (self.upper[k] - self.lower[k]))
                    .collect()
            })
            .collect();
        Ok(self
            .lattice_indices()
            .map(|ijk| Point::<D>::from_fn(|k, _| lines[k][ijk[k]]))
            .collect())
    }

    /// Final coordinates: reference lattice, interior jitter, then rotation about the centre.
    pub(crate) fn coordinates(&self, reference: &[Point<D>]) -> Vec<Point<D>> {
        let mut rng = SplitMix64::new(self.seed);
        let centre = Point::<D>::from_fn(|k, _| 0.5 * (self.lower[k] + self.upper[k]));
        self.lattice_indices()
            .zip(reference)
            .map(|(ijk, &x)| {
                let mut x = x;
                let interior = (0..D).all(|k| ijk[k] > 0 && ijk[k] < self.cells[k]);
                if interior && self.jitter > 0.0 {
                    for k in 0..D {
                        let step = |d: isize| {
                            let mut n = ijk;
                            n[k] = (n[k] as isize + d) as usize;
                            (reference[self.vertex_index(n) as usize][k] - x[k]).abs()
                        };
                        let width = step(-1).min(step(1));
                        x[k] += self.jitter * width * rng.symmetric_unit();
                    }
                }
                centre + self.rotation * (x - centre)
            })
            .collect()
    }

    /// All lattice multi-indices in vertex-index order.
    pub(crate) fn lattice_indices(&self) -> impl Iterator<Item = [usize; D]> + '_ {
        let extents = self.cells.map(|n| n + 1);
        (0..self.vertex_count()).map(move |index| unravel(index, extents))
    }

    /// All cell multi-indices (lower-corner lattice index).
    pub(crate) fn cell_indices(&self) -> impl Iterator<Item = [usize; D]> + '_ {
        let count: usize = self.cells.iter().product();
        (0..count).map(move |index| unravel(index, self.cells))
    }
}

/// The multi-index of a flat index with the first axis fastest.
fn unravel<const D: usize>(mut index: usize, extents: [usize; D]) -> [usize; D] {
    extents.map(|extent| {
        let i = index % extent;
        index /= extent;
        i
    })
}

impl Lattice<2> {
    /// Rotates by `angle` radians (counter-clockwise) about the rectangle centre.
    pub fn rotate_by(self, angle: f64) -> Self {
        self.rotate(*nalgebra::Rotation2::new(angle).matrix())
    }
}

impl Lattice<3> {
    /// Rotates by `angle` radians about `axis` (any non-zero vector) through the box centre.
    pub fn rotate_about(self, axis: [f64; 3], angle: f64) -> Self {
        let axis = nalgebra::Vector3::from(axis);
        let rotation = nalgebra::Unit::try_new(axis, 1e-300)
            .map(|a| *nalgebra::Rotation3::from_axis_angle(&a, angle).matrix())
            .unwrap_or_else(|| SMatrix::repeat(f64::NAN));
        self.rotate(rotation)
    }
}
