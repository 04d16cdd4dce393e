//! The Courant check reads the longest move of the step, taken before the walls put a
//! particle back: a particle that a fixed wall stops (its velocity then zero) still
//! reports the distance it moved, in cell widths.

use nalgebra::SVector;
use umls_constitutive::{ElasticParameters, LinearElastic};
use umls_engine::{EngineError, Particles, Pic, Simulation, StepSettings, Wall, WallKind};
use umls_kernels::{BSplineKernel, BSplineOrder};

const H: f64 = 0.1;
const DT: f64 = 1e-3;

/// One particle at x = 0.5 moving right at `courant` cells per step, on a quadratic
/// B-spline grid of spacing `H`, with a fixed wall just ahead of it. The wall holds the
/// particle only: it is given without its nodes, so the grid velocity stays the
/// particle's.
fn run_into_wall(courant: f64) -> Result<(), EngineError> {
    let grid =
        BSplineKernel::new(SVector::from([0.0]), H, [11], BSplineOrder::Quadratic).expect("grid");
    let mut particles = Particles::at_rest(vec![SVector::from([0.5])], vec![0.05], 1.0, ());
    particles.velocity[0] = SVector::from([courant * H / DT]);
    // At F = I the stress is zero: the particle moves at its own velocity.
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(1.0, 0.0).expect("parameters"),
    };
    let mut settings = StepSettings::new(DT);
    settings.max_courant = 0.5;
    let mut sim = Simulation::new(grid, material, Pic, particles, settings)?;
    sim.boundary.walls.push(Wall {
        kind: WallKind::Fixed,
        point: SVector::from([0.5 + 0.1 * H]),
        normal: SVector::from([1.0]),
        friction: 0.0,
    });
    sim.step()?;
    // The wall holds the particle with its velocity zero.
    assert_eq!(sim.particles().velocity[0][0], 0.0);
    assert!((sim.particles().position[0][0] - (0.5 + 0.1 * H)).abs() < 1e-15);
    Ok(())
}

#[test]
fn a_particle_stopped_by_a_wall_reports_its_whole_move() {
    // 0.4 cells: below the limit, and the wall stopped it.
    run_into_wall(0.4).expect("0.4 cells per step is below the limit of 0.5");
    // 0.8 cells: the step fails with the move itself (its square, 0.064 cells, or the
    // held particle's zero speed would pass).
    match run_into_wall(0.8) {
        Err(EngineError::Unstable {
            particle, courant, ..
        }) => {
            assert_eq!(particle, 0);
            assert!((courant - 0.8).abs() < 1e-12, "courant {courant}");
        }
        other => panic!("expected the Courant check to stop the step: {other:?}"),
    }
}
