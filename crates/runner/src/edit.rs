//! Editing a scene from the command line, so that studies (refinement, time-step and
//! jitter sweeps, other kernels) run the scene files as they are, without copies:
//!
//! - [`override_text`]: `--set KEY=VALUE` replaces one value of the TOML text before it
//!   is read (`time.cfl=0.5`, `mesh.lattice.jitter=0.3`, `bodies.0.seeding.lattice=0.025`),
//!   and `--set KEY=` removes it (`time.dt=` before `time.cfl=0.5` on a scene with a fixed
//!   step);
//! - [`refine`]: `--refine F` divides every length of the discretisation by `F` (lattice
//!   cells, particle spacing, B-spline grid spacing, a fixed time step), the step of a
//!   convergence study;
//! - [`refine_particles`]: `--particle-refine F` divides the particle spacing alone, so
//!   the particles per cell grow by `F^D`.
//!
//! ```
//! use umls_runner::edit::{override_text, refine};
//! use umls_runner::scene::Scene;
//!
//! let text = umls_runner::builtin::BUILTIN.iter().find(|b| b.name == "vortex").unwrap().toml;
//! let edited = override_text(text, "vortex", &[("time.cfl".into(), "0.1".into())])?;
//! let mut scene = Scene::parse(&edited, "vortex", None)?;
//! assert_eq!(scene.spec.time.cfl, Some(0.1));
//! refine(&mut scene, 2.0)?;
//! assert_eq!(scene.spec.mesh.lattice.as_ref().unwrap().cells, vec![60, 60]);
//! # Ok::<(), umls_runner::RunError>(())
//! ```

pub use crate::scene::{override_text, parse_assignment};

use crate::error::{Result, RunError};
use crate::scene::Scene;
use crate::schema::SeedingSpec;

/// Divides every length of the discretisation by `factor`: the lattice's cells are
/// multiplied (each count must come out whole), the particle spacing, the B-spline grid
/// spacing and a fixed time step divided. A scene on a mesh file cannot be refined this
/// way (the error says so).
pub fn refine(scene: &mut Scene, factor: f64) -> Result<()> {
    check_factor(scene, "--refine", factor)?;
    if factor == 1.0 {
        return Ok(());
    }
    let label = scene.label.clone();
    let Some(lattice) = scene.spec.mesh.lattice.as_mut() else {
        return Err(RunError::SceneValue {
            file: label,
            key: "mesh.file".into(),
            reason: "--refine needs a generated `[mesh.lattice]`; a mesh file is refined by \
                     meshing it again (e.g. scenes/meshes/make_meshes.py)"
                .into(),
        });
    };
    for (axis, cells) in lattice.cells.iter_mut().enumerate() {
        let refined = *cells as f64 * factor;
        if (refined - refined.round()).abs() > 1e-9 || refined < 1.0 {
            return Err(RunError::SceneValue {
                file: label,
                key: format!("mesh.lattice.cells[{axis}]"),
                reason: format!("{cells} cells × {factor} is not a whole number of cells"),
            });
        }
        *cells = refined.round() as usize;
    }
    if let Some(h) = scene.spec.kernel.grid_spacing.as_mut() {
        *h /= factor;
    }
    if let Some(dt) = scene.spec.time.dt.as_mut() {
        *dt /= factor;
    }
    scale_seeding(scene, factor);
    Ok(())
}

/// Divides the particle spacing of every lattice-seeded body by `factor`; bodies seeded
/// at quadrature points are left alone (their count follows the mesh).
pub fn refine_particles(scene: &mut Scene, factor: f64) -> Result<()> {
    check_factor(scene, "--particle-refine", factor)?;
    scale_seeding(scene, factor);
    Ok(())
}

fn scale_seeding(scene: &mut Scene, factor: f64) {
    for body in &mut scene.spec.bodies {
        match &mut body.seeding {
            SeedingSpec::Lattice(h) => *h /= factor,
            SeedingSpec::LatticeFrom { spacing, .. } => *spacing /= factor,
            SeedingSpec::Mesh(_) => {}
        }
    }
}

fn check_factor(scene: &Scene, option: &str, factor: f64) -> Result<()> {
    if factor.is_finite() && factor > 0.0 {
        Ok(())
    } else {
        Err(scene.value_error(option, format!("{factor}: must be positive")))
    }
}
