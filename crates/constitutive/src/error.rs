//! The constitutive crate's error type.

use thiserror::Error;

/// Invalid material parameters or a deformation a model cannot take.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ConstitutiveError {
    /// A material parameter out of its range.
    #[error("material parameter `{parameter}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
    /// det F ≤ 0 (inverted or collapsed material) for a model defined only for det F > 0.
    #[error("{model}: deformation gradient has det F = {det:.4e} ≤ 0")]
    NonPositiveJacobian {
        /// The model's name.
        model: &'static str,
        /// det F.
        det: f64,
    },
    /// A deformation gradient with a NaN or infinite entry.
    #[error("{model}: deformation gradient has a non-finite entry")]
    NonFiniteDeformation {
        /// The model's name.
        model: &'static str,
    },
    /// A model that does not exist in this dimension.
    #[error("{model} is not available for D = {dim}: {reason}")]
    UnsupportedDimension {
        /// The model's name.
        model: &'static str,
        /// The dimension.
        dim: usize,
        /// Why.
        reason: &'static str,
    },
}
