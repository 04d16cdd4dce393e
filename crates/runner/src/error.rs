//! The command line's error type: every message names the scene key, file or parameter.

use std::path::PathBuf;

use thiserror::Error;

/// Why a command failed.
#[derive(Debug, Error)]
pub enum RunError {
    /// The scene file is not valid TOML or does not match the schema (unknown key, wrong
    /// type); the message from the TOML reader names the key and line.
    #[error("{file}: {message}")]
    SceneSyntax {
        /// The scene file (or built-in scene name).
        file: String,
        /// The reader's message.
        message: String,
    },
    /// A mesh file could not be read; the reader's message names the line or byte.
    #[error("{file}: {message}")]
    MeshFile {
        /// The mesh file.
        file: String,
        /// The reader's message.
        message: String,
    },
    /// A value in the scene is out of range or inconsistent.
    #[error("{file}: `{key}`: {reason}")]
    SceneValue {
        /// The scene file (or built-in scene name).
        file: String,
        /// Dotted path of the key, e.g. `bodies[1].velocity`.
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// Not a built-in scene and not a readable file.
    #[error("no built-in scene `{name}` and no such file (built-in scenes: {known})")]
    UnknownScene {
        /// What was asked for.
        name: String,
        /// The built-in names.
        known: String,
    },
    /// Reading a mesh or writing output failed.
    #[error(transparent)]
    Io(#[from] umls_io::IoError),
    /// A generated mesh is invalid.
    #[error("mesh: {0}")]
    Mesh(#[from] umls_mesh::MeshError),
    /// The run was interrupted (Ctrl-C); its output up to then is written.
    #[error("interrupted at t = {time} (step {step}); the output up to then is written")]
    Interrupted {
        /// Simulated time reached.
        time: f64,
        /// Steps taken.
        step: usize,
    },
    /// The simulation stopped.
    #[error("simulation stopped: {0}")]
    Engine(#[from] umls_engine::EngineError),
    /// The energy plot could not be drawn.
    #[error("{path}: plotting failed: {message}")]
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// The plotting library's message.
        message: String,
    },
    /// A file or directory could not be written.
    #[error("{path}: {source}")]
    File {
        /// The path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// Shorthand.
pub type Result<T> = std::result::Result<T, RunError>;
