//! The explicit MPM step (symplectic Euler), generic over dimension, kernel, transfer
//! scheme and material. The transfer's [`crate::TransferShape`] is read at run time, so
//! one simulation type can serve every scheme ([`crate::AnyTransfer`]).

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use crate::boundary::Boundary;
use crate::diagnostics::{Diagnostics, Totals};
use crate::error::EngineError;
use crate::geostatic;
use crate::grid::Grid;
use crate::particles::Particles;
use crate::settings::{Damping, StencilStorage, StepSettings, TimeStepControl};
use crate::stencils::Stencils;
use crate::timing::{Lap, StageTimes};
use crate::transfer::{StressUpdate, TransferScheme};

mod body_forces;
mod checks;
mod constitutive;
mod fitted_clamps;
mod grid_to_particles;
mod mass_matrix;
mod musl;
mod particle_sort;
pub(crate) use particle_sort::id_in;
mod particles_to_grid;
mod tensor_rows;

/// A body acceleration b(p, x, t), added to gravity: called with the particle's index p
/// (its place in [`Simulation::particles`] when the simulation was built, which sorting
/// does not change: [`Simulation::particle_id`]), its current position x and the time.
/// The index lets a field depend on where the particle started: a manufactured
/// solution's force is a function of the reference position X, and evaluated at the
/// current position instead it acts on a particle that drifts off the exact motion with
/// the force meant for another place (the `vortex` scene's rim particles were pushed
/// further out by it, docs/scenes.md).
pub type BodyForce<const D: usize> =
    std::sync::Arc<dyn Fn(usize, &SVector<f64, D>, f64) -> SVector<f64, D> + Send + Sync>;

/// Refuses what a fused-force transfer (MLS-MPM) cannot do: its D_p⁻¹ must exist
/// (B-splines' constant one, or an MLS fit's per particle; not linear elements', which
/// vanishes at the vertices), and with no separate nodal force neither damping nor
/// MUSL's re-mapped gradient would act as they say.
fn check_transfer<const D: usize, K: Kernel<D>, T: TransferScheme>(
    transfer: &T,
    kernel: &K,
    settings: &StepSettings<D>,
) -> Result<(), EngineError> {
    if !transfer.shape().fused_force {
        return Ok(());
    }
    let unsupported = |setting, reason| {
        Err(EngineError::Unsupported {
            transfer: transfer.name(),
            setting,
            reason,
        })
    };
    if !kernel.regular_second_moment() {
        return unsupported(
            "a kernel whose second moment D_p can vanish (linear elements)",
            "its force uses ∇N_i = D_p⁻¹ N_i (x_i − x_p), which needs D_p positive definite",
        );
    }
    if settings.damping != crate::settings::Damping::None {
        return unsupported(
            "damping",
            "the force is folded into the momentum, and damping acts on the nodal force",
        );
    }
    if settings.mass_matrix != crate::settings::MassMatrix::Lumped {
        return unsupported(
            "the consistent mass matrix",
            "its momenta carry the force impulse, which the lumped mass must divide",
        );
    }
    if settings.stress_update == StressUpdate::Musl {
        return unsupported(
            "the MUSL stress update",
            "its velocity gradient is C_p, not one re-mapped from the grid",
        );
    }
    Ok(())
}

