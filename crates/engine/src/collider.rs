//! Walls of any shape as signed-distance colliders: the wall a kernel whose nodes do not
//! conform to it (a B-spline grid against a curved mesh boundary) still feels.
//!
//! A collider acts twice, as a planar [`crate::Wall`] does. On the grid, every node on
//! or beyond its surface (φ ≥ 0) within a reach of it takes the wall's condition along
//! the surface normal ∇φ/|∇φ| there ([`Collider::node_conditions`]). On the particles it
//! is a non-penetration constraint: a particle that G2P carried beyond the surface is put
//! back on it, x ← x − φ n, and loses its velocity into the wall ([`Collider::hold`]).

use std::sync::Arc;

use nalgebra::SVector;

use crate::boundary::{WallKind, coulomb};
use crate::sampled_distance::SampledDistance;

/// A wall given by a sampled signed distance φ (positive beyond the wall).
#[derive(Debug, Clone, PartialEq)]
pub struct Collider<const D: usize> {
    /// Fixed (stick) or slip.
    pub kind: WallKind,
    /// Coulomb's friction coefficient μ of a slip wall (0: frictionless); a fixed wall
    /// ignores it.
    pub friction: f64,
    /// The signed distance, shared with the clones of the boundary.
    pub distance: Arc<SampledDistance<D>>,
}

/// A node's condition from a collider: the node, the unit normal into the wall, and the
/// friction coefficient (`None` for a fixed node).
pub type NodeCondition<const D: usize> = (u32, SVector<f64, D>, Option<f64>);

impl<const D: usize> Collider<D> {
    /// φ(x), the unit normal into the wall at `x` and the length of ∇φ there, where the
    /// collider is sampled and its gradient does not vanish.
    fn normal(&self, x: &SVector<f64, D>) -> Option<(f64, SVector<f64, D>, f64)> {
        let (phi, gradient) = self.distance.at(x)?;
        let length = gradient.norm();
        (length > 0.0).then(|| (phi, gradient / length, length))
    }

    /// The conditions this collider puts on the nodes at `positions`: every node with
    /// −`tolerance` ≤ φ ≤ `reach` (on or beyond the surface, within the reach of a
    /// particle's stencil), with the normal there.
    pub fn node_conditions(
        &self,
        positions: impl IntoIterator<Item = SVector<f64, D>>,
        tolerance: f64,
        reach: f64,
    ) -> Vec<NodeCondition<D>> {
        positions
            .into_iter()
            .enumerate()
            .filter_map(|(n, x)| {
                let (phi, normal, _) = self.normal(&x)?;
                (phi >= -tolerance && phi <= reach).then(|| {
                    let friction = match self.kind {
                        WallKind::Fixed => None,
                        WallKind::Slip => Some(self.friction),
                    };
                    (n as u32, normal, friction)
                })
            })
            .collect()
    }

    /// Puts a particle beyond the surface back on it, and takes its velocity into the
    /// wall (all of it at a fixed wall; at a slip wall its normal part, and as much of
    /// its tangential part as Coulomb's law lets the normal part stop). Returns whether
    /// it moved the particle.
    pub fn hold(&self, x: &mut SVector<f64, D>, v: &mut SVector<f64, D>) -> bool {
        self.hold_moved(x, v, &SVector::zeros(), &SVector::zeros())
    }

    /// [`Self::hold`] for the collider moved by `offset` and moving at `velocity`: φ is
    /// read at x − offset, and the velocity the wall takes is the particle's relative to
    /// the wall's.
    pub(crate) fn hold_moved(
        &self,
        x: &mut SVector<f64, D>,
        v: &mut SVector<f64, D>,
        offset: &SVector<f64, D>,
        velocity: &SVector<f64, D>,
    ) -> bool {
        let Some((phi, normal, length)) = self.normal(&(*x - offset)) else {
            return false;
        };
        if phi <= 0.0 {
            return false;
        }
        // φ / |∇φ| is the distance to the surface to first order, also where the sampled
        // field is not a unit-gradient distance.
        *x -= normal * (phi / length);
        *v = velocity + self.node_velocity(&(*v - velocity), &normal);
        true
    }

