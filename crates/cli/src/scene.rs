//! Loading a scene: a built-in name or a TOML file, parsed into a [`SceneSpec`] and checked.

use std::path::{Path, PathBuf};

use crate::builtin::BUILTIN;
use crate::error::{CliError, Result};
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
        let spec: SceneSpec = toml::from_str(text).map_err(|e| CliError::SceneSyntax {
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
    /// [`crate::edit::override_text`]).
    pub fn load_with(name_or_path: &str, assignments: &[(String, String)]) -> Result<Self> {
        let (text, label, base) = Self::text(name_or_path)?;
        let text = crate::edit::override_text(&text, &label, assignments)?;
        Self::parse(&text, &label, base)
    }

    /// The text of a built-in scene or scene file, its label and its base directory.
    fn text(name_or_path: &str) -> Result<(String, String, Option<PathBuf>)> {
        if let Some(builtin) = BUILTIN.iter().find(|b| b.name == name_or_path) {
            return Ok((builtin.toml.to_string(), builtin.name.to_string(), None));
        }
        let path = Path::new(name_or_path);
        if path.is_dir() {
            return Err(CliError::File {
                path: path.to_path_buf(),
                source: std::io::Error::other(
                    "is a directory; give a scene file (.toml) or a built-in scene name",
                ),
            });
        }
        if !path.is_file() {
            return Err(CliError::UnknownScene {
                name: name_or_path.to_string(),
                known: BUILTIN
                    .iter()
                    .map(|b| b.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        let text = std::fs::read_to_string(path).map_err(|source| CliError::File {
            path: path.to_path_buf(),
            source,
        })?;
        let base = path.parent().map(Path::to_path_buf);
        Ok((text, path.display().to_string(), base))
    }

    /// An error about `key`.
    pub fn value_error(&self, key: impl Into<String>, reason: impl Into<String>) -> CliError {
        CliError::SceneValue {
            file: self.label.clone(),
            key: key.into(),
            reason: reason.into(),
        }
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