/// An MPM simulation.
pub struct Simulation<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> {
    /// The shape-function kernel (grid or mesh).
    pub kernel: K,
    /// The material ([`Self::material`], [`Self::material_mut`]).
    material: M,
    /// The transfer scheme.
    pub transfer: T,
    /// The particles ([`Self::particles`], [`Self::particles_mut`]).
    particles: Particles<D, M::State, K::Cache>,
    /// Boundary conditions.
    pub boundary: Boundary<D>,
    /// Step settings.
    pub settings: StepSettings<D>,
    /// Optional body acceleration b(p, x, t), added to `settings.gravity`.
    pub body_force: Option<BodyForce<D>>,
    step: usize,
    time: f64,
    dt: f64,
    totals: Totals<D>,
    stencils: Stencils<D>,
    scatter: crate::scatter::Scatter<D>,
    grid: Grid<D>,
    times: StageTimes,
    // Per-particle buffers the step reuses, so a step allocates nothing once they have
    // grown to the particle count.
    stress_buffer: Vec<SMatrix<f64, D, D>>,
    /// This step's body accelerations b(p, x_p, t), one per particle (empty without a
    /// body force), evaluated once for P2G and G2P.
    body_accelerations: Vec<SVector<f64, D>>,
    /// Whether `stress_buffer` holds the stresses of the particles' current F and state
    /// under the current material (left by the last deformation update; cleared by
    /// every mutable access to particles or material).
    stresses_current: bool,
    /// Scratch and results of the reaction sets' forces.
    reactions: (
        crate::grid::ReactionScratch<D>,
        Vec<crate::boundary::Reaction<D>>,
    ),
    /// This step's least-squares systems of the boundary's fitted clamps.
    clamp_systems: Vec<crate::fitted_clamp::ClampSystem<D>>,
    /// This step's systems of the boundary's face clamps.
    face_systems: Vec<crate::face_clamp::FaceSystem>,
    /// Buffers of the mass-matrix iterations (empty without them).
    mass_solve: mass_matrix::MassSolve<D>,
    /// Per stored particle, its index at construction (empty until the first sort:
    /// [`Self::particle_id`]).
    ids: Vec<u32>,
    /// How many times the particles have been sorted.
    sorts: usize,
}

/// Checks a number setting.
fn check(
    parameter: &'static str,
    value: f64,
    ok: bool,
    reason: &'static str,
) -> Result<(), EngineError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(EngineError::InvalidParameter {
            parameter,
            value,
            reason,
        })
    }
}

impl<const D: usize> StepSettings<D> {
    fn validate(&self) -> Result<(), EngineError> {
        check("dt", self.dt, self.dt > 0.0, "must be finite and positive")?;
        check(
            "gravity_ramp",
            self.gravity_ramp,
            self.gravity_ramp >= 0.0,
            "must be finite and non-negative",
        )?;
        check(
            "energy_growth_limit",
            self.energy_growth_limit,
            self.energy_growth_limit > 1.0,
            "must be finite and above 1",
        )?;
        check(
            "energy_check_interval",
            self.energy_check_interval as f64,
            self.energy_check_interval >= 1,
            "must be at least 1",
        )?;
        if self.max_wave_courant.is_nan() || self.max_wave_courant <= 0.0 {
            return Err(EngineError::InvalidParameter {
                parameter: "max_wave_courant",
                value: self.max_wave_courant,
                reason: "must be positive (infinite switches the check off)",
            });
        }
        check(
            "max_courant",
            self.max_courant,
            self.max_courant > 0.0,
            "must be finite and positive",
        )?;
        check(
            "cancellation_fraction",
            self.cancellation_fraction,
            (0.0..1.0).contains(&self.cancellation_fraction),
            "must lie in [0, 1)",
        )?;
        if self.gravity.iter().any(|g| !g.is_finite()) {
            return Err(EngineError::InvalidParameter {
                parameter: "gravity",
                value: self.gravity.norm(),
                reason: "must be finite",
            });
        }
        if let crate::settings::MassMatrix::Consistent { iterations, forces } = self.mass_matrix {
            check(
                "mass_matrix.iterations",
                iterations as f64,
                iterations >= 1,
                "must be at least 1",
            )?;
            check(
                "mass_matrix.forces",
                forces,
                (0.0..=1.0).contains(&forces),
                "must lie in [0, 1]",
            )?;
        }
        if let TimeStepControl::Adaptive { cfl } = self.time_step {
            check("cfl", cfl, cfl > 0.0, "must be finite and positive")?;
        }
        match self.damping {
            Damping::None => Ok(()),
            Damping::Local { alpha } => check(
                "damping.alpha",
                alpha,
                (0.0..1.0).contains(&alpha),
                "must lie in [0, 1)",
            ),
            Damping::MassProportional { beta } => check(
                "damping.beta",
                beta,
                beta >= 0.0,
                "must be finite and non-negative",
            ),
        }
    }
}