    /// The wall's rule on a velocity relative to the wall, with the unit normal `normal`
    /// into it: rest at a fixed wall, Coulomb's law at a slip wall.
    pub(crate) fn node_velocity(
        &self,
        relative: &SVector<f64, D>,
        normal: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        match self.kind {
            WallKind::Fixed => SVector::zeros(),
            WallKind::Slip => coulomb(relative, normal, self.friction),
        }
    }

    /// φ and the unit normal into the wall at `x` for the collider moved by `offset`.
    pub(crate) fn normal_moved(
        &self,
        x: &SVector<f64, D>,
        offset: &SVector<f64, D>,
    ) -> Option<(f64, SVector<f64, D>)> {
        self.normal(&(x - offset))
            .map(|(phi, normal, _)| (phi, normal))
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;

    fn bowl(kind: WallKind, friction: f64) -> Collider<2> {
        // Material inside the circle of radius 1: φ = |x| − 1.
        let field =
            SampledDistance::sample(Vector2::repeat(-1.5), Vector2::repeat(1.5), 0.005, |x| {
                x.norm() - 1.0
            })
            .unwrap();
        Collider {
            kind,
            friction,
            distance: Arc::new(field),
        }
    }

    /// A particle beyond a curved wall lands on it (to the sampling's accuracy), with
    /// the velocity the wall's kind leaves it.
    #[test]
    fn a_particle_beyond_a_circle_is_put_back_on_it() {
        let x0 = Vector2::new(0.8, 0.75);
        let v0 = Vector2::new(2.0, 1.0);
        let n = x0.normalize();
        let slip = v0 - n * v0.dot(&n);
        for (kind, friction) in [
            (WallKind::Slip, 0.0),
            (WallKind::Fixed, 0.0),
            (WallKind::Slip, 0.1),
        ] {
            let wall = bowl(kind, friction);
            let (mut x, mut v) = (x0, v0);
            assert!(wall.hold(&mut x, &mut v));
            // The sampled gradient is first-order accurate (4e-4 here at Δ = 0.005); the
            // distance along it second-order.
            assert!(
                (x.norm() - 1.0).abs() < 1e-4,
                "{kind:?}: |x| = {}",
                x.norm()
            );
            assert!((x.normalize() - n).norm() < 5e-4);
            match (kind, friction > 0.0) {
                (WallKind::Fixed, _) => assert_eq!(v, Vector2::zeros()),
                (WallKind::Slip, false) => assert!((v - slip).norm() < 5e-3, "{v:?}"),
                (WallKind::Slip, true) => {
                    // The tangential speed drops by μ times the normal speed stopped.
                    let slowed = slip.norm() - 0.1 * v0.dot(&n);
                    assert!((v.norm() - slowed).abs() < 5e-3, "{} vs {slowed}", v.norm());
                    assert!((v.normalize() - slip.normalize()).norm() < 5e-3);
                }
            }
        }
        // A particle inside is left alone.
        let wall = bowl(WallKind::Fixed, 0.0);
        let (mut x, mut v) = (Vector2::new(0.3, 0.2), v0);
        assert!(!wall.hold(&mut x, &mut v));
        assert_eq!((x, v), (Vector2::new(0.3, 0.2), v0));
    }

    /// The nodes on or beyond the surface within the reach take the condition, with the
    /// outward normal; nodes inside or farther beyond do not.
    #[test]
    fn nodes_beyond_the_surface_within_reach_are_held() {
        let wall = bowl(WallKind::Slip, 0.2);
        let nodes = [
            Vector2::new(0.5, 0.0),
            Vector2::new(1.05, 0.0),
            Vector2::new(0.0, -1.2),
            Vector2::new(1.4, 0.0),
        ];
        let held = wall.node_conditions(nodes, 1e-9, 0.25);
        assert_eq!(held.len(), 2);
        assert_eq!((held[0].0, held[1].0), (1, 2));
        // The sampled gradient is first-order accurate: Δ |∂²φ| / 2 = 2.4e-3 here.
        assert!((held[0].1 - Vector2::new(1.0, 0.0)).norm() < 5e-3);
        assert!((held[1].1 - Vector2::new(0.0, -1.0)).norm() < 5e-3);
        assert_eq!(held[0].2, Some(0.2));
    }
}
