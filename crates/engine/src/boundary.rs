//! Velocity boundary conditions: node sets (fixed, slip) and planar walls.
//!
//! A wall acts twice. On the grid it constrains every node on or beyond its plane (the
//! side away from the material): for B-splines those are the node layers outside the
//! wall that the stencils of particles near the wall still reach, so the wall holds
//! without ghost layers written by hand. On the particles it is a non-penetration
//! constraint: a particle that G2P carried across the plane is put back on it and loses
//! its outward normal velocity (and, at a fixed wall, its whole velocity). Kernels that
//! do not interpolate (UMLS, B-splines) have a non-zero velocity at the wall even when
//! every wall node is at rest, so the grid condition alone lets particles through.
//!
//! Walls given as node sets (a mesh's physical groups, curved or not) hold particles
//! the same way through the kernel: a particle that left the mesh through a boundary
//! facet whose nodes all carry a condition is put back on that facet.

use crate::scatter::{LIVE_SEGMENT, NODE_CHUNK, SEGMENTS_PER_CHUNK};
use nalgebra::SVector;
use rayon::prelude::*;
use umls_transfer::{DomainExit, Kernel};

use crate::collider::Collider;
use crate::face_clamp::FaceClamp;
use crate::fitted_clamp::FittedClamp;
use crate::moving_collider::MovingCollider;

/// Per-node marks of [`Boundary::node_marks`].
const SLIP: u8 = 1;
const FIXED: u8 = 2;

/// What a wall does to the velocity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WallKind {
    /// No-slip: zero velocity.
    Fixed,
    /// Frictionless slip: zero normal velocity, tangential velocity free.
    Slip,
}

/// A planar wall: the plane through `point` with unit `normal` pointing out of the
/// material (into the wall).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wall<const D: usize> {
    /// Fixed or slip.
    pub kind: WallKind,
    /// A point on the plane.
    pub point: SVector<f64, D>,
    /// Unit normal pointing away from the material.
    pub normal: SVector<f64, D>,
    /// Coulomb's friction coefficient μ of a slip wall (0: frictionless); a fixed wall
    /// ignores it.
    pub friction: f64,
}

impl<const D: usize> Wall<D> {
    /// A wall on the plane through `point` with normal ±`normal`, oriented so that it
    /// points away from the majority of `material` points (the particles it holds).
    /// `None` for a zero or non-finite normal.
    pub fn facing(
        kind: WallKind,
        point: SVector<f64, D>,
        normal: SVector<f64, D>,
        material: &[SVector<f64, D>],
    ) -> Option<Self> {
        let length = normal.norm();
        if !(length.is_finite() && length > 0.0) {
            return None;
        }
        let mut unit = normal / length;
        let beyond = material
            .iter()
            .filter(|x| (*x - point).dot(&unit) > 0.0)
            .count();
        if 2 * beyond > material.len() {
            unit = -unit;
        }
        Some(Self {
            kind,
            point,
            normal: unit,
            friction: 0.0,
        })
    }

    /// This wall with Coulomb's friction coefficient `mu` (a slip wall's).
    pub fn with_friction(self, mu: f64) -> Self {
        Self {
            friction: mu,
            ..self
        }
    }

    /// Signed distance of `x` from the plane, positive beyond the wall.
    #[inline]
    pub fn distance(&self, x: &SVector<f64, D>) -> f64 {
        (x - self.point).dot(&self.normal)
    }
}

/// Velocity boundary conditions on grid nodes and walls for the particles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Boundary<const D: usize> {
    /// Nodes whose velocity is zero. (The step sorts this list and `slip` by node,
    /// stably, which changes no node's result.)
    pub fixed: Vec<u32>,
    /// Nodes whose velocity loses its component along the given unit normal
    /// (frictionless slip; only the outward, separating component is kept if
    /// `separate` is set).
    pub slip: Vec<(u32, SVector<f64, D>)>,
    /// Whether slip nodes may move away from the wall (v·n > 0 kept).
    pub separate: bool,
    /// Nodes under Coulomb friction: the node, the unit normal into the wall and the
    /// friction coefficient μ. A node moving into the wall loses that motion and as much
    /// tangential speed as μ times it ([`coulomb`]); a node moving away is free.
    pub frictional: Vec<(u32, SVector<f64, D>, f64)>,
    /// Planar walls the particles may not cross (their nodes are in `fixed`/`slip`).
    pub walls: Vec<Wall<D>>,
    /// Walls of any shape the particles may not cross, as signed distances (their nodes
    /// are in `fixed`, `slip` or `frictional`; see [`Self::add_collider`]).
    pub colliders: Vec<Collider<D>>,
    /// Rigid obstacles in prescribed motion ([`Self::add_moving_collider`]): which nodes
    /// they hold is decided every step, at their position at [`Self::time`].
    pub moving: Vec<MovingCollider<D>>,
    /// The time the constrained velocities belong to: where moving obstacles are. The step
    /// sets it to its end time before the grid update.
    pub time: f64,
    /// Node sets whose reaction forces are summed each step (one per wall or group a
    /// user wants to read; a node in two sets counts in both). See
    /// [`crate::Simulation::reactions`].
    pub reaction_sets: Vec<Vec<u32>>,
    /// Clamps imposed on the fit: their nodes take the velocities under which their
    /// particles neither move nor deform, in the least-squares sense ([`FittedClamp`]).
    pub fitted: Vec<FittedClamp>,
    /// Clamps held on their face: the velocity vanishes where the body crosses the
    /// clamp's boundary, the clamp's other nodes are at rest ([`FaceClamp`]).
    pub faces: Vec<FaceClamp<D>>,
}

