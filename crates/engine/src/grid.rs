//! Nodal sums of P2G and the grid update: velocities, forces, damping, boundary
//! conditions, and the two guards against nodes whose mass cannot carry a velocity.
//!
//! **Cancelled nodes.** MLS shape functions can be negative, so a node's mass
//! m_i = Σ N_ip m_p can be small while the contributions Σ |N_ip| m_p are not: p_i / m_i
//! is then noise amplified by their ratio. A node with |m_i| ≤ ε Σ |N_ip| m_p carries no
//! velocity; its mass is counted as dropped and its momentum goes to the active nodes
//! (see below). Nodes that are merely
//! light (every contribution small and positive, as at the fringe of a body) are kept,
//! and so are nodes whose contributions are all negative (m_i < 0 at the fringe of an
//! MLS stencil: p_i / m_i is still a weighted mean of particle velocities). Non-negative
//! kernels drop nothing, and neither does UMLS on the scenes measured: momentum is
//! conserved to round-off.
//!
//! A node whose contributions add up to less than 10⁻¹² of a particle mass is round-off
//! (a particle on a facet or at a vertex gives the opposite vertices N = ±10⁻¹⁷): it is
//! treated as empty too, since dividing its force by such a mass would lose momentum
//! to cancellation in the sums.
//!
//! **Light, stiff nodes.** A node touched only by particles where N_i is small but ∇N_i
//! is not (linear elements: N → 0 at a facet while ∇N stays 1/h) has a local explicit
//! stability limit Δt_i = √(m_i / k_i), k_i = M Σ V_p |∇N_ip|², that goes to zero with
//! its mass. Its increment Δt f_i / m_i is then unbounded: the particles see it through
//! N_ip (bounded) but the velocity gradient sees it through ∇N_ip, and F inverts. Such a
//! node moves with the increment Δt f_i / (Δt² k_i) instead (selective mass scaling, as
//! explicit FE codes do for small elements); nodes within their own stability limit are
//! untouched. The same scaled velocity serves velocities, gradients and affine matrices:
//! scaling only the gradient would break the balance between the work of the nodal
//! forces and the change of stored energy by f_i·Δt² f_i (1/m_i − 1/Δt² k_i) > 0 per
//! step, which transfers without loss (APIC on linear elements) turn into growing
//! energy. The impulse the scaled node does not absorb, Δt f_i (1 − m_i / Δt² k_i), goes
//! to the active nodes in proportion to their mass, so momentum is conserved. This is
//! what lets linear elements run with USL where they inverted particles before.

use nalgebra::SVector;
use rayon::prelude::*;

use crate::boundary::Boundary;
use crate::scatter::{NODE_CHUNK, SEGMENTS_PER_CHUNK, live_ranges, live_segments};
use crate::settings::Damping;

/// Nodal fields of one step.
#[derive(Debug, Clone, Default)]
pub(crate) struct Grid<const D: usize> {
    /// m_i = Σ N m_p.
    pub mass: Vec<f64>,
    /// Σ |N| m_p, unless [`Self::abs_mass_is_mass`] (read it through
    /// [`Self::abs_mass`]).
    pub abs_mass: Vec<f64>,
    /// Whether P2G left `abs_mass` alone because every N ≥ 0 made it the mass
    /// (`Kernel::nonnegative_values`).
    pub abs_mass_is_mass: bool,
    /// Whether P2G left `force` and `stiffness` alone (a momentum-only scatter,
    /// MLS-MPM, whose momentum carries the force impulse): they are zero, and the
    /// update does not read them.
    pub momentum_only: bool,
    /// p_i = Σ N m_p (v_p + C_p (x_i − x_p)).
    pub momentum: Vec<SVector<f64, D>>,
    /// f_i: internal plus external force.
    pub force: Vec<SVector<f64, D>>,
    /// Σ V_p |∇N_ip|² (times the p-wave modulus: the node's diagonal stiffness).
    pub stiffness: Vec<f64>,
    /// v_i = p_i / m_i, written by the update only where [`Self::keep_velocity`] asks
    /// for it (else stale: no reader looks).
    pub velocity: Vec<SVector<f64, D>>,
    /// Whether the update writes `velocity` (and applies the walls to it): for FLIP,
    /// whose G2P reads it. Without a reader its store was 24 of the 80 bytes the update
    /// moved per node under MLS-MPM; local damping and the MUSL re-map compute it where
    /// they need it.
    pub keep_velocity: bool,
    /// ṽ_i = v_i + Δt f_i / m_i (Δt f_i / Δt² k_i on mass-scaled nodes), plus the
    /// redistributed impulse, with boundary conditions.
    pub new_velocity: Vec<SVector<f64, D>>,
    /// Per segment of [`crate::scatter::LIVE_SEGMENT`] nodes: whether it may hold
    /// non-zero values this step. The others hold zeros in every field but an unkept
    /// `velocity` (every writer leaves a node without mass at zero), so P2G's merge and
    /// the grid update skip them: a body in a large box of empty nodes does not pay for
    /// the box.
    pub live: Vec<bool>,
    /// Contributions below this mass are round-off (10⁻¹² of the heaviest particle).
    pub round_off_mass: f64,
}

