//! The explicit MPM step (symplectic Euler), generic over dimension, kernel, transfer
//! scheme and material, so a scene compiles to exactly the code it needs.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use crate::boundary::Boundary;
use crate::diagnostics::{Diagnostics, Totals};
use crate::error::EngineError;
use crate::geostatic;
use crate::grid::Grid;
use crate::parallel::lowest_failure;
use crate::particles::Particles;
use crate::settings::{Damping, StepSettings, TimeStepControl};
use crate::stencils::Stencils;
use crate::timing::{Lap, StageTimes};
use crate::transfer::{StressUpdate, TransferScheme};

/// A body acceleration field b(x, t), added to gravity.
pub type BodyForce<const D: usize> =
    std::sync::Arc<dyn Fn(&SVector<f64, D>, f64) -> SVector<f64, D> + Send + Sync>;

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

/// The affine matrix P2G spreads: C_p, scaled down if its kinetic energy at the
/// particle's new position, tr(C D C^T) with D = Σ N r rᵀ there, exceeds what it had
/// where G2P made it. For B-splines D is constant and nothing changes; for linear
/// elements D goes from 0 at a vertex to its largest at the centroid, so a particle
/// moving away from a vertex would carry the affine energy up with it — the energy
/// source that blew up linear elements with APIC. Skipped where D is not positive
/// (negative MLS values): there the bound means nothing.
fn limited_affine<const D: usize, K: Kernel<D>>(
    c: &SMatrix<f64, D, D>,
    moment: f64,
    stencils: &Stencils<D>,
    i: usize,
    kernel: &K,
    x: &SVector<f64, D>,
) -> SMatrix<f64, D, D> {
    if !moment.is_finite() || moment <= 0.0 {
        return if moment == 0.0 { SMatrix::zeros() } else { *c };
    }
    let mut d = SMatrix::<f64, D, D>::zeros();
    let st = stencils.of(i);
    for e in 0..st.len() {
        let r = kernel.node_position(st.nodes[e] as usize) - x;
        d += r * r.transpose() * st.values[e];
    }
    let now = (c * d * c.transpose()).trace();
    if now > moment * (1.0 + 1e-9) {
        c * (moment / now).sqrt()
    } else {
        *c
    }
}

