//! The MLS crate's error type.

use thiserror::Error;

/// What can go wrong evaluating MLS shape functions.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MlsError {
    /// The moment matrix is singular or its condition number exceeds the limit.
    #[error(
        "ill-conditioned moment matrix{}: condition number {condition:.3e} exceeds {limit:.3e} ({samples} samples with positive weight for a basis of size {basis})",
        simplex.map(|s| format!(" in simplex {s}")).unwrap_or_default()
    )]
    IllConditioned {
        /// Host simplex, when evaluated on a mesh.
        simplex: Option<u32>,
        /// 1-norm condition number (infinite when the Cholesky factorisation failed).
        condition: f64,
        /// The configured limit.
        limit: f64,
        /// Samples with positive weight.
        samples: usize,
        /// Size of the polynomial basis.
        basis: usize,
    },
    /// More samples than the fixed stencil capacity.
    #[error("{samples} samples exceed the stencil capacity {capacity}{}", simplex.map(|s| format!(" (1-ring of simplex {s})")).unwrap_or_default())]
    StencilOverflow {
        /// Host simplex, when evaluated on a mesh.
        simplex: Option<u32>,
        /// Samples supplied.
        samples: usize,
        /// [`crate::MAX_STENCIL`].
        capacity: usize,
    },
    /// Input arrays of different lengths.
    #[error(
        "sample arrays differ in length: {positions} positions, {weights} weights, {gradients} weight gradients"
    )]
    LengthMismatch {
        /// Number of positions.
        positions: usize,
        /// Number of weights.
        weights: usize,
        /// Number of weight gradients.
        gradients: usize,
    },
    /// Output slices whose length is not the host's 1-ring size.
    #[error(
        "the 1-ring of simplex {simplex} has {ring} vertices but the output slices hold {nodes} nodes, {values} values and {gradients} gradients"
    )]
    OutputLength {
        /// Host simplex.
        simplex: u32,
        /// Number of 1-ring vertices.
        ring: usize,
        /// Length of the node slice.
        nodes: usize,
        /// Length of the value slice.
        values: usize,
        /// Length of the gradient slice.
        gradients: usize,
    },
    /// A weight that is negative or not finite.
    #[error("sample {sample} has invalid weight {weight:.4e}")]
    InvalidWeight {
        /// Sample index.
        sample: usize,
        /// The weight.
        weight: f64,
    },
    /// The evaluation point lies outside the host simplex it was given with.
    #[error(
        "point lies outside simplex {simplex} (smallest barycentric coordinate {min_barycentric:.4e})"
    )]
    OutsideHost {
        /// The simplex.
        simplex: u32,
        /// Its smallest barycentric coordinate at the point.
        min_barycentric: f64,
    },
    /// A simplex index beyond the mesh.
    #[error("simplex {simplex} does not exist (mesh has {count})")]
    NoSuchSimplex {
        /// The index.
        simplex: u32,
        /// Number of simplices.
        count: usize,
    },
    /// The point is outside the mesh (location failed).
    #[error("point {point:?} is outside the mesh")]
    OutsideMesh {
        /// The coordinates.
        point: Vec<f64>,
    },
    /// A nodal field shorter than the node indices of a stencil.
    #[error("field has {len} entries but the stencil refers to node {node}")]
    FieldTooShort {
        /// Length of the field.
        len: usize,
        /// The node index beyond it.
        node: u32,
    },
    /// A parameter out of range.
    #[error("parameter `{parameter}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
}
