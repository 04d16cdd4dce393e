//! Gmsh MSH readers: format 4.1 (ASCII and binary, either byte order, partitioned or
//! not) and 2.2 (ASCII).
//!
//! Sections other than `$MeshFormat`, `$PhysicalNames`, `$Entities`,
//! `$PartitionedEntities`, `$Nodes` and `$Elements` (node data, periodicity, ghost
//! elements, parametrisations, comments) are skipped.
//!
//! Written here rather than taken from `mshio` because that crate reads 4.1 only, and
//! because every error must name the line (or byte) and section at fault; the parser is
//! a few hundred lines over one `cursor` and is fuzzed by the crate's tests.

mod coincident;
mod convert;
mod cursor;
mod format;
mod raw;
mod v2;
mod v4;

use std::path::Path;

use umls_mesh::{Orientation, SimplexMesh};

pub use format::MshVersion;

use crate::error::{IoError, Result};

/// How to read a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadOptions {
    /// What to do with negatively oriented cells (Gmsh writes triangles clockwise when
    /// the surface normal points along −z): fix them (default) or reject the file.
    pub orientation: Orientation,
}

/// A physical group of the file: its elements' vertices, and its cells or facets.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalGroup {
    /// The name from `$PhysicalNames`, or `physical <dim>D <tag>` for unnamed groups.
    pub name: String,
    /// Dimension of the group's elements.
    pub dimension: usize,
    /// Physical tag.
    pub tag: i32,
    /// Mesh vertices of the group's elements, sorted, without repeats.
    pub vertices: Vec<u32>,
    /// Indices of the mesh cells in the group (groups of the mesh dimension).
    pub cells: Vec<u32>,
    /// Lower-dimensional groups: their elements as mesh vertex indices, `dimension + 1`
    /// per element (boundary facets, edges or points).
    pub elements: Vec<u32>,
}

impl PhysicalGroup {
    fn empty(name: String, dimension: usize, tag: i32) -> Self {
        Self {
            name,
            dimension,
            tag,
            vertices: Vec::new(),
            cells: Vec::new(),
            elements: Vec::new(),
        }
    }
}

/// A mesh read from an MSH file.
#[derive(Debug, Clone)]
pub struct GmshMesh<const D: usize> {
    /// The mesh of the file's D-dimensional elements, over the nodes they use.
    pub mesh: SimplexMesh<D>,
    /// Physical groups of dimension ≤ D, sorted by (dimension, tag).
    pub groups: Vec<PhysicalGroup>,
    /// File node tag of each mesh vertex.
    pub vertex_tags: Vec<u64>,
    /// File element tag of each mesh cell.
    pub cell_tags: Vec<u64>,
    /// The format the file was in.
    pub version: MshVersion,
}

impl<const D: usize> GmshMesh<D> {
    /// The physical group called `name`.
    pub fn group(&self, name: &str) -> Option<&PhysicalGroup> {
        self.groups.iter().find(|g| g.name == name)
    }
}

/// A mesh of whatever dimension the file's highest-dimensional elements have.
#[derive(Debug, Clone)]
pub enum AnyGmshMesh {
    /// Segments.
    Segments(GmshMesh<1>),
    /// Triangles.
    Triangles(GmshMesh<2>),
    /// Tetrahedra.
    Tetrahedra(GmshMesh<3>),
}

/// Parses an MSH file's bytes as a D-dimensional mesh.
pub fn parse_msh<const D: usize>(bytes: &[u8], options: ReadOptions) -> Result<GmshMesh<D>> {
    let (version, raw) = format::parse_raw(bytes)?;
    convert::to_mesh(raw, version, options)
}

/// Parses an MSH file's bytes; the mesh dimension is that of its highest-dimensional elements.
pub fn parse_msh_any(bytes: &[u8], options: ReadOptions) -> Result<AnyGmshMesh> {
    let (version, raw) = format::parse_raw(bytes)?;
    match raw.elements.iter().map(|e| e.dimension).max() {
        Some(1) => convert::to_mesh(raw, version, options).map(AnyGmshMesh::Segments),
        Some(2) => convert::to_mesh(raw, version, options).map(AnyGmshMesh::Triangles),
        Some(3) => convert::to_mesh(raw, version, options).map(AnyGmshMesh::Tetrahedra),
        _ => Err(IoError::NoCells {
            dimension: 1,
            found: "only points or no elements at all".into(),
        }),
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|source| IoError::File {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads an MSH file as a D-dimensional mesh.
pub fn read_msh<const D: usize>(
    path: impl AsRef<Path>,
    options: ReadOptions,
) -> Result<GmshMesh<D>> {
    parse_msh(&read_bytes(path.as_ref())?, options)
}

/// Reads an MSH file, taking the mesh dimension from its elements.
pub fn read_msh_any(path: impl AsRef<Path>, options: ReadOptions) -> Result<AnyGmshMesh> {
    parse_msh_any(&read_bytes(path.as_ref())?, options)
}
