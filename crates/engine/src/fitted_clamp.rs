//! A clamp imposed on the velocity fit instead of on nodes.
//!
//! A fixed region given as nodes (every node inside it at rest) is a staircase of whole
//! cells: where its edge falls depends on how the mesh or grid lies under the body, and
//! with kernels that do not interpolate (UMLS, B-splines) the velocity interpolated at
//! the embedded particles next to the edge is not zero. A [`FittedClamp`] instead gives
//! its region's nodes the velocities under which the clamped particles neither move nor
//! deform, in the mass-weighted least-squares sense, given the free nodes' velocities:
//!
//! min over v_c (c in the clamp's nodes) of
//! Σ_p m_p (|Σ_i N_ip v_i|² + ℓ² |Σ_i v_i ⊗ ∇N_ip|²) + ε s Σ_c |v_c|²,
//!
//! where p runs over the clamped particles, i over all nodes of their stencils, ℓ is the
//! kernel's spacing and s the largest diagonal entry of the normal matrix. The clamped
//! particles are the material the clamp holds, so they move with the body, not with the
//! mesh: the clamp ends where they end, whatever the node layout.
//!
//! The velocity-gradient term is what keeps the clamp stable: with values alone, node
//! patterns that vanish at every clamped particle but not between them are free, and on
//! refined cantilevers they grew until the energy check stopped the run
//! (docs/umls-kernel.md has the measurements). The Tikhonov term (ε =
//! [`FITTED_CLAMP_REGULARISATION`]) only keeps the normal matrix regular.
//!
//! The normal matrix is dense over the clamp nodes the clamped particles reach and is
//! factorised once a step (v, ṽ and the MUSL re-map share it), so the cost grows with the cube of that
//! count: meant for clamps of up to a few thousand nodes (the cantilever's has 50–150).

use nalgebra::{Cholesky, DMatrix, DVector, Dyn, SVector};

/// Relative weight ε of the Tikhonov term that keeps the normal matrix regular.
pub const FITTED_CLAMP_REGULARISATION: f64 = 1e-6;

/// A clamp imposed on the fit: `nodes` (sorted, without repeats) carry the velocities
/// under which the velocity and its gradient at `particles` vanish (least squares).
#[derive(Debug, Clone, PartialEq)]
pub struct FittedClamp {
    nodes: Vec<u32>,
    particles: Vec<u32>,
    /// The length ℓ that weighs the velocity-gradient rows against the velocity rows
    /// (default 1; give the kernel's spacing, as the command line does).
    pub reach: f64,
}

/// One clamped particle's stencil: its mass, and (node, value, gradient) triples.
pub(crate) struct ClampRow<const D: usize> {
    pub mass: f64,
    pub entries: Vec<(u32, f64, SVector<f64, D>)>,
}

impl FittedClamp {
    /// A clamp whose `nodes` are fitted so that `particles` (indices into the
    /// simulation's particles) neither move nor deform. Repeated indices are merged.
    pub fn new(mut nodes: Vec<u32>, mut particles: Vec<u32>) -> Self {
        nodes.sort_unstable();
        nodes.dedup();
        particles.sort_unstable();
        particles.dedup();
        Self {
            nodes,
            particles,
            reach: 1.0,
        }
    }

    /// The nodes whose velocities are fitted.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// The particles held at rest (their slots in [`crate::Simulation::particles`],
    /// ascending as given; a particle sort renumbers them in place).
    pub fn particles(&self) -> &[u32] {
        &self.particles
    }

    /// Follows the particles to the slots a sort moved them to (`slot[old] = new`;
    /// indices beyond it name no particle and stay, for the step to report). The list
    /// keeps its order, so the fit sums its rows as before and gives the same bits.
    pub(crate) fn renumber(&mut self, slot: &[u32]) {
        for p in &mut self.particles {
            if let Some(&new) = slot.get(*p as usize) {
                *p = new;
            }
        }
    }

