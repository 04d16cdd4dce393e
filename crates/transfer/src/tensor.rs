//! Stencils that are tensor products of per-axis factors (B-spline and GIMP grids).

use nalgebra::SVector;

/// A stencil given by its per-axis factors: `W` nodes per axis, node (a₀, …, a_{D−1})
/// being `first + Σ_k a_k strides[k]` with N = Π_k `values[k][a_k]` (multiplied in axis
/// order), ∂N/∂x_j the same product with `values[j]` replaced by `derivatives[j]`, and
/// offset x_node − x = (`offsets[0][a₀]`, …). The entries are those of
/// [`crate::Kernel::stencil`], axis 0 fastest.
///
/// Transfers that sum per row of the stencil use it to take out of the inner loop what
/// does not change along axis 0: the other axes' weights and offsets, and so every
/// product with an offset of theirs (the affine momentum C (x_i − x) is
/// C₀ r₀ + Σ_{k>0} C_k r_k, the last terms one per row).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensorStencil<const D: usize, const W: usize> {
    /// The node at the stencil's lowest corner (a = 0 on every axis).
    pub first: usize,
    /// That node's place on the node lattice, per axis: `first` is
    /// `Σ_k corner[k] strides[k]`. Lets a transfer sum into a box of the lattice rather
    /// than into a range of node indices.
    pub corner: [usize; D],
    /// How far the node index moves per node along each axis.
    pub strides: [usize; D],
    /// N's factor per axis and node.
    pub values: [[f64; W]; D],
    /// The factor's derivative per axis and node (with respect to x_k, not to x_k / h).
    pub derivatives: [[f64; W]; D],
    /// x_node − x per axis and node.
    pub offsets: [[f64; W]; D],
}

impl<const D: usize, const W: usize> TensorStencil<D, W> {
    /// Calls `visit(node, N, ∇N, x_node − x)` for every entry, in node index order (rows
    /// along axis 0, the numbering's fastest axis), each N and ∂N/∂x_j the product of
    /// the factors in axis order. A grid kernel's [`crate::Kernel::stencil`] and
    /// [`crate::Kernel::visit_stencil`] give their entries through it, so both agree
    /// with the factors bit for bit.
    #[inline(always)]
    pub fn for_each_entry<F>(&self, mut visit: F)
    where
        F: FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    {
        let (first, strides) = (self.first, self.strides);
        let (w, dw, r) = (&self.values, &self.derivatives, &self.offsets);
        // The factors are multiplied in axis order, as N = Π_k w_k reads (regrouping
        // them would change the last bit of the results).
        let mut digits = [0usize; D];
        loop {
            let mut node = first;
            for k in 1..D {
                node += digits[k] * strides[k];
            }
            for a in 0..W {
                let mut value = w[0][a];
                for k in 1..D {
                    value *= w[k][digits[k]];
                }
                let gradient = SVector::<f64, D>::from_fn(|j, _| {
                    let mut g = if j == 0 { dw[0][a] } else { w[0][a] };
                    for k in 1..D {
                        g *= if k == j {
                            dw[k][digits[k]]
                        } else {
                            w[k][digits[k]]
                        };
                    }
                    g
                });
                let offset =
                    SVector::<f64, D>::from_fn(
                        |k, _| {
                            if k == 0 { r[0][a] } else { r[k][digits[k]] }
                        },
                    );
                visit((node + a) as u32, value, &gradient, &offset);
            }
            // The next row: an odometer over axes 1..D.
            let mut k = 1;
            loop {
                if k >= D {
                    return;
                }
                digits[k] += 1;
                if digits[k] < W {
                    break;
                }
                digits[k] = 0;
                k += 1;
            }
        }
    }
}
