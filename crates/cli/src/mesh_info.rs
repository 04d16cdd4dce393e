//! `umls mesh-info`: what a Gmsh file holds, as a report a person reads.

use std::fmt::Write as _;
use std::path::Path;

use umls_io::gmsh::{AnyGmshMesh, GmshMesh, ReadOptions, read_msh_any};

use umls_runner::{Result, RunError};

fn report<const D: usize>(m: &GmshMesh<D>, path: &Path) -> String {
    let mut out = String::new();
    let kind = ["", "segments", "triangles", "tetrahedra"][D];
    let _ = writeln!(out, "{}: MSH {:?}", path.display(), m.version);
    let _ = writeln!(
        out,
        "  {D}D mesh: {} vertices, {} {kind}",
        m.mesh.vertex_count(),
        m.mesh.simplex_count()
    );
    let (lower, upper) = m.mesh.bounding_box();
    let _ = writeln!(
        out,
        "  bounding box: {:?} to {:?}",
        lower.as_slice(),
        upper.as_slice()
    );
    let measure = ["", "length", "area", "volume"][D];
    let _ = writeln!(out, "  total {measure}: {}", m.mesh.total_volume());
    let _ = writeln!(
        out,
        "  boundary facets: {}",
        m.mesh.topology().boundary_facets().len()
    );
    for line in m.mesh.quality_summary().to_string().lines() {
        let _ = writeln!(out, "  {line}");
    }
    if m.groups.is_empty() {
        let _ = writeln!(out, "  physical groups: none");
    } else {
        let _ = writeln!(out, "  physical groups:");
        for g in &m.groups {
            let elements = if g.dimension == D {
                format!("{} cells", g.cells.len())
            } else {
                format!("{} elements", g.elements.len() / (g.dimension + 1))
            };
            let _ = writeln!(
                out,
                "    {:<16} {}D tag {:<4} {elements}, {} vertices",
                format!("\"{}\"", g.name),
                g.dimension,
                g.tag,
                g.vertices.len()
            );
        }
    }
    out
}

/// The report for the mesh file at `path`.
pub fn mesh_info(path: &Path) -> Result<String> {
    // The reader's errors name the line or byte; the file is named here.
    let mesh = read_msh_any(path, ReadOptions::default()).map_err(|e| RunError::MeshFile {
        file: path.display().to_string(),
        message: e.to_string(),
    })?;
    Ok(match mesh {
        AnyGmshMesh::Segments(m) => report(&m, path),
        AnyGmshMesh::Triangles(m) => report(&m, path),
        AnyGmshMesh::Tetrahedra(m) => report(&m, path),
    })
}
