//! Stage 2 of the step, P2G: every particle's mass, momentum and force to its stencil's
//! nodes, through [`crate::scatter::Scatter`] (parallel, bitwise independent of the
//! thread count).

use nalgebra::{SMatrix, SVector};
use umls_constitutive::Constitutive;
use umls_transfer::{Kernel, KernelError, Stencil, regular_inverse};

use super::Simulation;
use super::tensor_rows::{ParticleLoad, row_width, scatter_rows_for};
use crate::error::EngineError;
use crate::quadratic_modes::{ModeFrame, QuadraticModes};
use crate::scatter::Window;
use crate::stencils::{EntrySink, correction_mean, second_moment};
use crate::transfer::{SingularSecondMoment, TransferScheme};

/// The affine matrix P2G spreads: C_p, scaled down if its kinetic energy at the
/// particle's new position, tr(C D C^T) with D = Σ N r rᵀ there, exceeds what it had
/// where G2P made it. For B-splines D is constant and nothing changes; for linear
/// elements D goes from 0 at a vertex to its largest at the centroid, so a particle
/// moving away from a vertex would carry the affine energy up with it — the energy
/// source that blew up linear elements with APIC. Skipped where D is not positive
/// (negative MLS values): there the bound means nothing.
fn limited_affine<const D: usize>(
    c: &SMatrix<f64, D, D>,
    moment: f64,
    d: impl FnOnce() -> SMatrix<f64, D, D>,
) -> SMatrix<f64, D, D> {
    if !moment.is_finite() || moment <= 0.0 {
        return if moment == 0.0 { SMatrix::zeros() } else { *c };
    }
    let d = d();
    c * field_limit((c * d * c.transpose()).trace(), moment)
}

/// MLS-MPM's affine load with a particle's own second moment `d`: m C − Δt V τ D_p⁻¹,
/// C limited as APIC's is where D varies ([`limited_affine`]); `impulse` is Δt V τ.
///
/// # Errors
/// [`SingularSecondMoment`] where D_p has no usable inverse.
#[inline]
fn fused_affine<const D: usize, K>(
    c: &SMatrix<f64, D, D>,
    moment: f64,
    d: &SMatrix<f64, D, D>,
    mass: f64,
    impulse: &SMatrix<f64, D, D>,
) -> Result<SMatrix<f64, D, D>, KernelError> {
    let inverse = regular_inverse(d).ok_or_else(|| SingularSecondMoment::of::<D, K>(d))?;
    Ok(limited_affine(c, moment, || *d) * mass - impulse * inverse)
}

/// The factor that brings the energy `now` of a particle's affine and quadratic fields
/// at its new position down to `moment`, what they had where G2P made them: the
/// quadratic modes' G changes as a particle moves (for B-splines too), as D does for
/// mesh kernels, so without a bound their energy could grow with the motion alone
/// ([`limited_affine`] for C_p alone). 0 where the moment is 0, 1 where it is not a
/// positive number.
fn field_limit(now: f64, moment: f64) -> f64 {
    if !moment.is_finite() || moment <= 0.0 {
        return if moment == 0.0 { 0.0 } else { 1.0 };
    }
    if now > moment * (1.0 + 1e-9) {
        (moment / now).sqrt()
    } else {
        1.0
    }
}

/// One particle's contributions to the nodes of its stencil. `CORRECTED` is whether the
/// kernel has an integration correction: a constant, so that the kernels without one
/// (B-splines, whose visits are inlined here) keep an entry free of its branch. `A` is
/// 0 for a kernel whose values are never negative (no |N|-mass summed), else 1.
struct ScatterEntry<'w, const D: usize, const CORRECTED: bool, const A: usize> {
    window: &'w mut Window<D>,
    /// What the particle spreads (the affine matrix zero without an affine transfer).
    load: ParticleLoad<D>,
    /// The kernel's integration correction ξ_i per node (empty unless `CORRECTED`): the
    /// force's gradient is ∇N_i + N_i (ξ_i − ξ̄_p) ([`Kernel::force_gradient_correction`]).
    correction: &'w [SVector<f64, D>],
    /// ξ̄_p = Σ_i N_i ξ_i at the particle, which makes the corrections sum to zero over
    /// its stencil, so the internal forces still sum to zero (momentum is conserved).
    correction_mean: SVector<f64, D>,
    /// The particle's quadratic modes and their frame at its position (`None` unless
    /// the transfer has them and the stencil admits them).
    modes: Option<(ModeFrame<D>, QuadraticModes<D>)>,
}

