//! Barycentric coordinates and their gradients, with fixed capacity on the stack.

use nalgebra::SVector;

/// Largest number of vertices of a supported simplex (the tetrahedron).
pub const MAX_SIMPLEX_VERTICES: usize = 4;

/// Barycentric coordinates λ of a point with respect to a D-simplex.
///
/// Stored in a fixed array of [`MAX_SIMPLEX_VERTICES`] entries of which the
/// first D+1 are used: this keeps the type free of `D + 1` arithmetic (not
/// expressible on stable Rust) and allocation-free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Barycentric<const D: usize>(pub(crate) [f64; MAX_SIMPLEX_VERTICES]);

impl<const D: usize> Barycentric<D> {
    /// Builds from a slice of exactly D+1 coordinates; `None` for any other length.
    pub fn from_slice(coords: &[f64]) -> Option<Self> {
        (coords.len() == D + 1).then(|| {
            let mut c = [0.0; MAX_SIMPLEX_VERTICES];
            c[..=D].copy_from_slice(coords);
            Self(c)
        })
    }

    /// The D+1 coordinates, in the simplex's local vertex order.
    #[inline]
    pub fn as_slice(&self) -> &[f64] {
        &self.0[..=D]
    }

    /// The smallest coordinate: ≥ 0 inside the simplex, < 0 outside.
    #[inline]
    pub fn min(&self) -> f64 {
        self.as_slice()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    /// Local index of the smallest coordinate: the face to cross when walking towards the point.
    #[inline]
    pub fn argmin(&self) -> usize {
        let mut best = 0;
        for i in 1..=D {
            if self.0[i] < self.0[best] {
                best = i;
            }
        }
        best
    }
}

/// Gradients ∇λ_n of the barycentric coordinates of a simplex (constant on the simplex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarycentricGradients<const D: usize>(pub(crate) [SVector<f64, D>; MAX_SIMPLEX_VERTICES]);

impl<const D: usize> BarycentricGradients<D> {
    /// The D+1 gradients, in the simplex's local vertex order.
    #[inline]
    pub fn as_slice(&self) -> &[SVector<f64, D>] {
        &self.0[..=D]
    }
}
