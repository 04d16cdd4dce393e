//! The contents of an MSH file as read, before conversion to a [`umls_mesh::SimplexMesh`]:
//! nodes and elements with their file tags, and the physical groups they belong to.

use std::collections::{BTreeMap, BTreeSet};

use crate::error::{IoError, Position, Result};

/// Gmsh element types this reader accepts: (type number, nodes, dimension).
const SUPPORTED: [(i32, usize, usize); 4] = [(15, 1, 0), (1, 2, 1), (2, 3, 2), (4, 4, 3)];

/// Names of common element types this reader rejects, for messages.
const KNOWN_UNSUPPORTED: [(i32, &str); 10] = [
    (3, "4-node quadrangle"),
    (5, "8-node hexahedron"),
    (6, "6-node prism"),
    (7, "5-node pyramid"),
    (8, "3-node second-order line"),
    (9, "6-node second-order triangle"),
    (10, "9-node second-order quadrangle"),
    (11, "10-node second-order tetrahedron"),
    (16, "8-node second-order quadrangle"),
    (17, "20-node second-order hexahedron"),
];

/// Node count and dimension of a supported element type, or the error naming it.
pub(crate) fn element_shape(type_id: i32, element: u64, at: Position) -> Result<(usize, usize)> {
    SUPPORTED
        .iter()
        .find(|(t, _, _)| *t == type_id)
        .map(|&(_, nodes, dim)| (nodes, dim))
        .ok_or_else(|| IoError::UnsupportedElement {
            at,
            element,
            type_id,
            name: KNOWN_UNSUPPORTED
                .iter()
                .find(|(t, _)| *t == type_id)
                .map_or("unknown type", |(_, name)| name),
        })
}

/// One element as read.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawElement {
    pub(crate) tag: u64,
    pub(crate) dimension: usize,
    pub(crate) nodes: Vec<u64>,
    /// Physical group tags (of this element's dimension).
    pub(crate) physical: BTreeSet<i32>,
    pub(crate) at: Position,
}

/// A whole file.
#[derive(Debug, Default)]
pub(crate) struct RawMsh {
    /// (node tag, coordinates, position) in file order.
    pub(crate) nodes: Vec<(u64, [f64; 3], Position)>,
    pub(crate) elements: Vec<RawElement>,
    /// (dimension, physical tag) → name.
    pub(crate) names: BTreeMap<(usize, i32), String>,
}

impl RawMsh {
    /// Appends an element; a repeated tag is merged if it is the same element listed
    /// again for another physical group (MSH 2.2 does that), an error otherwise.
    pub(crate) fn push_element(
        &mut self,
        index: &mut std::collections::HashMap<u64, usize>,
        element: RawElement,
    ) -> Result<()> {
        match index.get(&element.tag) {
            Some(&i) => {
                let existing = &mut self.elements[i];
                if existing.nodes != element.nodes || existing.dimension != element.dimension {
                    return Err(IoError::DuplicateTag {
                        at: element.at,
                        entity: "element",
                        tag: element.tag,
                    });
                }
                existing.physical.extend(element.physical);
            }
            None => {
                index.insert(element.tag, self.elements.len());
                self.elements.push(element);
            }
        }
        Ok(())
    }
}
