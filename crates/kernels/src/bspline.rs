//! Tensor-product B-spline shape functions on a Cartesian grid: the structured-grid
//! reference of MPM.

use nalgebra::SVector;
use umls_transfer::{Kernel, KernelError, Stencil, TensorStencil};

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

    /// First stencil node for the coordinate ξ = (x − origin)/h: ⌊ξ − ½⌋ (quadratic) or
    /// ⌊ξ⌋ − 1 (cubic), `None` where it would be negative (or ξ is NaN). Truncation is
    /// the floor for the non-negative values kept, and compiles to one instruction on
    /// every x86-64, where `f64::floor` is a library call without SSE4.1.
    #[inline(always)]
    fn base(self, xi: f64) -> Option<usize> {
        match self {
            Self::Quadratic => (xi >= 0.5).then_some((xi - 0.5) as usize),
            // `then`, not `then_some`: below 1 the subtraction would underflow.
            Self::Cubic => (xi >= 1.0).then(|| xi as usize - 1),
        }
    }

    /// N(r) and dN/dr for the distance r (in units of h) from a node.
    #[inline(always)]
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
/// for quadratic splines that is ξ_k ∈ [0.5, n_k − 0.5), for cubic ξ_k ∈ [1, n_k − 1)
/// (ξ = (x − origin)/h); pad the grid by one or two cells around the material.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineKernel<const D: usize> {
    origin: SVector<f64, D>,
    h: f64,
    cells: [usize; D],
    order: BSplineOrder,
    /// 1 / h: the stencils multiply by it, as a division per node and axis cost G2P up
    /// to a tenth of its time.
    inverse_h: f64,
}

