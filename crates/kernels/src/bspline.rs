//! Tensor-product B-spline shape functions on a Cartesian grid: the structured-grid
//! reference of MPM.

use nalgebra::SVector;
use umls_transfer::{Kernel, KernelError, Stencil};

/// Polynomial order of the B-spline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BSplineOrder {
    /// Quadratic (C¹, 3 nodes per axis).
    Quadratic,
    /// Cubic (C², 4 nodes per axis).
    Cubic,
}

impl BSplineOrder {
    /// Nodes per axis in a stencil.
    pub fn width(self) -> usize {
        match self {
            Self::Quadratic => 3,
            Self::Cubic => 4,
        }
    }

    /// First stencil node (in units of h) for the coordinate ξ = (x − origin)/h.
    fn base(self, xi: f64) -> f64 {
        match self {
            Self::Quadratic => (xi - 0.5).floor(),
            Self::Cubic => xi.floor() - 1.0,
        }
    }

    /// N(r) and dN/dr for the distance r (in units of h) from a node.
    fn weight(self, r: f64) -> (f64, f64) {
        let a = r.abs();
        let sign = r.signum();
        match self {
            Self::Quadratic => {
                if a < 0.5 {
                    (0.75 - a * a, -2.0 * r)
                } else if a < 1.5 {
                    let t = 1.5 - a;
                    (0.5 * t * t, -sign * t)
                } else {
                    (0.0, 0.0)
                }
            }
            Self::Cubic => {
                if a < 1.0 {
                    (
                        0.5 * a * a * a - a * a + 2.0 / 3.0,
                        sign * (1.5 * a * a - 2.0 * a),
                    )
                } else if a < 2.0 {
                    let t = 2.0 - a;
                    (t * t * t / 6.0, -sign * 0.5 * t * t)
                } else {
                    (0.0, 0.0)
                }
            }
        }
    }
}

/// B-spline kernel on the grid `origin + h·(i₀, …, i_{D−1})`, `0 ≤ i_k ≤ cells[k]`.
///
/// Node index `i₀ + (n₀+1)(i₁ + (n₁+1) i₂)`. A point's stencil must lie inside the grid:
/// for quadratic splines that is ξ_k ∈ [0.5, n_k − 0.5], for cubic ξ_k ∈ [1, n_k − 1]
/// (ξ = (x − origin)/h); pad the grid by one or two cells around the material.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineKernel<const D: usize> {
    origin: SVector<f64, D>,
    h: f64,
    cells: [usize; D],
    order: BSplineOrder,
}

impl<const D: usize> BSplineKernel<D> {
    /// A grid of `cells` cells of size `h` from `origin`; `None` for h ≤ 0 or too few cells
    /// for one stencil.
    pub fn new(
        origin: SVector<f64, D>,
        h: f64,
        cells: [usize; D],
        order: BSplineOrder,
    ) -> Option<Self> {
        let ok = h.is_finite() && h > 0.0 && cells.iter().all(|&n| n + 1 >= order.width());
        ok.then_some(Self {
            origin,
            h,
            cells,
            order,
        })
    }

    /// The grid of spacing `h` covering the box [lower, upper] with
    /// [`Self::COVER_MARGIN`] extra cells on every side: a particle on the box boundary
    /// keeps its whole stencil, and walls there get their node layers. `None` for h ≤ 0 or
    /// non-finite input.
    pub fn covering(
        lower: SVector<f64, D>,
        upper: SVector<f64, D>,
        h: f64,
        order: BSplineOrder,
    ) -> Option<Self> {
        if !(h.is_finite() && h > 0.0) || lower.iter().chain(upper.iter()).any(|x| !x.is_finite()) {
            return None;
        }
        let margin = Self::COVER_MARGIN;
        let origin = lower.add_scalar(-(margin as f64) * h);
        // `as usize` saturates: an absurd ratio gives a huge count the caller can refuse.
        let cells: [usize; D] = std::array::from_fn(|k| {
            (((upper[k] - lower[k]) / h - 1e-9).ceil().max(1.0) as usize).saturating_add(2 * margin)
        });
        Self::new(origin, h, cells, order)
    }

    /// Cells added on each side of the box by [`Self::covering`].
    pub const COVER_MARGIN: usize = 2;

    /// Cells per axis.
    pub fn cells(&self) -> [usize; D] {
        self.cells
    }

    /// The spline order.
    pub fn order(&self) -> BSplineOrder {
        self.order
    }

    fn node_index(&self, ijk: [usize; D]) -> usize {
        let mut index = 0;
        for k in (0..D).rev() {
            index = index * (self.cells[k] + 1) + ijk[k];
        }
        index
    }
}

impl<const D: usize> Kernel<D> for BSplineKernel<D> {
    type Cache = ();

    fn node_count(&self) -> usize {
        self.cells.iter().map(|n| n + 1).product()
    }

