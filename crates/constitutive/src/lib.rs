//! Constitutive models for the material point method, generic over dimension
//! (D = 1, 2, 3; 2D is plane strain, 1D is uniaxial stress).
//!
//! Every model implements the [`Constitutive`] port: Kirchhoff stress τ = Jσ from the
//! deformation gradient F and a per-particle state, stored energy density, an explicit
//! return-mapping step (a no-op for elastic models), and the p-wave modulus for the CFL
//! bound.
//!
//! | model | type | state |
//! |---|---|---|
//! | small-strain linear elasticity | [`LinearElastic`] | `()` |
//! | compressible neo-Hookean | [`NeoHookean`] | `()` |
//! | St. Venant–Kirchhoff | [`StVenantKirchhoff`] | `()` |
//! | fixed corotated | [`FixedCorotated`] | `()` |
//! | weakly compressible fluid | [`WeaklyCompressibleFluid`] | `()` |
//! | Drucker–Prager (Hencky) | [`ElastoPlastic`]`<`[`DruckerPrager`]`>` | [`PlasticState`] |
//! | von Mises + hardening (Hencky) | [`ElastoPlastic`]`<`[`VonMises`]`>` | [`PlasticState`] |
//!
//! [`table::MaterialTable`] puts several of them in one simulation (a material id per
//! particle); its plastic part is a type parameter, so a table without plastic models
//! carries no plastic state.
//!
//! Parameters are validated on construction ([`ElasticParameters`]): E > 0,
//! −1 < ν < 0.5, angles in range; errors name the parameter and its value.
//!
//! ```
//! use nalgebra::Matrix2;
//! use umls_constitutive::{Constitutive, ElasticParameters, NeoHookean};
//!
//! let model = NeoHookean { parameters: ElasticParameters::from_young_poisson(1e6, 0.3)? };
//! let f = Matrix2::new(1.01, 0.02, 0.0, 0.99);
//! let sigma = Constitutive::<2>::cauchy_stress(&model, &f, &())?;
//! assert!((sigma - sigma.transpose()).norm() < 1e-9);
//! // Longitudinal wave speed for ρ = 1050, for the time-step bound.
//! let c = Constitutive::<2>::p_wave_speed(&model, 1050.0);
//! assert!((c - (1.3461538461538463e6f64 / 1050.0).sqrt()).abs() < 1e-9);
//! # Ok::<(), umls_constitutive::ConstitutiveError>(())
//! ```

mod elastic;
mod error;
mod fluid;
mod linalg;
mod model;
mod parameters;
mod plastic;
pub mod table;
mod yield_criteria;

pub use elastic::{FixedCorotated, LinearElastic, NeoHookean, StVenantKirchhoff};
pub use error::ConstitutiveError;
pub use fluid::WeaklyCompressibleFluid;
pub use linalg::{Matrix, determinant, signed_svd};
pub use model::Constitutive;
pub use parameters::ElasticParameters;
pub use plastic::{ElastoPlastic, PlasticState, Principal, YieldCriterion};
pub use yield_criteria::{ConeFit, DruckerPrager, VonMises};
