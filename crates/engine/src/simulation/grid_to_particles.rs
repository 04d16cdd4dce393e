//! Stage 4 of the step, G2P: velocity, affine matrix, position and velocity gradient
//! from the grid, then the walls.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::{Kernel, KernelError, Stencil, regular_inverse};

use super::Simulation;
use super::constitutive::update_one;
use super::tensor_rows::{gather_rows, row_width};
use crate::boundary::Boundary;
use crate::error::EngineError;
use crate::parallel::lowest_failure;
use crate::quadratic_modes::{ModeSums, QuadraticModes};
use crate::stencils::{EntrySink, Stencils};
use crate::transfer::{SingularSecondMoment, StressUpdate, TransferScheme, TransferShape};

/// What G2P computes for one particle.
#[derive(Debug, Clone, Copy)]
struct ParticleUpdate<const D: usize> {
    velocity: SVector<f64, D>,
    /// Moved with the PIC velocity Σ N ṽ_i.
    position: SVector<f64, D>,
    affine: SMatrix<f64, D, D>,
    affine_moment: f64,
    velocity_gradient: SMatrix<f64, D, D>,
}

/// The grid velocities before (`old`) and after (`new`) the grid update.
struct GridVelocities<'a, const D: usize> {
    old: &'a [SVector<f64, D>],
    new: &'a [SVector<f64, D>],
}

/// A particle's G2P sums over its stencil.
struct GatherSums<'a, const D: usize> {
    grid: &'a GridVelocities<'a, D>,
    /// Whether D_p is summed here (a kernel whose D_p varies, not stored with the
    /// stencil).
    sum_moment: bool,
    offsets: bool,
    pic: SVector<f64, D>,
    flip: SVector<f64, D>,
    grad_v: SMatrix<f64, D, D>,
    b: SMatrix<f64, D, D>,
    d: SMatrix<f64, D, D>,
    /// The quadratic modes' sums (`None` unless the transfer has them, so that the other
    /// transfers do not carry them through the stencil's loop).
    modes: Option<ModeSums<D>>,
}

impl<const D: usize> GatherSums<'_, D> {
    /// One entry's share of the sums, compiled for a transfer that reads the FLIP
    /// increment (`FLIP`) or not, and takes ∇v from C_p (`FUSED`) or sums it.
    #[inline(always)]
    fn add<const FLIP: bool, const FUSED: bool>(
        &mut self,
        node: u32,
        n: f64,
        gradient: &SVector<f64, D>,
        r: &SVector<f64, D>,
    ) {
        let node = node as usize;
        let v = self.grid.new[node];
        self.pic += v * n;
        if FLIP {
            self.flip += (v - self.grid.old[node]) * n;
        }
        if !FUSED {
            self.grad_v += v * gradient.transpose();
        }
        if self.offsets {
            if self.sum_moment {
                self.d += r * r.transpose() * n;
            }
            // Summed for every scheme with offsets, B_p's readers and the
            // velocity-gradient transfer alike (a few flops per node against a branch).
            self.b += v * r.transpose() * n;
            if let Some(modes) = &mut self.modes {
                modes.add(n, &v, r);
            }
        }
    }
}

/// [`GatherSums`] with the transfer's flags as constants, so the stencil's loop has no
/// branch on them.
struct Specialised<'s, 'g, const D: usize, const FLIP: bool, const FUSED: bool>(
    &'s mut GatherSums<'g, D>,
);

impl<const D: usize, const FLIP: bool, const FUSED: bool> EntrySink<D>
    for Specialised<'_, '_, D, FLIP, FUSED>
{
    #[inline(always)]
    fn entry(&mut self, node: u32, n: f64, gradient: &SVector<f64, D>, r: &SVector<f64, D>) {
        self.0.add::<FLIP, FUSED>(node, n, gradient, r);
    }
}

