//! A clamp imposed on its face: the velocity vanishes where the body enters the clamp.
//!
//! A fixed region given as nodes puts the clamp's edge at its last row of nodes, a
//! staircase whose distance inside the region changes with how the mesh or grid lies
//! under the body: moving a lattice by half a cell along a cantilever lengthens the
//! free beam by half a cell, and its tip swings 12 % deeper (docs/umls-kernel.md,
//! *The clamp held on its face*). A [`FaceClamp`] holds the body on the
//! clamp's face instead: at points where the body crosses the region's boundary
//! ([`face_points`]) the velocity is made to vanish by the least mass-weighted change of
//! the grid velocities:
//!
//! min over v_u (u in the face points' stencils) of
//! Σ_u (m_u + ε m̄) |v_u − v*_u|² + W m̄ Σ_q |Σ_u N_u(x_q) v_u|²,
//!
//! where v* is the velocity the grid update gave, m_u the nodal mass, m̄ the largest of
//! them, ε = [`FACE_CLAMP_REGULARISATION`] (it keeps nodes without mass regular) and W
//! the penalty ([`FaceClamp::penalty`]). The region's other nodes are at rest. The
//! region's nodes next to the face are free to move: they continue the field past the
//! face, as ghost nodes do, so that it vanishes on the face whatever the layout; the
//! particles inside the region next to the face move with them, a little.
//!
//! The map from v* to v is linear, the same for v, ṽ and the MUSL re-map within a step,
//! and it never raises the (m + ε m̄)-weighted kinetic energy (it moves v* towards the
//! constraint). The penalty is finite on purpose: a kernel that does not interpolate
//! (UMLS, B-splines) cannot make the velocity vanish on a line through its nodes without
//! holding the rows of nodes on both sides, so as W grows the beam stiffens (the
//! cantilever four cells thick: its aligned peak 2.4 % shallower at W = 10⁶ than at
//! 10⁴ and 7.5 % at 10⁸, where the turned runs part by up to 15 %; the default 10⁴ is
//! the smallest W measured that keeps them within 5 % there, and three times finer every
//! W from 10² to 10⁸ keeps them within 3 %: docs/umls-kernel.md, *Clamps*).

use nalgebra::{Cholesky, DMatrix, DVector, Dyn, SVector};
use umls_transfer::{Kernel, Stencil};

use crate::error::EngineError;

/// Relative weight ε of the nodes' mass floor: a node without mass costs ε m̄ to change.
pub const FACE_CLAMP_REGULARISATION: f64 = 1e-3;

/// Default penalty W of a face point's residual, relative to the heaviest node's mass.
pub const FACE_CLAMP_PENALTY: f64 = 1e4;

/// A clamp held on its face: the velocity vanishes at `points` (where the body crosses
/// the clamp's boundary), the clamp's other `nodes` are at rest.
///
/// The points do not move, so their stencils are evaluated once, when the clamp is
/// built ([`FaceClamp::new`]); each step builds only the mass-weighted system.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceClamp<const D: usize> {
    nodes: Vec<u32>,
    points: Vec<SVector<f64, D>>,
    /// Every node the points' stencils reach, sorted: the system's unknowns.
    unknowns: Vec<u32>,
    /// Each point's stencil as (position in `unknowns`, value) pairs.
    rows: Vec<Vec<(usize, f64)>>,
    /// The weight W of the face points' residuals against the heaviest node's mass
    /// (default [`FACE_CLAMP_PENALTY`]).
    pub penalty: f64,
}

/// One face point's stencil: (node, value) pairs.
type FaceRow = Vec<(u32, f64)>;

impl<const D: usize> FaceClamp<D> {
    /// A clamp whose region holds `nodes` and whose face is sampled at `points`, with
    /// the points' stencils evaluated by `kernel` (each from the kernel's default cache).
    /// Repeated nodes are merged. Fails with the index of the first point the kernel
    /// cannot evaluate (outside the domain, or an ill-conditioned fit). The clamp keeps
    /// `kernel`'s node numbers: a simulation with another kernel refuses it at its step.
    pub fn new<K: Kernel<D>>(
        kernel: &K,
        nodes: Vec<u32>,
        points: Vec<SVector<f64, D>>,
    ) -> Result<Self, EngineError> {
        let mut stencil = Stencil::new();
        let mut rows = Vec::with_capacity(points.len());
        for (point, x) in points.iter().enumerate() {
            kernel
                .stencil(x, &mut K::Cache::default(), &mut stencil)
                .map_err(|source| EngineError::FacePoint { point, source })?;
            rows.push(stencil.iter().map(|(n, v, _)| (n, v)).collect());
        }
        Ok(Self::from_rows(nodes, points, rows))
    }

