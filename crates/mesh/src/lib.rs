//! Simplicial meshes for the material point method: segments (D = 1), triangles
//! (D = 2) and tetrahedra (D = 3) from one generic source.
//!
//! A [`SimplexMesh`] is validated on construction (indices, repeated vertices,
//! degenerate and inverted simplices, non-manifold facets) and precomputes
//! what per-particle kernels query in their hot loop:
//!
//! - barycentric coordinates and their gradients from a stored affine inverse,
//! - vertex adjacency and vertex-to-simplex incidence (CSR), face neighbours,
//!   boundary facets with outward normals, boundary vertices and normals,
//! - per simplex, its **1-ring** (every vertex equal or edge-adjacent to a host
//!   vertex) with a bitmask of which host vertices each ring vertex is adjacent
//!   to, so the UMLS diminishing factor η_v = Σ_n λ_n A_{v,n} is a few adds,
//! - point location: a walk across face neighbours from a hint (O(1) for
//!   particles that moved a little), parry's BVH as the initial locator and
//!   fallback (features `dim2`, `dim3`; 1D needs neither).
//!
//! [`generate::Lattice`] builds interval, rectangle and box meshes, graded,
//! jittered and rotated, for tests and benchmark scenes; [`SimplexMesh::quality_summary`]
//! reports radius ratios, angles and edge ratios; [`SimplexMesh::sample_points`] places
//! quadrature-rule sample points (centroid, degree-2 Gauss) for seeding material points.
//!
//! ```
//! use umls_mesh::{generate::{Diagonal, Lattice}, SimplexMesh};
//! use nalgebra::Vector2;
//!
//! let mesh: SimplexMesh<2> = Lattice::new([0.0, 0.0], [1.0, 1.0], [8, 8])
//!     .jitter(0.2, 7)
//!     .triangles(Diagonal::Alternating)?;
//! assert_eq!(mesh.simplex_count(), 128);
//!
//! let x = Vector2::new(0.31, 0.47);
//! let found = mesh.locate(&x).expect("inside the unit square");
//! let lambda = found.barycentric.as_slice();
//! assert!((lambda.iter().sum::<f64>() - 1.0).abs() < 1e-12);
//! // A walk from any simplex finds the same host.
//! assert_eq!(mesh.locate_from(&x, 0).unwrap().simplex, found.simplex);
//! // The 1-ring of the host starts with the host's own vertices.
//! let ring = mesh.topology().one_ring(found.simplex as usize);
//! assert_eq!(&ring.vertices[..3], mesh.simplex(found.simplex as usize));
//! # Ok::<(), umls_mesh::MeshError>(())
//! ```

mod barycentric;
mod csr;
mod error;
mod facet_distance;
pub mod generate;
mod geometry;
mod locate;
mod mesh;
mod quality;
mod sampling;
#[cfg(feature = "proptest")]
pub mod strategies;
mod topology;

pub use barycentric::{Barycentric, BarycentricGradients, MAX_SIMPLEX_VERTICES};
pub use csr::Csr;
pub use error::MeshError;
pub use facet_distance::FacetDistance;
pub use locate::{INSIDE_TOLERANCE, Located, Walk};
pub use mesh::{DEGENERACY_TOLERANCE, EntityCounts, Orientation, Point, SimplexMesh};
pub use quality::{QualitySummary, SimplexQuality};
pub use sampling::SampleRule;
pub use topology::{BoundaryFacet, OneRing, Topology};
