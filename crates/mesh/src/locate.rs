//! Point location: a walk across face neighbours from a hint, a spatial index
//! (parry's BVH in 2D/3D, a sorted interval list in 1D) as the initial locator
//! and fallback, and brute force for testing.

use crate::barycentric::Barycentric;
use crate::error::MeshError;
use crate::mesh::{Point, SimplexMesh};

/// Barycentric tolerance: a point with every λ ≥ −`INSIDE_TOLERANCE` is inside the simplex.
///
/// Points on a shared facet (λ = 0 up to round-off) are then found in either neighbour.
pub const INSIDE_TOLERANCE: f64 = 1e-10;

/// Walk steps before giving up on the walk and asking the spatial index.
///
/// A visibility walk on a valid mesh reaches its target in O(distance / h) steps; the
/// cap only guards against cycling on pathological (non-Delaunay, 3D) configurations.
const MAX_WALK_STEPS: usize = 256;

/// A point found inside the mesh: its host simplex and barycentric coordinates there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Located<const D: usize> {
    /// Host simplex index.
    pub simplex: u32,
    /// Barycentric coordinates of the point in the host.
    pub barycentric: Barycentric<D>,
}

/// The spatial index used for location without a hint.
#[derive(Debug, Clone)]
pub(crate) enum SpatialIndex {
    /// 1D: simplices as (min, max, index) sorted by min; intervals of a valid mesh do not overlap.
    Intervals(Vec<(f64, f64, u32)>),
    #[cfg(feature = "dim2")]
    Bvh2(parry2d_f64::partitioning::Bvh),
    #[cfg(feature = "dim3")]
    Bvh3(parry3d_f64::partitioning::Bvh),
}

impl SpatialIndex {
    pub(crate) fn build<const D: usize>(
        vertices: &[Point<D>],
        simplices: &[u32],
        max_edge: f64,
    ) -> Result<Self, MeshError> {
        // Boxes are inflated so that points on a facet, up to round-off, fall into them.
        let pad = 1e-9 * max_edge;
        let boxes = simplices.chunks_exact(D + 1).map(|simplex| {
            let mut lo = Point::<D>::repeat(f64::INFINITY);
            let mut hi = Point::<D>::repeat(f64::NEG_INFINITY);
            for &v in simplex {
                let c = &vertices[v as usize];
                lo = lo.inf(c);
                hi = hi.sup(c);
            }
            (lo.add_scalar(-pad), hi.add_scalar(pad))
        });
        match D {
            1 => {
                let mut intervals: Vec<(f64, f64, u32)> = boxes
                    .enumerate()
                    .map(|(s, (lo, hi))| (lo[0], hi[0], s as u32))
                    .collect();
                intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
                Ok(Self::Intervals(intervals))
            }
            2 => {
                #[cfg(feature = "dim2")]
                {
                    use parry2d_f64::bounding_volume::Aabb;
                    use parry2d_f64::math::Vector;
                    use parry2d_f64::partitioning::{Bvh, BvhBuildStrategy};
                    let aabbs: Vec<Aabb> = boxes
                        .map(|(lo, hi)| {
                            Aabb::new(Vector::new(lo[0], lo[1]), Vector::new(hi[0], hi[1]))
                        })
                        .collect();
                    Ok(Self::Bvh2(Bvh::from_leaves(
                        BvhBuildStrategy::Binned,
                        &aabbs,
                    )))
                }
                #[cfg(not(feature = "dim2"))]
                {
                    drop(boxes);
                    Err(MeshError::DimensionFeatureDisabled {
                        dim: 2,
                        feature: "dim2",
                    })
                }
            }
            _ => {
                #[cfg(feature = "dim3")]
                {
                    use parry3d_f64::bounding_volume::Aabb;
                    use parry3d_f64::math::Vector;
                    use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
                    let aabbs: Vec<Aabb> = boxes
                        .map(|(lo, hi)| {
                            Aabb::new(
                                Vector::new(lo[0], lo[1], lo[2]),
                                Vector::new(hi[0], hi[1], hi[2]),
                            )
                        })
                        .collect();
                    Ok(Self::Bvh3(Bvh::from_leaves(
                        BvhBuildStrategy::Binned,
                        &aabbs,
                    )))
                }
                #[cfg(not(feature = "dim3"))]
                {
                    drop(boxes);
                    Err(MeshError::DimensionFeatureDisabled {
                        dim: 3,
                        feature: "dim3",
                    })
                }
            }
        }
    }

