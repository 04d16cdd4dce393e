//! Walls and friction through the scene runner: Coulomb friction against the sliding
//! block's closed form with every kind of kernel, a grid kernel held inside a curved mesh
//! wall by its signed-distance collider, obstacles at rest and in motion, and the
//! `friction` key's validation.

use umls_runner::RunError;
use umls_runner::run::run;
use umls_runner::scene::Scene;
use umls_runner::schema::KernelKind;

#[path = "common/runs.rs"]
mod runs;
use runs::{completed_run, metric, options, variant};

/// The block slides down the turned incline at g (sin θ − μ cos θ) with the mesh kernels,
/// whose mesh conforms to the incline, and with quadratic B-splines, whose grid the
/// incline cuts: the RMS velocity error over the run stays below 2 % of the final speed,
/// and no particle is put back on the incline more than now and then.
#[test]
fn the_sliding_block_follows_the_closed_form_with_every_kernel() {
    let scene = Scene::load("sliding-block").unwrap();
    for kernel in [KernelKind::Umls, KernelKind::LinearFe, KernelKind::Bspline2] {
        let (s, _) = completed_run(&scene, &format!("slide-{kernel:?}"), kernel, None);
        let error = metric(&s, "velocity_rmse");
        assert!(error < 0.02, "{kernel:?}: velocity_rmse {error}");
    }
    // Without friction the block slides faster than the reference: the error is the
    // whole μ g cos θ T, a third of the final speed.
    let frictionless = variant("sliding-block", &[("friction = 0.2", "friction = 0.0")]);
    let (s, _) = completed_run(&frictionless, "slide-frictionless", KernelKind::Umls, None);
    let error = metric(&s, "velocity_rmse");
    assert!(error > 0.25, "frictionless: velocity_rmse {error}");
}

/// Above the friction angle (μ = 0.8 > tan 30°) the block sticks: its velocity stays
/// under 2 % of the frictionless block's final speed.
#[test]
fn the_block_sticks_above_the_friction_angle() {
    let scene = variant("sliding-block", &[("friction = 0.2", "friction = 0.8")]);
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        let (s, history) = completed_run(&scene, &format!("stick-{kernel:?}"), kernel, None);
        let mass = history.last("mass");
        let momentum = history.last("momentum_x").hypot(history.last("momentum_y"));
        let free = 10.0 * 0.5 * 0.6;
        assert!(
            momentum / mass < 0.02 * free,
            "{kernel:?}: {} m/s, {s}",
            momentum / mass
        );
    }
}

/// A grid kernel in the curved bowl: the mesh's `wall` group reaches it as a collider,
/// so no particle ends beyond the wall (`wall_crossings`), as with UMLS, whose particles
/// the mesh itself holds.
#[test]
fn a_curved_mesh_wall_holds_a_grid_kernels_particles() {
    let scene = Scene::load("fluid-bowl").unwrap();
    for kernel in [KernelKind::Bspline2, KernelKind::Bspline3, KernelKind::Umls] {
        let (s, _) = completed_run(&scene, &format!("bowl-wall-{kernel:?}"), kernel, None);
        assert_eq!(metric(&s, "wall_crossings"), 0.0, "{kernel:?}: {s}");
        assert_eq!(metric(&s, "max_wall_depth"), 0.0, "{kernel:?}");
    }
}

/// `friction` is Coulomb's coefficient of a slip condition: on a fixed one, or negative,
/// it is refused with the key named.
#[test]
fn friction_on_a_fixed_wall_or_below_zero_is_refused() {
    for (replace, expected) in [
        (
            "kind = \"fixed\"\nplane = { point = [0.0, 0.0], normal = [0.0, -1.0] }\nfriction = 0.2",
            "slip",
        ),
        (
            "kind = \"slip\"\nplane = { point = [0.0, 0.0], normal = [0.0, -1.0] }\nfriction = -0.1",
            "negative",
        ),
    ] {
        let scene = variant(
            "sliding-block",
            &[(
                "kind = \"slip\"\nplane = { point = [0.0, 0.0], normal = [0.0, -1.0] }\nfriction = 0.2",
                replace,
            )],
        );
        let err = run(&scene, &options("slide-refused", None, Some(1e-3))).unwrap_err();
        assert!(
            matches!(&err, RunError::SceneValue { key, .. } if key == "boundaries[0].friction"),
            "{err}"
        );
        assert!(err.to_string().contains(expected), "{err}");
    }
}