/// What one grid update set aside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GridUpdateReport<const D: usize> {
    /// Mass of cancelled nodes.
    pub dropped_mass: f64,
    /// Momentum p_i + Δt f_i of empty nodes and the impulse mass-scaled nodes could not
    /// absorb, handed on to the active nodes.
    pub redistributed_momentum: SVector<f64, D>,
    /// Nodes whose increment for velocity gradients was mass-scaled.
    pub scaled_nodes: usize,
    /// Work moving obstacles did on the nodes: their impulse times their velocity.
    pub boundary_work: f64,
}

/// The momenta the reaction sets' nodes would reach without constraints,
/// p_i + Δt f_i, reused every step.
#[derive(Debug, Clone, Default)]
pub(crate) struct ReactionScratch<const D: usize> {
    before: Vec<SVector<f64, D>>,
    /// Each set node's reaction in the last step, sets one after the other.
    pub nodal: Vec<SVector<f64, D>>,
}

impl<const D: usize> ReactionScratch<D> {
    /// Bytes held.
    pub fn bytes(&self) -> usize {
        crate::memory::bytes(&self.before) + crate::memory::bytes(&self.nodal)
    }

    /// Records p_i + Δt f_i of the reaction sets' nodes, before damping or constraints
    /// touch the forces.
    pub fn record(
        &mut self,
        boundary: &Boundary<D>,
        momentum: &[SVector<f64, D>],
        force: &[SVector<f64, D>],
        dt: f64,
    ) {
        self.before.clear();
        self.before.extend(
            boundary
                .reaction_sets
                .iter()
                .flatten()
                .map(|&n| momentum[n as usize] + force[n as usize] * dt),
        );
    }

    /// The reactions of the sets, from the velocities after the constraints.
    pub fn reactions(
        &mut self,
        boundary: &Boundary<D>,
        mass: &[f64],
        velocity: &[SVector<f64, D>],
        dt: f64,
        out: &mut Vec<crate::boundary::Reaction<D>>,
    ) {
        out.clear();
        self.nodal.clear();
        let mut before = self.before.iter();
        for set in &boundary.reaction_sets {
            let mut r = crate::boundary::Reaction::default();
            for (&n, free) in set.iter().zip(before.by_ref()) {
                // The force the constraint added: (m v − (p + Δt f)) / Δt.
                let impulse = (velocity[n as usize] * mass[n as usize] - free) / dt;
                self.nodal.push(impulse);
                r.force += impulse;
                r.magnitude += impulse.norm();
            }
            out.push(r);
        }
    }
}

impl<const D: usize> Grid<D> {
    /// Bytes held by the nodal fields.
    pub fn bytes(&self) -> usize {
        use crate::memory::bytes;
        bytes(&self.mass)
            + bytes(&self.abs_mass)
            + bytes(&self.momentum)
            + bytes(&self.force)
            + bytes(&self.stiffness)
            + bytes(&self.velocity)
            + bytes(&self.new_velocity)
            + bytes(&self.live)
    }