    fn node_position(&self, node: usize) -> SVector<f64, D> {
        let mut rest = node;
        SVector::<f64, D>::from_fn(|k, _| {
            let i = rest % (self.cells[k] + 1);
            rest /= self.cells[k] + 1;
            self.origin[k] + self.h * i as f64
        })
    }

    fn spacing(&self) -> f64 {
        self.h
    }

    fn constant_second_moment(&self) -> Option<f64> {
        // The variance of the quadratic (cubic) B-spline is 1/4 (1/3) per axis, and the
        // tensor product's cross terms vanish (each axis' first moment is zero).
        Some(match self.order {
            BSplineOrder::Quadratic => self.h * self.h / 4.0,
            BSplineOrder::Cubic => self.h * self.h / 3.0,
        })
    }

    fn stencil(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError> {
        let width = self.order.width();
        let mut base = [0usize; D];
        // Per axis: weights and derivatives of the `width` nodes.
        let mut w = [[0.0; 4]; D];
        let mut dw = [[0.0; 4]; D];
        for k in 0..D {
            let xi = (x[k] - self.origin[k]) / self.h;
            let b = self.order.base(xi);
            if !(b >= 0.0 && b + (width - 1) as f64 <= self.cells[k] as f64) {
                return Err(KernelError::OutsideDomain {
                    point: x.iter().copied().collect(),
                });
            }
            base[k] = b as usize;
            for a in 0..width {
                let (value, derivative) = self.order.weight(xi - (b + a as f64));
                w[k][a] = value;
                dw[k][a] = derivative / self.h;
            }
        }
        out.clear();
        let count = width.pow(D as u32);
        for flat in 0..count {
            let mut offsets = [0usize; D];
            let mut rest = flat;
            for o in offsets.iter_mut() {
                *o = rest % width;
                rest /= width;
            }
            let mut value = 1.0;
            for k in 0..D {
                value *= w[k][offsets[k]];
            }
            let gradient = SVector::<f64, D>::from_fn(|j, _| {
                (0..D)
                    .map(|k| {
                        if k == j {
                            dw[k][offsets[k]]
                        } else {
                            w[k][offsets[k]]
                        }
                    })
                    .product()
            });
            let node = self.node_index(std::array::from_fn(|k| base[k] + offsets[k]));
            out.push(node as u32, value, gradient)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;

    #[test]
    fn covering_grid_reaches_past_the_box_by_its_margin() {
        let (lower, upper) = (Vector2::new(-1.0, 0.5), Vector2::new(2.0, 1.7));
        let h = 0.25;
        let grid = BSplineKernel::covering(lower, upper, h, BSplineOrder::Quadratic).unwrap();
        let margin = BSplineKernel::<2>::COVER_MARGIN as f64 * h;
        let first = grid.node_position(0);
        let last = grid.node_position(grid.node_count() - 1);
        for k in 0..2 {
            assert!((first[k] - (lower[k] - margin)).abs() < 1e-12);
            // The far side: at least the margin beyond the box, less than a cell more.
            assert!(last[k] >= upper[k] + margin - 1e-12 && last[k] < upper[k] + margin + h);
        }
        assert_eq!(grid.cells(), [12 + 4, 5 + 4]);
        assert!(BSplineKernel::covering(lower, upper, 0.0, BSplineOrder::Cubic).is_none());
        assert!(BSplineKernel::covering(lower, upper, f64::NAN, BSplineOrder::Cubic).is_none());
    }
    /// Node indices split into grid coordinates x fastest, for every node of a 3D grid
    /// with awkward counts and for indices beyond 2³² in 2D.
    #[test]
    fn node_positions_match_integer_division() {
        let grid = BSplineKernel::new(
            nalgebra::Vector3::new(-0.3, 0.1, 2.0),
            0.05,
            [6, 12, 48],
            BSplineOrder::Cubic,
        )
        .unwrap();
        for node in 0..grid.node_count() {
            let (i, j, k) = (node % 7, (node / 7) % 13, node / 91);
            let expected = nalgebra::Vector3::new(
                -0.3 + 0.05 * i as f64,
                0.1 + 0.05 * j as f64,
                2.0 + 0.05 * k as f64,
            );
            assert_eq!(grid.node_position(node), expected, "node {node}");
        }
        let wide = BSplineKernel::new(
            Vector2::zeros(),
            1.0,
            [99_999, 40_000],
            BSplineOrder::Quadratic,
        )
        .unwrap();
        for node in [
            0,
            99_999,
            100_000,
            100_001,
            4_000_099_999,
            wide.node_count() - 1,
        ] {
            let expected = Vector2::new((node % 100_000) as f64, (node / 100_000) as f64);
            assert_eq!(wide.node_position(node), expected, "node {node}");
        }
    }
}