    /// A clamp from the points' stencils `rows` (one per point).
    fn from_rows(mut nodes: Vec<u32>, points: Vec<SVector<f64, D>>, rows: Vec<FaceRow>) -> Self {
        nodes.sort_unstable();
        nodes.dedup();
        let mut unknowns: Vec<u32> = rows.iter().flatten().map(|e| e.0).collect();
        unknowns.sort_unstable();
        unknowns.dedup();
        let rows = rows
            .iter()
            .map(|row| {
                row.iter()
                    .map(|&(n, c)| (unknowns.partition_point(|&u| u < n), c))
                    .collect()
            })
            .collect();
        Self {
            nodes,
            points,
            unknowns,
            rows,
            penalty: FACE_CLAMP_PENALTY,
        }
    }

    /// The region's nodes (sorted).
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// The face points where the velocity is held at zero.
    pub fn points(&self) -> &[SVector<f64, D>] {
        &self.points
    }

    /// The nodes the constraint moves, sorted: the region's nodes and those of the face
    /// points' stencils (a reaction set for the clamp).
    pub fn moved_nodes(&self) -> Vec<u32> {
        let mut nodes: Vec<u32> = self.nodes.iter().chain(&self.unknowns).copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }

    /// The largest node number the clamp holds or moves (`None` without any).
    pub(crate) fn largest_node(&self) -> Option<u32> {
        self.nodes.last().max(self.unknowns.last()).copied()
    }

    /// This step's system from the nodal `mass`: the factorised normal matrix over the
    /// unknowns.
    pub(crate) fn system(&self, mass: &[f64]) -> FaceSystem {
        let heaviest = self
            .unknowns
            .iter()
            .map(|&n| mass[n as usize])
            .fold(0.0, f64::max);
        // Without mass anywhere near the face there is nothing to hold this step.
        if self.unknowns.is_empty() || heaviest <= 0.0 {
            return FaceSystem {
                weights: Vec::new(),
                cholesky: None,
            };
        }
        let weights: Vec<f64> = self
            .unknowns
            .iter()
            .map(|&n| mass[n as usize] + FACE_CLAMP_REGULARISATION * heaviest)
            .collect();
        let mut normal = DMatrix::<f64>::from_diagonal(&DVector::from_column_slice(&weights));
        let penalty = self.penalty * heaviest;
        for row in &self.rows {
            for &(a, ca) in row {
                for &(b, cb) in row {
                    normal[(a, b)] += penalty * ca * cb;
                }
            }
        }
        FaceSystem {
            cholesky: normal.cholesky(),
            weights,
        }
    }

    /// Applies the step's `system` to `velocity`: the region's nodes at rest, then the
    /// face points' stencil nodes moved least (mass-weighted) towards zero velocity on
    /// the face.
    pub(crate) fn hold(&self, system: &FaceSystem, velocity: &mut [SVector<f64, D>]) {
        // The targets: what the update gave, read before the region is set to rest.
        let targets: Vec<SVector<f64, D>> = self
            .unknowns
            .iter()
            .map(|&n| velocity[n as usize])
            .collect();
        for &n in &self.nodes {
            velocity[n as usize] = SVector::zeros();
        }
        let Some(cholesky) = &system.cholesky else {
            return;
        };
        for d in 0..D {
            let rhs = DVector::from_iterator(
                targets.len(),
                targets.iter().zip(&system.weights).map(|(t, w)| w * t[d]),
            );
            let x = cholesky.solve(&rhs);
            for (j, &n) in self.unknowns.iter().enumerate() {
                velocity[n as usize][d] = x[j];
            }
        }
    }
}

/// One step's system of a [`FaceClamp`], shared by v, ṽ and the MUSL re-map.
pub(crate) struct FaceSystem {
    /// The unknowns' weights m_u + ε m̄.
    weights: Vec<f64>,
    /// The factorised normal matrix (`None` without unknowns or mass near the face, when
    /// the region's nodes are simply at rest).
    cholesky: Option<Cholesky<f64, Dyn>>,
}

