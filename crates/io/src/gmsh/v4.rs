//! MSH 4.1, ASCII and binary: `$Entities` carry the physical tags, `$Nodes` and
//! `$Elements` come in entity blocks. Binary files use 4-byte `int`, 8-byte `size_t` and
//! 8-byte `double` in the byte order announced in `$MeshFormat`.

use std::collections::{BTreeSet, HashMap, HashSet};

use super::cursor::Cursor;
use super::raw::{RawElement, RawMsh, element_shape};
use crate::error::{IoError, Position, Result};

/// Physical tags of each (dimension, entity tag).
pub(crate) type EntityPhysicals = HashMap<(usize, i32), Vec<i32>>;

/// Reads an `int` field: a token in ASCII files, 4 bytes in binary ones.
fn int(c: &mut Cursor<'_>, expected: &'static str) -> Result<i32> {
    if c.binary {
        c.int(expected)
    } else {
        c.parse(expected)
    }
}

/// Reads a `size_t` field.
fn size(c: &mut Cursor<'_>, expected: &'static str) -> Result<u64> {
    if c.binary {
        c.size(expected)
    } else {
        c.parse(expected)
    }
}

/// Reads a `size_t` count that cannot exceed what is left at `min_bytes` per item.
fn count(c: &mut Cursor<'_>, expected: &'static str, min_bytes: usize) -> Result<usize> {
    if c.binary {
        c.size_count(expected, min_bytes)
    } else {
        c.count(expected, min_bytes)
    }
}

fn double(c: &mut Cursor<'_>, expected: &'static str) -> Result<f64> {
    if c.binary {
        c.double(expected)
    } else {
        c.parse(expected)
    }
}

/// An entity dimension, 0 to 3.
fn dimension(c: &mut Cursor<'_>) -> Result<(usize, Position)> {
    let at = c.position();
    let dim = int(c, "an entity dimension")?;
    match usize::try_from(dim) {
        Ok(d) if d <= 3 => Ok((d, at)),
        _ => Err(IoError::BadField {
            at,
            section: c.section,
            expected: "an entity dimension 0..=3",
            found: dim.to_string(),
        }),
    }
}

/// The part of an entity record shared by `$Entities` and `$PartitionedEntities`:
/// coordinates (X Y Z for points, a bounding box for higher entities), the physical
/// tags, which are returned, and the bounding entities of curves, surfaces and volumes.
fn entity_physical_tags(c: &mut Cursor<'_>, dim: usize) -> Result<Vec<i32>> {
    let coordinates = if dim == 0 { 3 } else { 6 };
    for _ in 0..coordinates {
        double(c, "an entity coordinate")?;
    }
    let n_physical = count(c, "the number of physical tags", 4)?;
    let tags = (0..n_physical)
        .map(|_| int(c, "a physical tag"))
        .collect::<Result<Vec<i32>>>()?;
    if dim > 0 {
        let n_bounding = count(c, "the number of bounding entities", 4)?;
        for _ in 0..n_bounding {
            int(c, "a bounding entity tag")?;
        }
    }
    Ok(tags)
}

pub(crate) fn read_entities(c: &mut Cursor<'_>) -> Result<EntityPhysicals> {
    c.start_binary();
    let counts = [
        count(c, "the number of point entities", 4)?,
        count(c, "the number of curve entities", 4)?,
        count(c, "the number of surface entities", 4)?,
        count(c, "the number of volume entities", 4)?,
    ];
    let mut physicals = EntityPhysicals::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = int(c, "an entity tag")?;
            physicals.insert((dim, tag), entity_physical_tags(c, dim)?);
        }
    }
    Ok(physicals)
}

