//! Stage 2b of the step (optional): the grid velocity P2G's momenta stand for, solved
//! towards the consistent mass matrix instead of the lumped one
//! ([`crate::MassMatrix::Consistent`]).
//!
//! The lumped velocity v_i = p_i / m_i is a weighted mean of the particles' velocities;
//! interpolated back by G2P it is a smoothed copy of what the particles carried, so every
//! round trip filters the particle field, the more the wider the stencil (what PIC and
//! the PIC part of FLIP lose). The consistent mass matrix M_ij = Σ_p m_p N_ip N_jp makes
//! the round trip the mass-weighted least-squares projection onto the nodal basis, which
//! keeps whatever the basis can represent. It is approximated by Jacobi iterations with
//! the lumped matrix as preconditioner (Nairn and Hammerquist's FMPM(k)):
//!
//! v⁽⁰⁾ = p / m,  v⁽ʳ⁺¹⁾ = v⁽ʳ⁾ + (p − A v⁽ʳ⁾) / m,
//!
//! where A v = Σ_p m_p N_ip u_p(x_i) and u_p is the field the transfer makes of v at the
//! particle: u_p(x) = Σ_j N_jp v_j for PIC and FLIP, plus C_p[v] (x − x_p) for affine
//! transfers, with C_p[v] the transfer's own affine matrix of v (B_p D_p⁻¹ for APIC), plus
//! the quadratic modes of v for [`crate::QuadraticApic`] (which keep Σ_i N_ip u_p(x_i)
//! = Σ_i N_ip v_i, so momentum and the fixed points below stay). With
//! non-negative N the lumped matrix bounds A, so the iterations converge towards the
//! projection, fastest for the smooth modes, and stopping early leaves the rough ones
//! lumped. Properties the tests hold:
//!
//! - the total momentum is unchanged (Σ_i (A v)_i = Σ_i m_i v_i by partition of unity,
//!   and Σ_i N_ip (x_i − x_p) = 0 for the affine part);
//! - a field the transfer reproduces (constant, or affine for affine transfers) is a
//!   fixed point: the lumped solution is already its projection.
//!
//! The forces may take the matrix (1 − β) M_L + β A instead (β < 1; ½ is the mixed
//! matrix, whose frequency errors from lumping and from the consistent matrix cancel
//! in their leading term for linear elements): the update becomes
//! v⁽ʳ⁺¹⁾ = v⁽ʳ⁾ + β (p − A v⁽ʳ⁾) / m + (1 − β)(p / m − v⁽ʳ⁾), whose iteration matrix is
//! β times the consistent one's, so it converges faster.
//!
//! Each iteration is one gather and one scatter over the stencils, as costly as a G2P
//! and a P2G of momentum only.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::{Kernel, Stencil};

use super::Simulation;
use crate::error::EngineError;
use crate::quadratic_modes::ModeSums;
use crate::scatter::{NODE_CHUNK, NodalSums, Scatter};
use crate::transfer::TransferScheme;

/// The iterations' nodal buffers, kept from step to step.
#[derive(Debug, Clone, Default)]
pub(crate) struct MassSolve<const D: usize> {
    /// The current iterate v⁽ʳ⁾.
    velocity: Vec<SVector<f64, D>>,
    /// A v⁽ʳ⁾, and the masses the same scatter sums (unused).
    product: Vec<SVector<f64, D>>,
    mass: Vec<f64>,
    abs_mass: Vec<f64>,
    /// The right-hand side with the boundary conditions applied.
    constrained: Vec<SVector<f64, D>>,
    live: Vec<bool>,
    /// Its own particle order and windows, so that the live chunks it tracks are those
    /// of its own arrays.
    scatter: Scatter<D>,
}

