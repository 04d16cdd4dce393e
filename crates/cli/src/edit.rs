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
//! use umls_cli::edit::{override_text, refine};
//! use umls_cli::scene::Scene;
//!
//! let text = umls_cli::builtin::BUILTIN.iter().find(|b| b.name == "vortex").unwrap().toml;
//! let edited = override_text(text, "vortex", &[("time.cfl".into(), "0.1".into())])?;
//! let mut scene = Scene::parse(&edited, "vortex", None)?;
//! assert_eq!(scene.spec.time.cfl, Some(0.1));
//! refine(&mut scene, 2.0)?;
//! assert_eq!(scene.spec.mesh.lattice.as_ref().unwrap().cells, vec![60, 60]);
//! # Ok::<(), umls_cli::CliError>(())
//! ```

use crate::error::{CliError, Result};
use crate::scene::Scene;
use crate::schema::SeedingSpec;

/// Splits `KEY=VALUE` at the first `=`.
pub fn parse_assignment(text: &str) -> std::result::Result<(String, String), String> {
    let (key, value) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}`: expected KEY=VALUE, e.g. time.cfl=0.5"))?;
    if key.trim().is_empty() {
        return Err(format!("`{text}`: the key is empty"));
    }
    Ok((key.trim().to_string(), value.trim().to_string()))
}

/// The scene text `text` with each `(key, value)` set: a dotted key names nested tables
/// and array elements (`bodies.0.velocity`), missing tables are created, and the value is
/// read as a TOML value (`0.5`, `[20, 88]`, `"umls"`, `{ lattice = 0.05 }`) or else taken
/// as a string (`kind=bspline2`); an empty value removes the key.
pub fn override_text(text: &str, label: &str, assignments: &[(String, String)]) -> Result<String> {
    if assignments.is_empty() {
        return Ok(text.to_string());
    }
    let syntax = |message: String| CliError::SceneSyntax {
        file: label.to_string(),
        message,
    };
    let mut document = toml::Value::Table(
        text.parse::<toml::Table>()
            .map_err(|e: toml::de::Error| syntax(e.to_string()))?,
    );
    for (key, value) in assignments {
        set(&mut document, key, parse_value(value)).map_err(|reason| CliError::SceneValue {
            file: label.to_string(),
            key: key.clone(),
            reason,
        })?;
    }
    toml::to_string(&document).map_err(|e| syntax(format!("cannot write the edited scene: {e}")))
}

/// Sets the value at the dotted `key` inside `document`, or removes it (`None`).
fn set(
    document: &mut toml::Value,
    key: &str,
    value: Option<toml::Value>,
) -> std::result::Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut at = document;
    for (i, part) in parts.iter().enumerate() {
        let walked = parts[..i].join(".");
        let last = i + 1 == parts.len();
        // An array is entered by an index, or implicitly when it has one entry.
        if let toml::Value::Array(items) = at {
            if let Ok(index) = part.parse::<usize>() {
                let count = items.len();
                if index >= count {
                    return Err(format!(
                        "`{walked}` has {count} entries; there is no entry {index}"
                    ));
                }
                if last {
                    match value {
                        Some(v) => items[index] = v,
                        None => {
                            items.remove(index);
                        }
                    }
                    return Ok(());
                }
                at = &mut items[index];
                continue;
            }
            if items.len() != 1 {
                return Err(format!(
                    "`{walked}` is an array of {} entries: name one by its index, e.g. `{walked}.0.{part}`",
                    items.len()
                ));
            }
            at = &mut items[0];
        }
        let toml::Value::Table(table) = at else {
            return Err(format!("`{walked}` is a value, not a table"));
        };
        if last {
            match value {
                Some(v) => table.insert(part.to_string(), v),
                None => table.remove(*part),
            };
            return Ok(());
        }
        at = table
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    }
    Ok(())
}

/// A TOML value, or the text as a string when it is not one; nothing for empty text.
fn parse_value(text: &str) -> Option<toml::Value> {
    if text.is_empty() {
        return None;
    }
    Some(
        format!("v = {text}")
            .parse::<toml::Table>()
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(text.to_string())),
    )
}

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
        return Err(CliError::SceneValue {
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
            return Err(CliError::SceneValue {
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
