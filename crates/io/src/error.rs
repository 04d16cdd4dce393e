//! The I/O crate's error type.

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;
use umls_mesh::MeshError;

/// Where in a file something went wrong: a line in ASCII text, a byte offset in binary data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Position {
    /// 1-based line number.
    Line(usize),
    /// 0-based byte offset (binary sections).
    Byte(usize),
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Position::Line(line) => write!(f, "line {line}"),
            Position::Byte(offset) => write!(f, "byte {offset}"),
        }
    }
}

/// Everything that can go wrong reading a mesh or writing results.
///
/// Parse errors name the position (line or byte) and the `$Section` of the file.
#[derive(Debug, Error)]
pub enum IoError {
    /// The operating system refused a read or write.
    #[error("{path}: {source}")]
    File {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file ended inside a section.
    #[error("{at}: file ends inside ${section} while reading {expected}")]
    Truncated {
        /// Position of the end of the file.
        at: Position,
        /// The section being read.
        section: &'static str,
        /// What was expected next.
        expected: &'static str,
    },
    /// A field that should be a number is not, or is out of range.
    #[error("{at}: in ${section}, {expected} expected, found `{found}`")]
    BadField {
        /// Position of the field.
        at: Position,
        /// The section being read.
        section: &'static str,
        /// What was expected.
        expected: &'static str,
        /// The text found (shortened).
        found: String,
    },
    /// A structural problem: a missing or misplaced section marker, a bad header.
    #[error("{at}: {message}")]
    Malformed {
        /// Position.
        at: Position,
        /// What is wrong.
        message: String,
    },
    /// A mesh format version this reader does not handle.
    #[error(
        "{at}: MSH format {version} is not supported (readable: 4.1 ASCII and binary, 2.2 ASCII)"
    )]
    UnsupportedVersion {
        /// Position of the version field.
        at: Position,
        /// The version (and mode) found.
        version: String,
    },
    /// An element type that is not a point, segment, triangle or tetrahedron.
    #[error(
        "{at}: element {element} has Gmsh type {type_id} ({name}); only points (15), 2-node segments (1), 3-node triangles (2) and 4-node tetrahedra (4) are supported"
    )]
    UnsupportedElement {
        /// Position of the element.
        at: Position,
        /// Element tag.
        element: u64,
        /// Gmsh element type number.
        type_id: i32,
        /// Its name, where known.
        name: &'static str,
    },
    /// An element refers to a node tag that the file does not define.
    #[error("{at}: element {element} refers to node {node}, which $Nodes does not define")]
    UnknownNode {
        /// Position of the element.
        at: Position,
        /// Element tag.
        element: u64,
        /// The missing node tag.
        node: u64,
    },
    /// Two nodes or two different elements with the same tag.
    #[error("{at}: {entity} tag {tag} is defined twice")]
    DuplicateTag {
        /// Position of the second definition.
        at: Position,
        /// "node" or "element".
        entity: &'static str,
        /// The tag.
        tag: u64,
    },
    /// A required section is missing.
    #[error("the file has no ${section} section")]
    MissingSection {
        /// Section name.
        section: &'static str,
    },
    /// No element of the requested dimension.
    #[error("the file has no {dimension}D cells ({found})")]
    NoCells {
        /// The cell dimension asked for.
        dimension: usize,
        /// What the file holds instead.
        found: String,
    },
    /// Elements of a higher dimension than requested.
    #[error(
        "element {element} is {found}-dimensional but a {requested}D mesh was requested; read the file as {found}D"
    )]
    DimensionTooHigh {
        /// Element tag.
        element: u64,
        /// Its dimension.
        found: usize,
        /// The requested mesh dimension.
        requested: usize,
    },
    /// A node of a D < 3 mesh lies off the coordinate plane (or line) the mesh is read in.
    #[error(
        "node {node} has coordinate {value:.6e} on axis {axis}; a {dimension}D mesh must lie in the plane (or on the line) where the remaining coordinates are 0"
    )]
    NotFlat {
        /// Node tag.
        node: u64,
        /// Axis (0 = x).
        axis: usize,
        /// The offending coordinate.
        value: f64,
        /// The mesh dimension.
        dimension: usize,
    },
    /// Two nodes the cells use lie at the same point: the cells on either side would share
    /// no vertex there, an internal crack the file most likely does not mean.
    #[error(
        "{at}: nodes {first} and {second} both lie at ({point}); cells on either side would not be joined there (an internal crack). Merge duplicate nodes (Gmsh: Coherence Mesh, or Geometry.Tolerance when the CAD has duplicate points)"
    )]
    CoincidentNodes {
        /// Position of the second node's definition.
        at: Position,
        /// Tag of the node defined first.
        first: u64,
        /// Tag of the node defined later at the same point.
        second: u64,
        /// The shared point, as "x, y, z".
        point: String,
    },
    /// A lower-dimensional (boundary) element uses a node that no cell uses.
    #[error(
        "element {element} (a {dimension}D element of physical group {group}) uses node {node}, which belongs to no cell"
    )]
    DetachedElement {
        /// Element tag.
        element: u64,
        /// Its dimension.
        dimension: usize,
        /// Its physical group.
        group: String,
        /// The node tag.
        node: u64,
    },
    /// The cells do not form a valid mesh (degenerate, inverted, non-manifold, …).
    #[error("{at}: element {element}: {source}")]
    InvalidMesh {
        /// Where the offending element is defined (the `$Elements` header if the problem
        /// is not tied to one element).
        at: Position,
        /// Tag of the offending element (0 if the problem is not tied to one).
        element: u64,
        /// The mesh validation error.
        source: MeshError,
    },
    /// A field written to a result file has the wrong length.
    #[error("field `{field}` has {found} values, expected {expected}")]
    FieldLength {
        /// Field name.
        field: String,
        /// Values given.
        found: usize,
        /// Values expected.
        expected: usize,
    },
    /// A chart could not be drawn or written.
    #[error("{path}: cannot draw the chart: {message}")]
    Chart {
        /// The SVG file.
        path: PathBuf,
        /// What the plotting backend reported.
        message: String,
    },
}

/// Shorthand.
pub type Result<T> = std::result::Result<T, IoError>;