/// The force the constraints of one reaction set exert on the body in the last step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reaction<const D: usize> {
    /// Σ (m_i v_i − p_i − Δt f_i) / Δt over the set's nodes: what the constraints added
    /// to the nodal forces f_i (gravity and stress) to give the nodes' new momenta.
    pub force: SVector<f64, D>,
    /// The same sum of magnitudes: the total, which a closed wall pressed from
    /// inside has although its vector sum vanishes (pressure × area for a slip wall).
    pub magnitude: f64,
}

impl<const D: usize> Default for Reaction<D> {
    fn default() -> Self {
        Self {
            force: SVector::zeros(),
            magnitude: 0.0,
        }
    }
}

impl<const D: usize> Boundary<D> {
    /// Nodes of `kernel` within `tolerance` of the plane through `point` with normal `normal`.
    pub fn nodes_on_plane<K: Kernel<D>>(
        kernel: &K,
        point: &SVector<f64, D>,
        normal: &SVector<f64, D>,
        tolerance: f64,
    ) -> Vec<u32> {
        let unit = normal.normalize();
        (0..kernel.node_count())
            .filter(|&n| (kernel.node_position(n) - point).dot(&unit).abs() <= tolerance)
            .map(|n| n as u32)
            .collect()
    }

    /// Nodes of `kernel` on `wall`'s plane (within `tolerance`) or beyond it.
    pub fn nodes_of_wall<K: Kernel<D>>(kernel: &K, wall: &Wall<D>, tolerance: f64) -> Vec<u32> {
        (0..kernel.node_count())
            .filter(|&n| wall.distance(&kernel.node_position(n)) >= -tolerance)
            .map(|n| n as u32)
            .collect()
    }

