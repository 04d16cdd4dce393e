//! MSH 2.2 ASCII: `$Nodes` as `tag x y z` lines, `$Elements` as
//! `tag type ntags physical elementary … nodes…` lines. An element in several physical
//! groups is listed once per group.

use std::collections::{BTreeSet, HashMap};

use super::cursor::Cursor;
use super::raw::{RawElement, RawMsh, element_shape};
use crate::error::{IoError, Result};

/// Smallest ASCII node line: "1 0 0 0\n".
const MIN_NODE_BYTES: usize = 8;
/// Smallest ASCII element line: "1 15 0 1\n".
const MIN_ELEMENT_BYTES: usize = 9;

pub(crate) fn read_nodes(c: &mut Cursor<'_>, raw: &mut RawMsh) -> Result<()> {
    let n = c.count("the number of nodes", MIN_NODE_BYTES)?;
    let mut seen = HashMap::with_capacity(n);
    for _ in 0..n {
        let (tag, at) = c.parse_at::<u64>("a node tag")?;
        let x = [
            c.parse("an x coordinate")?,
            c.parse("a y coordinate")?,
            c.parse("a z coordinate")?,
        ];
        if seen.insert(tag, ()).is_some() {
            return Err(IoError::DuplicateTag {
                at,
                entity: "node",
                tag,
            });
        }
        raw.nodes.push((tag, x, at));
    }
    Ok(())
}

pub(crate) fn read_elements(c: &mut Cursor<'_>, raw: &mut RawMsh) -> Result<()> {
    let n = c.count("the number of elements", MIN_ELEMENT_BYTES)?;
    let mut index = HashMap::with_capacity(n);
    for _ in 0..n {
        let (tag, at) = c.parse_at::<u64>("an element tag")?;
        let type_id: i32 = c.parse("an element type")?;
        let (nodes, dimension) = element_shape(type_id, tag, at)?;
        let tags = c.count("the number of element tags", 2)?;
        let mut physical = BTreeSet::new();
        for k in 0..tags {
            let value: i32 = c.parse("an element tag value")?;
            // The first tag is the physical group (0: none); the rest are the elementary
            // entity and partitions, which the mesh does not need.
            if k == 0 && value != 0 {
                physical.insert(value);
            }
        }
        let nodes = (0..nodes)
            .map(|_| c.parse("a node tag of the element"))
            .collect::<Result<Vec<u64>>>()?;
        raw.push_element(
            &mut index,
            RawElement {
                tag,
                dimension,
                nodes,
                physical,
                at,
            },
        )?;
    }
    Ok(())
}
