//! A stencil evaluation that fails is reported the same way whether stencils are stored
//! or recomputed. With recomputed stencils the ordering pass asks a UMLS kernel only for
//! the host's 1-ring range, so the fit's failure comes from P2G instead of stage 1; the
//! error must still be a step error naming the particle and the kernel's cause.

use std::sync::Arc;

use nalgebra::Vector2;
use umls_constitutive::WeaklyCompressibleFluid;
use umls_engine::{EngineError, Particles, Simulation, StencilStorage, StepSettings};
use umls_kernels::{GradientKind, Umls2};
use umls_mesh::{Orientation, SimplexMesh};
use umls_mls::MAX_STENCIL;
use umls_transfer::KernelError;

/// A fan of `n` triangles around the origin: every triangle's 1-ring holds all n + 1
/// vertices.
fn fan(n: usize) -> SimplexMesh<2> {
    let mut vertices = vec![Vector2::zeros()];
    let mut simplices = Vec::new();
    for k in 0..n {
        let angle = std::f64::consts::TAU * k as f64 / n as f64;
        vertices.push(Vector2::new(angle.cos(), angle.sin()));
        simplices.extend([0, 1 + k as u32, 1 + ((k + 1) % n) as u32]);
    }
    SimplexMesh::new(vertices, simplices, Orientation::Fix).unwrap()
}

/// The first step's error with one particle inside the fan, whose stencil overflows the
/// full gradient's fixed capacity.
fn first_step_error(storage: StencilStorage) -> EngineError {
    let mesh = Arc::new(fan(MAX_STENCIL + 6));
    let kernel = Umls2::new(mesh).with_gradient(GradientKind::Full);
    let particles = Particles::at_rest(vec![Vector2::new(0.3, 0.01)], vec![1e-3], 1.0, ());
    let mut settings = StepSettings::new(1e-4);
    settings.stencil_storage = storage;
    let material = WeaklyCompressibleFluid::new(400.0, 1.0).unwrap();
    let mut sim = Simulation::new(kernel, material, umls_engine::Apic, particles, settings)
        .expect("the particle is inside the mesh");
    sim.step().unwrap_err()
}

#[test]
fn a_failing_fit_is_named_alike_with_stored_and_recomputed_stencils() {
    let stored = first_step_error(StencilStorage::Store);
    let recomputed = first_step_error(StencilStorage::Recompute);
    for error in [&stored, &recomputed] {
        match error {
            EngineError::Kernel {
                step: 0,
                particle: 0,
                source: KernelError::Evaluation { kernel, source },
            } => {
                assert_eq!(*kernel, "UMLS");
                let message = source.to_string();
                assert!(message.contains("exceed the stencil capacity"), "{message}");
            }
            other => panic!("expected the particle's kernel error, got {other:?}"),
        }
    }
    assert_eq!(stored.to_string(), recomputed.to_string());
}