/// `$PartitionedEntities`: in a partitioned file the element blocks refer to these
/// entities, each with its own physical tags.
pub(crate) fn read_partitioned_entities(c: &mut Cursor<'_>) -> Result<EntityPhysicals> {
    c.start_binary();
    count(c, "the number of partitions", 0)?;
    let ghosts = count(c, "the number of ghost entities", 8)?;
    for _ in 0..ghosts {
        int(c, "a ghost entity tag")?;
        int(c, "a ghost entity partition")?;
    }
    let counts = [
        count(c, "the number of partitioned point entities", 4)?,
        count(c, "the number of partitioned curve entities", 4)?,
        count(c, "the number of partitioned surface entities", 4)?,
        count(c, "the number of partitioned volume entities", 4)?,
    ];
    let mut physicals = EntityPhysicals::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = int(c, "a partitioned entity tag")?;
            dimension(c)?;
            int(c, "a parent entity tag")?;
            let partitions = count(c, "the number of partitions of the entity", 4)?;
            for _ in 0..partitions {
                int(c, "a partition tag")?;
            }
            physicals.insert((dim, tag), entity_physical_tags(c, dim)?);
        }
    }
    Ok(physicals)
}

pub(crate) fn read_nodes(c: &mut Cursor<'_>, raw: &mut RawMsh) -> Result<()> {
    c.start_binary();
    let blocks = count(c, "the number of node blocks", 4)?;
    let total = count(c, "the number of nodes", 8)?;
    size(c, "the smallest node tag")?;
    size(c, "the largest node tag")?;
    raw.nodes.reserve(total);
    let mut seen = HashSet::with_capacity(total);
    for _ in 0..blocks {
        let (entity_dim, _) = dimension(c)?;
        int(c, "an entity tag")?;
        let parametric = int(c, "the parametric flag")? != 0;
        let n = count(c, "the number of nodes in the block", 8)?;
        let mut tags = Vec::with_capacity(n);
        for _ in 0..n {
            let at = c.position();
            let tag = size(c, "a node tag")?;
            if !seen.insert(tag) {
                return Err(IoError::DuplicateTag {
                    at,
                    entity: "node",
                    tag,
                });
            }
            tags.push((tag, at));
        }
        let extra = if parametric { entity_dim } else { 0 };
        for (tag, at) in tags {
            let x = [
                double(c, "an x coordinate")?,
                double(c, "a y coordinate")?,
                double(c, "a z coordinate")?,
            ];
            for _ in 0..extra {
                double(c, "a parametric coordinate")?;
            }
            raw.nodes.push((tag, x, at));
        }
    }
    if raw.nodes.len() != total {
        return Err(c.malformed(format!(
            "$Nodes announces {total} nodes but its blocks hold {}",
            raw.nodes.len()
        )));
    }
    Ok(())
}

pub(crate) fn read_elements(
    c: &mut Cursor<'_>,
    raw: &mut RawMsh,
    physicals: &EntityPhysicals,
) -> Result<()> {
    c.start_binary();
    let blocks = count(c, "the number of element blocks", 4)?;
    let total = count(c, "the number of elements", 8)?;
    size(c, "the smallest element tag")?;
    size(c, "the largest element tag")?;
    let mut index = HashMap::with_capacity(total);
    for _ in 0..blocks {
        let (entity_dim, _) = dimension(c)?;
        let entity = int(c, "an entity tag")?;
        let type_at = c.position();
        let type_id = int(c, "an element type")?;
        let n = count(c, "the number of elements in the block", 8)?;
        let physical: BTreeSet<i32> = physicals
            .get(&(entity_dim, entity))
            .into_iter()
            .flatten()
            .copied()
            .collect();
        for k in 0..n {
            let at = c.position();
            let tag = size(c, "an element tag")?;
            let (nodes, dimension) =
                element_shape(type_id, tag, if k == 0 { type_at } else { at })?;
            let nodes = (0..nodes)
                .map(|_| size(c, "a node tag of the element"))
                .collect::<Result<Vec<u64>>>()?;
            raw.push_element(
                &mut index,
                RawElement {
                    tag,
                    dimension,
                    nodes,
                    physical: physical.clone(),
                    at,
                },
            )?;
        }
    }
    if raw.elements.len() != total {
        return Err(c.malformed(format!(
            "$Elements announces {total} elements but its blocks hold {}",
            raw.elements.len()
        )));
    }
    Ok(())
}