impl<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> Simulation<D, K, M, T> {
    /// A simulation of `particles` on `kernel` with `material` and `transfer`.
    pub fn new(
        kernel: K,
        material: M,
        transfer: T,
        particles: Particles<D, M::State, K::Cache>,
        settings: StepSettings<D>,
    ) -> Result<Self, EngineError> {
        settings.validate()?;
        check_transfer(&transfer, &kernel, &settings)?;
        let nodes = kernel.node_count();
        let grid = Grid::new(nodes, particles.mass.iter().copied().fold(0.0, f64::max));
        Ok(Self {
            kernel,
            material,
            transfer,
            particles,
            boundary: Boundary::default(),
            dt: settings.dt,
            settings,
            body_force: None,
            step: 0,
            time: 0.0,
            totals: Totals::default(),
            stencils: Stencils::default(),
            scatter: Default::default(),
            times: StageTimes::default(),
            stress_buffer: Vec::new(),
            body_accelerations: Vec::new(),
            stresses_current: false,
            reactions: Default::default(),
            clamp_systems: Vec::new(),
            face_systems: Vec::new(),
            mass_solve: Default::default(),
            ids: Vec::new(),
            sorts: 0,
            grid,
        })
    }

    /// The particles, in storage order: the order they were given in, unless
    /// [`StepSettings::particle_sort_interval`] sorts them ([`Self::particle_id`] gives a
    /// slot's index at construction).
    pub fn particles(&self) -> &Particles<D, M::State, K::Cache> {
        &self.particles
    }

    /// The particles, to edit between steps (positions, velocities, F, state, …). The
    /// stresses the last step computed for the next one are recomputed from what the
    /// particles hold after the edit.
    pub fn particles_mut(&mut self) -> &mut Particles<D, M::State, K::Cache> {
        self.stresses_current = false;
        &mut self.particles
    }

    /// The material.
    pub fn material(&self) -> &M {
        &self.material
    }

    /// The material, to change between steps; as for [`Self::particles_mut`], the next
    /// step recomputes the stresses with it.
    pub fn material_mut(&mut self) -> &mut M {
        self.stresses_current = false;
        &mut self.material
    }

    /// Steps taken.
    pub fn step_count(&self) -> usize {
        self.step
    }

    /// Simulated time.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The time step of the last step (the configured one before the first step).
    pub fn last_dt(&self) -> f64 {
        self.dt
    }

    /// The largest wave Courant number Δt / Δt_stable of the steps so far, measured as
    /// the guard measures it (at the speeds and densities each step starts from), the
    /// step the guard refused ([`EngineError::TimeStepTooLarge`]) included; 0 before the
    /// first step.
    pub fn max_wave_courant(&self) -> f64 {
        self.totals.max_wave_courant
    }

    /// The bytes the simulation holds, by what they grow with (after a step, the
    /// scratch buffers have their working size).
    pub fn memory_use(&self) -> crate::memory::MemoryUse {
        use crate::memory::bytes;
        let p = &self.particles;
        let (stored, ranges) = self.stencils.bytes();
        let (order, windows) = self.scatter.bytes();
        crate::memory::MemoryUse {
            particle_count: p.len(),
            particles: bytes(&p.position)
                + bytes(&p.velocity)
                + bytes(&p.affine)
                + bytes(&p.affine_moment)
                + bytes(&p.quadratic)
                + bytes(&p.deformation)
                + bytes(&p.volume)
                + bytes(&p.mass)
                + bytes(&p.state)
                + bytes(&p.cache)
                + bytes(&self.ids),
            particle_scratch: bytes(&self.stress_buffer)
                + bytes(&self.body_accelerations)
                + ranges
                + order,
            stencils: stored,
            nodes: self.grid.bytes()
                + windows
                + self.reactions.0.bytes()
                + bytes(&self.reactions.1)
                + self.mass_solve.bytes(),
        }
    }

