//! Mesh and result I/O for umls.
//!
//! - [`gmsh`]: read Gmsh MSH files (4.1 ASCII and binary, 2.2 ASCII) into a
//!   [`umls_mesh::SimplexMesh`] with the file's physical groups as named vertex, cell and
//!   facet sets. Errors name the line (or byte) and section at fault; no input panics.
//! - [`vtk`]: write `.vtu` files (particles as point clouds with fields, meshes with
//!   node and cell fields) and `.pvd` collections that ParaView opens as an animation.
//! - [`csv`]: write time histories with a header row.
//! - [`chart`]: line charts, stability maps and stacked bars as SVG, with titles, axis labels that carry units, optional
//!   log axes and a legend beside the plot, shared by the command line, the examples and
//!   the bench report.
//!
//! The `base64` crate encodes binary VTK arrays (a well-kept, dependency-free encoder);
//! `plotters` (SVG backend only) draws the charts, which would be a great deal of
//! hand-written SVG geometry otherwise.
//!
//! ```
//! use umls_io::gmsh::{parse_msh, ReadOptions};
//! use umls_io::vtk::{Encoding, UnstructuredGrid};
//!
//! let msh = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n\
//!     $PhysicalNames\n1\n0 1 \"left\"\n$EndPhysicalNames\n\
//!     $Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n\
//!     $Elements\n3\n1 15 2 1 1 1\n2 2 2 0 1 1 2 3\n3 2 2 0 1 1 3 4\n$EndElements\n";
//! let file = parse_msh::<2>(msh, ReadOptions::default())?;
//! assert_eq!(file.mesh.simplex_count(), 2);
//! assert_eq!(file.group("left").map(|g| g.vertices.clone()), Some(vec![0]));
//!
//! let mut grid = UnstructuredGrid::from_mesh(&file.mesh);
//! grid.add_cell_field("area", 1, (0..2).map(|s| file.mesh.volume(s)).collect())?;
//! assert!(grid.to_vtu(Encoding::Ascii).contains("Name=\"area\""));
//! # Ok::<(), umls_io::IoError>(())
//! ```

pub mod chart;
pub mod csv;
mod error;
pub mod gmsh;
pub mod vtk;

use std::path::Path;

pub use error::{IoError, Position, Result};

/// Writes `bytes` to `path`, naming the path in the error.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|source| IoError::File {
        path: path.to_path_buf(),
        source,
    })
}
