//! The benchmark scenes of UMLS-MPM, each with its parameters, its background mesh, its
//! particles, and its reference and error metric, runnable with any kernel.
//!
//! | scene | module | reference |
//! |---|---|---|
//! | `vibrating-bar` | [`vibrating_bar`] | analytic mode-1 solution (velocity RMSE, energy error) |
//! | `colliding-disks` | [`colliding_disks`] | momentum conservation, energy history, stress roughness |
//!
//! Swapping the kernel of a scene is one line:
//!
//! ```
//! use umls_engine::Flip;
//! use umls_kernels::{LinearFeKernel, Umls2};
//! use umls_scenes::colliding_disks::CollidingDisks;
//!
//! let scene = CollidingDisks { end_time: 0.05, ..CollidingDisks::default() };
//! assert_eq!(scene.particles::<()>().len(), 416);
//! let mesh = scene.shared_mesh()?;
//!
//! let mut umls = scene.simulation(Umls2::new(mesh.clone()), Flip { alpha: 0.99 })?;
//! let mut fe = scene.simulation(LinearFeKernel::new(mesh), Flip { alpha: 0.99 })?; // the one line
//! for _ in 0..50 {
//!     umls.step()?;
//!     fe.step()?;
//! }
//! // In free flight both kernels move the disks rigidly: same momentum, same energy.
//! let (a, b) = (umls.diagnostics()?, fe.diagnostics()?);
//! assert!((a.kinetic - b.kinetic).abs() < 1e-9 * a.kinetic);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod colliding_disks;
pub mod vibrating_bar;

/// Names of the built-in scenes, with one line each.
pub const SCENES: [(&str, &str); 2] = [
    (
        "vibrating-bar",
        "1D bar fixed at one end, mode-1 vibration against the analytic solution",
    ),
    (
        "colliding-disks",
        "two elastic disks collide and rebound (Sulsky et al. 1994) on a jittered triangle mesh",
    ),
];
