//! The mesh crate's error type.

use thiserror::Error;

/// Everything that can be wrong with a user-supplied mesh or generator input.
///
/// Every variant names the simplex, vertex or parameter at fault so that a
/// message read in a log is enough to find the problem in the input.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// The mesh has no vertices or no simplices.
    #[error("mesh is empty: {vertices} vertices, {simplices} simplices")]
    Empty {
        /// Number of vertices supplied.
        vertices: usize,
        /// Number of simplices supplied.
        simplices: usize,
    },
    /// A flat connectivity array whose length is not a multiple of D+1.
    #[error("connectivity has {len} entries, not a multiple of {stride} vertices per simplex")]
    ConnectivityLength {
        /// Length of the flat array.
        len: usize,
        /// Vertices per simplex (D+1).
        stride: usize,
    },
    /// More vertices or simplices than the 32-bit indices used internally can address.
    #[error("too many {what}: {count} exceeds the 32-bit index limit")]
    TooLarge {
        /// "vertices" or "simplices".
        what: &'static str,
        /// The count supplied.
        count: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate on axis {axis}")]
    NonFiniteCoordinate {
        /// Vertex index.
        vertex: usize,
        /// Axis (0 = x).
        axis: usize,
    },
    /// A simplex refers to a vertex that does not exist.
    #[error(
        "simplex {simplex} (local vertex {local}) refers to vertex {index}, but the mesh has {vertex_count} vertices"
    )]
    VertexIndexOutOfRange {
        /// Simplex index.
        simplex: usize,
        /// Position of the bad index inside the simplex.
        local: usize,
        /// The index found.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A simplex lists the same vertex twice.
    #[error("simplex {simplex} lists vertex {vertex} more than once")]
    RepeatedVertex {
        /// Simplex index.
        simplex: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A simplex with (numerically) zero volume.
    #[error(
        "simplex {simplex} is degenerate: signed volume {volume:.4e} is below the tolerance {tolerance:.4e}"
    )]
    DegenerateSimplex {
        /// Simplex index.
        simplex: usize,
        /// Its signed volume (length, area).
        volume: f64,
        /// The tolerance it fell below (relative to its longest edge).
        tolerance: f64,
    },
    /// A simplex with negative orientation, under [`crate::Orientation::Reject`].
    #[error("simplex {simplex} is inverted: signed volume {volume:.4e} < 0")]
    InvertedSimplex {
        /// Simplex index.
        simplex: usize,
        /// Its signed volume.
        volume: f64,
    },
    /// A facet shared by more than two simplices (the mesh is not a manifold).
    #[error(
        "facet {facet:?} is shared by simplices {first}, {second} and {third}: the mesh is not a manifold"
    )]
    NonManifoldFacet {
        /// Vertices of the facet.
        facet: Vec<u32>,
        /// First simplex holding the facet.
        first: usize,
        /// Second simplex holding the facet.
        second: usize,
        /// The simplex that made it three.
        third: usize,
    },
    /// The crate was built without the feature that provides point location in this dimension.
    #[error("point location for D = {dim} needs the `{feature}` feature of umls-mesh")]
    DimensionFeatureDisabled {
        /// The dimension.
        dim: usize,
        /// The feature to enable.
        feature: &'static str,
    },
    /// A distance to boundary facets was asked for, and no boundary facet was chosen.
    #[error("no boundary facet was chosen to measure a distance to")]
    NoFacets,
    /// A mesh generator got a parameter out of its range.
    #[error("generator parameter `{parameter}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        parameter: &'static str,
        /// The value given, formatted.
        value: String,
        /// What the valid range is.
        reason: &'static str,
    },
}