    /// Adds `wall`: constrains its nodes (on the plane within `tolerance`, or beyond it)
    /// and keeps particles on the material side. Returns the nodes constrained.
    pub fn add_wall<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        wall: Wall<D>,
        tolerance: f64,
    ) -> Vec<u32> {
        let nodes = Self::nodes_of_wall(kernel, &wall, tolerance);
        match wall.kind {
            WallKind::Fixed => self.fixed.extend(nodes.iter().copied()),
            WallKind::Slip if wall.friction > 0.0 => self
                .frictional
                .extend(nodes.iter().map(|&n| (n, wall.normal, wall.friction))),
            WallKind::Slip => self.slip.extend(nodes.iter().map(|&n| (n, wall.normal))),
        }
        self.walls.push(wall);
        nodes
    }

    /// Adds `collider`: the nodes of `kernel` on or beyond its surface (within
    /// `tolerance`) and at most `reach` beyond it take its condition along its normal
    /// there, and the particles are kept on the material side. Returns the nodes held.
    pub fn add_collider<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        collider: Collider<D>,
        tolerance: f64,
        reach: f64,
    ) -> Vec<u32> {
        let positions = (0..kernel.node_count()).map(|n| kernel.node_position(n));
        let held = collider.node_conditions(positions, tolerance, reach);
        for &(node, normal, friction) in &held {
            match friction {
                None => self.fixed.push(node),
                Some(mu) if mu > 0.0 => self.frictional.push((node, normal, mu)),
                Some(_) => self.slip.push((node, normal)),
            }
        }
        self.colliders.push(collider);
        held.into_iter().map(|(node, _, _)| node).collect()
    }

    /// Adds an obstacle moving at `velocity` from t = 0 to `until`: the nodes of
    /// `kernel` it may reach take its condition whenever they are on or beyond its surface
    /// (within `tolerance`) and at most `reach` beyond it, relative to its velocity, and
    /// particles are kept out of it. Returns the nodes it may reach (its reaction set).
    pub fn add_moving_collider<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        collider: Collider<D>,
        velocity: SVector<f64, D>,
        tolerance: f64,
        reach: f64,
        until: f64,
    ) -> Vec<u32> {
        let moving = MovingCollider::new(kernel, collider, velocity, tolerance, reach, until);
        let nodes = moving.candidate_nodes();
        self.moving.push(moving);
        nodes
    }

    /// Adds a clamp held on its face. Returns the nodes its constraint moves, for a
    /// reaction set ([`FaceClamp::moved_nodes`]).
    pub fn add_face_clamp(&mut self, clamp: FaceClamp<D>) -> Vec<u32> {
        let nodes = clamp.moved_nodes();
        self.faces.push(clamp);
        nodes
    }

    /// Applies the node conditions to grid velocities.
    pub(crate) fn apply(&self, velocity: &mut [SVector<f64, D>]) {
        for &node in &self.fixed {
            velocity[node as usize] = SVector::zeros();
        }
        for (node, normal) in &self.slip {
            let v = &mut velocity[*node as usize];
            let vn = v.dot(normal);
            if !self.separate || vn < 0.0 {
                *v -= normal * vn;
            }
        }
        for (node, normal, mu) in &self.frictional {
            let v = &mut velocity[*node as usize];
            *v = coulomb(v, normal, *mu);
        }
        for obstacle in &self.moving {
            obstacle.apply_range(velocity, 0, self.time, |_| true, None);
        }
    }

    /// Orders the node conditions by node, which [`Self::apply_live`] needs. The sort of
    /// `slip` is stable, so a node under two walls (a corner) is still projected on
    /// their normals in the order given: every node ends where [`Self::apply`] puts it.
    /// A pass over the lists when they are sorted already.
    pub(crate) fn sort_by_node(&mut self) {
        // Checked every step (the lists are public), in parallel: serial, the check of a
        // box's wall nodes was 1 % of a one-thread B-spline step.
        if !self.fixed.par_windows(2).all(|w| w[0] <= w[1]) {
            self.fixed.sort_unstable();
        }
        if !self.slip.par_windows(2).all(|w| w[0].0 <= w[1].0) {
            self.slip.sort_by_key(|(node, _)| *node);
        }
        if !self.frictional.is_sorted_by_key(|(node, _, _)| *node) {
            self.frictional.sort_by_key(|(node, _, _)| *node);
        }
    }

    /// [`Self::apply`] in parallel over the chunks of [`NODE_CHUNK`] nodes with a
    /// segment marked `live` (per [`LIVE_SEGMENT`] nodes), on the nodes of live segments;
    /// the others hold zero velocities, which every condition keeps. Needs
    /// [`Self::sort_by_node`]. Each node sees its conditions in the same order as
    /// under [`Self::apply`] (fixed first, then its slip normals), so the result is the
    /// same, bit for bit. With the nodes' masses, returns the work moving obstacles did
    /// on the nodes (impulse times velocity, [`MovingCollider`]), summed in chunk order;
    /// else 0.
    pub(crate) fn apply_live(
        &self,
        velocity: &mut [SVector<f64, D>],
        live: &[bool],
        mass: Option<&[f64]>,
    ) -> f64 {
        let chunks = velocity
            .par_chunks_mut(NODE_CHUNK)
            .zip(live.par_chunks(SEGMENTS_PER_CHUNK))
            .enumerate();
        if self.moving.is_empty() {
            // Nothing does work: no per-chunk sums to collect.
            chunks.for_each(|(c, (chunk, live))| self.hold_chunk(c, chunk, live));
            return 0.0;
        }
        let works: Vec<f64> = chunks
            .map(|(c, (chunk, live))| {
                if !live.iter().any(|&l| l) {
                    return 0.0;
                }
                self.hold_chunk(c, chunk, live);
                let start = (c * NODE_CHUNK) as u32;
                let live_node = |node: u32| live[(node - start) as usize / LIVE_SEGMENT];
                let masses = mass.map(|m| &m[start as usize..start as usize + chunk.len()]);
                self.moving
                    .iter()
                    .map(|obstacle| {
                        obstacle.apply_range(chunk, start, self.time, live_node, masses)
                    })
                    .sum::<f64>()
            })
            .collect();
        // In chunk order: the same sum on any number of threads.
        works.iter().sum()
    }

    /// The conditions at rest (fixed, slip, frictional) on chunk `c` of [`NODE_CHUNK`]
    /// nodes, on the nodes of its `live` segments.
    fn hold_chunk(&self, c: usize, chunk: &mut [SVector<f64, D>], live: &[bool]) {
        if !live.iter().any(|&l| l) {
            return;
        }
        let start = (c * NODE_CHUNK) as u32;
        let end = start + chunk.len() as u32;
        let fixed = &self.fixed
            [self.fixed.partition_point(|&n| n < start)..self.fixed.partition_point(|&n| n < end)];
        // Nodes of segments not live are zero and stay so: skipping them spares the cache
        // misses of a wall's nodes far from the body.
        let live_node = |node: u32| live[(node - start) as usize / LIVE_SEGMENT];
        for &node in fixed.iter().filter(|&&n| live_node(n)) {
            chunk[(node - start) as usize] = SVector::zeros();
        }
        let slip = &self.slip[self.slip.partition_point(|(n, _)| *n < start)
            ..self.slip.partition_point(|(n, _)| *n < end)];
        for (node, normal) in slip.iter().filter(|(n, _)| live_node(*n)) {
            let v = &mut chunk[(node - start) as usize];
            let vn = v.dot(normal);
            if !self.separate || vn < 0.0 {
                *v -= normal * vn;
            }
        }
        let frictional = &self.frictional[self.frictional.partition_point(|(n, _, _)| *n < start)
            ..self.frictional.partition_point(|(n, _, _)| *n < end)];
        for (node, normal, mu) in frictional.iter().filter(|(n, _, _)| live_node(*n)) {
            let v = &mut chunk[(node - start) as usize];
            *v = coulomb(v, normal, *mu);
        }
    }

    /// Whether any node condition is set (walls given as node sets, such as mesh groups).
    pub(crate) fn has_node_conditions(&self) -> bool {
        !self.fixed.is_empty()
            || !self.slip.is_empty()
            || !self.frictional.is_empty()
            || !self.fitted.is_empty()
            || !self.faces.is_empty()
    }

    /// Marks per node: fixed, slip, or free.
    pub(crate) fn node_marks(&self, nodes: usize) -> Vec<u8> {
        let mut marks = vec![0u8; nodes];
        for node in self
            .slip
            .iter()
            .map(|(n, _)| n)
            .chain(self.frictional.iter().map(|(n, _, _)| n))
        {
            marks[*node as usize] |= SLIP;
        }
        for &node in self
            .fixed
            .iter()
            .chain(self.fitted.iter().flat_map(|c| c.nodes()))
            .chain(self.faces.iter().flat_map(|c| c.nodes()))
        {
            marks[node as usize] |= FIXED;
        }
        marks
    }

    /// A particle that left the kernel's domain through a facet whose nodes all carry a
    /// condition has hit a wall given as a node set (a mesh group): it is put back on the
    /// facet and loses its velocity into it (all of it when every node is fixed).
    /// Returns whether it was moved; a particle leaving through a free facet is left to
    /// the kernel's error.
    pub(crate) fn hold_at_facet(
        marks: &[u8],
        exit: &DomainExit<D>,
        x: &mut SVector<f64, D>,
        v: &mut SVector<f64, D>,
    ) -> bool {
        let facet = exit.facet();
        if facet.iter().any(|&n| marks[n as usize] == 0) {
            return false;
        }
        *x = exit.inside;
        if facet.iter().all(|&n| marks[n as usize] & FIXED != 0) {
            *v = SVector::zeros();
        } else {
            let vn = v.dot(&exit.normal);
            if vn > 0.0 {
                *v -= exit.normal * vn;
            }
        }
        true
    }

    /// Keeps a particle on the material side of every wall: a particle beyond a wall is
    /// put back on its plane and loses its velocity into the wall (all of it at a fixed
    /// wall). Returns whether the particle was moved.
    pub(crate) fn hold(&self, x: &mut SVector<f64, D>, v: &mut SVector<f64, D>) -> bool {
        let mut moved = false;
        for wall in &self.walls {
            let depth = wall.distance(x);
            if depth > 0.0 {
                *x -= wall.normal * depth;
                moved = true;
                match wall.kind {
                    WallKind::Fixed => *v = SVector::zeros(),
                    WallKind::Slip => *v = coulomb(v, &wall.normal, wall.friction),
                }
            }
        }
        for collider in &self.colliders {
            moved |= collider.hold(x, v);
        }
        for obstacle in &self.moving {
            moved |= obstacle.hold(x, v, self.time);
        }
        moved
    }
}