    /// Arrays for `nodes` nodes.
    pub fn new(nodes: usize, heaviest_particle: f64) -> Self {
        Self {
            round_off_mass: 1e-12 * heaviest_particle,
            mass: vec![0.0; nodes],
            abs_mass: vec![0.0; nodes],
            abs_mass_is_mass: false,
            momentum_only: false,
            keep_velocity: true,
            momentum: vec![SVector::zeros(); nodes],
            force: vec![SVector::zeros(); nodes],
            stiffness: vec![0.0; nodes],
            velocity: vec![SVector::zeros(); nodes],
            new_velocity: vec![SVector::zeros(); nodes],
            live: vec![false; live_segments(nodes)],
        }
    }

    /// Σ |N| m_p per node.
    pub fn abs_mass(&self) -> &[f64] {
        abs_mass_of(&self.mass, &self.abs_mass, self.abs_mass_is_mass)
    }

    /// Whether node `i` carries a velocity (see the module docs).
    #[inline]
    pub fn is_active(&self, i: usize, cancellation_fraction: f64) -> bool {
        active_node(
            self.mass[i],
            self.abs_mass()[i],
            self.round_off_mass,
            cancellation_fraction,
        )
    }

    /// The lowest node whose updated velocity is not finite. Only chunks with a live
    /// segment can hold anything but zeros, so only they are read, in parallel; the
    /// lowest chunk's first such node is the lowest overall, whatever the thread count.
    pub fn first_non_finite_velocity(&self) -> Option<usize> {
        self.new_velocity
            .par_chunks(NODE_CHUNK)
            .zip(self.live.par_chunks(SEGMENTS_PER_CHUNK))
            .enumerate()
            .filter(|(_, (_, live))| live.iter().any(|&l| l))
            .find_map_first(|(c, (chunk, _))| {
                chunk
                    .iter()
                    .position(|v| !v.iter().all(|x| x.is_finite()))
                    .map(|i| c * NODE_CHUNK + i)
            })
    }