impl<const D: usize> MassSolve<D> {
    /// Bytes held (they grow with the nodes).
    pub fn bytes(&self) -> usize {
        use crate::memory::bytes;
        let (order, windows) = self.scatter.bytes();
        bytes(&self.velocity)
            + bytes(&self.product)
            + bytes(&self.mass)
            + bytes(&self.abs_mass)
            + bytes(&self.constrained)
            + bytes(&self.live)
            + order
            + windows
    }
}

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// With the consistent mass matrix, replaces the nodal momenta p_i of active nodes
    /// by m_i v_i⁽ᵏ⁾, and with its `forces` the forces f_i by m_i a_i⁽ᵏ⁾ likewise, so that
    /// the grid update's divisions by m_i give the iterates. Nothing to do when lumped.
    pub(super) fn iterate_mass_matrix(&mut self) -> Result<(), EngineError> {
        let mass = self.settings.mass_matrix;
        let velocity = mass.velocity_iterations();
        if velocity > 0 {
            let mut momentum = std::mem::take(&mut self.grid.momentum);
            let solved =
                self.solve_mass_matrix(&mut momentum, velocity, 1.0, self.transfer.shape().affine);
            self.grid.momentum = momentum;
            solved?;
        }
        let forces = mass.force_iterations();
        if forces > 0 {
            // The equation of motion's matrix: the plain one, no affine part, in its share.
            let mut force = std::mem::take(&mut self.grid.force);
            let solved = self.solve_mass_matrix(&mut force, forces, mass.force_share(), false);
            self.grid.force = force;
            solved?;
        }
        Ok(())
    }

    /// Replaces `rhs` (m_i times a nodal field, summed by P2G) on active nodes by m_i
    /// times the k-th Jacobi iterate of M x = rhs, k = `iterations`, where
    /// M = (1 − β) M_L + β A, β = `share`, and A is the consistent mass matrix, with the
    /// transfer's affine part if `affine`.
    fn solve_mass_matrix(
        &mut self,
        rhs: &mut [SVector<f64, D>],
        iterations: usize,
        share: f64,
        affine: bool,
    ) -> Result<(), EngineError> {
        let step = self.step;
        let fraction = self.settings.cancellation_fraction;
        let nodes = self.grid.mass.len();
        let solve = &mut self.mass_solve;
        solve.velocity.resize(nodes, SVector::zeros());
        solve.product.resize(nodes, SVector::zeros());
        solve.mass.resize(nodes, 0.0);
        solve.abs_mass.resize(nodes, 0.0);
        solve
            .live
            .resize(crate::scatter::live_segments(nodes), false);
        let grid = &self.grid;
        let active = |i: usize| grid.is_active(i, fraction);
        let rhs_in: &[SVector<f64, D>] = rhs;
        // One Jacobi update v ← v + (rhs − (1 − β) m v − β A v) / m on the active nodes,
        // taken as v + β (rhs − A v) / m + (1 − β) (rhs / m − v), which for β = 1 is
        // v + (rhs − A v) / m bit for bit; the first, from v = 0 (no product), is the
        // lumped v = rhs / m.
        let jacobi = |velocity: &mut [SVector<f64, D>], product: Option<&[SVector<f64, D>]>| {
            velocity
                .par_iter_mut()
                .enumerate()
                .with_min_len(NODE_CHUNK)
                .for_each(|(i, v)| match (active(i), product) {
                    (true, Some(product)) => {
                        let (rhs, m) = (rhs_in[i], grid.mass[i]);
                        *v += (rhs - product[i]) / m * share + (rhs / m - *v) * (1.0 - share)
                    }
                    (true, None) => *v = rhs_in[i] / grid.mass[i],
                    (false, Some(_)) => {}
                    (false, None) => *v = SVector::zeros(),
                });
        };
        jacobi(&mut solve.velocity, None);
        let boundary = &self.boundary;
        boundary.apply(&mut solve.velocity);
        let (p, kernel, stencils, transfer, ids) = (
            &self.particles,
            &self.kernel,
            &self.stencils,
            self.transfer,
            &self.ids,
        );
        let moment_scale = kernel.constant_second_moment();
        let quadratic = transfer.shape().quadratic;
        for _ in 0..iterations {
            let velocity = &solve.velocity;
            let sums = NodalSums {
                mass: &mut solve.mass,
                abs_mass: &mut solve.abs_mass,
                stiffness: &mut [],
                momentum: &mut solve.product,
                force: &mut [],
                live: &mut solve.live,
                momentum_only: true,
                // |N|-mass summed whatever the kernel: this scatter is not the hot path.
                nonnegative: false,
            };
            solve
                .scatter
                .scatter(stencils.ranges(), ids, sums, None, |block, window| {
                    let mut scratch = Stencil::new();
                    for &i in block {
                        let i = i as usize;
                        let (m, x) = (p.mass[i], p.position[i]);
                        stencils.with(i, kernel, &x, &p.cache[i], &mut scratch, |st| {
                            // The field the transfer makes of v at the particle.
                            let mut value = SVector::<f64, D>::zeros();
                            let (mut b, mut d, mut grad_v) =
                                (SMatrix::zeros(), SMatrix::zeros(), SMatrix::zeros());
                            let mut mode_sums = (affine && quadratic).then(ModeSums::<D>::default);
                            for e in 0..st.len() {
                                let (n, v) = (st.values[e], velocity[st.nodes[e] as usize]);
                                value += v * n;
                                if affine {
                                    let r = st.offset(e, kernel, &x);
                                    b += v * r.transpose() * n;
                                    d += r * r.transpose() * n;
                                    grad_v += v * st.gradients[e].transpose();
                                    if let Some(sums) = &mut mode_sums {
                                        sums.add(n, &v, &r);
                                    }
                                }
                            }
                            let c = if !affine {
                                SMatrix::zeros()
                            } else if let Some(s) = moment_scale {
                                transfer.affine_with_constant_moment(&b, s, &grad_v)
                            } else {
                                transfer.affine(&b, &d, &grad_v)
                            };
                            // The quadratic modes of v, with their frame, where the
                            // transfer has them.
                            // (The frame from the summed D, as P2G builds it; the fit
                            // with the kernel's D, as G2P makes it.)
                            let modes = mode_sums.as_ref().and_then(|sums| {
                                let frame = sums.frame(&d)?;
                                let d = moment_scale.map_or(d, |s| SMatrix::identity() * s);
                                Some((frame, sums.fit(&value, &b, &d).0))
                            });
                            for e in 0..st.len() {
                                let n = st.values[e];
                                let mut u = value;
                                if affine {
                                    let r = st.offset(e, kernel, &x);
                                    u += c * r;
                                    if let Some((frame, modes)) = &modes {
                                        u += frame.velocity(modes, &r);
                                    }
                                }
                                window.add_momentum::<1>(
                                    window.record(st.nodes[e] as usize),
                                    n * m,
                                    n.abs() * m,
                                    u * (n * m),
                                );
                            }
                        })?;
                    }
                    Ok(())
                })
                .map_err(|(particle, source)| EngineError::Kernel {
                    step,
                    particle,
                    source,
                })?;
            jacobi(&mut solve.velocity, Some(&solve.product));
            // Projected Jacobi: the iterates stay admissible, so the constrained
            // components take no part in the fit of the free ones.
            boundary.apply(&mut solve.velocity);
        }
        // Only active nodes carry a velocity; the others keep their momentum (or force)
        // for the grid update to hand on. The constrained components of the right-hand
        // side are kept as they were, so the reactions the grid update takes from them
        // are the lumped ones (the same at rest).
        solve.constrained.clear();
        solve.constrained.extend_from_slice(rhs_in);
        boundary.apply(&mut solve.constrained);
        let (velocity, constrained) = (&solve.velocity, &solve.constrained);
        rhs.par_iter_mut()
            .enumerate()
            .with_min_len(NODE_CHUNK)
            .for_each(|(i, x)| {
                if active(i) {
                    *x += velocity[i] * grid.mass[i] - constrained[i];
                }
            });
        Ok(())
    }
}
