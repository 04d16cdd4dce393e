//! The manifold crate's error type.

use thiserror::Error;

/// What can go wrong building or querying a manifold MLS approximation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ManifoldError {
    /// No samples, or a zero ambient dimension.
    #[error("point cloud is empty ({samples} samples of dimension {dimension})")]
    Empty {
        /// Number of samples.
        samples: usize,
        /// Ambient dimension.
        dimension: usize,
    },
    /// An array whose length does not fit the declared sizes.
    #[error("{what}: expected length {expected}, found {found}")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A NaN or infinite coordinate or value.
    #[error("{what} {index} is not finite")]
    NonFinite {
        /// "sample", "value" or "query".
        what: &'static str,
        /// Its index.
        index: usize,
    },
    /// The intrinsic dimension must satisfy 1 ≤ d < n.
    #[error("intrinsic dimension d = {intrinsic} must satisfy 1 ≤ d < n = {ambient}")]
    IntrinsicDimension {
        /// d.
        intrinsic: usize,
        /// n.
        ambient: usize,
    },
    /// Fewer samples with positive weight than the polynomial needs.
    #[error(
        "{found} neighbours with positive weight, but a degree-{degree} polynomial in {intrinsic} variables needs at least {needed}"
    )]
    TooFewNeighbours {
        /// Neighbours with positive weight.
        found: usize,
        /// Monomials of the basis.
        needed: usize,
        /// Polynomial degree m.
        degree: usize,
        /// Intrinsic dimension d.
        intrinsic: usize,
    },
    /// The weighted design matrix is numerically rank deficient.
    #[error(
        "weighted least-squares fit is rank deficient: |R| diagonal ratio {ratio:e} (neighbours nearly on a lower-dimensional set)"
    )]
    RankDeficient {
        /// Smallest over largest |R_ii| of the QR factor.
        ratio: f64,
    },
    /// The chart iteration did not settle.
    #[error("local chart did not converge in {iterations} iterations (last step {step:e} × σ)")]
    NotConverged {
        /// Iterations performed.
        iterations: usize,
        /// Last ‖Δq‖ / σ.
        step: f64,
    },
    /// A parameter out of range.
    #[error("parameter `{parameter}` = {value}: {reason}")]
    InvalidParameter {
        /// Name.
        parameter: &'static str,
        /// Value.
        value: f64,
        /// Valid range.
        reason: &'static str,
    },
}
