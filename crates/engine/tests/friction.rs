//! Coulomb friction at a wall against the sliding block's closed form: an elastic block on
//! a plane inclined at θ under gravity g accelerates along it at g (sin θ − μ cos θ) when
//! μ < tan θ, and stays at rest when μ ≥ tan θ. Checked on a quadratic B-spline grid with
//! the wall on a grid line (a planar wall, gravity turned by θ) and with the incline
//! turned against the grid (a signed-distance collider, gravity downwards), where the
//! nodes take the wall's condition along a normal no grid axis has.

use std::sync::Arc;

use nalgebra::{SVector, Vector2};
use umls_constitutive::{ElasticParameters, LinearElastic};
use umls_engine::{
    Apic, Collider, Particles, SampledDistance, Simulation, StepSettings, Wall, WallKind,
};
use umls_kernels::{BSplineKernel, BSplineOrder};

const H: f64 = 0.05;
const G: f64 = 10.0;
const THETA: f64 = std::f64::consts::FRAC_PI_6;
const END: f64 = 0.6;

/// How the incline is given to the engine.
#[derive(Debug, Clone, Copy)]
enum Incline {
    /// A planar wall on the grid line y = 0.5, gravity turned by θ.
    GridLine,
    /// A collider on the plane through (1, 0.5) turned by θ, gravity straight down.
    Turned,
}

/// The block's mean velocity along the incline after `END` seconds of sliding with
/// friction `mu`.
fn slide(incline: Incline, mu: f64) -> f64 {
    let grid = BSplineKernel::new(Vector2::new(0.0, 0.0), H, [60, 40], BSplineOrder::Quadratic)
        .expect("grid");
    // The incline's frame: `along` points down the slope, `up` out of it.
    let (along, up, gravity) = match incline {
        Incline::GridLine => (
            Vector2::new(1.0, 0.0),
            Vector2::new(0.0, 1.0),
            Vector2::new(G * THETA.sin(), -G * THETA.cos()),
        ),
        Incline::Turned => (
            Vector2::new(THETA.cos(), -THETA.sin()),
            Vector2::new(THETA.sin(), THETA.cos()),
            Vector2::new(0.0, -G),
        ),
    };
    let foot = Vector2::new(1.0, 0.5);
    // A 0.4 × 0.2 block resting on the incline, four particles per cell.
    let spacing = H / 2.0;
    let mut positions = Vec::new();
    for i in 0..16 {
        for j in 0..8 {
            let s = -0.8 + (i as f64 + 0.5) * spacing;
            let t = (j as f64 + 0.5) * spacing;
            positions.push(foot + along * s + up * t);
        }
    }
    let n = positions.len();
    let particles = Particles::at_rest(positions, vec![spacing * spacing; n], 1000.0, ());
    let material = LinearElastic {
        parameters: ElasticParameters::from_young_poisson(2e6, 0.3).expect("parameters"),
    };
    let mut settings = StepSettings::new(2e-4);
    settings.gravity = gravity;
    let mut sim = Simulation::new(grid, material, Apic, particles, settings).expect("simulation");
    let wall_normal = -up;
    match incline {
        Incline::GridLine => {
            let wall = Wall {
                kind: WallKind::Slip,
                point: foot,
                normal: wall_normal,
                friction: mu,
            };
            let held = sim.boundary.add_wall(&sim.kernel, wall, 1e-9);
            assert!(!held.is_empty());
        }
        Incline::Turned => {
            let plane = |x: &SVector<f64, 2>| (x - foot).dot(&wall_normal);
            let field = SampledDistance::sample(
                Vector2::new(-0.2, -0.2),
                Vector2::new(3.2, 2.2),
                H / 2.0,
                plane,
            )
            .expect("field");
            let collider = Collider {
                kind: WallKind::Slip,
                friction: mu,
                distance: Arc::new(field),
            };
            let held = sim
                .boundary
                .add_collider(&sim.kernel, collider, 1e-9, 3.0 * H);
            assert!(!held.is_empty());
        }
    }
    while sim.time() < END - 1e-9 {
        sim.step().expect("step");
    }
    let p = sim.particles();
    let mass: f64 = p.mass.iter().sum();
    let momentum: Vector2<f64> = p.mass.iter().zip(&p.velocity).map(|(m, v)| v * *m).sum();
    // No particle went into the incline.
    for x in &p.position {
        assert!(
            (x - foot).dot(&up) > -1e-6 * H,
            "{incline:?}: {x:?} below the incline"
        );
    }
    (momentum / mass).dot(&along)
}

/// Below tan θ the block slides at g (sin θ − μ cos θ), within 4 %.
#[test]
fn a_block_slides_at_the_closed_form_acceleration() {
    for incline in [Incline::GridLine, Incline::Turned] {
        for mu in [0.0, 0.2, 0.4] {
            let exact = G * (THETA.sin() - mu * THETA.cos()) * END;
            let v = slide(incline, mu);
            assert!(
                (v / exact - 1.0).abs() < 0.04,
                "{incline:?}, μ = {mu}: {v} m/s against {exact} m/s"
            );
        }
    }
}

/// At μ ≥ tan θ (0.577) the block sticks: its speed stays below 2 % of the frictionless
/// block's.
#[test]
fn a_block_sticks_above_the_friction_angle() {
    for incline in [Incline::GridLine, Incline::Turned] {
        let v = slide(incline, 0.8);
        let free = G * THETA.sin() * END;
        assert!(v.abs() < 0.02 * free, "{incline:?}: {v} m/s");
    }
}