/// Coulomb friction on a velocity `v` against a wall with unit normal `normal` (pointing
/// into the wall) and coefficient `mu`: a velocity moving into the wall (v·n > 0) loses
/// that normal part, and its tangential part shrinks by μ times it, to rest at most
/// (stick); a velocity moving away is left as it is. μ = 0 is frictionless slip that
/// lets the body separate.
pub(crate) fn coulomb<const D: usize>(
    v: &SVector<f64, D>,
    normal: &SVector<f64, D>,
    mu: f64,
) -> SVector<f64, D> {
    let vn = v.dot(normal);
    if vn <= 0.0 {
        return *v;
    }
    let tangential = v - normal * vn;
    if mu == 0.0 {
        return tangential;
    }
    let speed = tangential.norm();
    if speed <= mu * vn {
        SVector::zeros()
    } else {
        tangential * (1.0 - mu * vn / speed)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;

    /// Coulomb's law on a node moving into a wall at 45°: μ = 0.5 takes half the
    /// tangential speed, μ = 1 stops it, and a node moving away is left alone.
    #[test]
    fn coulomb_friction_takes_mu_times_the_normal_speed() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let v = Vector3::new(2.0, 0.0, 2.0);
        assert_eq!(coulomb(&v, &n, 0.0), Vector3::new(2.0, 0.0, 0.0));
        assert_eq!(coulomb(&v, &n, 0.5), Vector3::new(1.0, 0.0, 0.0));
        assert_eq!(coulomb(&v, &n, 1.0), Vector3::zeros());
        assert_eq!(coulomb(&v, &n, 3.0), Vector3::zeros());
        let away = Vector3::new(2.0, 0.0, -1.0);
        assert_eq!(coulomb(&away, &n, 0.5), away);
    }

    /// Sorted and applied per live chunk in parallel, the node conditions give what the
    /// serial pass over the lists as given gives, bit for bit: nodes under several
    /// walls (fixed and slip, two slip normals, repeated entries) included, with and
    /// without separation; chunks not live hold zeros and stay zero.
    #[test]
    fn live_chunks_in_parallel_equal_the_serial_pass() {
        let nodes = 5 * NODE_CHUNK + 123;
        let mut seed = 7u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let segment = crate::scatter::LIVE_SEGMENT;
        // Chunk 2 wholly dead; in chunk 4 only its second segment is live.
        let live: Vec<bool> = (0..crate::scatter::live_segments(nodes))
            .map(|s| match s / SEGMENTS_PER_CHUNK {
                2 => false,
                4 => s % SEGMENTS_PER_CHUNK == 1,
                _ => true,
            })
            .collect();
        let velocity: Vec<Vector3<f64>> = (0..nodes)
            .map(|i| {
                if live[i / segment] {
                    Vector3::new(
                        (next() % 2001) as f64 / 1000.0 - 1.0,
                        (next() % 2001) as f64 / 1000.0 - 1.0,
                        (next() % 2001) as f64 / 1000.0 - 1.0,
                    )
                } else {
                    Vector3::zeros()
                }
            })
            .collect();
        let normals = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, -1.0, 0.0),
            Vector3::new(0.6, 0.0, 0.8),
        ];
        for separate in [false, true] {
            let mut boundary = Boundary::<3> {
                separate,
                ..Boundary::default()
            };
            for _ in 0..3000 {
                let node = (next() % nodes as u64) as u32;
                let normal = normals[(next() % 3) as usize];
                match next() % 5 {
                    0 => boundary.fixed.push(node),
                    1 => boundary.frictional.push((node, normal, 0.4)),
                    _ => boundary.slip.push((node, normal)),
                }
            }
            // Corners: the same nodes under two and three walls, in both orders.
            for node in [5u32, 4100, 9000] {
                boundary.slip.push((node, normals[0]));
                boundary.slip.push((node, normals[2]));
                boundary.slip.push((node, normals[1]));
            }
            let mut serial = velocity.clone();
            boundary.apply(&mut serial);
            boundary.sort_by_node();
            assert!(boundary.fixed.is_sorted());
            assert!(boundary.frictional.is_sorted_by_key(|(n, _, _)| *n));
            let mut parallel = velocity.clone();
            boundary.apply_live(&mut parallel, &live, None);
            for (i, (a, b)) in serial.iter().zip(&parallel).enumerate() {
                assert_eq!(
                    a.map(f64::to_bits),
                    b.map(f64::to_bits),
                    "node {i}, separate {separate}"
                );
            }
        }
    }
}