    /// Wall time spent in each stage of [`Self::step`] so far.
    pub fn stage_times(&self) -> &StageTimes {
        &self.times
    }

    /// The last step's Δt, or before the first step the one it will take.
    fn current_dt(&self, max_speed: f64, min_density: f64) -> f64 {
        match (self.step, self.settings.time_step) {
            (0, TimeStepControl::Fixed) => self.settings.dt,
            (0, TimeStepControl::Adaptive { cfl }) => {
                self.settings
                    .dt
                    .min(self.stable_step_from(cfl, max_speed, min_density))
            }
            _ => self.dt,
        }
    }

    /// Why the guard refuses a step of `dt` against the stable step `stable`: one
    /// particle kicked beyond the others' speed ([`EngineError::ParticleKick`]) where
    /// the step is stable at the particles' mass-weighted RMS speed, else a step too
    /// large for the waves and the body's motion ([`EngineError::TimeStepTooLarge`]).
    fn step_refused(&self, step: usize, dt: f64, stable: f64) -> EngineError {
        let wave_courant = dt / stable;
        let p = &self.particles;
        let (mass, energy) = p
            .mass
            .iter()
            .zip(&p.velocity)
            .fold((0.0, 0.0), |(m, e), (mp, v)| {
                (m + mp, e + mp * v.norm_squared())
            });
        let rms = if mass > 0.0 {
            (energy / mass).sqrt()
        } else {
            0.0
        };
        let at_rms = self.stable_step_from(1.0, rms, self.totals.min_density);
        // The fastest particle now (the first among equals): the one the guard's speed is.
        let (particle, speed) =
            p.velocity
                .iter()
                .map(|v| v.norm())
                .enumerate()
                .fold(
                    (0, 0.0),
                    |best, (i, s)| if s > best.1 { (i, s) } else { best },
                );
        if rms > 0.0 && dt <= self.settings.max_wave_courant * at_rms {
            return EngineError::ParticleKick {
                step,
                particle,
                speed,
                ratio: speed / rms,
                wave_courant,
            };
        }
        EngineError::TimeStepTooLarge {
            step,
            dt,
            stable,
            wave_courant,
        }
    }

    /// Largest particle speed and smallest particle density m / (V⁰ det F) now.
    fn speed_and_density(&self) -> (f64, f64) {
        let p = &self.particles;
        (0..p.len())
            .into_par_iter()
            .map(|i| {
                let j = umls_constitutive::determinant(&p.deformation[i]);
                (p.velocity[i].norm(), p.mass[i] / (p.volume[i] * j))
            })
            .reduce(|| (0.0, f64::INFINITY), |a, b| (a.0.max(b.0), a.1.min(b.1)))
    }

    /// The explicit step bound cfl · h / (c + |v|_max) from a speed and a density,
    /// divided by the mass matrix's [`crate::MassMatrix::force_step_factor`] when mass
    /// iterations act on the forces (they raise the highest frequency).
    fn stable_step_from(&self, cfl: f64, max_speed: f64, min_density: f64) -> f64 {
        let c = self.material.p_wave_speed(min_density);
        cfl * self.kernel.spacing()
            / (c + max_speed)
            / self.settings.mass_matrix.force_step_factor()
    }

    /// The stable time step for Courant number `cfl`: cfl · h / (c + |v|_max), with h the
    /// kernel's effective spacing ([`Kernel::spacing`]), c the p-wave speed at the
    /// smallest current particle density and |v|_max the fastest particle. The same
    /// definition for every kernel; `cfl` = 1 is the stability limit. With k mass
    /// iterations on the forces ([`crate::MassMatrix::Consistent`]) it is divided by
    /// [`crate::MassMatrix::force_step_factor`] (√k for the consistent matrix).
    pub fn stable_time_step(&self, cfl: f64) -> f64 {
        let (speed, density) = self.speed_and_density();
        self.stable_step_from(cfl, speed, density)
    }

