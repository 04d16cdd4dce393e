//! Moving least squares generic over dimension and polynomial basis, and the C¹
//! diminishing-weight UMLS kernel on simplicial meshes.
//!
//! The core ([`shape_functions`], [`PointCloudMls`]) works on any point set: given samples
//! x_v with weights w_v ≥ 0 it fits a polynomial of the chosen basis by weighted least
//! squares around a point x and returns shape functions N_v(x) with either the
//! reconstructed gradient (the fit's linear coefficients, the default), the full
//! derivative, or for UMLS the derivative at frozen diminishing factors
//! ([`GradientKind`]). Dimension (1, 2, 3) and basis ([`Linear`], [`Quadratic`]) are
//! compile-time parameters; an evaluation allocates nothing and fills
//! a fixed-capacity [`Stencil`] on the stack. Ill-conditioned moment matrices fail with a
//! typed error or are regularised, as the caller chooses ([`Conditioning`]).
//!
//! With the default `mesh` feature, [`UmlsKernel`] evaluates the UMLS kernel on a
//! [`umls_mesh::SimplexMesh`]: the samples are the host simplex's 1-ring and the weights
//! w_v = η_v · d_v combine the [`diminishing_factor`] η_v = Σ_n λ_n A_{v,n} with a radial
//! weight d_v (or η_v^p · d_v, [`UmlsKernel::with_diminishing_exponent`]). Shape
//! functions and reconstructed gradients are continuous across facets (the tests measure
//! the jumps), unlike linear finite-element shape functions.
//! [`UmlsKernel::evaluate_into`] writes the same values straight into a caller's arrays
//! of any length (an MPM engine's stencil storage), with no intermediate stencil;
//! [`UmlsKernel::fit_into`] keeps the fit as its weights and a [`UmlsFit`] (M⁻¹ and the
//! scale), from which [`UmlsFit::visit`] rebuilds the same entries later, bit for bit.
//!
//! ```
//! use nalgebra::Vector2;
//! use umls_mesh::generate::{Diagonal, Lattice};
//! use umls_mls::{GradientKind, Linear, Stencil, UmlsKernel};
//!
//! let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [10, 10]).jitter(0.2, 1).triangles(Diagonal::Right)?;
//! let kernel = UmlsKernel::new(&mesh);
//! let mut stencil = Stencil::new();
//! let x = Vector2::new(0.43, 0.61);
//! let host = kernel.evaluate_at::<3, Linear>(&mesh, &x, None, GradientKind::Reconstructed, &mut stencil)?;
//!
//! // Linear fields are reproduced exactly, value and gradient.
//! let field: Vec<f64> = mesh.vertices().iter().map(|v| 2.0 * v.x - 3.0 * v.y + 1.0).collect();
//! let (value, gradient) = stencil.interpolate(&field)?;
//! assert!((value - (2.0 * x.x - 3.0 * x.y + 1.0)).abs() < 1e-12);
//! assert!((gradient - Vector2::new(2.0, -3.0)).norm() < 1e-10);
//! assert!(stencil.len() > 3, "the 1-ring of simplex {host} is larger than the simplex");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod basis;
mod cholesky;
mod diminishing;
mod error;
mod point_cloud;
mod solve;
mod stencil;
#[cfg(feature = "mesh")]
mod umls;
#[cfg(feature = "mesh")]
mod umls_fit;
mod weight;

pub use basis::{Linear, PolynomialBasis, Quadratic};
pub use diminishing::{
    diminishing_factor, diminishing_gradient, powered_diminishing, powered_diminishing_slope,
};
pub use error::MlsError;
pub use point_cloud::PointCloudMls;
pub use solve::{Conditioning, IllConditionedPolicy, Samples, shape_functions};
pub use stencil::{GradientKind, MAX_STENCIL, Stencil};
#[cfg(feature = "mesh")]
pub use umls::{DEFAULT_SUPPORT_FACTOR, HOST_TOLERANCE, SupportRadius, UmlsKernel};
#[cfg(feature = "mesh")]
pub use umls_fit::UmlsFit;
pub use weight::{
    CubicBSpline, DEFAULT_SHARPENING, Profile, SharpenedBSpline, WeightFunction, WendlandC2,
};
