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
        "only {found} samples have positive weight within the bandwidth, but a degree-{degree} polynomial in {intrinsic} variables has {needed} coefficients"
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
    /// The bandwidth rule gave no usable σ (zero, or not finite: samples at one
    /// position, or coordinates so large that distances overflow).
    #[error(
        "bandwidth σ = {sigma:.4e} from the distance to the {neighbours}-th nearest distinct sample is not a positive finite number"
    )]
    BandwidthUndefined {
        /// The σ found.
        sigma: f64,
        /// K* of the rule.
        neighbours: usize,
    },
    /// The neighbours are nearly on a lower-dimensional set: the local plane is undefined.
    #[error(
        "the neighbours span fewer than d directions (relative spread of the d-th direction {ratio:.4e})"
    )]
    RankDeficient {
        /// Relative spread of the weakest tangent direction (0 when undefined).
        ratio: f64,
    },
    /// The weighted fit does not pin down its coefficients: the samples are too uneven
    /// (for instance all on a line of a surface) even after widening the bandwidth.
    #[error(
        "fit is ill-conditioned: condition number {condition:.4e} exceeds {limit:.4e} at bandwidth σ = {sigma:.4e} (samples too uneven around the query)"
    )]
    IllConditioned {
        /// Condition number of the column-equilibrated weighted design.
        condition: f64,
        /// The limit of the settings.
        limit: f64,
        /// Widest bandwidth tried.
        sigma: f64,
    },
    /// The query is too far from every sample: the data do not determine its chart.
    #[error(
        "query is {distance:.4e} from the nearest sample, beyond the limit {limit:.4e} (max_offset × σ): the data do not determine its chart"
    )]
    QueryTooFar {
        /// Distance to the nearest sample.
        distance: f64,
        /// `max_offset` × σ there.
        limit: f64,
    },
    /// The query sits near a centre of curvature of the reconstructed manifold (the
    /// centre of a sampled sphere): many points are about equally close, so its
    /// projection and value are not unique.
    #[error(
        "query is {distance:.4e} from the reconstructed manifold, near its centre of curvature (radius {radius:.4e}): the projection is not unique"
    )]
    FocalQuery {
        /// Distance from the query to its projection.
        distance: f64,
        /// Smallest radius of curvature towards the query.
        radius: f64,
    },
    /// The fit raised a [`crate::Concerns`] concern and the settings refuse such fits
    /// ([`crate::Settings::refuse_untrustworthy`]).
    #[error("untrustworthy fit at bandwidth σ = {sigma:.4e}: {concern}")]
    Untrustworthy {
        /// The first concern raised.
        concern: &'static str,
        /// The bandwidth of the fit.
        sigma: f64,
    },
    /// A neighbour index asked about a cloud it was not built from.
    #[error("the neighbour index was built from a different point cloud")]
    ForeignCloud,
    /// The chart iteration did not settle.
    #[error("local chart did not converge in {iterations} iterations (last step {step:.4e} × σ)")]
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
