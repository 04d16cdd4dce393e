//! MPM shape-function kernels behind the [`umls_transfer::Kernel`] port:
//!
//! - `UmlsMeshKernel` (`Umls1`, `Umls2`, `Umls3`): the C¹ UMLS kernel on a
//!   simplicial mesh (umls-mls + umls-mesh; feature `mesh`, on by default), with an
//!   optional integration correction of its force gradients fitted once over the mesh
//!   (`UmlsMeshKernel::with_integration_correction`; rayon integrates the mesh in
//!   parallel, which is why the feature pulls it);
//! - `LinearFeKernel`: P1 hat functions on the same mesh, the classic unstructured MPM
//!   with cell-crossing error (feature `mesh`);
//! - [`BSplineKernel`]: quadratic or cubic B-splines on a Cartesian grid, the
//!   structured-grid reference (always; with `default-features = false` the crate is
//!   this alone, without the mesh crate and parry). Its stencils are tensor products,
//!   which it also hands over as per-axis factors (`Kernel::tensor_stencil`) for
//!   transfers that sum them row by row.
//!
//! [`presets`] names the built-in kernels (`umls` and its variants, `linear-fe`,
//! `bspline2`, `bspline3`) with their settings and, per dimension, their types: what
//! scene files and the command line select (feature `mesh`).
//!
//! Every kernel passes the same conformance suite (`testing::check_kernel`, public with
//! the feature `testing` so that a kernel written elsewhere can run it too): partition
//! of unity, linear reproduction of values and gradients, the declared second moment,
//! valid node indices, and cache-independence. Swapping kernels in a study is a change of one type:
//!
//! ```
//! use std::sync::Arc;
//! use nalgebra::Vector2;
//! use umls_kernels::{LinearFeKernel, Umls2};
//! use umls_mesh::generate::{Diagonal, Lattice};
//! use umls_transfer::{Kernel, Stencil};
//!
//! fn sum_of_weights<K: Kernel<2>>(kernel: &K, x: &Vector2<f64>) -> f64 {
//!     let mut st = Stencil::new();
//!     kernel.stencil(x, &mut K::Cache::default(), &mut st).expect("inside");
//!     st.values().iter().sum()
//! }
//! let mesh = Arc::new(Lattice::new([0.0, 0.0], [1.0, 1.0], [8, 8]).triangles(Diagonal::Right)?);
//! let x = Vector2::new(0.3, 0.6);
//! assert!((sum_of_weights(&Umls2::new(mesh.clone()), &x) - 1.0).abs() < 1e-12);
//! assert!((sum_of_weights(&LinearFeKernel::new(mesh), &x) - 1.0).abs() < 1e-12);
//! # Ok::<(), umls_mesh::MeshError>(())
//! ```

mod bspline;
#[cfg(feature = "mesh")]
mod integration_correction;
#[cfg(feature = "mesh")]
mod mesh_kernels;
#[cfg(feature = "mesh")]
pub mod presets;

#[cfg(feature = "testing")]
pub mod testing;

pub use bspline::{BSplineKernel, BSplineOrder};
#[cfg(feature = "mesh")]
pub use mesh_kernels::{
    HostCache, LinearFeKernel, Umls1, Umls2, Umls3, UmlsMeshKernel, UmlsQuadratic2, UmlsQuadratic3,
};
#[cfg(feature = "mesh")]
pub use umls_mls::GradientKind;
