//! What every wall given by a signed distance shares, whether it comes from a mesh
//! group ([`crate::group_wall::GroupWall`]) or from a region's surface (an obstacle or a
//! container): how densely the distance is sampled into the engine's [`Collider`], how
//! far beyond the surface grid nodes take its condition, and how the particles found
//! beyond it at the end are counted.

use std::sync::Arc;

use nalgebra::SVector;
use umls_engine::{Collider, SampledDistance, SampledDistanceError, WallKind};

/// Samples of the signed distance per kernel spacing: the normal the grid nodes and the
/// particles take is then first-order accurate in half a spacing, the distance second.
const SAMPLES_PER_SPACING: f64 = 2.0;

/// How far beyond the wall, in kernel spacings, grid nodes take the wall's condition: the
/// reach of a cubic B-spline stencil (two spacings) and a spacing of margin.
pub(crate) const NODE_REACH: f64 = 3.0;

/// The collider of the signed distance `distance` (positive beyond the wall), sampled at
/// half the kernel's node `spacing` over the box `lower..upper`.
pub(crate) fn sampled_collider<const D: usize>(
    kind: WallKind,
    friction: f64,
    (lower, upper): (SVector<f64, D>, SVector<f64, D>),
    spacing: f64,
    distance: impl Fn(&SVector<f64, D>) -> f64 + Sync,
) -> Result<Collider<D>, SampledDistanceError> {
    let field = SampledDistance::sample(lower, upper, spacing / SAMPLES_PER_SPACING, distance)?;
    Ok(Collider {
        kind,
        friction,
        distance: Arc::new(field),
    })
}

/// How many of the signed distances `distances` exceed `tolerance` (points beyond the
/// wall), and the largest of them (0 when none does).
pub(crate) fn count_beyond(distances: impl Iterator<Item = f64>, tolerance: f64) -> (usize, f64) {
    distances
        .filter(|&d| d > tolerance)
        .fold((0, 0.0), |(n, deepest), d| (n + 1, f64::max(deepest, d)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Only distances beyond the tolerance count, and the deepest is their maximum.
    #[test]
    fn counts_the_points_beyond_the_tolerance() {
        let distances = [-1.0, 0.0, 0.005, 0.02, 0.3, 0.1];
        assert_eq!(count_beyond(distances.into_iter(), 0.01), (3, 0.3));
        assert_eq!(count_beyond([-0.5, 0.01].into_iter(), 0.01), (0, 0.0));
    }
}