    /// Calls `visit` with every simplex whose (padded) bounding box contains `x`.
    fn for_each_candidate<const D: usize>(&self, x: &Point<D>, mut visit: impl FnMut(u32)) {
        match self {
            Self::Intervals(intervals) => {
                // The last interval starting at or before x, and its predecessor for x on a shared vertex.
                let end = intervals.partition_point(|iv| iv.0 <= x[0]);
                for iv in intervals[end.saturating_sub(2)..end].iter() {
                    if x[0] <= iv.1 {
                        visit(iv.2);
                    }
                }
            }
            #[cfg(feature = "dim2")]
            Self::Bvh2(bvh) => {
                let p = parry2d_f64::math::Vector::new(x[0], x[1]);
                bvh.leaves(|node| node.aabb().contains_local_point(p))
                    .for_each(visit);
            }
            #[cfg(feature = "dim3")]
            Self::Bvh3(bvh) => {
                let p = parry3d_f64::math::Vector::new(x[0], x[1], x[2]);
                bvh.leaves(|node| node.aabb().contains_local_point(p))
                    .for_each(visit);
            }
        }
    }
}

impl<const D: usize> SimplexMesh<D> {
    /// Locates `x` with the spatial index; `None` when `x` is outside the mesh.
    ///
    /// Among candidate simplices the one where `x` is deepest inside (largest min λ) wins,
    /// so a point on a shared facet gets a deterministic host.
    pub fn locate(&self, x: &Point<D>) -> Option<Located<D>> {
        let mut best: Option<Located<D>> = None;
        self.index.for_each_candidate(x, |s| {
            let barycentric = self.barycentric(s as usize, x);
            let depth = barycentric.min();
            if depth >= -INSIDE_TOLERANCE && best.is_none_or(|b| depth > b.barycentric.min()) {
                best = Some(Located {
                    simplex: s,
                    barycentric,
                });
            }
        });
        best
    }

    /// Locates `x` by walking across face neighbours from `hint` (the last known host),
    /// falling back to [`Self::locate`] when the walk reaches the boundary or takes too long.
    ///
    /// For particles that moved by a fraction of an element this costs O(1) barycentric
    /// evaluations. `None` when `x` is outside the mesh. An out-of-range hint is
    /// treated as no hint.
    pub fn locate_from(&self, x: &Point<D>, hint: u32) -> Option<Located<D>> {
        match self.walk(x, hint) {
            Walk::Found(located) => Some(located),
            Walk::Stuck => self.locate(x),
        }
    }

    /// The walk alone: the host if reached, [`Walk::Stuck`] at the boundary or the step cap.
    pub fn walk(&self, x: &Point<D>, hint: u32) -> Walk<D> {
        let mut s = hint as usize;
        if s >= self.simplex_count() {
            return Walk::Stuck;
        }
        for _ in 0..MAX_WALK_STEPS {
            let barycentric = self.barycentric(s, x);
            let exit = barycentric.argmin();
            if barycentric.as_slice()[exit] >= -INSIDE_TOLERANCE {
                return Walk::Found(Located {
                    simplex: s as u32,
                    barycentric,
                });
            }
            match self.topology.neighbor(s, exit) {
                Some(next) => s = next as usize,
                None => return Walk::Stuck,
            }
        }
        Walk::Stuck
    }

    /// Locates `x` by testing every simplex: O(n), for tests and as a reference.
    pub fn locate_brute_force(&self, x: &Point<D>) -> Option<Located<D>> {
        let mut best: Option<Located<D>> = None;
        for s in 0..self.simplex_count() {
            let barycentric = self.barycentric(s, x);
            let depth = barycentric.min();
            if depth >= -INSIDE_TOLERANCE && best.is_none_or(|b| depth > b.barycentric.min()) {
                best = Some(Located {
                    simplex: s as u32,
                    barycentric,
                });
            }
        }
        best
    }
}

/// Outcome of a walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walk<const D: usize> {
    /// The walk reached the simplex containing the point.
    Found(Located<D>),
    /// The walk left through a boundary facet or hit the step cap: the point is outside the
    /// mesh or behind a concavity; ask [`SimplexMesh::locate`].
    Stuck,
}