/// Points sampling the face where a body crosses a region's boundary: for every pair of
/// particles at most `reach` apart with one inside the region and one outside, the point
/// between them on the boundary (bisection on `inside`, to 10⁻⁹ of their distance);
/// points closer than `reach / 2` to one kept before are dropped. Give `reach` about
/// 1.5 particle spacings, so that a lattice's diagonal neighbours count and a jittered
/// one's gaps are bridged. Deterministic: the result depends on the particles' order
/// only through which of two near points is kept.
pub fn face_points<const D: usize>(
    positions: &[SVector<f64, D>],
    inside: impl Fn(&SVector<f64, D>) -> bool,
    reach: f64,
) -> Vec<SVector<f64, D>> {
    if positions.is_empty() || reach.is_nan() || reach <= 0.0 {
        return Vec::new();
    }
    let is_in: Vec<bool> = positions.iter().map(&inside).collect();
    let outside = CellIndex::new(
        positions
            .iter()
            .zip(&is_in)
            .filter(|(_, i)| !**i)
            .map(|(x, _)| *x),
        reach,
    );
    let mut points: Vec<SVector<f64, D>> = Vec::new();
    let mut kept = CellIndex::new(std::iter::empty(), reach / 2.0);
    for (p, _) in positions.iter().zip(&is_in).filter(|(_, i)| **i) {
        outside.for_each_near(p, reach, |q| {
            let point = crossing(p, q, &inside);
            let mut near = false;
            kept.for_each_near(&point, reach / 2.0, |_| near = true);
            if !near {
                kept.insert(point);
                points.push(point);
            }
        });
    }
    points
}