/// One particle's G2P: particle `p` at position `x` with velocity `old`, its stencil
/// visited once (recomputed ones without being stored, [`Stencils::visit`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn gather<const D: usize, K: Kernel<D>, T: TransferScheme, const FLIP: bool, const FUSED: bool>(
    stencils: &Stencils<D>,
    p: usize,
    cache: &K::Cache,
    scratch: &mut Stencil<D>,
    kernel: &K,
    transfer: &T,
    shape: TransferShape,
    grid: &GridVelocities<'_, D>,
    x: SVector<f64, D>,
    old: &SVector<f64, D>,
    dt: f64,
    modes_out: Option<&mut QuadraticModes<D>>,
) -> Result<ParticleUpdate<D>, (usize, KernelError)> {
    let moment_scale = kernel.constant_second_moment();
    let offsets = shape.affine && (shape.uses_moments || moment_scale.is_none());
    let stored_moment = stencils.stored_second_moment(p);
    let new_sums = || GatherSums::<D> {
        grid,
        sum_moment: moment_scale.is_none() && stored_moment.is_none(),
        offsets,
        pic: SVector::zeros(),
        flip: SVector::zeros(),
        grad_v: SMatrix::zeros(),
        b: SMatrix::zeros(),
        d: match (moment_scale, stored_moment) {
            (Some(s), _) => SMatrix::identity() * s,
            (None, Some(d)) => *d,
            (None, None) => SMatrix::zeros(),
        },
        modes: shape.quadratic.then(ModeSums::default),
    };
    // A tensor-product stencil that is not stored is summed row by row, where D_p is
    // constant or unused. Stored entries get sums of their own, which no kernel call
    // takes: they stay in registers (through `visit`, whose other modes pass the sink
    // to the kernel, they were reloaded from memory at every entry).
    let tensor_width = row_width(kernel).filter(|_| {
        stencils.recomputed() && (moment_scale.is_some() || !shape.affine) && !shape.quadratic
    });
    // The row sums are compiled only for kernel types that may have them.
    let sums = if K::MAY_BE_TENSOR_PRODUCT
        && let Some(width) = tensor_width
    {
        // The rows compiled for this loop's FLIP and FUSED, and for whether B_p is read.
        let (pic, flip, grad_v, b) = match (width, shape.uses_moments) {
            (3, false) => gather_rows::<D, 3, false, FUSED, FLIP>(
                &kernel.tensor_stencil::<3>(&x).map_err(|e| (p, e))?,
                grid.new,
                grid.old,
            ),
            (3, true) => gather_rows::<D, 3, true, FUSED, FLIP>(
                &kernel.tensor_stencil::<3>(&x).map_err(|e| (p, e))?,
                grid.new,
                grid.old,
            ),
            (_, false) => gather_rows::<D, 4, false, FUSED, FLIP>(
                &kernel.tensor_stencil::<4>(&x).map_err(|e| (p, e))?,
                grid.new,
                grid.old,
            ),
            (_, true) => gather_rows::<D, 4, true, FUSED, FLIP>(
                &kernel.tensor_stencil::<4>(&x).map_err(|e| (p, e))?,
                grid.new,
                grid.old,
            ),
        };
        GatherSums {
            pic,
            flip,
            grad_v,
            b,
            ..new_sums()
        }
    } else if stencils.stores_entries() {
        let mut sums = new_sums();
        let sink = &mut Specialised::<_, FLIP, FUSED>(&mut sums);
        stencils.visit_entries(p, kernel, &x, offsets, sink);
        sums
    } else {
        let mut sums = new_sums();
        let sink = &mut Specialised::<_, FLIP, FUSED>(&mut sums);
        stencils.visit(p, kernel, &x, cache, scratch, offsets, sink)?;
        sums
    };
    let GatherSums {
        pic,
        flip,
        grad_v,
        b,
        d,
        modes,
        ..
    } = sums;
    // The modes' energy joins C_p's in the moment P2G's limiter reads.
    let mut mode_energy = 0.0;
    if shape.quadratic {
        if let (Some(out), Some(modes)) = (modes_out, modes) {
            (*out, mode_energy) = modes.fit(&pic, &b, &d);
        }
    }
    // Read through the shape, so that a scheme chosen at run time ([`AnyTransfer`]) is
    // asked only what its shape says it answers.
    let affine = match moment_scale {
        _ if !shape.affine => SMatrix::zeros(),
        Some(s) => transfer.affine_with_constant_moment(&b, s, &grad_v),
        // MLS-MPM's C_p is also its velocity gradient, so it has no fallback where D_p
        // is singular (APIC's is ∇v): the particle is reported, as P2G reports it.
        None if FUSED => {
            b * regular_inverse(&d).ok_or_else(|| (p, SingularSecondMoment::of::<D, K>(&d)))?
        }
        None => transfer.affine(&b, &d, &grad_v),
    };
    Ok(ParticleUpdate {
        velocity: if FLIP {
            transfer.velocity(old, &pic, &flip)
        } else {
            pic
        },
        position: x + pic * dt,
        // tr(C D Cᵀ), which P2G's limiter compares with at the next position; with
        // D = s I it is s |C|² (and P2G reads it only where D varies or quadratic modes
        // add their energy).
        affine_moment: mode_energy
            + match (shape.affine, moment_scale) {
                (false, _) => 0.0,
                (true, Some(s)) => s * affine.norm_squared(),
                (true, None) => (affine * d * affine.transpose()).trace(),
            },
        affine,
        // MLS-MPM takes C_p as the velocity gradient (its ∇N is D⁻¹ N r).
        velocity_gradient: if FUSED { affine } else { grad_v },
    })
}

