//! P2G and the grid update skip segments of nodes that no particle reached in this step
//! or the last (P2G's windows being boxes of the B-spline lattice); a body crossing a
//! large grid must leave no stale values behind it.

use nalgebra::{SVector, Vector2};
use umls_constitutive::{ElasticParameters, LinearElastic};
use umls_engine::{Particles, Pic, Simulation, StepSettings};
use umls_kernels::{BSplineKernel, BSplineOrder};
use umls_transfer::Kernel;

/// A block of 10 × 10 particles flies diagonally across a 200 × 200 grid (about 40,000
/// nodes, ten chunks): after every step, the nodes beyond the reach of every particle's
/// stencil have no mass and no velocity, and momentum is what it was.
#[test]
fn a_body_crossing_the_grid_leaves_no_stale_nodes() {
    let h = 0.01;
    let grid = BSplineKernel::new(
        SVector::from([0.0, 0.0]),
        h,
        [200, 200],
        BSplineOrder::Quadratic,
    )
    .unwrap();
    let mut x = Vec::new();
    for i in 0..10 {
        for j in 0..10 {
            x.push(Vector2::new(
                0.2 + (i as f64 + 0.5) * 0.005,
                0.2 + (j as f64 + 0.5) * 0.005,
            ));
        }
    }
    let n = x.len();
    let mut particles = Particles::at_rest(x, vec![0.005 * 0.005; n], 1000.0, ());
    for v in &mut particles.velocity {
        *v = Vector2::new(2.0, 3.0);
    }
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(1e4, 0.3).unwrap(),
    };
    let mut sim = Simulation::new(grid, material, Pic, particles, StepSettings::new(1e-3)).unwrap();
    let start = sim.diagnostics().unwrap().momentum;
    for step in 0..200 {
        sim.step().unwrap();
        let reach = 2.0 * h;
        let (mass, velocity) = sim.grid();
        let positions = &sim.particles().position;
        for (node, (m, v)) in mass.iter().zip(velocity).enumerate() {
            let at = sim.kernel.node_position(node);
            let far = positions.iter().all(|p| (p - at).amax() > reach);
            if far {
                assert!(
                    *m == 0.0 && v.norm() == 0.0,
                    "step {step}: node {node} at {at:?} keeps mass {m} and velocity {v:?}"
                );
            }
        }
    }
    let momentum = sim.diagnostics().unwrap().momentum;
    assert!(
        (momentum - start).norm() < 1e-12 * start.norm(),
        "{momentum:?} against {start:?}"
    );
    // The block has crossed several chunks of 4096 nodes (20 rows of 201 nodes each),
    // and many more live segments of 16.
    let centre = sim.particles().position.iter().sum::<Vector2<f64>>() / n as f64;
    assert!(centre.y > 0.7, "{centre:?}");
}
