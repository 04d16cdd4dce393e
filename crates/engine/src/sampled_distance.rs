//! A signed distance sampled on a uniform lattice and read back by multilinear
//! interpolation: the form in which a wall of any shape reaches a kernel whose nodes do
//! not lie on it (a B-spline grid against a curved mesh boundary).
//!
//! Sampling once and interpolating keeps the per-particle cost of a wall at 2^D reads,
//! whatever the wall's geometry, and makes no demand on how the distance was computed
//! (parry's point queries on mesh facets, an analytic shape). Multilinear interpolation
//! reproduces an affine function exactly, so a planar wall is held exactly; a curved one
//! to O(Δ²) in the sample spacing Δ.

use nalgebra::SVector;
use rayon::prelude::*;

/// Samples per parallel work item of [`SampledDistance::sample`].
const SAMPLE_CHUNK: usize = 1024;

/// A signed distance φ on the lattice `origin + Δ·i`, positive beyond the wall (inside
/// the obstacle), negative on the material's side.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledDistance<const D: usize> {
    origin: SVector<f64, D>,
    spacing: f64,
    counts: [usize; D],
    values: Vec<f64>,
}

/// What [`SampledDistance::sample`] refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampledDistanceError {
    /// The spacing is not finite and positive.
    #[error("the sample spacing must be finite and positive, got {0}")]
    Spacing(f64),
    /// The box has a non-finite corner or fewer than two samples along an axis.
    #[error("the sampled box needs finite corners and two samples along every axis")]
    Box,
    /// The distance was not finite at a sample.
    #[error("the distance is not finite at ({0:?})")]
    NotFinite(Vec<f64>),
    /// More samples than a lattice may hold.
    #[error("{0} samples exceed the limit of {MAX_SAMPLES}")]
    TooMany(usize),
}

/// The largest lattice [`SampledDistance::sample`] builds (8 bytes a sample: 1 GiB).
pub const MAX_SAMPLES: usize = 1 << 27;

