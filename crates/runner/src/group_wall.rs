//! A wall given as a mesh group, for a kernel whose nodes do not conform to it: its
//! signed distance (from parry's point queries on the group's boundary facets), sampled
//! into the engine's [`Collider`]; and the count of particles found beyond it at the end.
//!
//! The sign comes from the mesh: a point outside the mesh whose nearest boundary facet is
//! one of the wall's is beyond the wall (positive). A point outside the mesh nearer to a
//! boundary that is not the wall (an open top, a free surface) is not: the material may
//! go there.

use std::collections::HashSet;
use std::sync::Arc;

use nalgebra::SVector;
use umls_engine::{Collider, SampledDistance, WallKind};
use umls_mesh::{FacetDistance, MeshError, SimplexMesh};

/// Samples of the signed distance per kernel spacing: the normal the grid nodes and the
/// particles take is then first-order accurate in half a spacing, the distance second.
const SAMPLES_PER_SPACING: f64 = 2.0;

/// How far beyond the wall, in kernel spacings, grid nodes take the wall's condition: the
/// reach of a cubic B-spline stencil (two spacings) and a spacing of margin.
pub(crate) const NODE_REACH: f64 = 3.0;

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

    /// The collider a kernel of node spacing `spacing` feels: the signed distance sampled
    /// at half the spacing over the mesh's box and the nodes' reach beyond it.
    pub(crate) fn collider(
        &self,
        kind: WallKind,
        friction: f64,
        spacing: f64,
    ) -> Result<Collider<D>, umls_engine::SampledDistanceError> {
        let sample = spacing / SAMPLES_PER_SPACING;
        let margin = (NODE_REACH + 1.0) * spacing;
        let (lower, upper) = self.mesh.bounding_box();
        let field = SampledDistance::sample(
            lower.add_scalar(-margin),
            upper.add_scalar(margin),
            sample,
            |x| self.signed_distance(x, spacing),
        )?;
        Ok(Collider {
            kind,
            friction,
            distance: Arc::new(field),
        })
    }

    /// How many of `positions` lie beyond the wall by more than `tolerance`, and the
    /// deepest one's distance beyond it (0 when none is beyond).
    pub(crate) fn beyond(&self, positions: &[SVector<f64, D>], tolerance: f64) -> (usize, f64) {
        positions
            .iter()
            .filter(|x| self.mesh.locate(x).is_none())
            .map(|x| self.signed_distance(x, tolerance))
            .filter(|&d| d > tolerance)
            .fold((0, 0.0), |(n, deepest), d| (n + 1, f64::max(deepest, d)))
    }
}
