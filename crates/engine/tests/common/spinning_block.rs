//! A block of neo-Hookean particles spinning and falling inside the unit box: the scene
//! of the tests that compare whole runs bit for bit (thread counts, particle sorts).

use nalgebra::SVector;
use umls_constitutive::{ElasticParameters, NeoHookean};
use umls_engine::{Particles, Region, Simulation, StepSettings, TransferScheme, lattice_samples};
use umls_transfer::Kernel;

/// Particles on a lattice of spacing `h` filling [0.3, 0.7]^D, density 1000, spinning
/// about the block's centre at `spin` radians per second in the plane of axes 0 and 1.
pub fn particles<const D: usize, C: Copy + Default>(h: f64, spin: f64) -> Particles<D, (), C> {
    let lower = SVector::<f64, D>::from_element(0.3);
    let upper = SVector::<f64, D>::from_element(0.7);
    Particles::seed(
        &lattice_samples(lower, upper, h),
        &Region::Box { lower, upper },
        1000.0,
        (),
        |x| {
            let mut v = SVector::<f64, D>::zeros();
            v[0] = -(x[1] - 0.5) * spin;
            v[1] = (x[0] - 0.5) * spin;
            v
        },
    )
}

/// [`particles`] of neo-Hookean material (E = 10⁴, ν = 0.3) on `kernel` under `settings`
/// with gravity 9.81 along −x_{D−1}, stepped at 0.3 of the stable time step.
pub fn simulation<const D: usize, K: Kernel<D>, T: TransferScheme>(
    kernel: K,
    transfer: T,
    (h, spin): (f64, f64),
    mut settings: StepSettings<D>,
) -> Simulation<D, K, NeoHookean, T> {
    let material = NeoHookean {
        parameters: ElasticParameters::from_young_poisson(1e4, 0.3).unwrap(),
    };
    settings.gravity[D - 1] = -9.81;
    let particles = particles::<D, K::Cache>(h, spin);
    let mut sim = Simulation::new(kernel, material, transfer, particles, settings).unwrap();
    sim.settings.dt = sim.stable_time_step(0.3);
    sim
}
