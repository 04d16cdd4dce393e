//! Manifold moving least squares (Sober, Aizenbud & Levin, arXiv 1711.00765): from
//! samples r_i ∈ Rⁿ near an unknown d-dimensional manifold, with values f_i ∈ Rᵏ,
//! approximate f and the manifold itself at any query point.
//!
//! Per query r: find the samples within the bandwidth σ ([`NeighbourIndex`], exact, fast
//! for any n), express them in a local frame of at most K + 1 dimensions, fit the local
//! chart (q, H) — an affine d-plane with r − q ⊥ H — by an Anderson-accelerated weighted
//! affine fit ([`Chart`]), then fit a polynomial of total degree ≤ m in the chart
//! coordinates by weighted least squares (QR of √W P). The constant term is f̃(r), the
//! linear terms the gradient in chart coordinates; the same fit of r_i − q gives the
//! projection of r onto the manifold. The error is O(h^{m+1}) for smooth noiseless data
//! and the cost per query is linear in n.
//!
//! σ follows the local sample spacing, times a growth chosen per cloud by leave-one-out
//! cross-validation ([`Bandwidth::Adaptive`], the default): 1 on clean data, wider on
//! noisy data, so the error keeps falling with N at fixed noise. Every [`Estimate`]
//! carries a [`FitQuality`] (condition number, effective samples, estimated noise and
//! standard error, σ over the local reach) and its [`Concerns`]. A fit that stays
//! ill-conditioned after widening σ, and a query with no well-defined chart (far from the
//! samples, or at a centre of curvature), is an error, never a silent value.
//! docs/manifold-mls.md records every choice with its measurement.
//!
//! ```
//! use umls_manifold::{ManifoldMls, PointCloud, Settings};
//!
//! // 400 samples of the unit circle in R², with f = x·y.
//! let mut points = Vec::new();
//! let mut values = Vec::new();
//! for i in 0..400 {
//!     let t = i as f64 * std::f64::consts::TAU / 400.0;
//!     points.extend([t.cos(), t.sin()]);
//!     values.push(t.cos() * t.sin());
//! }
//! let mls = ManifoldMls::new(PointCloud::new(2, points, 1, values)?, Settings::new(1, 2))?;
//! let t: f64 = 0.3;
//! let estimate = mls.evaluate(&[t.cos(), t.sin()])?;
//! assert!((estimate.value[0] - t.cos() * t.sin()).abs() < 1e-6);
//! assert!(estimate.quality.condition < 10.0);
//! // A point 1 % off the circle projects back onto it (error O(h³) ≈ 6·10⁻⁷ here).
//! let p = mls.evaluate(&[1.01 * t.cos(), 1.01 * t.sin()])?.projection;
//! assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0).abs() < 5e-6);
//! // The centre of the circle has no chart: every sample is equally close.
//! assert!(mls.evaluate(&[0.0, 0.0]).is_err());
//! # Ok::<(), umls_manifold::ManifoldError>(())
//! ```

mod chart;
mod cloud;
mod dense;
mod error;
mod frame;
mod mmls;
mod neighbors;
mod pca;
mod polynomial;

pub use chart::{ANDERSON_MEMORY, Chart, theta};
pub use cloud::PointCloud;
pub use error::ManifoldError;
pub use mmls::{Bandwidth, Concerns, Estimate, FitQuality, ManifoldMls, Settings};
/// The linear-algebra crate of [`Chart`] and [`Estimate`]: use it to name their types
/// without a dependency of your own.
pub use nalgebra;
pub use neighbors::{Neighbour, NeighbourIndex, SearchStrategy, TREE_DIM};
pub use polynomial::Monomials;