    /// Velocities from momenta and forces, damping, boundary conditions.
    pub fn update(
        &mut self,
        dt: f64,
        modulus: f64,
        cancellation_fraction: f64,
        damping: Damping,
        boundary: &Boundary<D>,
        mut reactions: Option<&mut (ReactionScratch<D>, Vec<crate::boundary::Reaction<D>>)>,
    ) -> GridUpdateReport<D> {
        let mut report = GridUpdateReport {
            dropped_mass: 0.0,
            redistributed_momentum: SVector::zeros(),
            scaled_nodes: 0,
            boundary_work: 0.0,
        };
        let mut active_mass = 0.0;
        if let Some(r) = reactions.as_deref_mut() {
            r.0.record(boundary, &self.momentum, &self.force, dt);
        }
        if let Damping::Local { .. } = damping {
            // Local damping acts per component on the force the node is free to follow:
            // the part a wall takes (fixed, or normal to a slip wall) must not be damped,
            // or a wall's reaction becomes a friction-like force along an inclined wall
            // that overshoots every step (an inclined column crept down its walls).
            // Projecting the force before the update changes nothing else: the
            // velocity is projected after it anyway.
            self.velocity
                .par_iter_mut()
                .zip(self.mass.par_iter().zip(self.momentum.par_iter()))
                .with_min_len(NODE_CHUNK)
                .for_each(|(v, (&m, p))| {
                    *v = if m != 0.0 { p / m } else { SVector::zeros() };
                });
            boundary.apply(&mut self.velocity);
            boundary.apply(&mut self.force);
        }
        // In parallel over fixed chunks of nodes; the chunks' partial sums are added in
        // chunk order, so the report does not depend on the thread count.
        let round_off = self.round_off_mass;
        let momentum_only = self.momentum_only;
        let keep_velocity = self.keep_velocity;
        let local_damping = matches!(damping, Damping::Local { .. });
        // Not through `Self::abs_mass`, which would borrow the whole grid.
        let abs_mass = abs_mass_of(&self.mass, &self.abs_mass, self.abs_mass_is_mass);
        let partials: Vec<(f64, SVector<f64, D>, usize, f64)> = self
            .mass
            .par_chunks(NODE_CHUNK)
            .zip(abs_mass.par_chunks(NODE_CHUNK))
            .zip(self.momentum.par_chunks(NODE_CHUNK))
            .zip(self.force.par_chunks(NODE_CHUNK))
            .zip(self.stiffness.par_chunks(NODE_CHUNK))
            .zip(self.velocity.par_chunks_mut(NODE_CHUNK))
            .zip(self.new_velocity.par_chunks_mut(NODE_CHUNK))
            .zip(self.live.par_chunks(SEGMENTS_PER_CHUNK))
            .map(
                |(
                    ((((((mass, abs_mass), momentum), force), stiffness), velocity), new_velocity),
                    live,
                )| {
                    let (mut dropped, mut redistributed, mut scaled, mut active) =
                        (0.0, SVector::<f64, D>::zeros(), 0usize, 0.0);
                    // A segment no particle reached, now or in the last step, is zero
                    // (its nodes would add zeros to the sums).
                    for i in live_ranges(live, mass.len()).flatten() {
                        let m = mass[i];
                        // The zero arrays of a momentum-only scatter are not read: the
                        // same values, less memory traffic.
                        let (force_i, stiffness_i) = if momentum_only {
                            (SVector::zeros(), 0.0)
                        } else {
                            (force[i], stiffness[i])
                        };
                        if !active_node(m, abs_mass[i], round_off, cancellation_fraction) {
                            // A node with no mass at all can still carry a force (N = 0,
                            // ∇N ≠ 0).
                            dropped += m;
                            redistributed += momentum[i] + force_i * dt;
                            if keep_velocity {
                                velocity[i] = SVector::zeros();
                            }
                            new_velocity[i] = SVector::zeros();
                            continue;
                        }
                        active += m;
                        let v = momentum[i] / m;
                        let f = if local_damping {
                            damped(force_i, velocity[i], m, damping)
                        } else {
                            damped(force_i, v, m, damping)
                        };
                        let scaled_mass = dt * dt * modulus * stiffness_i;
                        if keep_velocity {
                            velocity[i] = v;
                        }
                        if scaled_mass > m.abs() {
                            // Selective mass scaling: the node moves as if it had mass
                            // Δt² k, and the impulse it cannot absorb goes to the active
                            // nodes with the rest.
                            scaled += 1;
                            new_velocity[i] = v + f * (dt / scaled_mass.copysign(m));
                            redistributed += f * (dt * (1.0 - m.abs() / scaled_mass));
                        } else {
                            new_velocity[i] = v + f * (dt / m);
                        }
                    }
                    (dropped, redistributed, scaled, active)
                },
            )
            .collect();
        for (dropped, redistributed, scaled, active) in partials {
            report.dropped_mass += dropped;
            report.redistributed_momentum += redistributed;
            report.scaled_nodes += scaled;
            active_mass += active;
        }
        // The impulse of empty nodes (a particle exactly on a facet gives the opposite
        // vertex N = 0 but ∇N ≠ 0, so a force and no mass) and what mass-scaled nodes
        // did not absorb go to the active nodes in proportion to their mass: momentum
        // stays conserved to round-off, and the amount is reported.
        if active_mass > 0.0 && report.redistributed_momentum.norm_squared() > 0.0 {
            let shift = report.redistributed_momentum / active_mass;
            let mass = &self.mass;
            self.new_velocity
                .par_iter_mut()
                .enumerate()
                .with_min_len(NODE_CHUNK)
                .for_each(|(i, v)| {
                    if active_node(mass[i], abs_mass[i], round_off, cancellation_fraction) {
                        *v += shift;
                    }
                });
        }
        if keep_velocity {
            boundary.apply_live(&mut self.velocity, &self.live, None);
        }
        // The work moving obstacles do is energy put in, as gravity's is.
        report.boundary_work =
            boundary.apply_live(&mut self.new_velocity, &self.live, Some(&self.mass));
        if let Some(r) = reactions {
            r.0.reactions(boundary, &self.mass, &self.new_velocity, dt, &mut r.1);
        }
        report
    }
}

/// Σ |N| m_p per node from the grid's arrays: the mass itself where P2G did not sum it
/// apart (`is_mass`, a kernel whose values are never negative).
fn abs_mass_of<'a>(mass: &'a [f64], abs_mass: &'a [f64], is_mass: bool) -> &'a [f64] {
    if is_mass { mass } else { abs_mass }
}

