//! The benchmark scenes of UMLS-MPM, each with its parameters, its background mesh, its
//! particles, and its reference and error metric, runnable with any kernel.
//!
//! | scene | module | reference |
//! |---|---|---|
//! | `vibrating-bar` | [`vibrating_bar`] | analytic mode-1 solution (velocity RMSE, energy error) |
//! | `colliding-disks` | [`colliding_disks`] | momentum conservation, energy history, stress roughness |
//!
//! ```
//! use umls_scenes::colliding_disks::CollidingDisks;
//!
//! let scene = CollidingDisks::default();
//! let particles = scene.particles::<()>();
//! assert_eq!(particles.len(), 416);
//! assert_eq!(scene.mesh()?.simplex_count(), 800);
//! # Ok::<(), umls_mesh::MeshError>(())
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