impl<const D: usize, const CORRECTED: bool, const A: usize> ScatterEntry<'_, D, CORRECTED, A> {
    /// One entry's share, compiled for a transfer that spreads C_p (`AFFINE`) or not,
    /// and folds the force into the momentum (`FUSED`) or not.
    #[inline(always)]
    fn add<const AFFINE: bool, const FUSED: bool>(
        &mut self,
        node: u32,
        n: f64,
        gradient: &SVector<f64, D>,
        r: &SVector<f64, D>,
    ) {
        let m = self.load.mass;
        if FUSED {
            // `velocity` is m (v + Δt a) and `affine` m C − Δt V τ D⁻¹ here.
            let momentum = self.load.velocity + self.load.affine * r;
            let k = self.window.record(node as usize);
            self.window
                .add_momentum::<A>(k, n * m, n.abs() * m, momentum * n);
            return;
        }
        let mut mv = self.load.velocity;
        if AFFINE {
            mv += self.load.affine * r;
        }
        if let Some((frame, modes)) = &self.modes {
            mv += frame.velocity(modes, r);
        }
        let corrected;
        let gradient = if CORRECTED {
            corrected = gradient + (self.correction[node as usize] - self.correction_mean) * n;
            &corrected
        } else {
            gradient
        };
        let k = self.window.record(node as usize);
        self.window.add::<A>(
            k,
            n * m,
            n.abs() * m,
            self.load.volume * gradient.norm_squared(),
            mv * (n * m),
            self.load.acceleration * (n * m) - self.load.stress_volume * gradient,
        );
    }
}

/// [`ScatterEntry`] with the transfer's flags as constants, so the stencil's loop has no
/// branch on them.
struct Specialised<
    's,
    'w,
    const D: usize,
    const CORRECTED: bool,
    const A: usize,
    const AFFINE: bool,
    const FUSED: bool,
>(&'s mut ScatterEntry<'w, D, CORRECTED, A>);

impl<const D: usize, const CORRECTED: bool, const A: usize, const AFFINE: bool, const FUSED: bool>
    EntrySink<D> for Specialised<'_, '_, D, CORRECTED, A, AFFINE, FUSED>
{
    #[inline(always)]
    fn entry(&mut self, node: u32, n: f64, gradient: &SVector<f64, D>, r: &SVector<f64, D>) {
        self.0.add::<AFFINE, FUSED>(node, n, gradient, r);
    }
}