impl<const D: usize> SampledDistance<D> {
    /// Samples `distance` on the lattice of spacing `spacing` covering the box
    /// `lower`..`upper` (rounded out to whole cells), in parallel.
    pub fn sample(
        lower: SVector<f64, D>,
        upper: SVector<f64, D>,
        spacing: f64,
        distance: impl Fn(&SVector<f64, D>) -> f64 + Sync,
    ) -> Result<Self, SampledDistanceError> {
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(SampledDistanceError::Spacing(spacing));
        }
        let finite = lower.iter().chain(upper.iter()).all(|c| c.is_finite());
        if !finite || (0..D).any(|a| upper[a] <= lower[a]) {
            return Err(SampledDistanceError::Box);
        }
        let mut counts = [0; D];
        let mut total = 1usize;
        for (a, count) in counts.iter_mut().enumerate() {
            *count = ((upper[a] - lower[a]) / spacing).ceil() as usize + 1;
            total = total.saturating_mul(*count);
        }
        if total > MAX_SAMPLES {
            return Err(SampledDistanceError::TooMany(total));
        }
        let mut field = Self {
            origin: lower,
            spacing,
            counts,
            values: vec![0.0; total],
        };
        let point = |i: usize| field.sample_point(i);
        let values: Vec<f64> = (0..total)
            .into_par_iter()
            .with_min_len(SAMPLE_CHUNK)
            .map(|i| distance(&point(i)))
            .collect();
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(SampledDistanceError::NotFinite(
                field.sample_point(i).as_slice().to_vec(),
            ));
        }
        field.values = values;
        Ok(field)
    }

    /// The lattice spacing Δ.
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// Samples along each axis.
    pub fn counts(&self) -> [usize; D] {
        self.counts
    }

    /// Bytes the samples take.
    pub fn bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<f64>()
    }

    /// The position of sample `i` (first axis fastest).
    fn sample_point(&self, mut i: usize) -> SVector<f64, D> {
        let mut x = self.origin;
        for (a, &count) in self.counts.iter().enumerate() {
            x[a] += self.spacing * (i % count) as f64;
            i /= count;
        }
        x
    }

    /// φ(x) and ∇φ(x) by multilinear interpolation in the cell holding `x`; `None` outside
    /// the sampled box (no wall there).
    pub fn at(&self, x: &SVector<f64, D>) -> Option<(f64, SVector<f64, D>)> {
        let mut base = 0;
        let mut stride = 1;
        let mut t = [0.0; D];
        for (a, &count) in self.counts.iter().enumerate() {
            let s = (x[a] - self.origin[a]) / self.spacing;
            if !(s >= 0.0 && s <= (count - 1) as f64) {
                return None;
            }
            // The last sample's cell is the one below it.
            let cell = (s.floor() as usize).min(count - 2);
            t[a] = s - cell as f64;
            base += cell * stride;
            stride *= count;
        }
        let mut value = 0.0;
        let mut gradient = SVector::<f64, D>::zeros();
        for corner in 0..1usize << D {
            let mut index = base;
            let mut stride = 1;
            let mut weight = 1.0;
            let mut partial = [1.0; D];
            for (a, (&ta, &count)) in t.iter().zip(&self.counts).enumerate() {
                let high = (corner >> a) & 1 == 1;
                let (w, dw) = if high { (ta, 1.0) } else { (1.0 - ta, -1.0) };
                if high {
                    index += stride;
                }
                stride *= count;
                weight *= w;
                for (b, p) in partial.iter_mut().enumerate() {
                    *p *= if a == b { dw } else { w };
                }
            }
            let phi = self.values[index];
            value += weight * phi;
            for (g, p) in gradient.iter_mut().zip(&partial) {
                *g += p * phi;
            }
        }
        Some((value, gradient / self.spacing))
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Vector2, Vector3};

    use super::*;

    /// An affine distance (a plane) is interpolated exactly, value and gradient, at
    /// points off the samples.
    #[test]
    fn a_plane_is_reproduced_exactly() {
        let normal = Vector3::new(0.3, -0.5, 0.8).normalize();
        let plane = |x: &Vector3<f64>| normal.dot(x) - 0.2;
        let field =
            SampledDistance::sample(Vector3::repeat(-1.0), Vector3::repeat(1.0), 0.13, plane)
                .unwrap();
        for x in [
            Vector3::new(0.11, -0.37, 0.52),
            Vector3::new(-0.93, 0.2, 0.0),
            Vector3::new(0.999, 0.999, -0.999),
        ] {
            let (phi, grad) = field.at(&x).unwrap();
            assert!((phi - plane(&x)).abs() < 1e-14, "{phi} at {x:?}");
            assert!((grad - normal).norm() < 1e-13, "{grad:?} at {x:?}");
        }
        assert!(field.at(&Vector3::new(2.0, 0.0, 0.0)).is_none());
    }

    /// A circle's distance is interpolated to second order in the spacing: halving Δ
    /// divides the largest error near the circle by about four.
    #[test]
    fn a_circle_converges_at_second_order() {
        let circle = |x: &Vector2<f64>| x.norm() - 0.6;
        let error = |spacing: f64| {
            let field = SampledDistance::sample(
                Vector2::repeat(-1.0),
                Vector2::repeat(1.0),
                spacing,
                circle,
            )
            .unwrap();
            (0..400)
                .map(|k| {
                    let angle = 0.0157 * k as f64;
                    let r = 0.5 + 0.2 * ((7 * k) % 11) as f64 / 10.0;
                    let x = Vector2::new(angle.cos(), angle.sin()) * r;
                    (field.at(&x).unwrap().0 - circle(&x)).abs()
                })
                .fold(0.0, f64::max)
        };
        let (coarse, fine) = (error(0.1), error(0.05));
        let order = (coarse / fine).log2();
        assert!(
            order > 1.7 && order < 2.5,
            "order {order} ({coarse} → {fine})"
        );
    }

    #[test]
    fn bad_input_is_refused() {
        let zero = |_: &Vector2<f64>| 0.0;
        let (lo, hi) = (Vector2::repeat(0.0), Vector2::repeat(1.0));
        assert_eq!(
            SampledDistance::sample(lo, hi, 0.0, zero),
            Err(SampledDistanceError::Spacing(0.0))
        );
        assert_eq!(
            SampledDistance::sample(hi, lo, 0.1, zero),
            Err(SampledDistanceError::Box)
        );
        assert!(matches!(
            SampledDistance::sample(lo, hi, 0.1, |x: &Vector2<f64>| 1.0 / (x[0] - 0.5)),
            Err(SampledDistanceError::NotFinite(_))
        ));
        assert!(matches!(
            SampledDistance::sample(lo, hi, 1e-5, zero),
            Err(SampledDistanceError::TooMany(_))
        ));
    }
}