    /// Nodal masses and velocities of the last step (after the grid update).
    pub fn grid(&self) -> (&[f64], &[SVector<f64, D>]) {
        (&self.grid.mass, &self.grid.new_velocity)
    }

    /// The forces the constraints of each of `boundary.reaction_sets` exerted on the
    /// body in the last step (empty before the first step, without sets, or when
    /// `settings.measure_reactions` was off for it).
    pub fn reactions(&self) -> &[crate::boundary::Reaction<D>] {
        &self.reactions.1
    }

    /// Each reaction-set node's reaction in the last step, the sets one after the other
    /// in the order of `boundary.reaction_sets` (empty before the first step).
    pub fn node_reactions(&self) -> &[SVector<f64, D>] {
        &self.reactions.0.nodal
    }

    /// Kirchhoff stress of every particle.
    pub fn stresses(&self) -> Result<Vec<SMatrix<f64, D, D>>, EngineError> {
        let p = &self.particles;
        (0..p.len())
            .into_par_iter()
            .map(|i| {
                self.material
                    .kirchhoff_stress(&p.deformation[i], &p.state[i])
                    .map_err(|source| EngineError::Material {
                        step: self.step,
                        particle: self.particle_id(i),
                        source,
                    })
            })
            .collect()
    }

    /// Σ V⁰ ψ(F) over the particles (in parallel, summed in particle order).
    fn elastic_energy(&self) -> Result<f64, EngineError> {
        let p = &self.particles;
        let energies: Vec<f64> = (0..p.len())
            .into_par_iter()
            .map(|i| {
                self.material
                    .energy_density(&p.deformation[i], &p.state[i])
                    .map(|psi| psi * p.volume[i])
                    .map_err(|source| EngineError::Material {
                        step: self.step,
                        particle: i,
                        source,
                    })
            })
            .collect::<Result<_, _>>()?;
        // Serial sum: the same result for any thread count.
        Ok(energies.iter().sum())
    }

    /// Energies, momentum, speeds and Courant numbers now, with the run's totals.
    pub fn diagnostics(&self) -> Result<Diagnostics<D>, EngineError> {
        let p = &self.particles;
        let elastic = self.elastic_energy()?;
        let mut kinetic = 0.0;
        let mut momentum = SVector::<f64, D>::zeros();
        for (m, v) in p.mass.iter().zip(&p.velocity) {
            kinetic += 0.5 * m * v.norm_squared();
            momentum += v * *m;
        }
        let (max_speed, min_density) = self.speed_and_density();
        let h = self.kernel.spacing();
        let c = self.material.p_wave_speed(min_density);
        let dt = self.current_dt(max_speed, min_density);
        Ok(Diagnostics {
            step: self.step,
            time: self.time,
            dt,
            kinetic,
            elastic,
            external_work: self.totals.external_work,
            momentum,
            mass: p.mass.iter().sum(),
            max_speed,
            courant: max_speed * dt / h,
            wave_courant: (c + max_speed) * dt / h * self.settings.mass_matrix.force_step_factor(),
            dropped_mass: self.totals.dropped_mass,
            redistributed_momentum: self.totals.redistributed_momentum,
            wall_corrections: self.totals.wall_corrections,
            mass_scaled_nodes: self.totals.mass_scaled_nodes,
        })
    }

