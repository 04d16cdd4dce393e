//! Loading a scene: a built-in name or a TOML file, parsed into a [`SceneSpec`] and checked.

use std::path::{Path, PathBuf};

use crate::builtin::BUILTIN;
use crate::error::{Result, RunError};
use crate::schema::SceneSpec;

/// A parsed scene and where it came from.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The parsed file.
    pub spec: SceneSpec,
    /// The file path or built-in name, for messages.
    pub label: String,
    /// Directory that relative mesh paths start from (`None` for built-in scenes, whose
    /// meshes are embedded).
    pub base_dir: Option<PathBuf>,
}

impl Scene {
    /// Parses scene text; `label` names it in errors.
    pub fn parse(text: &str, label: &str, base_dir: Option<PathBuf>) -> Result<Self> {
        let spec: SceneSpec = toml::from_str(text).map_err(|e| RunError::SceneSyntax {
            file: label.to_string(),
            message: e.to_string(),
        })?;
        Ok(Self {
            spec,
            label: label.to_string(),
            base_dir,
        })
    }

    /// A built-in scene by name, or else a scene file at that path.
    pub fn load(name_or_path: &str) -> Result<Self> {
        Self::load_with(name_or_path, &[])
    }

    /// [`Scene::load`] with values replaced first (`umls run --set KEY=VALUE`; see
    /// [`override_text`]).
    pub fn load_with(name_or_path: &str, assignments: &[(String, String)]) -> Result<Self> {
        let (text, label, base) = Self::text(name_or_path)?;
        let edited = override_text(&text, &label, assignments)?;
        Self::parse(&edited, &label, base.clone())
            .map_err(|error| Self::blame_edit(&text, &label, assignments, error))
    }

    /// The error of an edited scene that does not parse, told in the user's terms: the
    /// edited text's line numbers mean nothing to them, so an error an edit caused names
    /// the first assignment after which the scene no longer parses, and the file.
    fn blame_edit(
        text: &str,
        label: &str,
        assignments: &[(String, String)],
        error: RunError,
    ) -> RunError {
        if assignments.is_empty() || toml::from_str::<SceneSpec>(text).is_err() {
            return error;
        }
        for n in 1..=assignments.len() {
            let Ok(edited) = override_text(text, label, &assignments[..n]) else {
                return error;
            };
            if let Err(e) = toml::from_str::<SceneSpec>(&edited) {
                let (key, value) = &assignments[n - 1];
                return RunError::SceneValue {
                    file: label.to_string(),
                    key: key.clone(),
                    reason: format!("as set by `--set {key}={value}`: {}", e.message()),
                };
            }
        }
        error
    }

    /// The text of a built-in scene or scene file, its label and its base directory.
    fn text(name_or_path: &str) -> Result<(String, String, Option<PathBuf>)> {
        if let Some(builtin) = BUILTIN.iter().find(|b| b.name == name_or_path) {
            return Ok((builtin.toml.to_string(), builtin.name.to_string(), None));
        }
        let path = Path::new(name_or_path);
        if path.is_dir() {
            return Err(RunError::File {
                path: path.to_path_buf(),
                source: std::io::Error::other(
                    "is a directory; give a scene file (.toml) or a built-in scene name",
                ),
            });
        }
        if !path.is_file() {
            return Err(RunError::UnknownScene {
                name: name_or_path.to_string(),
                known: BUILTIN
                    .iter()
                    .map(|b| b.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        let text = std::fs::read_to_string(path).map_err(|source| RunError::File {
            path: path.to_path_buf(),
            source,
        })?;
        let base = path.parent().map(Path::to_path_buf);
        Ok((text, path.display().to_string(), base))
    }

    /// An error about `key`.
    pub fn value_error(&self, key: impl Into<String>, reason: impl Into<String>) -> RunError {
        RunError::SceneValue {
            file: self.label.clone(),
            key: key.into(),
            reason: reason.into(),
        }
    }

    /// A D-vector from the file's list at `key`: D finite components.
    pub fn vector<const D: usize>(
        &self,
        key: &str,
        values: &[f64],
    ) -> Result<nalgebra::SVector<f64, D>> {
        if values.len() != D {
            return Err(self.value_error(
                key,
                format!(
                    "{} components given, the scene is {D}-dimensional",
                    values.len()
                ),
            ));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(self.value_error(key, "components must be finite"));
        }
        Ok(nalgebra::SVector::from_fn(|k, _| values[k]))
    }

    /// The bytes of the mesh file named in `[mesh] file`.
    pub fn mesh_bytes(&self, file: &str) -> Result<Vec<u8>> {
        self.file_bytes("mesh.file", file)
    }

    /// The contents of a file the scene names at `key` (a mesh, reference data): beside
    /// the scene file, or embedded for a built-in scene.
    pub fn file_bytes(&self, key: &str, file: &str) -> Result<Vec<u8>> {
        match &self.base_dir {
            None => crate::builtin::FILES
                .iter()
                .find(|(name, _)| *name == file)
                .map(|(_, bytes)| bytes.to_vec())
                .ok_or_else(|| self.value_error(key, format!("no embedded file `{file}`"))),
            Some(dir) => {
                let path = dir.join(file);
                std::fs::read(&path).map_err(|source| {
                    self.value_error(key, format!("{}: {source}", path.display()))
                })
            }
        }
    }
}

// `--set KEY=VALUE` on a scene's text, before it is read (see `crate::edit`).
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
    let syntax = |message: String| RunError::SceneSyntax {
        file: label.to_string(),
        message,
    };
    let mut document = toml::Value::Table(
        text.parse::<toml::Table>()
            .map_err(|e: toml::de::Error| syntax(e.to_string()))?,
    );
    for (key, value) in assignments {
        set(&mut document, key, parse_value(value)).map_err(|reason| RunError::SceneValue {
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
