//! The explicit MPM step (symplectic Euler), generic over dimension, kernel, transfer
//! scheme and material, so a scene compiles to exactly the code it needs.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use crate::error::EngineError;
use crate::particles::Particles;
use crate::stencils::Stencils;
use crate::transfer::{StressUpdate, TransferScheme};

/// A body acceleration field b(x, t), added to gravity.
pub type BodyForce<const D: usize> =
    std::sync::Arc<dyn Fn(&SVector<f64, D>, f64) -> SVector<f64, D> + Send + Sync>;

/// Velocity boundary conditions on grid nodes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Boundary<const D: usize> {
    /// Nodes whose velocity is zero.
    pub fixed: Vec<u32>,
    /// Nodes whose velocity loses its component along the given unit normal
    /// (frictionless slip; only the outward, separating component is kept if
    /// `separate` is set).
    pub slip: Vec<(u32, SVector<f64, D>)>,
    /// Whether slip nodes may move away from the wall (v·n > 0 kept).
    pub separate: bool,
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

    /// Fixes every node on the plane (see [`Self::nodes_on_plane`]).
    pub fn fix_plane<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        point: &SVector<f64, D>,
        normal: &SVector<f64, D>,
        tolerance: f64,
    ) {
        self.fixed
            .extend(Self::nodes_on_plane(kernel, point, normal, tolerance));
    }

    /// Frictionless slip along the plane for every node on it, with the plane's unit normal.
    pub fn slip_plane<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        point: &SVector<f64, D>,
        normal: &SVector<f64, D>,
        tolerance: f64,
    ) {
        let unit = normal.normalize();
        self.slip.extend(
            Self::nodes_on_plane(kernel, point, normal, tolerance)
                .into_iter()
                .map(|n| (n, unit)),
        );
    }

    fn apply(&self, velocity: &mut [SVector<f64, D>]) {
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
    }
}

/// Step settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSettings<const D: usize> {
    /// Time step Δt.
    pub dt: f64,
    /// Body acceleration (gravity).
    pub gravity: SVector<f64, D>,
    /// Where the stress is updated.
    pub stress_update: StressUpdate,
    /// Stop with [`EngineError::EnergyBlowUp`] when the total energy exceeds this factor
    /// times its initial value (checked when the initial energy is positive).
    pub energy_growth_limit: f64,
    /// Nodes with mass below this fraction of the largest nodal mass are treated as empty
    /// (zero velocity): MLS shape functions can be negative or tiny at the edge of a stencil.
    pub min_mass_fraction: f64,
}

impl<const D: usize> StepSettings<D> {
    /// Time step `dt`, no gravity, USL, energy limit 10×, mass threshold 10⁻¹⁰.
    pub fn new(dt: f64) -> Self {
        Self {
            dt,
            gravity: SVector::zeros(),
            stress_update: StressUpdate::Usl,
            energy_growth_limit: 10.0,
            min_mass_fraction: 1e-10,
        }
    }
}

/// Energies and momentum of the particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diagnostics<const D: usize> {
    /// Step number.
    pub step: usize,
    /// Time.
    pub time: f64,
    /// Σ ½ m |v|².
    pub kinetic: f64,
    /// Σ V⁰ ψ(F).
    pub elastic: f64,
    /// Σ m v.
    pub momentum: SVector<f64, D>,
    /// Σ m.
    pub mass: f64,
    /// max |v|.
    pub max_speed: f64,
    /// Courant number max|v| Δt / h.
    pub courant: f64,
}

impl<const D: usize> Diagnostics<D> {
    /// Kinetic plus elastic energy.
    pub fn total_energy(&self) -> f64 {
        self.kinetic + self.elastic
    }
}

/// Particle blocks of the parallel P2G scatter: a fixed number, so that results do not
/// depend on the thread count; more blocks than cores keeps the work balanced.
const P2G_BLOCKS: usize = 8;

/// Below this many particles the scatter runs as one block: resetting and reducing the
/// per-block grid buffers would cost more than it saves.
const P2G_PARALLEL_MIN: usize = 8192;

/// One block's share of the nodal sums.
#[derive(Default)]
struct GridBuffer<const D: usize> {
    mass: Vec<f64>,
    momentum: Vec<SVector<f64, D>>,
    force: Vec<SVector<f64, D>>,
}