    /// Sets every particle's stress to the geostatic state of a body at rest under
    /// `settings.gravity`: σ_v = −ρ |g| d along gravity and `k0` σ_v across it, with d the
    /// depth below the highest particle of the particle's vertical column (columns one
    /// particle wide) plus half a particle. Imposed as an elastic pre-strain (see
    /// [`geostatic::prestrain`]), so it works for every material. K0 = ν/(1 − ν) is the
    /// elastic value under lateral confinement.
    pub fn set_geostatic_stress(&mut self, k0: f64) -> Result<(), EngineError> {
        check("k0", k0, k0 >= 0.0, "must be finite and non-negative")?;
        let g = self.settings.gravity;
        if g.norm() == 0.0 {
            return Err(EngineError::InvalidParameter {
                parameter: "gravity",
                value: 0.0,
                reason: "a geostatic stress needs gravity",
            });
        }
        let p = &self.particles;
        let depths = geostatic::depths(&p.position, &p.volume, &g);
        let material = &self.material;
        let stretches: Vec<Result<SMatrix<f64, D, D>, EngineError>> = (0..p.len())
            .into_par_iter()
            .map(|i| {
                let density = p.mass[i] / p.volume[i];
                let target = geostatic::geostatic_stress(&g, density, depths[i], k0);
                geostatic::prestrain(material, &p.state[i], &target).ok_or(
                    EngineError::InitialStress {
                        particle: self.particle_id(i),
                        reason: "the material cannot carry this stress (Newton's method did not converge)",
                    },
                )
            })
            .collect();
        self.stresses_current = false;
        for (f, u) in self.particles.deformation.iter_mut().zip(stretches) {
            *f = u?;
        }
        Ok(())
    }

    /// One explicit step: locate and evaluate stencils, P2G, grid update with boundary
    /// conditions, G2P, walls, deformation and stress update, failure checks (after
    /// storing the particles in P2G's order when
    /// [`StepSettings::particle_sort_interval`] says so). An error names a particle by
    /// its index at construction ([`Self::particle_id`]).
    pub fn step(&mut self) -> Result<(), EngineError> {
        self.step_until(f64::INFINITY)
    }

    /// One step toward `end_time`: [`Self::step`], with an adaptive Δt
    /// ([`TimeStepControl::Adaptive`]) shortened so that it does not pass `end_time`. A
    /// fixed Δt is taken as it is: [`Self::plan_until`] sets it to land on the end time.
    pub fn step_until(&mut self, end_time: f64) -> Result<(), EngineError> {
        if self.sort_due() {
            let mut clock = Lap::start();
            self.sort_particles();
            self.times.stencils += clock.lap();
        }
        self.advance(end_time - self.time)
            .map_err(|e| e.naming_particle_by(|slot| self.particle_id(slot)))
    }

