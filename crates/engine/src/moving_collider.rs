//! Rigid obstacles in prescribed motion: a [`Collider`] translated at a constant velocity
//! (a footing pressed into the ground, a penetrator).
//!
//! Which nodes lie on or beyond the moving surface changes from step to step, so the
//! condition is not a fixed node list: every step the grid update reads φ at each of the
//! nodes the obstacle can reach over the run (found once, from φ's Lipschitz bound) at the
//! obstacle's position at the step's end, and gives those on or beyond it the wall's rule
//! on their velocity relative to the obstacle's. Particles carried beyond the surface are
//! put back on it with the same relative rule.

use nalgebra::SVector;
use umls_transfer::Kernel;

use crate::collider::Collider;

/// A collider moving at a constant velocity, with the nodes it may reach.
#[derive(Debug, Clone, PartialEq)]
pub struct MovingCollider<const D: usize> {
    /// The obstacle at t = 0.
    pub collider: Collider<D>,
    /// Its velocity: at time t its surface is the one at t = 0 moved by `velocity` · t.
    pub velocity: SVector<f64, D>,
    /// How far beyond the surface nodes take the condition.
    pub reach: f64,
    /// How far before the surface nodes take it (round-off on nodes on the surface).
    pub tolerance: f64,
    /// The nodes the surface may reach (ascending), with their positions.
    nodes: Vec<(u32, SVector<f64, D>)>,
}

impl<const D: usize> MovingCollider<D> {
    /// `collider` moving at `velocity` from t = 0 to `until`, over the nodes of `kernel`:
    /// the candidates are the nodes whose φ at t = 0 is within `velocity`·`until` of the
    /// band −`tolerance` ≤ φ ≤ `reach` (a signed distance changes by at most the
    /// distance moved).
    pub fn new<K: Kernel<D>>(
        kernel: &K,
        collider: Collider<D>,
        velocity: SVector<f64, D>,
        tolerance: f64,
        reach: f64,
        until: f64,
    ) -> Self {
        let travel = velocity.norm() * until.max(0.0);
        let nodes = (0..kernel.node_count())
            .filter_map(|n| {
                let x = kernel.node_position(n);
                let (phi, _) = collider.distance.at(&x).unwrap_or((f64::NEG_INFINITY, x));
                // Outside the sampled box a node may still come within reach as the
                // obstacle moves: keep it when the box could move over it.
                let candidate = if phi.is_finite() {
                    phi - travel <= reach && phi + travel >= -tolerance
                } else {
                    travel > 0.0
                };
                candidate.then_some((n as u32, x))
            })
            .collect();
        Self {
            collider,
            velocity,
            reach,
            tolerance,
            nodes,
        }
    }

    /// The nodes the obstacle may reach: its reaction set.
    pub fn candidate_nodes(&self) -> Vec<u32> {
        self.nodes.iter().map(|(n, _)| *n).collect()
    }

    /// Applies the wall's rule at time `time` to the candidates among nodes
    /// `start`..`start + velocity.len()` whose `live` test holds: a node on or beyond the
    /// surface within the reach takes the obstacle's velocity plus the rule on its
    /// velocity relative to it. With the nodes' masses (aligned with `velocity`), returns
    /// the work the obstacle did: its impulse on the nodes, Σ m (v′ − v), times its
    /// velocity (a wall at rest does no work); else 0.
    pub(crate) fn apply_range(
        &self,
        velocity: &mut [SVector<f64, D>],
        start: u32,
        time: f64,
        live: impl Fn(u32) -> bool,
        mass: Option<&[f64]>,
    ) -> f64 {
        let end = start + velocity.len() as u32;
        let offset = self.velocity * time;
        let first = self.nodes.partition_point(|(n, _)| *n < start);
        let last = self.nodes.partition_point(|(n, _)| *n < end);
        let mut work = 0.0;
        for (node, x) in self.nodes[first..last].iter().filter(|(n, _)| live(*n)) {
            let Some((phi, normal)) = self.collider.normal_moved(x, &offset) else {
                continue;
            };
            if phi < -self.tolerance || phi > self.reach {
                continue;
            }
            let k = (node - start) as usize;
            let v = &mut velocity[k];
            let before = *v;
            *v = self.velocity + self.collider.node_velocity(&(*v - self.velocity), &normal);
            if let Some(mass) = mass {
                work += mass[k] * (*v - before).dot(&self.velocity);
            }
        }
        work
    }