/// Runs `$visit` with `$sink` bound to the entry `$entry` specialised for `$shape`: the
/// flags are read once per particle, not at every entry.
macro_rules! specialised {
    ($shape:expr, $entry:expr, $sink:ident => $visit:expr) => {
        match ($shape.affine, $shape.fused_force) {
            (false, false) => {
                let $sink = &mut Specialised::<_, _, _, false, false>($entry);
                $visit
            }
            (true, false) => {
                let $sink = &mut Specialised::<_, _, _, true, false>($entry);
                $visit
            }
            (true, true) => {
                let $sink = &mut Specialised::<_, _, _, true, true>($entry);
                $visit
            }
            (false, true) => {
                let $sink = &mut Specialised::<_, _, _, false, true>($entry);
                $visit
            }
        }
    };
}

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// P2G into the grid's mass, |N|-mass (unless the kernel's values are never
    /// negative), stiffness, momentum and force.
    pub(super) fn particles_to_grid(&mut self) -> Result<(), EngineError> {
        let nonnegative = self.kernel.nonnegative_values();
        self.grid.abs_mass_is_mass = nonnegative;
        let fused = self.transfer.shape().fused_force;
        self.grid.momentum_only = fused;
        // MLS-MPM's gradient is D_p⁻¹ N_i r_i, not the kernel's, so the kernel's
        // correction of its gradient does not apply.
        let corrected = self.kernel.force_gradient_correction().filter(|_| !fused);
        // The corrected P2G is compiled only for kernel types that may correct (the
        // guards are constants after monomorphization).
        match (corrected.is_some(), nonnegative) {
            (true, false) if K::MAY_CORRECT_FORCE_GRADIENTS => self.scatter_particles::<true, 1>(),
            (true, true) if K::MAY_CORRECT_FORCE_GRADIENTS => self.scatter_particles::<true, 0>(),
            (_, false) => self.scatter_particles::<false, 1>(),
            (_, true) => self.scatter_particles::<false, 0>(),
        }
    }

    /// [`Self::particles_to_grid`] for a kernel with (`CORRECTED`) or without an
    /// integration correction, summing the |N|-mass (`A` = 1) or not (0).
    fn scatter_particles<const CORRECTED: bool, const A: usize>(
        &mut self,
    ) -> Result<(), EngineError> {
        let shape = self.transfer.shape();
        let stresses = &self.stress_buffer;
        let p = &self.particles;
        let (stencils, kernel, time, step) = (&self.stencils, &self.kernel, self.time, self.step);
        let gravity = self.settings.gravity_at(time);
        let body = &self.body_accelerations;
        let ids = &self.ids;
        let g = &mut self.grid;
        let sums = crate::scatter::NodalSums {
            mass: &mut g.mass,
            abs_mass: &mut g.abs_mass,
            stiffness: &mut g.stiffness,
            momentum: &mut g.momentum,
            force: &mut g.force,
            live: &mut g.live,
            momentum_only: shape.fused_force,
            nonnegative: A == 0,
        };
        // With a constant second moment (B-splines) the affine energy cannot grow as a
        // particle moves, and the limiter has nothing to do.
        let varying_moment = kernel.constant_second_moment().is_none();
        // MLS-MPM's D where it is one constant (B-splines); otherwise each particle's.
        let constant_moment = kernel.constant_second_moment().unwrap_or(f64::NAN);
        let dt = self.dt;
        let ranges = stencils.ranges();
        let correction = kernel.force_gradient_correction().filter(|_| CORRECTED);
        // A tensor-product stencil that is not stored is summed row by row
        // ([`scatter_rows`]), where no entry-wise correction, |N|-mass or limiter needs
        // the entries one by one.
        // (Nor quadratic modes, whose frame P2G evaluates from the whole stencil.)
        let entrywise = CORRECTED || (shape.affine && varying_moment) || shape.quadratic;
        let tensor_width =
            row_width(kernel).filter(|_| A == 0 && !entrywise && stencils.recomputed());
        // Summed row by row, the blocks' windows can be boxes of the kernel's lattice.
        let lattice = tensor_width
            .and(kernel.node_lattice())
            .map(crate::scatter::Lattice::new);
        self.scatter
            .scatter(ranges, ids, sums, lattice.as_ref(), |block, window| {
                let mut scratch = Stencil::new();
                for &i in block {
                    let i = i as usize;
                    let (m, v, x) = (p.mass[i], p.velocity[i], p.position[i]);
                    let volume = p.volume[i];
                    let stress_volume = stresses[i] * volume;
                    let acceleration =
                        gravity + body.get(i).copied().unwrap_or_else(SVector::zeros);
                    let mut sink = ScatterEntry::<D, CORRECTED, A> {
                        window,
                        load: ParticleLoad {
                            mass: m,
                            velocity: v,
                            affine: SMatrix::zeros(),
                            volume,
                            stress_volume,
                            acceleration,
                        },
                        correction: correction.unwrap_or(&[]),
                        correction_mean: SVector::zeros(),
                        modes: None,
                    };
                    let stored_moment = stencils.stored_second_moment(i);
                    // The limiter and the correction's ξ̄_p read the whole stencil before
                    // the first entry, unless the stencil stage stored what they need.
                    // (Quadratic modes have a limiter of their own, below.)
                    let limiter_reads = shape.affine
                        && varying_moment
                        && stored_moment.is_none()
                        && !shape.quadratic;
                    let stored_mean = correction.and(stencils.stored_correction_mean(i));
                    let mean_reads = correction.is_some() && stored_mean.is_none();
                    if let Some(mean) = stored_mean {
                        sink.correction_mean = *mean;
                    }
                    if shape.fused_force {
                        // MLS-MPM: ∇N_i ≈ D⁻¹ N_i r_i folds the stress impulse into the
                        // affine term, and gravity into the momentum.
                        sink.load.velocity = (v + acceleration * dt) * m;
                        if !varying_moment {
                            let inverse_moment = 1.0 / constant_moment;
                            sink.load.affine =
                                p.affine[i] * m - stress_volume * (dt * inverse_moment);
                        } else if let Some(d) = stored_moment {
                            sink.load.affine = fused_affine::<D, K>(
                                &p.affine[i],
                                p.affine_moment[i],
                                d,
                                m,
                                &(stress_volume * dt),
                            )
                            .map_err(|e| (i, e))?;
                        }
                        // Otherwise D_p is summed from the stencil below (`limiter_reads`).
                    } else if let Some(d) = stored_moment.filter(|_| shape.affine) {
                        // D_p summed with the stencil ([`Stencils::compute`]): the entries
                        // are visited once.
                        sink.load.affine = limited_affine(&p.affine[i], p.affine_moment[i], || *d);
                    } else if shape.affine && !limiter_reads {
                        sink.load.affine = p.affine[i];
                    }
                    // The row sums are compiled only for kernel types that may have them.
                    if K::MAY_BE_TENSOR_PRODUCT
                        && let Some(width) = tensor_width
                    {
                        let (window, load) = (&mut *sink.window, &sink.load);
                        match width {
                            3 => {
                                let t = kernel.tensor_stencil::<3>(&x).map_err(|e| (i, e))?;
                                scatter_rows_for::<D, 3>(shape, &t, window, load);
                            }
                            _ => {
                                let t = kernel.tensor_stencil::<4>(&x).map_err(|e| (i, e))?;
                                scatter_rows_for::<D, 4>(shape, &t, window, load);
                            }
                        }
                    } else if limiter_reads || mean_reads || shape.quadratic {
                        // One evaluation serves the whole-stencil sums and the entries.
                        stencils
                            .with(i, kernel, &x, &p.cache[i], &mut scratch, |st| {
                                if let Some(xi) = correction.filter(|_| mean_reads) {
                                    sink.correction_mean = correction_mean(&st, xi);
                                }
                                if shape.fused_force && limiter_reads {
                                    let d = second_moment(&st, kernel, &x);
                                    sink.load.affine = fused_affine::<D, K>(
                                        &p.affine[i],
                                        p.affine_moment[i],
                                        &d,
                                        m,
                                        &(stress_volume * dt),
                                    )?;
                                } else if limiter_reads {
                                    sink.load.affine =
                                        limited_affine(&p.affine[i], p.affine_moment[i], || {
                                            second_moment(&st, kernel, &x)
                                        });
                                }
                                if shape.quadratic {
                                    // The modes' frame at the particle's new position, and one
                                    // limit for C_p and the modes together.
                                    let entries = || {
                                        (0..st.len())
                                            .map(|e| (st.values[e], st.offset(e, kernel, &x)))
                                    };
                                    if let Some((frame, summed)) = ModeFrame::of_stencil(entries())
                                    {
                                        let (c, modes) = (p.affine[i], p.quadratic[i]);
                                        let d = if varying_moment {
                                            summed
                                        } else {
                                            SMatrix::identity() * constant_moment
                                        };
                                        let now = (c * d * c.transpose()).trace()
                                            + frame.energy(&modes, entries());
                                        let limit = field_limit(now, p.affine_moment[i]);
                                        sink.load.affine = c * limit;
                                        sink.modes = Some((frame, modes.map(|m| m * limit)));
                                    }
                                }
                                specialised!(shape, &mut sink, entries => {
                                    for e in 0..st.len() {
                                        let r = st.offset(e, kernel, &x);
                                        entries.entry(
                                            st.nodes[e],
                                            st.values[e],
                                            &st.gradients[e],
                                            &r,
                                        );
                                    }
                                });
                                Ok(())
                            })?
                            .map_err(|e| (i, e))?;
                    } else {
                        specialised!(shape, &mut sink, entries => stencils.visit(
                            i,
                            kernel,
                            &x,
                            &p.cache[i],
                            &mut scratch,
                            shape.affine,
                            entries,
                        ))?;
                    }
                }
                Ok(())
            })
            .map_err(|(particle, source)| EngineError::Kernel {
                step,
                particle,
                source,
            })
    }
}