    /// [`Self::step`] without the sort, naming particles by their slots (compiled into
    /// `step`, as the stages were before the sort wrapped them).
    /// `remaining` caps an adaptive Δt (the time left to an end time).
    #[inline(always)]
    fn advance(&mut self, remaining: f64) -> Result<(), EngineError> {
        let step = self.step;
        // The kernel and settings are public fields: a combination the transfer cannot
        // work with may have been set since construction.
        check_transfer(&self.transfer, &self.kernel, &self.settings)?;
        let shape = self.transfer.shape();
        if shape.quadratic {
            // One set of modes per particle, zero for particles given without them
            // (a no-op once sized).
            let n = self.particles.len();
            let zero = [SVector::zeros(); crate::MAX_QUADRATIC_MODES];
            self.particles.quadratic.resize(n, zero);
        }
        if self.totals.initial_energy.is_none() {
            let start = self.diagnostics()?;
            self.totals.initial_energy = Some(start.total_energy());
            self.totals.energy_supplied = start.total_energy();
            (self.totals.max_speed, self.totals.min_density) = self.speed_and_density();
        }
        let dt =
            match self.settings.time_step {
                TimeStepControl::Fixed => self.settings.dt,
                TimeStepControl::Adaptive { cfl } => self.settings.dt.min(remaining).min(
                    self.stable_step_from(cfl, self.totals.max_speed, self.totals.min_density),
                ),
            };
        self.dt = dt;
        // Every condition of this step acts on velocities of its end, where moving
        // obstacles then stand.
        self.boundary.time = self.time + dt;
        // The stability limit with the speeds and densities the step starts from (those
        // an adaptive step is sized by, so a cfl ≤ 1 never trips it).
        let stable = self.stable_step_from(1.0, self.totals.max_speed, self.totals.min_density);
        self.totals.max_wave_courant = self.totals.max_wave_courant.max(dt / stable);
        if dt > self.settings.max_wave_courant * stable {
            return Err(self.step_refused(step, dt, stable));
        }
        let mut clock = Lap::start();
        // 1. Stencils. MUSL reads the start-of-step stencils after the particles have
        // moved, so it needs them stored.
        let storage = match self.settings.stress_update {
            StressUpdate::Musl => StencilStorage::Store,
            StressUpdate::Usl => self.settings.stencil_storage,
        };
        self.stencils
            .compute(
                &self.kernel,
                storage,
                (
                    shape.affine && self.kernel.constant_second_moment().is_none(),
                    !shape.fused_force,
                ),
                &self.particles.position,
                &mut self.particles.cache,
            )
            .map_err(|(particle, source)| EngineError::Kernel {
                step,
                particle,
                source,
            })?;
        self.times.stencils += clock.lap();
        // 2. Stresses, then P2G.
        self.compute_stresses()?;
        self.times.constitutive += clock.lap();
        self.evaluate_body_forces();
        self.particles_to_grid()?;
        self.iterate_mass_matrix()?;
        self.times.particles_to_grid += clock.lap();
        // 3. Grid update, summing the reaction sets' forces only when they will be read.
        let measure = self.settings.measure_reactions && !self.boundary.reaction_sets.is_empty();
        if !measure {
            self.reactions.1.clear();
            self.reactions.0.nodal.clear();
        }
        // Fitted and face clamps change node velocities after the update, so with them
        // the reactions are taken around both.
        let clamps_after_update =
            !self.boundary.fitted.is_empty() || !self.boundary.faces.is_empty();
        if measure && clamps_after_update {
            self.reactions
                .0
                .record(&self.boundary, &self.grid.momentum, &self.grid.force, dt);
        }
        self.boundary.sort_by_node();
        // Only FLIP's G2P reads the velocities before the update.
        self.grid.keep_velocity = shape.uses_flip;
        let report = self.grid.update(
            dt,
            self.material.p_wave_modulus(),
            self.settings.cancellation_fraction,
            self.settings.damping,
            &self.boundary,
            (measure && !clamps_after_update).then_some(&mut self.reactions),
        );
        self.apply_clamps_after_update()?;
        if measure && clamps_after_update {
            let (scratch, out) = &mut self.reactions;
            scratch.reactions(
                &self.boundary,
                &self.grid.mass,
                &self.grid.new_velocity,
                dt,
                out,
            );
        }
        self.totals.dropped_mass += report.dropped_mass;
        self.totals.redistributed_momentum += report.redistributed_momentum;
        self.totals.mass_scaled_nodes += report.scaled_nodes;
        self.totals.external_work += report.boundary_work;
        if let Some(node) = self.grid.first_non_finite_velocity() {
            return Err(EngineError::NonFinite {
                step,
                field: "velocity",
                entity: "node",
                index: node,
            });
        }
        self.times.grid_update += clock.lap();
        // 4. G2P and walls.
        let updated = self.grid_to_particles(dt);
        self.times.grid_to_particles += clock.lap();
        // 5. Deformation and stress update: under USL G2P made it (its time is
        // G2P's); MUSL re-maps the velocities first.
        let min_density = match updated? {
            Some(min_density) => min_density,
            None => {
                self.musl_velocity_gradients()?;
                self.times.grid_to_particles += clock.lap();
                self.update_deformation(dt)?
            }
        };
        self.times.constitutive += clock.lap();
        self.step += 1;
        self.time += dt;
        // 6. Failure detection.
        self.check_particles(step, dt, min_density)?;
        if self.step % self.settings.energy_check_interval == 0 {
            self.check_energy(step)?;
        }
        self.times.checks += clock.lap();
        self.times.steps += 1;
        Ok(())
    }
}