/// An MPM simulation.
pub struct Simulation<const D: usize, K: Kernel<D>, M: Constitutive<D>, T: TransferScheme> {
    /// The shape-function kernel (grid or mesh).
    pub kernel: K,
    /// The material.
    pub material: M,
    /// The transfer scheme.
    pub transfer: T,
    /// The particles.
    pub particles: Particles<D, M::State, K::Cache>,
    /// Boundary conditions.
    pub boundary: Boundary<D>,
    /// Step settings.
    pub settings: StepSettings<D>,
    /// Optional body acceleration field b(x, t), added to `settings.gravity`.
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
    /// Scratch and results of the reaction sets' forces.
    reactions: (
        crate::grid::ReactionScratch<D>,
        Vec<crate::boundary::Reaction<D>>,
    ),
    velocity_gradients: Vec<SMatrix<f64, D, D>>,
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
            reactions: Default::default(),
            velocity_gradients: Vec::new(),
            grid,
        })
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

    /// The explicit step bound cfl · h / (c + |v|_max) from a speed and a density.
    fn stable_step_from(&self, cfl: f64, max_speed: f64, min_density: f64) -> f64 {
        let c = self.material.p_wave_speed(min_density);
        cfl * self.kernel.spacing() / (c + max_speed)
    }

    /// The stable time step for Courant number `cfl`: cfl · h / (c + |v|_max), with h the
    /// kernel's effective spacing ([`Kernel::spacing`]), c the p-wave speed at the
    /// smallest current particle density and |v|_max the fastest particle. The same
    /// definition for every kernel; `cfl` = 1 is the stability limit.
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
                        particle: i,
                        source,
                    })
            })
            .collect()
    }

    /// Kirchhoff stresses into the reused buffer; among failures the lowest particle
    /// index wins, so the report does not depend on the thread count.
    fn compute_stresses(&mut self) -> Result<(), EngineError> {
        let (material, step, p) = (&self.material, self.step, &self.particles);
        self.stress_buffer.resize(p.len(), SMatrix::zeros());
        self.stress_buffer
            .par_iter_mut()
            .enumerate()
            .map(|(i, stress)| -> Result<(), (usize, EngineError)> {
                *stress = material
                    .kirchhoff_stress(&p.deformation[i], &p.state[i])
                    .map_err(|source| {
                        (
                            i,
                            EngineError::Material {
                                step,
                                particle: i,
                                source,
                            },
                        )
                    })?;
                Ok(())
            })
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))
            .map_err(|(_, e)| e)
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
            wave_courant: (c + max_speed) * dt / h,
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
                        particle: i,
                        reason: "the material cannot carry this stress (Newton's method did not converge)",
                    },
                )
            })
            .collect();
        for (f, u) in self.particles.deformation.iter_mut().zip(stretches) {
            *f = u?;
        }
        Ok(())
    }

    /// One explicit step: locate and evaluate stencils, P2G, grid update with boundary
    /// conditions, G2P, walls, deformation and stress update, failure checks.
    pub fn step(&mut self) -> Result<(), EngineError> {
        let step = self.step;
        if self.totals.initial_energy.is_none() {
            let start = self.diagnostics()?;
            self.totals.initial_energy = Some(start.total_energy());
            self.totals.energy_supplied = start.total_energy();
            (self.totals.max_speed, self.totals.min_density) = self.speed_and_density();
        }
        let dt = match self.settings.time_step {
            TimeStepControl::Fixed => self.settings.dt,
            TimeStepControl::Adaptive { cfl } => self.settings.dt.min(self.stable_step_from(
                cfl,
                self.totals.max_speed,
                self.totals.min_density,
            )),
        };
        self.dt = dt;
        // The stability limit with the speeds and densities the step starts from (those
        // an adaptive step is sized by, so a cfl ≤ 1 never trips it).
        let stable = self.stable_step_from(1.0, self.totals.max_speed, self.totals.min_density);
        if dt > self.settings.max_wave_courant * stable {
            return Err(EngineError::TimeStepTooLarge {
                step,
                dt,
                stable,
                wave_courant: dt / stable,
            });
        }
        let mut clock = Lap::start();
        // 1. Stencils.
        self.stencils
            .compute(
                &self.kernel,
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
        self.particles_to_grid();
        self.times.particles_to_grid += clock.lap();
        // 3. Grid update, summing the reaction sets' forces only when they will be read.
        let measure = self.settings.measure_reactions && !self.boundary.reaction_sets.is_empty();
        if !measure {
            self.reactions.1.clear();
            self.reactions.0.nodal.clear();
        }
        let report = self.grid.update(
            dt,
            self.material.p_wave_modulus(),
            self.settings.cancellation_fraction,
            self.settings.damping,
            &self.boundary,
            measure.then_some(&mut self.reactions),
        );
        self.totals.dropped_mass += report.dropped_mass;
        self.totals.redistributed_momentum += report.redistributed_momentum;
        self.totals.mass_scaled_nodes += report.scaled_nodes;
        if let Some(node) = self
            .grid
            .new_velocity
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(EngineError::NonFinite {
                step,
                field: "velocity",
                entity: "node",
                index: node,
            });
        }
        self.times.grid_update += clock.lap();
        // 4. G2P and walls.
        self.grid_to_particles(dt);
        if self.settings.stress_update == StressUpdate::Musl {
            self.velocity_gradients = self.musl_velocity_gradients();
        }
        self.times.grid_to_particles += clock.lap();
        // 5. Deformation and stress update.
        let gradients = std::mem::take(&mut self.velocity_gradients);
        let deformed = self.update_deformation(&gradients, dt);
        self.velocity_gradients = gradients;
        let min_density = deformed?;
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

    /// P2G: every particle's mass, momentum and force to its stencil's nodes, through
    /// [`crate::scatter::Scatter`] (parallel, bitwise independent of the thread count).
    fn particles_to_grid(&mut self) {
        let stresses = &self.stress_buffer;
        let p = &self.particles;
        let (stencils, kernel, time) = (&self.stencils, &self.kernel, self.time);
        let gravity = self.settings.gravity_at(time);
        let body_force = self.body_force.as_ref();
        let g = &mut self.grid;
        let sums = crate::scatter::NodalSums {
            mass: &mut g.mass,
            abs_mass: &mut g.abs_mass,
            stiffness: &mut g.stiffness,
            momentum: &mut g.momentum,
            force: &mut g.force,
        };
        // With a constant second moment (B-splines) the affine energy cannot grow as a
        // particle moves, and the limiter has nothing to do.
        let varying_moment = kernel.constant_second_moment().is_none();
        self.scatter.scatter(stencils, p.len(), sums, |i, window| {
            let (m, v, x) = (p.mass[i], p.velocity[i], p.position[i]);
            let c = match (T::AFFINE, varying_moment) {
                (false, _) => SMatrix::zeros(),
                (true, true) => {
                    limited_affine(&p.affine[i], p.affine_moment[i], stencils, i, kernel, &x)
                }
                (true, false) => p.affine[i],
            };
            let volume = p.volume[i];
            let stress_volume = stresses[i] * volume;
            let acceleration = gravity + body_force.map_or(SVector::zeros(), |b| b(&x, time));
            let st = stencils.of(i);
            for e in 0..st.len() {
                let node = st.nodes[e] as usize;
                let n = st.values[e];
                let gradient = st.gradients[e];
                let mut mv = v;
                if T::AFFINE {
                    mv += c * (kernel.node_position(node) - x);
                }
                window.add(
                    node,
                    n * m,
                    n.abs() * m,
                    volume * gradient.norm_squared(),
                    mv * (n * m),
                    acceleration * (n * m) - stress_volume * gradient,
                );
            }
        });
    }

    /// G2P: velocity, affine matrix, position, velocity gradient; then the walls. The
    /// velocity gradients go to `self.velocity_gradients`.
    fn grid_to_particles(&mut self, dt: f64) {
        let (kernel, transfer, stencils) = (&self.kernel, self.transfer, &self.stencils);
        let (old_v, new_v) = (&self.grid.velocity, &self.grid.new_velocity);
        let moment_scale = kernel.constant_second_moment();
        let constant_moment = moment_scale.map(|s| SMatrix::<f64, D, D>::identity() * s);
        // One particle's G2P from its stencil; evaluated inside the write-back below, so
        // the results go straight to the particle arrays (no per-particle buffer).
        let gather = |i: usize, x: SVector<f64, D>, old: &SVector<f64, D>| {
            let mut pic = SVector::<f64, D>::zeros();
            let mut flip = SVector::<f64, D>::zeros();
            let mut grad_v = SMatrix::<f64, D, D>::zeros();
            let mut b = SMatrix::<f64, D, D>::zeros();
            let mut d = constant_moment.unwrap_or_else(SMatrix::zeros);
            let st = stencils.of(i);
            for e in 0..st.len() {
                let node = st.nodes[e] as usize;
                let n = st.values[e];
                pic += new_v[node] * n;
                flip += (new_v[node] - old_v[node]) * n;
                grad_v += new_v[node] * st.gradients[e].transpose();
                if T::AFFINE && (T::USES_MOMENTS || constant_moment.is_none()) {
                    let r = kernel.node_position(node) - x;
                    if constant_moment.is_none() {
                        d += r * r.transpose() * n;
                    }
                    if T::USES_MOMENTS {
                        b += new_v[node] * r.transpose() * n;
                    }
                }
            }
            let affine = match moment_scale {
                Some(s) => transfer.affine_with_constant_moment(&b, s, &grad_v),
                None => transfer.affine(&b, &d, &grad_v),
            };
            ParticleUpdate {
                velocity: transfer.velocity(old, &pic, &flip),
                position: x + pic * dt,
                affine_moment: if T::AFFINE {
                    (affine * d * affine.transpose()).trace()
                } else {
                    0.0
                },
                affine,
                velocity_gradient: grad_v,
            }
        };
        let mut velocity_gradients = std::mem::take(&mut self.velocity_gradients);
        velocity_gradients.resize(self.particles.len(), SMatrix::zeros());
        let p = &mut self.particles;
        let (gravity, time) = (self.settings.gravity_at(self.time), self.time);
        let body_force = self.body_force.as_ref();
        let (boundary, kernel) = (&self.boundary, &self.kernel);
        let marks = boundary
            .has_node_conditions()
            .then(|| boundary.node_marks(self.grid.mass.len()));
        let chunk = crate::stencils::CHUNK;
        // In parallel over fixed chunks; the partial sums are joined in chunk order.
        let partials: Vec<(f64, (usize, f64), usize)> = p
            .velocity
            .par_chunks_mut(chunk)
            .zip(p.position.par_chunks_mut(chunk))
            .zip(p.affine.par_chunks_mut(chunk))
            .zip(p.affine_moment.par_chunks_mut(chunk))
            .zip(velocity_gradients.par_chunks_mut(chunk))
            .enumerate()
            .map(
                |(c, ((((velocity, position), affine), moment), gradient))| {
                    // Work of gravity and body forces with the mean of old and new velocity:
                    // the trapezoidal rule balances the kinetic energy of a free fall exactly.
                    let mut power = 0.0;
                    // The longest move (the position follows the PIC velocity, which for FLIP
                    // can differ from the stored one): the Courant check reads it.
                    let mut longest = (0, 0.0f64);
                    let mut corrections = 0;
                    for k in 0..velocity.len() {
                        let i = c * chunk + k;
                        let u = &gather(i, position[k], &velocity[k]);
                        let acceleration =
                            body_force.map_or(gravity, |b| gravity + b(&position[k], time));
                        power += p.mass[i] * acceleration.dot(&(velocity[k] + u.velocity)) * 0.5;
                        let moved = (u.position - position[k]).norm();
                        if moved > longest.1 {
                            longest = (i, moved);
                        }
                        velocity[k] = u.velocity;
                        position[k] = u.position;
                        affine[k] = u.affine;
                        moment[k] = u.affine_moment;
                        gradient[k] = u.velocity_gradient;
                        if boundary.hold(&mut position[k], &mut velocity[k]) {
                            corrections += 1;
                        }
                        if let Some(marks) = &marks {
                            if let Some(exit) = kernel.domain_exit(&position[k], &p.cache[i]) {
                                if Boundary::hold_at_facet(
                                    marks,
                                    &exit,
                                    &mut position[k],
                                    &mut velocity[k],
                                ) {
                                    corrections += 1;
                                }
                            }
                        }
                    }
                    (power, longest, corrections)
                },
            )
            .collect();
        let mut power = 0.0;
        let mut longest = (0, 0.0f64);
        for (chunk_power, chunk_longest, corrections) in partials {
            power += chunk_power;
            if chunk_longest.1 > longest.1 {
                longest = chunk_longest;
            }
            self.totals.wall_corrections += corrections;
        }
        self.totals.external_work += power * dt;
        self.totals.longest_move = longest;
        self.velocity_gradients = velocity_gradients;
    }

    /// F ← (I + Δt ∇v) F and the return map; the smallest density m / (V⁰ det F).
    fn update_deformation(
        &mut self,
        velocity_gradients: &[SMatrix<f64, D, D>],
        dt: f64,
    ) -> Result<f64, EngineError> {
        let step = self.step;
        let material = &self.material;
        let p = &mut self.particles;
        let (mass, volume) = (&p.mass, &p.volume);
        p.deformation
            .par_iter_mut()
            .zip(p.state.par_iter_mut())
            .zip(velocity_gradients.par_iter())
            .enumerate()
            .map(|(i, ((f, state), gv))| {
                let fail = |e| (i, e);
                *f = (SMatrix::<f64, D, D>::identity() + gv * dt) * *f;
                if !f.iter().all(|c| c.is_finite()) {
                    return Err(fail(EngineError::NonFinite {
                        step,
                        field: "deformation gradient",
                        entity: "particle",
                        index: i,
                    }));
                }
                let det = umls_constitutive::determinant(f);
                if det <= 0.0 {
                    return Err(fail(EngineError::Inverted {
                        step,
                        particle: i,
                        det,
                    }));
                }
                material.return_map(f, state).map_err(|source| {
                    fail(EngineError::Material {
                        step,
                        particle: i,
                        source,
                    })
                })?;
                Ok(mass[i] / (volume[i] * det))
            })
            // Among failures the lowest particle index wins, so the report does not
            // depend on the thread count.
            .reduce(|| Ok(f64::INFINITY), |a, b| lowest_failure(a, b, f64::min))
            .map_err(|(_, e)| e)
    }

    /// NaN and Courant checks after a step; records speed and density for the next Δt.
    fn check_particles(
        &mut self,
        step: usize,
        dt: f64,
        min_density: f64,
    ) -> Result<(), EngineError> {
        let p = &self.particles;
        if let Some(i) = (0..p.len())
            .find(|&i| !(p.velocity[i].iter().chain(p.position[i].iter())).all(|c| c.is_finite()))
        {
            return Err(EngineError::NonFinite {
                step,
                field: "velocity or position",
                entity: "particle",
                index: i,
            });
        }
        // The fastest particle, the first one among equals.
        let (fastest, max_speed) = p
            .velocity
            .iter()
            .map(|v| v.norm_squared())
            .enumerate()
            .fold((0, 0.0), |a, (i, s)| if s > a.1 { (i, s) } else { a });
        let max_speed = max_speed.max(0.0).sqrt();
        let h = self.kernel.spacing();
        let (mover, moved) = self.totals.longest_move;
        let (particle, courant) = if moved / h > max_speed * dt / h {
            (mover, moved / h)
        } else {
            (fastest, max_speed * dt / h)
        };
        if courant > self.settings.max_courant {
            return Err(EngineError::Unstable {
                step,
                particle,
                courant,
                limit: self.settings.max_courant,
            });
        }
        self.totals.max_speed = max_speed;
        self.totals.min_density = min_density;
        Ok(())
    }

    /// The energy check: kinetic + elastic energy against what was put in.
    fn check_energy(&mut self, step: usize) -> Result<(), EngineError> {
        let p = &self.particles;
        let kinetic: f64 = p
            .mass
            .iter()
            .zip(&p.velocity)
            .map(|(m, v)| 0.5 * m * v.norm_squared())
            .sum();
        let energy = kinetic + self.elastic_energy()?;
        let initial = self.totals.initial_energy.unwrap_or(0.0);
        let t = &mut self.totals;
        t.energy_supplied = t.energy_supplied.max(initial + t.external_work);
        if t.energy_supplied > 0.0 && energy > self.settings.energy_growth_limit * t.energy_supplied
        {
            return Err(EngineError::EnergyBlowUp {
                step,
                energy,
                initial: t.energy_supplied,
                factor: self.settings.energy_growth_limit,
            });
        }
        Ok(())
    }

    /// MUSL: re-map the updated particle momenta to the grid and take the velocity
    /// gradient of that grid velocity (stencils of the start of the step).
    fn musl_velocity_gradients(&mut self) -> Vec<SMatrix<f64, D, D>> {
        let g = &mut self.grid;
        g.momentum.iter_mut().for_each(|m| *m = SVector::zeros());
        let p = &self.particles;
        for i in 0..p.len() {
            let st = self.stencils.of(i);
            for e in 0..st.len() {
                let node = st.nodes[e] as usize;
                g.momentum[node] += p.velocity[i] * (st.values[e] * p.mass[i]);
            }
        }
        let fraction = self.settings.cancellation_fraction;
        for node in 0..g.mass.len() {
            g.velocity[node] = if g.is_active(node, fraction) {
                g.momentum[node] / g.mass[node]
            } else {
                SVector::zeros()
            };
        }
        self.boundary.apply(&mut g.velocity);
        let (stencils, v) = (&self.stencils, &g.velocity);
        (0..p.len())
            .into_par_iter()
            .map(|i| {
                let st = stencils.of(i);
                st.nodes
                    .iter()
                    .zip(st.gradients)
                    .fold(SMatrix::<f64, D, D>::zeros(), |acc, (&node, gradient)| {
                        acc + v[node as usize] * gradient.transpose()
                    })
            })
            .collect()
    }
}
