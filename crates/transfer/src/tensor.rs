//! Stencils that are tensor products of per-axis factors (B-spline grids).

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
