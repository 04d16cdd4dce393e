//! A wall given as a mesh group, for a kernel whose nodes do not conform to it: its
//! signed distance (from parry's point queries on the group's boundary facets), sampled
//! into the engine's [`umls_engine::Collider`]; and the count of particles found beyond
//! it at the end.
//!
//! The sign comes from the mesh: a point outside the mesh whose nearest boundary facet is
//! one of the wall's is beyond the wall (positive). A point outside the mesh nearer to a
//! boundary that is not the wall (an open top, a free surface) is not: the material may
//! go there.

use std::collections::HashSet;

use nalgebra::SVector;
use umls_mesh::{FacetDistance, MeshError, SimplexMesh};

use crate::sampled_wall::{NODE_REACH, count_beyond};

/// A mesh group's wall: the distance to its facets and to the whole boundary.
pub(crate) struct GroupWall<'a, const D: usize> {
    mesh: &'a SimplexMesh<D>,
    wall: FacetDistance<D>,
    boundary: FacetDistance<D>,
}

impl<'a, const D: usize> GroupWall<'a, D> {
    /// The wall of the boundary facets whose vertices are all in `vertices`.
    pub(crate) fn new(mesh: &'a SimplexMesh<D>, vertices: &[u32]) -> Result<Self, MeshError> {
        let group: HashSet<u32> = vertices.iter().copied().collect();
        let wall =
            mesh.facet_distance(|f| mesh.facet_vertices(f).iter().all(|v| group.contains(v)))?;
        let boundary = mesh.facet_distance(|_| true)?;
        Ok(Self {
            mesh,
            wall,
            boundary,
        })
    }

    /// The signed distance from `x` to the wall, positive beyond it; `scale` sets the
    /// round-off below which the wall counts as the nearest boundary.
    pub(crate) fn signed_distance(&self, x: &SVector<f64, D>, scale: f64) -> f64 {
        let (_, d) = self.wall.closest(x);
        if self.mesh.locate(x).is_some() {
            return -d;
        }
        let (_, nearest) = self.boundary.closest(x);
        if d <= nearest + 1e-9 * scale { d } else { -d }
    }

    /// The box over which a kernel of node spacing `spacing` samples the wall: the mesh's
    /// box and the nodes' reach beyond it.
    pub(crate) fn sample_box(&self, spacing: f64) -> (SVector<f64, D>, SVector<f64, D>) {
        let margin = (NODE_REACH + 1.0) * spacing;
        let (lower, upper) = self.mesh.bounding_box();
        (lower.add_scalar(-margin), upper.add_scalar(margin))
    }

    /// How many of `positions` lie beyond the wall by more than `tolerance`, and the
    /// deepest one's distance beyond it (0 when none is beyond).
    pub(crate) fn beyond(&self, positions: &[SVector<f64, D>], tolerance: f64) -> (usize, f64) {
        let outside = positions
            .iter()
            .filter(|x| self.mesh.locate(x).is_none())
            .map(|x| self.signed_distance(x, tolerance));
        count_beyond(outside, tolerance)
    }
}
