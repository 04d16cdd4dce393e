//! From the raw file contents to a validated [`SimplexMesh`] with named sets: cells are
//! the elements of the mesh dimension, lower-dimensional elements only feed the physical
//! groups, and nodes no cell uses are dropped.

use std::collections::{BTreeMap, HashMap};

use nalgebra::SVector;
use umls_mesh::{MeshError, SimplexMesh};

use super::coincident::{COINCIDENCE_TOLERANCE, first_coincident};
use super::raw::RawMsh;
use super::{GmshMesh, MshVersion, PhysicalGroup, ReadOptions};
use crate::error::{IoError, Result};

/// Coordinates beyond the mesh dimension must vanish to this fraction of the mesh extent.
const FLATNESS_TOLERANCE: f64 = 1e-12;

/// The simplex a mesh validation error is about, if any.
fn simplex_of(error: &MeshError) -> Option<usize> {
    match error {
        MeshError::VertexIndexOutOfRange { simplex, .. }
        | MeshError::RepeatedVertex { simplex, .. }
        | MeshError::DegenerateSimplex { simplex, .. }
        | MeshError::InvertedSimplex { simplex, .. } => Some(*simplex),
        MeshError::NonManifoldFacet { third, .. } => Some(*third),
        _ => None,
    }
}

fn describe(raw: &RawMsh) -> String {
    let mut counts = [0usize; 4];
    for e in &raw.elements {
        counts[e.dimension] += 1;
    }
    let parts: Vec<String> = counts
        .iter()
        .enumerate()
        .filter(|&(_, &n)| n > 0)
        .map(|(d, n)| format!("{n} elements of dimension {d}"))
        .collect();
    if parts.is_empty() {
        "no elements".into()
    } else {
        parts.join(", ")
    }
}

fn group_name(raw: &RawMsh, dimension: usize, tag: i32) -> String {
    raw.names
        .get(&(dimension, tag))
        .cloned()
        .unwrap_or_else(|| format!("physical {dimension}D {tag}"))
}

pub(crate) fn to_mesh<const D: usize>(
    raw: RawMsh,
    version: MshVersion,
    options: ReadOptions,
) -> Result<GmshMesh<D>> {
    let node_index: HashMap<u64, usize> = raw
        .nodes
        .iter()
        .enumerate()
        .map(|(i, (tag, _, _))| (*tag, i))
        .collect();
    for e in &raw.elements {
        if e.dimension > D {
            return Err(IoError::DimensionTooHigh {
                element: e.tag,
                found: e.dimension,
                requested: D,
            });
        }
        if let Some(&node) = e.nodes.iter().find(|n| !node_index.contains_key(n)) {
            return Err(IoError::UnknownNode {
                at: e.at,
                element: e.tag,
                node,
            });
        }
    }
    let cells: Vec<_> = raw.elements.iter().filter(|e| e.dimension == D).collect();
    if cells.is_empty() {
        return Err(IoError::NoCells {
            dimension: D,
            found: describe(&raw),
        });
    }

    // Vertices: the nodes the cells use, in file order.
    let mut used = vec![false; raw.nodes.len()];
    for cell in &cells {
        for n in &cell.nodes {
            used[node_index[n]] = true;
        }
    }
    let mut new_index = vec![u32::MAX; raw.nodes.len()];
    let mut vertices = Vec::new();
    let mut vertex_tags = Vec::new();
    let extent = raw
        .nodes
        .iter()
        .zip(&used)
        .filter(|(_, u)| **u)
        .flat_map(|((_, x, _), _)| x.iter().map(|c| c.abs()))
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    for (i, (tag, x, _)) in raw.nodes.iter().enumerate() {
        if !used[i] {
            continue;
        }
        if let Some(axis) = (D..3).find(|&k| x[k].abs() > FLATNESS_TOLERANCE * extent) {
            return Err(IoError::NotFlat {
                node: *tag,
                axis,
                value: x[axis],
                dimension: D,
            });
        }
        new_index[i] = vertices.len() as u32;
        vertices.push(SVector::<f64, D>::from_fn(|k, _| x[k]));
        vertex_tags.push(*tag);
    }
    if let Some((first, second)) = first_coincident(&vertices, COINCIDENCE_TOLERANCE * extent) {
        let (_, x, at) = &raw.nodes[node_index[&vertex_tags[second]]];
        return Err(IoError::CoincidentNodes {
            at: *at,
            first: vertex_tags[first],
            second: vertex_tags[second],
            point: x[..D]
                .iter()
                .map(|c| format!("{c}"))
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let vertex_of = |tag: &u64| new_index[node_index[tag]];

    let connectivity: Vec<u32> = cells
        .iter()
        .flat_map(|c| c.nodes.iter().map(vertex_of))
        .collect();
    let cell_tags: Vec<u64> = cells.iter().map(|c| c.tag).collect();
    let mesh = SimplexMesh::new(vertices, connectivity, options.orientation).map_err(|source| {
        let cell = simplex_of(&source).map(|s| cells[s]);
        IoError::InvalidMesh {
            at: cell.map_or(cells[0].at, |c| c.at),
            element: cell.map_or(0, |c| c.tag),
            source,
        }
    })?;

    // Physical groups, including named groups that hold no element.
    let mut groups: BTreeMap<(usize, i32), PhysicalGroup> = raw
        .names
        .keys()
        .filter(|(dim, _)| *dim <= D)
        .map(|&(dimension, tag)| {
            (
                (dimension, tag),
                PhysicalGroup::empty(group_name(&raw, dimension, tag), dimension, tag),
            )
        })
        .collect();
    let mut cell_number = 0u32;
    for e in &raw.elements {
        let is_cell = e.dimension == D;
        for &tag in &e.physical {
            let group = groups.entry((e.dimension, tag)).or_insert_with(|| {
                PhysicalGroup::empty(group_name(&raw, e.dimension, tag), e.dimension, tag)
            });
            if is_cell {
                group.cells.push(cell_number);
            }
            for n in &e.nodes {
                let v = vertex_of(n);
                if v == u32::MAX {
                    return Err(IoError::DetachedElement {
                        element: e.tag,
                        dimension: e.dimension,
                        group: group.name.clone(),
                        node: *n,
                    });
                }
                group.vertices.push(v);
                if !is_cell {
                    group.elements.push(v);
                }
            }
        }
        if is_cell {
            cell_number += 1;
        }
    }
    let groups = groups
        .into_values()
        .map(|mut g| {
            g.vertices.sort_unstable();
            g.vertices.dedup();
            g
        })
        .collect();
    Ok(GmshMesh {
        mesh,
        groups,
        vertex_tags,
        cell_tags,
        version,
    })
}
