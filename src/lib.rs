//! UMLS-MPM: the material point method on unstructured simplicial meshes with
//! C¹-continuous moving-least-squares kernels, and moving least squares on sampled
//! manifolds.
//!
//! This facade re-exports the member crates so that one dependency gives the whole
//! toolkit; each crate can also be used alone:
//!
//! - [`mesh`] (`umls-mesh`): simplicial meshes, topology, 1-rings, point location,
//!   generators, quality;
//! - [`mls`] (`umls-mls`): MLS generic over dimension and basis, and the UMLS kernel;
//! - [`constitutive`] (`umls-constitutive`): elastic, fluid and elastoplastic material models;
//! - [`manifold`] (`umls-manifold`): moving least squares on point clouds sampled near a
//!   manifold in Rⁿ;
//! - [`transfer`] (`umls-transfer`), [`kernels`] (`umls-kernels`), [`engine`]
//!   (`umls-engine`): the kernel port, the UMLS / linear-FE / B-spline kernels, and the
//!   explicit MPM engine;
//! - [`ugimp`] (`umls-ugimp`): the uGIMP kernel on a grid, a kernel written against the
//!   port alone;
//! - [`runner`] (`umls-runner`): scenes as a library: the scene format, the built-in
//!   scenes and the runner that steps any kernel through them ([`runner::run_with`]);
//! - [`io`] (`umls-io`): Gmsh mesh reading, VTK (`.vtu`, `.pvd`) and CSV writing.
//!
//! The `umls` command line is the separate `umls-cli` crate (`crates/cli`).
//!
//! ```
//! use umls::mesh::generate::{Diagonal, Lattice};
//! use umls::mls::{GradientKind, Linear, Stencil, UmlsKernel};
//!
//! let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4]).triangles(Diagonal::Right)?;
//! let kernel = UmlsKernel::new(&mesh);
//! let mut stencil = Stencil::new();
//! kernel.evaluate::<3, Linear>(&mesh, 0, &mesh.centroid(0), GradientKind::Reconstructed, &mut stencil)?;
//! assert!((stencil.values().iter().sum::<f64>() - 1.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use umls_constitutive as constitutive;
pub use umls_engine as engine;
pub use umls_io as io;
pub use umls_kernels as kernels;
pub use umls_manifold as manifold;
pub use umls_mesh as mesh;
pub use umls_mls as mls;
pub use umls_runner as runner;
pub use umls_transfer as transfer;
pub use umls_ugimp as ugimp;