/// The point between `a` (inside) and `b` (outside) where the segment leaves the region.
fn crossing<const D: usize>(
    a: &SVector<f64, D>,
    b: &SVector<f64, D>,
    inside: &impl Fn(&SVector<f64, D>) -> bool,
) -> SVector<f64, D> {
    let (mut lo, mut hi) = (0.0, 1.0);
    // 30 halvings: 10⁻⁹ of the segment.
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if inside(&(a + (b - a) * mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    a + (b - a) * (0.5 * (lo + hi))
}

/// Points binned in cubic cells, for the neighbour queries of [`face_points`].
struct CellIndex<const D: usize> {
    cell: f64,
    bins: std::collections::HashMap<[i64; D], Vec<SVector<f64, D>>>,
}

impl<const D: usize> CellIndex<D> {
    fn new(points: impl Iterator<Item = SVector<f64, D>>, cell: f64) -> Self {
        let mut index = Self {
            cell,
            bins: std::collections::HashMap::new(),
        };
        for x in points {
            index.insert(x);
        }
        index
    }

    fn key(&self, x: &SVector<f64, D>) -> [i64; D] {
        std::array::from_fn(|k| (x[k] / self.cell).floor() as i64)
    }

    fn insert(&mut self, x: SVector<f64, D>) {
        self.bins.entry(self.key(&x)).or_default().push(x);
    }

    /// Calls `f` for every stored point within `radius` (≤ the cell size) of `x`, in a
    /// fixed order (cells in lexicographic order, points in insertion order).
    fn for_each_near(&self, x: &SVector<f64, D>, radius: f64, mut f: impl FnMut(&SVector<f64, D>)) {
        let centre = self.key(x);
        let neighbours = 3usize.pow(D as u32);
        for code in 0..neighbours {
            let mut rest = code;
            let key: [i64; D] = std::array::from_fn(|k| {
                let offset = (rest % 3) as i64 - 1;
                rest /= 3;
                centre[k] + offset
            });
            if let Some(bin) = self.bins.get(&key) {
                for q in bin {
                    if (q - x).norm() <= radius {
                        f(q);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clamp with region nodes 0–2 and two face points whose stencils reach nodes 1–4,
    /// on nodes of unequal mass (node 5 untouched).
    fn clamp_and_rows() -> (FaceClamp<2>, Vec<FaceRow>, Vec<f64>) {
        let rows = vec![
            vec![(1, 0.3), (2, 0.5), (3, 0.2)],
            vec![(2, 0.1), (3, 0.6), (4, 0.3)],
        ];
        let clamp = FaceClamp::from_rows(vec![2, 0, 1], vec![SVector::zeros(); 2], rows.clone());
        let mass = vec![1.0, 0.5, 2.0, 3.0, 0.0, 1.0];
        (clamp, rows, mass)
    }

    /// The constrained velocities: region nodes outside the stencils at rest, nodes
    /// outside both untouched, the face points' velocities cut below 10⁻³ of what they
    /// were, and the (m + ε m̄)-weighted kinetic energy of the moved nodes not raised.
    #[test]
    fn holding_the_face_moves_the_nodes_least_and_adds_no_energy() {
        let (clamp, rows, mass) = clamp_and_rows();
        let system = clamp.system(&mass);
        let before: Vec<SVector<f64, 2>> = (0..6)
            .map(|n| SVector::from([1.0 + n as f64, 0.5 - 0.3 * n as f64]))
            .collect();
        let mut after = before.clone();
        clamp.hold(&system, &mut after);
        assert_eq!(after[0], SVector::<f64, 2>::zeros());
        assert_eq!(after[5], before[5]);
        let at = |v: &[SVector<f64, 2>], row: &FaceRow| -> SVector<f64, 2> {
            row.iter().map(|&(n, c)| v[n as usize] * c).sum()
        };
        for row in &rows {
            assert!(at(&after, row).norm() < 1e-3 * at(&before, row).norm());
        }
        let energy = |v: &[SVector<f64, 2>]| -> f64 {
            (1..5)
                .map(|n| (mass[n] + FACE_CLAMP_REGULARISATION * 3.0) * v[n].norm_squared())
                .sum()
        };
        assert!(energy(&after) <= energy(&before));
    }

    /// In 3D the face of a block of particles 4 × 4 × 4, 0.1 apart, cut by x = 0 is
    /// sampled on the plane across the block's whole section, no two points closer than
    /// half the reach.
    #[test]
    fn face_points_sample_a_plane_through_a_block() {
        let mut x = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                for k in 0..4 {
                    let c = |n: usize| (n as f64 - 1.5) * 0.1;
                    x.push(SVector::<f64, 3>::new(c(i), c(j) + 1.0, c(k)));
                }
            }
        }
        let reach = 0.15;
        let points = face_points(&x, |x| x.x <= 0.0, reach);
        assert!(points.iter().all(|p| p.x.abs() < 1e-9));
        for j in 0..4 {
            for k in 0..4 {
                let (y, z) = ((j as f64 - 1.5) * 0.1 + 1.0, (k as f64 - 1.5) * 0.1);
                let near = |p: &SVector<f64, 3>| (p.y - y).hypot(p.z - z) <= 0.075;
                assert!(points.iter().any(near), "no point near ({y}, {z})");
            }
        }
        for (a, p) in points.iter().enumerate() {
            assert!(
                points[a + 1..]
                    .iter()
                    .all(|q| (p - q).norm() >= reach / 2.0)
            );
        }
    }

    /// The stencils' nodes are the unknowns, each row's entries found among them; the
    /// moved nodes are those and the region's.
    #[test]
    fn the_moved_nodes_are_the_region_and_the_stencils() {
        let (clamp, rows, _) = clamp_and_rows();
        assert_eq!(clamp.moved_nodes(), vec![0, 1, 2, 3, 4]);
        for (local, row) in clamp.rows.iter().zip(&rows) {
            for (&(j, c), &(n, v)) in local.iter().zip(row) {
                assert_eq!((clamp.unknowns[j], c), (n, v));
            }
        }
    }

    /// With no mass near the face there is nothing to hold: the region is at rest and
    /// the other nodes keep their velocities.
    #[test]
    fn without_mass_near_the_face_only_the_region_is_at_rest() {
        let (clamp, _, _) = clamp_and_rows();
        let system = clamp.system(&[0.0; 6]);
        let mut v = vec![SVector::from([1.0, 2.0]); 6];
        clamp.hold(&system, &mut v);
        assert!(v[..3].iter().all(|v| *v == SVector::<f64, 2>::zeros()));
        assert!(v[3..].iter().all(|v| *v == SVector::from([1.0, 2.0])));
    }
}