    /// Puts a particle beyond the surface at time `time` back on it (the rule on its
    /// velocity relative to the obstacle's). Returns whether it moved the particle.
    pub(crate) fn hold(&self, x: &mut SVector<f64, D>, v: &mut SVector<f64, D>, time: f64) -> bool {
        self.collider
            .hold_moved(x, v, &(self.velocity * time), &self.velocity)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::Vector2;

    use super::*;
    use crate::boundary::WallKind;
    use crate::sampled_distance::SampledDistance;

    /// A kernel of nodes on a row, enough of `Kernel` for the candidates.
    struct Row(Vec<Vector2<f64>>);

    impl Kernel<2> for Row {
        type Cache = ();
        const MAY_BE_TENSOR_PRODUCT: bool = false;
        fn node_count(&self) -> usize {
            self.0.len()
        }
        fn node_position(&self, node: usize) -> Vector2<f64> {
            self.0[node]
        }
        fn spacing(&self) -> f64 {
            0.1
        }
        fn stencil(
            &self,
            _: &Vector2<f64>,
            _: &mut (),
            _: &mut umls_transfer::Stencil<2>,
        ) -> Result<(), umls_transfer::KernelError> {
            unreachable!("the candidates read node positions only")
        }
    }

    /// A piston, the half-plane x ≤ 0 at t = 0 moving right at 2: at t = 0.25 its face is
    /// at x = 0.5, the nodes behind it within the reach take its velocity (fixed) or keep
    /// their tangential velocity (slip), the others are untouched; a particle behind the
    /// face is put on it with the piston's normal velocity.
    #[test]
    fn a_moving_piston_holds_the_nodes_behind_its_face() {
        let field = SampledDistance::sample(
            Vector2::new(-2.0, -1.0),
            Vector2::new(2.0, 1.0),
            0.05,
            |x| -x[0],
        )
        .unwrap();
        let nodes = Row((0..11).map(|i| Vector2::new(0.1 * i as f64, 0.0)).collect());
        let speed = Vector2::new(2.0, 0.0);
        for kind in [WallKind::Fixed, WallKind::Slip] {
            let collider = Collider {
                kind,
                friction: 0.0,
                distance: Arc::new(field.clone()),
            };
            let piston = MovingCollider::new(&nodes, collider, speed, 1e-9, 0.25, 0.5);
            // Within reach over the run: φ(x, t) = 2t − x for t ≤ 0.5 reaches −x + 1.
            assert_eq!(piston.candidate_nodes(), (0..11).collect::<Vec<u32>>());
            let mut v = vec![Vector2::new(-1.0, 3.0); 11];
            let work = piston.apply_range(&mut v, 0, 0.25, |_| true, Some(&[2.0; 11]));
            // Nodes 3–5, each of mass 2, from (−1, 3) to (2, 0) (fixed) or (2, 3) (slip):
            // the impulse 2 · (3, ·) per node times V = (2, 0).
            let expected_work = 3.0 * 2.0 * 3.0 * 2.0;
            assert!((work - expected_work).abs() < 1e-12, "{kind:?}: {work}");
            for (i, v) in v.iter().enumerate() {
                let x = 0.1 * i as f64;
                // φ = 0.5 − x; held for 0.5 − 0.25 ≤ x ≤ 0.5 (nodes 3, 4, 5).
                let held = (3..=5).contains(&i);
                let expected = match (held, kind) {
                    (false, _) => Vector2::new(-1.0, 3.0),
                    (true, WallKind::Fixed) => speed,
                    (true, WallKind::Slip) => Vector2::new(2.0, 3.0),
                };
                assert!(
                    (v - expected).norm() < 1e-12,
                    "{kind:?}, node at {x}: {v:?}"
                );
            }
            let (mut x, mut v) = (Vector2::new(0.3, 0.2), Vector2::new(0.0, 1.0));
            assert!(piston.hold(&mut x, &mut v, 0.25));
            assert!((x - Vector2::new(0.5, 0.2)).norm() < 1e-12, "{x:?}");
            let expected = match kind {
                WallKind::Fixed => speed,
                WallKind::Slip => Vector2::new(2.0, 1.0),
            };
            assert!((v - expected).norm() < 1e-12, "{kind:?}: {v:?}");
        }
    }
}