/// One chunk's share of the G2P totals.
#[derive(Debug)]
struct ChunkTotals {
    /// Work of the body loads.
    power: f64,
    /// The longest move (particle, squared distance).
    longest: (usize, f64),
    /// Particles the walls put back.
    corrections: usize,
    /// The fastest particle (the first among equals) and its speed².
    fastest: (usize, f64),
    /// The first particle left with a non-finite velocity or position.
    non_finite: Option<usize>,
    /// The smallest density m / (V⁰ det F) after the deformation update, where G2P
    /// made it (infinite otherwise).
    min_density: f64,
    /// The deformation update's first failure (particle, error), where G2P made it.
    deformation_failure: Option<(usize, EngineError)>,
}

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// G2P and the walls, and under USL each particle's deformation update (stage 5)
    /// right after its G2P, while the particle is in cache: that returns the smallest
    /// density the update found. Under MUSL the velocity gradients go to the stress
    /// buffer instead (P2G has read this step's stresses), where the re-map overwrites
    /// them and [`Self::update_deformation`] turns each into the next stress in place,
    /// and this returns `None`.
    ///
    /// A kernel error anywhere comes first (the lowest particle's), then a deformation
    /// update's (the lowest particle's, after the G2P totals are recorded): the order
    /// the stages report in when they run one after the other.
    pub(super) fn grid_to_particles(&mut self, dt: f64) -> Result<Option<f64>, EngineError> {
        self.stresses_current = false;
        let deform = self.settings.stress_update == StressUpdate::Usl;
        let material = &self.material;
        let mut stress_slots = std::mem::take(&mut self.stress_buffer);
        stress_slots.resize(self.particles.len(), SMatrix::zeros());
        let (kernel, transfer, stencils) = (&self.kernel, self.transfer, &self.stencils);
        let shape = transfer.shape();
        let quadratic = shape.quadratic;
        let grid = GridVelocities {
            old: &self.grid.velocity,
            new: &self.grid.new_velocity,
        };
        let p = &mut self.particles;
        let (mass, volume) = (&p.mass, &p.volume);
        // The modes' chunks where the transfer has them (sized with the particles at the
        // step's start), `None` per chunk otherwise.
        let chunks = p.velocity.len().div_ceil(crate::stencils::CHUNK);
        let mode_chunks = p
            .quadratic
            .par_chunks_mut(crate::stencils::CHUNK)
            .map(Some)
            .chain(rayon::iter::repeat_n((), chunks).map(|_| None));
        let (gravity, step) = (self.settings.gravity_at(self.time), self.step);
        let body = &self.body_accelerations;
        let boundary = &self.boundary;
        // The node marks are built at the first particle that leaves the kernel's
        // domain (mesh kernels at walls given as node sets), not every step: a grid
        // kernel never asks, and the marks are a pass over every node.
        let conditions = boundary.has_node_conditions();
        let nodes = self.grid.mass.len();
        let marks = std::sync::OnceLock::new();
        let chunk = crate::stencils::CHUNK;
        // In parallel over fixed chunks; each particle's results go straight to the
        // particle arrays, and the partial sums are joined in chunk order.
        let partials: Result<Vec<ChunkTotals>, _> = p
            .velocity
            .par_chunks_mut(chunk)
            .zip(p.position.par_chunks_mut(chunk))
            .zip(p.affine.par_chunks_mut(chunk))
            .zip(p.affine_moment.par_chunks_mut(chunk))
            .zip(stress_slots.par_chunks_mut(chunk))
            .zip(p.cache.par_chunks_mut(chunk))
            .zip(p.deformation.par_chunks_mut(chunk))
            .zip(p.state.par_chunks_mut(chunk))
            .zip(mode_chunks)
            .enumerate()
            .map(
                |(
                    c,
                    (
                        (((((((velocity, position), affine), moment), slot), cache), fs), states),
                        mut modes,
                    ),
                )| {
                    // The chunk's slices at one length, so the loop below indexes them
                    // without a bounds check per particle and array.
                    let n = velocity.len();
                    let (position, affine, moment) =
                        (&mut position[..n], &mut affine[..n], &mut moment[..n]);
                    let (slot, cache) = (&mut slot[..n], &mut cache[..n]);
                    let (fs, states) = (&mut fs[..n], &mut states[..n]);
                    let mass = &mass[c * chunk..c * chunk + n];
                    let volume = &volume[c * chunk..c * chunk + n];
                    let mut scratch = Stencil::new();
                    // Work of gravity and body forces with the mean of old and new velocity:
                    // the trapezoidal rule balances the kinetic energy of a free fall exactly.
                    let mut power = 0.0;
                    // The longest move (the position follows the PIC velocity, which for FLIP
                    // can differ from the stored one): the Courant check reads it. Squared
                    // lengths are compared, and the root is taken once, of the longest (a
                    // root per particle stalled the loop: 5 % of G2P's samples).
                    let mut longest = (0, 0.0f64);
                    let mut corrections = 0;
                    // What the step's checks read, gathered here while the particle is
                    // in cache instead of in a serial pass after the step.
                    let mut fastest = (0, 0.0f64);
                    let mut non_finite = None;
                    let mut min_density = f64::INFINITY;
                    // A failing update does not stop the chunk, as in
                    // [`Simulation::update_deformation`].
                    let mut deformation_failure = None;
                    // The loop compiled for the transfer's shape (the FLIP increment read
                    // or not, the force fused or not), chosen once per chunk: no branch
                    // on it per particle or stencil entry.
                    macro_rules! particles {
                        ($flip:literal, $fused:literal) => {
                            for k in 0..n {
                                let i = c * chunk + k;
                                let x = position[k];
                                let u = gather::<D, K, T, $flip, $fused>(
                                    stencils,
                                    i,
                                    &cache[k],
                                    &mut scratch,
                                    kernel,
                                    &transfer,
                                    shape,
                                    &grid,
                                    x,
                                    &velocity[k],
                                    dt,
                                    modes
                                        .as_deref_mut()
                                        .filter(|_| quadratic)
                                        .map(|m| &mut m[k]),
                                )?;
                                let acceleration = body.get(i).map_or(gravity, |b| gravity + b);
                                power +=
                                    mass[k] * acceleration.dot(&(velocity[k] + u.velocity)) * 0.5;
                                let moved = (u.position - x).norm_squared();
                                if moved > longest.1 {
                                    longest = (i, moved);
                                }
                                velocity[k] = u.velocity;
                                position[k] = u.position;
                                affine[k] = u.affine;
                                moment[k] = u.affine_moment;
                                if deform {
                                    // The particle's stress slot takes its next stress (under
                                    // MUSL its velocity gradient, which the re-map replaces).
                                    match update_one(
                                        material,
                                        &mut fs[k],
                                        &mut states[k],
                                        &u.velocity_gradient,
                                        &mut slot[k],
                                        dt,
                                        step,
                                        i,
                                    ) {
                                        Ok(det) => {
                                            min_density =
                                                min_density.min(mass[k] / (volume[k] * det));
                                        }
                                        Err(e) => {
                                            deformation_failure.get_or_insert((i, e));
                                        }
                                    }
                                } else {
                                    slot[k] = u.velocity_gradient;
                                }
                                if boundary.hold(&mut position[k], &mut velocity[k]) {
                                    corrections += 1;
                                }
                                if conditions {
                                    if let Some(exit) =
                                        kernel.domain_exit(&position[k], &mut cache[k])
                                    {
                                        if Boundary::hold_at_facet(
                                            marks.get_or_init(|| boundary.node_marks(nodes)),
                                            &exit,
                                            &mut position[k],
                                            &mut velocity[k],
                                        ) {
                                            corrections += 1;
                                        }
                                    }
                                }
                                let speed = velocity[k].norm_squared();
                                if speed > fastest.1 {
                                    fastest = (i, speed);
                                }
                                if non_finite.is_none()
                                    && !velocity[k]
                                        .iter()
                                        .chain(position[k].iter())
                                        .all(|c| c.is_finite())
                                {
                                    non_finite = Some(i);
                                }
                            }
                        };
                    }
                    match (shape.uses_flip, shape.fused_force) {
                        (false, false) => particles!(false, false),
                        (true, false) => particles!(true, false),
                        (false, true) => particles!(false, true),
                        (true, true) => particles!(true, true),
                    }
                    Ok(vec![ChunkTotals {
                        power,
                        longest,
                        corrections,
                        fastest,
                        non_finite,
                        min_density,
                        deformation_failure,
                    }])
                },
            )
            .reduce(
                || Ok(Vec::new()),
                |a, b| {
                    lowest_failure(a, b, |mut x, y| {
                        x.extend(y);
                        x
                    })
                },
            );
        self.stress_buffer = stress_slots;
        let partials = partials.map_err(|(particle, source)| EngineError::Kernel {
            step,
            particle,
            source,
        })?;
        let mut power = 0.0;
        let mut longest = (0, 0.0f64);
        let mut fastest = (0, 0.0f64);
        let mut non_finite = None;
        let mut min_density = f64::INFINITY;
        let mut deformation_failure = None;
        for chunk in partials {
            power += chunk.power;
            if chunk.longest.1 > longest.1 {
                longest = chunk.longest;
            }
            if chunk.fastest.1 > fastest.1 {
                fastest = chunk.fastest;
            }
            non_finite = non_finite.or(chunk.non_finite);
            self.totals.wall_corrections += chunk.corrections;
            min_density = min_density.min(chunk.min_density);
            // The chunks come in particle order: the first failure is the lowest.
            deformation_failure = deformation_failure.or(chunk.deformation_failure);
        }
        self.totals.external_work += power * dt;
        self.totals.longest_move = (longest.0, longest.1.sqrt());
        self.totals.fastest = fastest;
        self.totals.first_non_finite = non_finite;
        if !deform {
            return Ok(None);
        }
        // Whole only if every particle got its stress.
        self.stresses_current = deformation_failure.is_none();
        match deformation_failure {
            Some((_, e)) => Err(e),
            None => Ok(Some(min_density)),
        }
    }
}