/// Whether a node with mass `m` and Σ|N| m_p = `abs_mass` carries velocity: above the
/// round-off mass, and not mostly cancelled by negative MLS values.
pub(crate) fn active_node(
    m: f64,
    abs_mass: f64,
    round_off: f64,
    cancellation_fraction: f64,
) -> bool {
    abs_mass > round_off && m.abs() > cancellation_fraction * abs_mass
}

/// The nodal force with damping against the node's velocity `v`.
fn damped<const D: usize>(
    force: SVector<f64, D>,
    v: SVector<f64, D>,
    mass: f64,
    damping: Damping,
) -> SVector<f64, D> {
    match damping {
        Damping::None => force,
        Damping::Local { alpha } => {
            force - SVector::<f64, D>::from_fn(|k, _| alpha * force[k].abs() * signum0(v[k]))
        }
        Damping::MassProportional { beta } => force - v * (beta * mass),
    }
}

/// sign(x) with sign(0) = 0 (a node at rest is not damped).
fn signum0(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scatter::live_segments;

    const NODES: usize = 300;

    /// Pseudo-random nodal sums for `step`: masses in [0.5, 1.5) with every seventh node
    /// empty (momentum and force left over: the redistribution path), and stiffnesses
    /// up to 2, which at Δt² M = 1 scales the mass of about half the nodes.
    fn fill(grid: &mut Grid<3>, step: u64) {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64 ^ step.wrapping_mul(0x2545_f491_4f6c_dd1d);
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 10_000) as f64 / 10_000.0
        };
        for i in 0..NODES {
            grid.mass[i] = if i % 7 == 0 { 0.0 } else { 0.5 + next() };
            grid.momentum[i] = SVector::from_fn(|_, _| next() - 0.5);
            grid.force[i] = SVector::from_fn(|_, _| 4.0 * next() - 2.0);
            grid.stiffness[i] = 2.0 * next();
        }
    }

    /// Whether `keep_velocity` is set changes neither the new velocities nor the report,
    /// under every damping (local damping reads its own v_i), over two updates from
    /// different sums (so that a v_i left from the first would show in the second); where
    /// it is set, v_i is p_i / m_i with the walls applied.
    #[test]
    fn storing_the_velocity_before_the_update_changes_nothing_else() {
        let normal = SVector::<f64, 3>::new(0.6, 0.0, 0.8);
        let boundary = Boundary::<3> {
            fixed: vec![3, 40, 202],
            slip: vec![(5, normal), (41, normal), (250, normal)],
            ..Default::default()
        };
        let dampings = [
            Damping::None,
            Damping::Local { alpha: 0.3 },
            Damping::MassProportional { beta: 0.5 },
        ];
        for damping in dampings {
            let mut kept = Grid::<3>::new(NODES, 1.5);
            kept.live = vec![true; live_segments(NODES)];
            kept.abs_mass_is_mass = true;
            let mut unkept = kept.clone();
            unkept.keep_velocity = false;
            for step in 0..2 {
                fill(&mut kept, step);
                fill(&mut unkept, step);
                let a = kept.update(1e-3, 1e6, 1e-10, damping, &boundary, None);
                let b = unkept.update(1e-3, 1e6, 1e-10, damping, &boundary, None);
                assert_eq!(a, b, "{damping:?}, step {step}");
                assert!(
                    a.scaled_nodes > 50,
                    "{damping:?}: {} scaled",
                    a.scaled_nodes
                );
                assert!(a.redistributed_momentum.norm() > 0.0, "{damping:?}");
                for i in 0..NODES {
                    let (x, y) = (kept.new_velocity[i], unkept.new_velocity[i]);
                    assert!(
                        x.iter().zip(&y).all(|(x, y)| x.to_bits() == y.to_bits()),
                        "{damping:?}, step {step}, node {i}: {x:?} against {y:?}"
                    );
                    let m = kept.mass[i];
                    let mut expected = if m > 0.0 {
                        kept.momentum[i] / m
                    } else {
                        SVector::zeros()
                    };
                    if boundary.fixed.contains(&(i as u32)) {
                        expected = SVector::zeros();
                    } else if let Some((_, n)) =
                        boundary.slip.iter().find(|(node, _)| *node as usize == i)
                    {
                        expected -= n * expected.dot(n);
                    }
                    assert_eq!(kept.velocity[i], expected, "{damping:?}, node {i}");
                }
            }
        }
    }
}