impl<const D: usize> GridBuffer<D> {
    fn reset(&mut self, nodes: usize) {
        self.mass.clear();
        self.mass.resize(nodes, 0.0);
        self.momentum.clear();
        self.momentum.resize(nodes, SVector::zeros());
        self.force.clear();
        self.force.resize(nodes, SVector::zeros());
    }
}

/// What G2P computes for one particle.
struct ParticleUpdate<const D: usize> {
    velocity: SVector<f64, D>,
    /// Moved with the PIC velocity Σ N ṽ_i.
    position: SVector<f64, D>,
    affine: SMatrix<f64, D, D>,
    velocity_gradient: SMatrix<f64, D, D>,
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
    initial_energy: Option<f64>,
    stencils: Stencils<D>,
    blocks: Vec<GridBuffer<D>>,
    node_mass: Vec<f64>,
    node_momentum: Vec<SVector<f64, D>>,
    node_force: Vec<SVector<f64, D>>,
    node_velocity: Vec<SVector<f64, D>>,
    node_new_velocity: Vec<SVector<f64, D>>,
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
        if !(settings.dt.is_finite() && settings.dt > 0.0) {
            return Err(EngineError::InvalidParameter {
                parameter: "dt",
                value: settings.dt,
                reason: "must be finite and positive",
            });
        }
        let nodes = kernel.node_count();
        Ok(Self {
            kernel,
            material,
            transfer,
            particles,
            boundary: Boundary::default(),
            settings,
            body_force: None,
            step: 0,
            time: 0.0,
            initial_energy: None,
            stencils: Stencils::default(),
            blocks: Vec::new(),
            node_mass: vec![0.0; nodes],
            node_momentum: vec![SVector::zeros(); nodes],
            node_force: vec![SVector::zeros(); nodes],
            node_velocity: vec![SVector::zeros(); nodes],
            node_new_velocity: vec![SVector::zeros(); nodes],
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

    /// The largest stable time step for CFL number `cfl`: cfl · h / c, with c the p-wave
    /// speed at the smallest particle density.
    pub fn stable_time_step(&self, cfl: f64) -> f64 {
        let density = self
            .particles
            .mass
            .iter()
            .zip(&self.particles.volume)
            .map(|(m, v)| m / v)
            .fold(f64::INFINITY, f64::min);
        cfl * self.kernel.spacing() / self.material.p_wave_speed(density)
    }

    /// Nodal masses and velocities of the last step (after the grid update).
    pub fn grid(&self) -> (&[f64], &[SVector<f64, D>]) {
        (&self.node_mass, &self.node_new_velocity)
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

    /// Energies, momentum and speed now.
    pub fn diagnostics(&self) -> Result<Diagnostics<D>, EngineError> {
        let p = &self.particles;
        let energies: Vec<f64> = (0..p.len())
            .into_par_iter()
            .map(|i| {
                self.material
                    .energy_density(&p.deformation[i], &p.state[i])
                    .map(|psi| psi * p.volume[i])
            })
            .collect::<Result<_, _>>()
            .map_err(|source| EngineError::Material {
                step: self.step,
                particle: 0,
                source,
            })?;
        // Serial sums: the same result for any thread count.
        let elastic = energies.iter().sum();
        let mut kinetic = 0.0;
        let mut momentum = SVector::<f64, D>::zeros();
        let mut max_speed: f64 = 0.0;
        for (m, v) in p.mass.iter().zip(&p.velocity) {
            kinetic += 0.5 * m * v.norm_squared();
            momentum += v * *m;
            max_speed = max_speed.max(v.norm());
        }
        Ok(Diagnostics {
            step: self.step,
            time: self.time,
            kinetic,
            elastic,
            momentum,
            mass: p.mass.iter().sum(),
            max_speed,
            courant: max_speed * self.settings.dt / self.kernel.spacing(),
        })
    }

    /// One explicit step: locate and evaluate stencils, P2G, grid update with boundary
    /// conditions, G2P, deformation and stress update, failure checks.
    pub fn step(&mut self) -> Result<(), EngineError> {
        let dt = self.settings.dt;
        let step = self.step;
        if self.initial_energy.is_none() {
            self.initial_energy = Some(self.diagnostics()?.total_energy());
        }
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
        // 2. P2G. Stresses in parallel, then the scatter in P2G_BLOCKS fixed particle blocks,
        // each into its own grid buffer, in parallel; buffers are summed per node in block
        // order. The split does not depend on the thread count, so neither do the sums.
        let stresses = self.stresses()?;
        let p = &self.particles;
        let (stencils, kernel, settings, time) =
            (&self.stencils, &self.kernel, &self.settings, self.time);
        let body_force = self.body_force.as_ref();
        let block_count = if p.len() < P2G_PARALLEL_MIN {
            1
        } else {
            P2G_BLOCKS
        };
        let block_len = p.len().div_ceil(block_count).max(1);
        let nodes = self.node_mass.len();
        self.blocks.resize_with(block_count, GridBuffer::default);
        self.blocks
            .par_iter_mut()
            .enumerate()
            .for_each(|(block, buffer)| {
                buffer.reset(nodes);
                let end = ((block + 1) * block_len).min(p.len());
                let start = (block * block_len).min(end);
                for (i, stress) in stresses.iter().enumerate().take(end).skip(start) {
                    let (m, v, c, x) = (p.mass[i], p.velocity[i], p.affine[i], p.position[i]);
                    let stress_volume = stress * p.volume[i];
                    let acceleration =
                        settings.gravity + body_force.map_or(SVector::zeros(), |b| b(&x, time));
                    for e in stencils.range(i) {
                        let node = stencils.nodes[e] as usize;
                        let n = stencils.values[e];
                        buffer.mass[node] += n * m;
                        let mut mv = v;
                        if T::AFFINE {
                            mv += c * (kernel.node_position(node) - x);
                        }
                        buffer.momentum[node] += mv * (n * m);
                        buffer.force[node] +=
                            acceleration * (n * m) - stress_volume * stencils.gradients[e];
                    }
                }
            });
        let blocks = &self.blocks;
        self.node_mass
            .par_iter_mut()
            .zip(self.node_momentum.par_iter_mut())
            .zip(self.node_force.par_iter_mut())
            .enumerate()
            .for_each(|(node, ((mass, momentum), force))| {
                *mass = blocks.iter().map(|b| b.mass[node]).sum();
                *momentum = blocks
                    .iter()
                    .fold(SVector::zeros(), |acc, b| acc + b.momentum[node]);
                *force = blocks
                    .iter()
                    .fold(SVector::zeros(), |acc, b| acc + b.force[node]);
            });
        // 3. Grid update.
        let threshold =
            self.settings.min_mass_fraction * self.node_mass.iter().copied().fold(0.0, f64::max);
        for node in 0..self.node_mass.len() {
            let m = self.node_mass[node];
            if m > threshold {
                self.node_velocity[node] = self.node_momentum[node] / m;
                self.node_new_velocity[node] =
                    self.node_velocity[node] + self.node_force[node] * (dt / m);
            } else {
                self.node_velocity[node] = SVector::zeros();
                self.node_new_velocity[node] = SVector::zeros();
            }
        }
        self.boundary.apply(&mut self.node_velocity);
        self.boundary.apply(&mut self.node_new_velocity);
        if let Some(node) = self
            .node_new_velocity
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
        // 4. G2P: velocity, affine matrix, position, velocity gradient.
        let (kernel, transfer, stencils) = (&self.kernel, self.transfer, &self.stencils);
        let (old_v, new_v) = (&self.node_velocity, &self.node_new_velocity);
        let positions = &self.particles.position;
        let velocities = &self.particles.velocity;
        let updates: Vec<ParticleUpdate<D>> = (0..self.particles.len())
            .into_par_iter()
            .with_min_len(crate::stencils::CHUNK)
            .map(|i| {
                let x = positions[i];
                let mut pic = SVector::<f64, D>::zeros();
                let mut flip = SVector::<f64, D>::zeros();
                let mut grad_v = SMatrix::<f64, D, D>::zeros();
                let mut b = SMatrix::<f64, D, D>::zeros();
                let mut d = SMatrix::<f64, D, D>::zeros();
                for e in stencils.range(i) {
                    let node = stencils.nodes[e] as usize;
                    let n = stencils.values[e];
                    pic += new_v[node] * n;
                    flip += (new_v[node] - old_v[node]) * n;
                    grad_v += new_v[node] * stencils.gradients[e].transpose();
                    if T::USES_MOMENTS {
                        let r = kernel.node_position(node) - x;
                        b += new_v[node] * r.transpose() * n;
                        d += r * r.transpose() * n;
                    }
                }
                ParticleUpdate {
                    velocity: transfer.velocity(&velocities[i], &pic, &flip),
                    position: x + pic * dt,
                    affine: transfer.affine(&b, &d, &grad_v),
                    velocity_gradient: grad_v,
                }
            })
            .collect();
        let mut velocity_gradients = Vec::with_capacity(updates.len());
        for (i, update) in updates.into_iter().enumerate() {
            self.particles.velocity[i] = update.velocity;
            self.particles.position[i] = update.position;
            self.particles.affine[i] = update.affine;
            velocity_gradients.push(update.velocity_gradient);
        }
        if self.settings.stress_update == StressUpdate::Musl {
            velocity_gradients = self.musl_velocity_gradients(threshold);
        }
        // 5. Deformation and stress update.
        let material = &self.material;
        let results: Vec<Result<(), EngineError>> = self
            .particles
            .deformation
            .par_iter_mut()
            .zip(self.particles.state.par_iter_mut())
            .zip(velocity_gradients.par_iter())
            .enumerate()
            .map(|(i, ((f, state), gv))| {
                *f = (SMatrix::<f64, D, D>::identity() + gv * dt) * *f;
                if !f.iter().all(|c| c.is_finite()) {
                    return Err(EngineError::NonFinite {
                        step,
                        field: "deformation gradient",
                        entity: "particle",
                        index: i,
                    });
                }
                let det = umls_constitutive::determinant(f);
                if det <= 0.0 {
                    return Err(EngineError::Inverted {
                        step,
                        particle: i,
                        det,
                    });
                }
                material
                    .return_map(f, state)
                    .map_err(|source| EngineError::Material {
                        step,
                        particle: i,
                        source,
                    })
            })
            .collect();
        results.into_iter().collect::<Result<Vec<()>, _>>()?;
        self.step += 1;
        self.time += dt;
        // 6. Failure detection.
        if let Some(i) = self
            .particles
            .velocity
            .iter()
            .zip(&self.particles.position)
            .position(|(v, x)| !(v.iter().chain(x.iter()).all(|c| c.is_finite())))
        {
            return Err(EngineError::NonFinite {
                step,
                field: "velocity or position",
                entity: "particle",
                index: i,
            });
        }
        if let Some(initial) = self.initial_energy.filter(|e| *e > 0.0) {
            let energy = self.diagnostics()?.total_energy();
            if energy > self.settings.energy_growth_limit * initial {
                return Err(EngineError::EnergyBlowUp {
                    step,
                    energy,
                    initial,
                    factor: self.settings.energy_growth_limit,
                });
            }
        }
        Ok(())
    }

    /// MUSL: re-map the updated particle momenta to the grid and take the velocity
    /// gradient of that grid velocity (stencils of the start of the step).
    fn musl_velocity_gradients(&mut self, threshold: f64) -> Vec<SMatrix<f64, D, D>> {
        self.node_momentum
            .iter_mut()
            .for_each(|m| *m = SVector::zeros());
        let p = &self.particles;
        for i in 0..p.len() {
            for e in self.stencils.range(i) {
                let node = self.stencils.nodes[e] as usize;
                self.node_momentum[node] += p.velocity[i] * (self.stencils.values[e] * p.mass[i]);
            }
        }
        for node in 0..self.node_mass.len() {
            let m = self.node_mass[node];
            self.node_velocity[node] = if m > threshold {
                self.node_momentum[node] / m
            } else {
                SVector::zeros()
            };
        }
        self.boundary.apply(&mut self.node_velocity);
        let (stencils, v) = (&self.stencils, &self.node_velocity);
        (0..p.len())
            .into_par_iter()
            .map(|i| {
                stencils
                    .range(i)
                    .fold(SMatrix::<f64, D, D>::zeros(), |acc, e| {
                        acc + v[stencils.nodes[e] as usize] * stencils.gradients[e].transpose()
                    })
            })
            .collect()
    }
}