    /// The least-squares system of this step's clamped-particle stencils `rows`: the
    /// unknowns (the clamp's nodes the rows reach) and the factorised normal matrix,
    /// which every velocity field of the step shares ([`Self::fit`]).
    pub(crate) fn system<const D: usize>(&self, rows: Vec<ClampRow<D>>) -> ClampSystem<D> {
        // Unknowns: the clamp's nodes the rows reach, numbered in node order.
        let mut unknowns: Vec<u32> = rows
            .iter()
            .flat_map(|r| r.entries.iter().map(|e| e.0))
            .filter(|n| self.nodes.binary_search(n).is_ok())
            .collect();
        unknowns.sort_unstable();
        unknowns.dedup();
        let k = unknowns.len();
        let mut normal = DMatrix::<f64>::zeros(k, k);
        let mut local: Vec<(usize, f64)> = Vec::new();
        self.for_each_row(&rows, |weight, coefficients| {
            local.clear();
            local.extend(coefficients.filter_map(|(n, c)| Some((index(&unknowns, n)?, c))));
            for &(a, ca) in &local {
                for &(b, cb) in &local {
                    normal[(a, b)] += weight * ca * cb;
                }
            }
        });
        let scale = (0..k).map(|j| normal[(j, j)]).fold(0.0, f64::max);
        for j in 0..k {
            normal[(j, j)] += FITTED_CLAMP_REGULARISATION * scale;
        }
        let cholesky = if k == 0 { None } else { normal.cholesky() };
        ClampSystem {
            rows,
            unknowns,
            cholesky,
        }
    }

    /// Fits the clamp's nodes of `velocity` with the step's `system`: nodes the rows do
    /// not reach are set to rest, the others to the regularised least-squares solution
    /// given the other nodes' velocities.
    pub(crate) fn fit<const D: usize>(
        &self,
        system: &ClampSystem<D>,
        velocity: &mut [SVector<f64, D>],
    ) {
        for &n in &self.nodes {
            velocity[n as usize] = SVector::zeros();
        }
        let Some(cholesky) = &system.cholesky else {
            return;
        };
        let unknowns = &system.unknowns;
        let mut rhs = vec![DVector::<f64>::zeros(unknowns.len()); D];
        let mut local: Vec<(usize, f64)> = Vec::new();
        // The clamp's nodes are unknown; the free nodes' part of each row is the target.
        self.for_each_row(&system.rows, |weight, coefficients| {
            let mut target = SVector::<f64, D>::zeros();
            local.clear();
            for (n, c) in coefficients {
                match index(unknowns, n) {
                    Some(j) => local.push((j, c)),
                    None => target -= velocity[n as usize] * c,
                }
            }
            for &(a, ca) in &local {
                for (d, r) in rhs.iter_mut().enumerate() {
                    r[a] += weight * ca * target[d];
                }
            }
        });
        for (d, r) in rhs.into_iter().enumerate() {
            let x = cholesky.solve(&r);
            for (j, &n) in unknowns.iter().enumerate() {
                velocity[n as usize][d] = x[j];
            }
        }
    }

    /// Calls `f(weight, coefficients)` for every scalar least-squares row Σ_i c_i v_i = 0:
    /// per clamped particle its velocity (c_i = N_ip) and each component of its velocity
    /// gradient (c_i = ℓ ∂_d N_ip), weighted by its mass.
    fn for_each_row<const D: usize>(
        &self,
        rows: &[ClampRow<D>],
        mut f: impl FnMut(f64, &mut dyn Iterator<Item = (u32, f64)>),
    ) {
        for row in rows {
            f(row.mass, &mut row.entries.iter().map(|e| (e.0, e.1)));
            for d in 0..D {
                f(
                    row.mass,
                    &mut row.entries.iter().map(|e| (e.0, e.2[d] * self.reach)),
                );
            }
        }
    }
}

/// One step's least-squares system of a [`FittedClamp`]: built once
/// ([`FittedClamp::system`]) and applied to v, ṽ and, under MUSL, the re-mapped velocity.
pub(crate) struct ClampSystem<const D: usize> {
    rows: Vec<ClampRow<D>>,
    /// The clamp's nodes the rows reach, sorted.
    unknowns: Vec<u32>,
    /// The factorised normal matrix (`None` with no unknowns or a failed factorisation,
    /// when the clamp's nodes are simply at rest).
    cholesky: Option<Cholesky<f64, Dyn>>,
}

/// The position of node `n` among the sorted `unknowns`.
fn index(unknowns: &[u32], n: u32) -> Option<usize> {
    unknowns.binary_search(&n).ok()
}