/// The incline given as a container, the half-space above it, instead of a plane: a
/// signed-distance collider for every kernel, mesh kernels included, that slides the
/// block as the plane does.
#[test]
fn a_container_half_space_holds_the_block_as_the_plane_does() {
    let scene = variant(
        "sliding-block",
        &[(
            "plane = { point = [0.0, 0.0], normal = [0.0, -1.0] }",
            "container = { half-space = { normal = [0.0, -1.0], offset = 0.0 } }",
        )],
    );
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        let name = format!("slide-container-{kernel:?}");
        let (s, _) = completed_run(&scene, &name, kernel, None);
        let error = metric(&s, "velocity_rmse");
        assert!(error < 0.02, "{kernel:?}: velocity_rmse {error}");
        assert_eq!(metric(&s, "wall_crossings"), 0.0, "{kernel:?}");
    }
}

/// A bump on the incline, a ball obstacle: the sliding block runs into it, no particle
/// ends inside the ball, and the obstacle's reaction force is in the history, with a
/// mesh kernel and with a grid kernel.
#[test]
fn no_particle_enters_a_ball_obstacle() {
    let scene = variant(
        "sliding-block",
        &[
            (
                "upper = [1.4, 0.4]\ncells = [28, 8]",
                "upper = [1.4, 0.8]\ncells = [28, 16]",
            ),
            (
                "friction = 0.2\n",
                "friction = 0.2\n\n[[boundaries]]\nkind = \"slip\"\nobstacle = { ball = { centre = [0.9, 0.0], radius = 0.15 } }\n",
            ),
        ],
    );
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        let (s, history) = completed_run(&scene, &format!("bump-{kernel:?}"), kernel, Some(0.45));
        assert_eq!(metric(&s, "wall_crossings"), 0.0, "{kernel:?}: {s}");
        let column = history.column("reaction1_magnitude");
        let pushed = history.rows.iter().map(|r| r[column]).fold(0.0, f64::max);
        assert!(pushed > 0.0, "{kernel:?}: the bump never pushed");
    }
}

/// A rigid pusher in prescribed motion: a box obstacle moving at 0.5 m/s sticks to the
/// block's back face and pushes it along a frictional floor (gravity straight down, no
/// incline). After the contact the block moves with the pusher: its mean velocity over
/// the second half of the run is within 3 % of 0.5 m/s, and no particle is inside the
/// pusher, with a mesh kernel and a grid kernel.
#[test]
fn a_moving_obstacle_pushes_the_block() {
    let scene = variant(
        "sliding-block",
        &[
            (
                "gravity = [5.0, -8.660254037844386]",
                "gravity = [0.0, -10.0]",
            ),
            ("[transform]\nrotation = -30.0\n", ""),
            (
                "friction = 0.2\n",
                "friction = 0.2\n\n[[boundaries]]\nkind = \"fixed\"\nobstacle = { box = { lower = [-0.3, 0.02], upper = [0.08, 0.3] } }\nvelocity = [0.5, 0.0]\n",
            ),
        ],
    );
    for kernel in [KernelKind::Umls, KernelKind::Bspline2] {
        let (s, history) = completed_run(&scene, &format!("pusher-{kernel:?}"), kernel, Some(0.5));
        assert_eq!(metric(&s, "wall_crossings"), 0.0, "{kernel:?}: {s}");
        // The block rings after the impact: its speed is averaged over the rows after
        // 0.25 s, ten periods of its lowest mode.
        let (time, px, mass) = (
            history.column("time"),
            history.column("momentum_x"),
            history.column("mass"),
        );
        let late: Vec<f64> = history
            .rows
            .iter()
            .filter(|r| r[time] > 0.25)
            .map(|r| r[px] / r[mass])
            .collect();
        let speed = late.iter().sum::<f64>() / late.len() as f64;
        assert!((speed / 0.5 - 1.0).abs() < 0.03, "{kernel:?}: {speed} m/s");
    }
}
