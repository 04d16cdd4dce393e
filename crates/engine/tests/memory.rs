//! What a simulation holds per particle, from its own accounting
//! (`Simulation::memory_use`): the particle state plus a step's per-particle scratch stays
//! within 400 bytes for quadratic B-splines in 3D (stencils recomputed where used; a step
//! keeps no velocity-gradient buffer besides the stresses) and
//! 600 bytes for UMLS with recomputed stencils; stored stencils add their entries, or
//! about a quarter of that as UMLS factors.

use std::sync::Arc;

use nalgebra::{SVector, Vector3};
use umls_constitutive::WeaklyCompressibleFluid;
use umls_engine::{Apic, MemoryUse, Particles, Simulation, StencilStorage, StepSettings};
use umls_kernels::{BSplineKernel, BSplineOrder, Umls3};
use umls_mesh::generate::Lattice;
use umls_transfer::Kernel;

/// A fluid block of particles spaced `h` in [0.3, 0.7]³ of the unit box, after two steps.
fn memory<K: Kernel<3>>(kernel: K, h: f64, storage: StencilStorage) -> MemoryUse {
    let (x, volume): (Vec<Vector3<f64>>, Vec<f64>) =
        umls_engine::lattice_points(Vector3::repeat(0.3), Vector3::repeat(0.7), h).unzip();
    let particles = Particles::at_rest(x, volume, 1.0, ());
    let mut settings = StepSettings::new(1e-4);
    settings.gravity = Vector3::new(0.0, -9.8, 0.0);
    settings.stencil_storage = storage;
    let material = WeaklyCompressibleFluid::new(400.0, 1.0).unwrap();
    let mut sim = Simulation::new(kernel, material, Apic, particles, settings).unwrap();
    for _ in 0..2 {
        sim.step().unwrap();
    }
    sim.memory_use()
}

#[test]
fn bspline_particles_stay_within_400_bytes_and_stored_stencils_are_the_difference() {
    let grid = BSplineKernel::new(
        SVector::repeat(-0.1),
        0.05,
        [24; 3],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    let recomputed = memory(grid.clone(), 0.02, StencilStorage::KernelChoice);
    assert!(recomputed.particle_count >= 8000);
    assert_eq!(recomputed.stencils, 0, "B-splines recompute by default");
    let per_particle = recomputed.bytes_per_particle();
    assert!(per_particle <= 400.0, "{per_particle} B per particle");
    // The state alone: x, v (24 B each), C, F (72 B each), C's moment, V⁰, m (8 B each).
    assert!(recomputed.particles >= recomputed.particle_count * 216);
    // A step's scratch: the stresses (72 B; G2P leaves the velocity gradients in
    // their slots), the node range (8 B) and the P2G order (16 B: each particle's node,
    // id and slot as its sort key, and the order; the key vector grows by doubling), not
    // a velocity-gradient buffer besides.
    let scratch = recomputed.particle_scratch as f64 / recomputed.particle_count as f64;
    assert!((92.0..120.0).contains(&scratch), "{scratch} B of scratch");
    let stored = memory(grid, 0.02, StencilStorage::Store);
    // 27 entries of a node (4 B), a value (8 B) and a gradient (24 B), in vectors that
    // grow by doubling (so less than twice that).
    let stencil = stored.stencils as f64 / stored.particle_count as f64;
    assert!(
        (27.0 * 36.0..2.0 * 27.0 * 36.0 + 16.0).contains(&stencil),
        "{stencil} B"
    );
    assert_eq!(stored.particles, recomputed.particles);
}

#[test]
fn umls_particles_stay_within_600_bytes_with_recomputed_stencils() {
    let mesh = Arc::new(
        Lattice::new([0.0; 3], [1.0; 3], [16; 3])
            .tetrahedra()
            .unwrap(),
    );
    let recomputed = memory(Umls3::new(mesh.clone()), 0.025, StencilStorage::Recompute);
    assert_eq!(recomputed.stencils, 0);
    let per_particle = recomputed.bytes_per_particle();
    assert!(per_particle <= 600.0, "{per_particle} B per particle");
    let stored = memory(Umls3::new(mesh.clone()), 0.025, StencilStorage::Store);
    assert!(stored.stencils > 0);
    // A stored UMLS stencil has tens of entries of 36 B.
    let stencil = stored.stencils as f64 / stored.particle_count as f64;
    assert!((10.0 * 36.0..64.0 * 36.0).contains(&stencil), "{stencil} B");
    assert!(stored.bytes_per_particle_with_stencils() > per_particle + 10.0 * 36.0);
    // Factored: 8 B per entry (10 to 64 of them), M⁻¹ (16 numbers) and 1/s per particle,
    // and 8 B of offset, in vectors that grow by doubling.
    let factored = memory(Umls3::new(mesh), 0.025, StencilStorage::Factored);
    let got = factored.stencils as f64 / factored.particle_count as f64;
    let per_particle = 17.0 * 8.0 + 8.0;
    assert!(
        (per_particle + 10.0 * 8.0..2.0 * (per_particle + 64.0 * 8.0)).contains(&got),
        "{got} B factored"
    );
    assert!(got < stencil, "{got} B factored, {stencil} B stored");
    assert_eq!(factored.particles, stored.particles);
}
