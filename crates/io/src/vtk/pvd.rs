//! `.pvd` collections: one file that lists the frames of a time series, so ParaView opens
//! the whole animation at once.

use std::fmt::Write as _;
use std::path::Path;

use super::xml::escape;
use crate::error::Result;
use crate::write_file;

/// A time series of data files.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Collection {
    /// (time, file path relative to the `.pvd`).
    pub frames: Vec<(f64, String)>,
}

impl Collection {
    /// Adds a frame.
    pub fn push(&mut self, time: f64, file: impl Into<String>) {
        self.frames.push((time, file.into()));
    }

    /// The `.pvd` document.
    pub fn to_pvd(&self) -> String {
        let mut out = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (time, file) in &self.frames {
            let _ = writeln!(
                out,
                "    <DataSet timestep=\"{time}\" group=\"\" part=\"0\" file=\"{}\"/>",
                escape(file)
            );
        }
        out.push_str("  </Collection>\n</VTKFile>\n");
        out
    }

    /// Writes the `.pvd` file (rewrite it after each frame to keep it current while a run
    /// is in progress).
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        write_file(path.as_ref(), self.to_pvd().as_bytes())
    }
}