impl<const D: usize> BSplineKernel<D> {
    /// A grid of `cells` cells of size `h` from `origin`; `None` for h ≤ 0, too few cells
    /// for one stencil, or more nodes than u32 indices address (2³²).
    pub fn new(
        origin: SVector<f64, D>,
        h: f64,
        cells: [usize; D],
        order: BSplineOrder,
    ) -> Option<Self> {
        // Stencils carry node indices as u32: every node must have one.
        let nodes = cells
            .iter()
            .try_fold(1usize, |count, &n| count.checked_mul(n.checked_add(1)?));
        let addressable = nodes.is_some_and(|count| count - 1 <= u32::MAX as usize);
        let ok = h.is_finite()
            && h > 0.0
            && addressable
            && cells.iter().all(|&n| n + 1 >= order.width());
        ok.then_some(Self {
            origin,
            h,
            cells,
            order,
            inverse_h: 1.0 / h,
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

    /// The first stencil node per axis, or the error if the stencil leaves the grid.
    #[inline(always)]
    fn base_nodes(&self, x: &SVector<f64, D>) -> Result<[usize; D], KernelError> {
        self.base_nodes_of(self.order, x)
    }

    /// [`Self::base_nodes`] for `order` (this kernel's), passed so that a caller which has
    /// matched on it gets its arithmetic folded.
    #[inline(always)]
    fn base_nodes_of(
        &self,
        order: BSplineOrder,
        x: &SVector<f64, D>,
    ) -> Result<[usize; D], KernelError> {
        let width = order.width();
        let mut base = [0usize; D];
        for k in 0..D {
            match order.base((x[k] - self.origin[k]) * self.inverse_h) {
                // Checked: a huge ξ saturates to usize::MAX.
                Some(b)
                    if b.checked_add(width - 1)
                        .is_some_and(|top| top <= self.cells[k]) =>
                {
                    base[k] = b
                }
                _ => {
                    return Err(KernelError::OutsideDomain {
                        point: x.iter().copied().collect(),
                    });
                }
            }
        }
        Ok(base)
    }

    /// How far the node index moves per step along each axis.
    fn strides(&self) -> [usize; D] {
        let mut strides = [1usize; D];
        for k in 1..D {
            strides[k] = strides[k - 1] * (self.cells[k - 1] + 1);
        }
        strides
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
    const MAY_CORRECT_FORCE_GRADIENTS: bool = false;

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

    fn nonnegative_values(&self) -> bool {
        // Products of per-axis B-spline weights, each ≥ 0 (zero beyond the support).
        true
    }

    fn recompute_stencils(&self) -> bool {
        // 3^D (4^D) products of per-axis weights: cheaper than storing ~1 KB per particle
        // in 3D and reading it back twice.
        true
    }

    fn tensor_width(&self) -> Option<usize> {
        Some(self.order.width())
    }

    fn node_lattice(&self) -> Option<[usize; D]> {
        Some(std::array::from_fn(|k| self.cells[k] + 1))
    }

    #[inline(always)]
    fn tensor_stencil<const W: usize>(
        &self,
        x: &SVector<f64, D>,
    ) -> Result<TensorStencil<D, W>, KernelError> {
        match self.order {
            BSplineOrder::Quadratic if W == 3 => {
                self.tensor_of_width::<W>(BSplineOrder::Quadratic, x)
            }
            BSplineOrder::Cubic if W == 4 => self.tensor_of_width::<W>(BSplineOrder::Cubic, x),
            _ => Err(KernelError::NotTensorProduct {
                kernel: std::any::type_name::<Self>(),
                width: W,
            }),
        }
    }

    // Inlined into the stencil stage's loop: as a call (the compiler's choice moved
    // with unrelated engine code) the stage took half as long again on the fluid box.
    #[inline(always)]
    fn node_range(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        _: &mut Stencil<D>,
    ) -> Result<(u32, u32), KernelError> {
        let base = self.base_nodes(x)?;
        let top: [usize; D] = std::array::from_fn(|k| base[k] + self.order.width() - 1);
        Ok((self.node_index(base) as u32, self.node_index(top) as u32))
    }

    fn stencil(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        out: &mut Stencil<D>,
    ) -> Result<(), KernelError> {
        let count = self.order.width().pow(D as u32);
        let entries = out.entries_mut(count);
        let mut e = 0;
        self.entries(x, |node, value, gradient, offset| {
            entries.nodes[e] = node;
            entries.values[e] = value;
            entries.gradients[e] = *gradient;
            entries.offsets[e] = *offset;
            e += 1;
        })
    }

    #[inline(always)]
    fn visit_stencil<F>(
        &self,
        x: &SVector<f64, D>,
        _: &mut (),
        _: &mut Stencil<D>,
        visit: F,
    ) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        self.entries(x, visit)
    }
}

impl<const D: usize> BSplineKernel<D> {
    /// The stencil at `x` as per-axis factors, for `order` (this kernel's), whose stencil
    /// is `W` nodes wide per axis. Each offset is computed as node_position(i) − x would
    /// be, so both agree bit for bit.
    #[inline(always)]
    fn tensor_of_width<const W: usize>(
        &self,
        order: BSplineOrder,
        x: &SVector<f64, D>,
    ) -> Result<TensorStencil<D, W>, KernelError> {
        debug_assert!(order == self.order && W == order.width());
        let base = self.base_nodes_of(order, x)?;
        let mut tensor = TensorStencil {
            first: self.node_index(base),
            corner: base,
            strides: self.strides(),
            values: [[0.0; W]; D],
            derivatives: [[0.0; W]; D],
            offsets: [[0.0; W]; D],
        };
        for k in 0..D {
            let xi = (x[k] - self.origin[k]) * self.inverse_h;
            for a in 0..W {
                let node = (base[k] + a) as f64;
                let (value, derivative) = order.weight(xi - node);
                tensor.values[k][a] = value;
                tensor.derivatives[k][a] = derivative * self.inverse_h;
                tensor.offsets[k][a] = self.origin[k] + self.h * node - x[k];
            }
        }
        Ok(tensor)
    }

    /// The stencil at `x`, entry by entry: `visit(node, N, ∇N, x_node − x)` with nodes
    /// in index order (rows along axis 0, the numbering's fastest axis). One body for
    /// [`Kernel::stencil`] and [`Kernel::visit_stencil`], so both give the same bits.
    #[inline(always)]
    fn entries<F>(&self, x: &SVector<f64, D>, visit: F) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        // The width as a constant: the loops over a row's nodes unroll and their
        // per-axis tables need no bounds checks (with the width read at run time, P2G
        // took 3–6 % longer with quadratic splines and a quarter longer with cubic ones).
        match self.order {
            BSplineOrder::Quadratic => {
                self.entries_of_width::<3, F>(BSplineOrder::Quadratic, x, visit)
            }
            BSplineOrder::Cubic => self.entries_of_width::<4, F>(BSplineOrder::Cubic, x, visit),
        }
    }

    /// [`Self::entries`] for `order` (this kernel's), whose stencil is `W` nodes wide per
    /// axis; passed as an argument so that its weights' branches fold as well.
    #[inline(always)]
    fn entries_of_width<const W: usize, F>(
        &self,
        order: BSplineOrder,
        x: &SVector<f64, D>,
        visit: F,
    ) -> Result<(), KernelError>
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        self.tensor_of_width::<W>(order, x)?.for_each_entry(visit);
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
        // 2³² nodes have u32 indices; one more layer does not.
        let at_limit = [65_535, 65_535];
        assert!(
            BSplineKernel::new(Vector2::zeros(), 1.0, at_limit, BSplineOrder::Quadratic).is_some()
        );
        let beyond = [65_535, 65_536];
        assert!(
            BSplineKernel::new(Vector2::zeros(), 1.0, beyond, BSplineOrder::Quadratic).is_none()
        );
        let absurd = [usize::MAX, 3];
        assert!(
            BSplineKernel::new(Vector2::zeros(), 1.0, absurd, BSplineOrder::Quadratic).is_none()
        );
    }
    /// Points off the grid by any amount, or not numbers, are outside the domain for both
    /// the stencil and the node range (no overflow in the base node).
    #[test]
    fn far_and_non_finite_points_are_outside() {
        for order in [BSplineOrder::Quadratic, BSplineOrder::Cubic] {
            let grid = BSplineKernel::new(Vector2::zeros(), 0.1, [10, 10], order).unwrap();
            let mut st = Stencil::new();
            for bad in [
                -0.01,
                0.99,
                1e300,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NAN,
            ] {
                let x = Vector2::new(0.5, bad);
                let outside = |r: Result<(), KernelError>| {
                    matches!(r, Err(KernelError::OutsideDomain { .. }))
                };
                assert!(
                    outside(grid.stencil(&x, &mut (), &mut st)),
                    "{order:?} {bad}"
                );
                assert!(
                    outside(grid.node_range(&x, &mut (), &mut st).map(|_| ())),
                    "{order:?} {bad}"
                );
            }
            // The last point inside: its stencil's top node is the grid's last.
            let edge = match order {
                BSplineOrder::Quadratic => 0.94,
                BSplineOrder::Cubic => 0.89,
            };
            let range = grid
                .node_range(&Vector2::new(edge, edge), &mut (), &mut st)
                .unwrap();
            assert_eq!(range.1 as usize, grid.node_count() - 1, "{order:?}");
        }
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
