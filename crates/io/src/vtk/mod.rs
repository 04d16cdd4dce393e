//! VTK XML output for ParaView: `.vtu` unstructured grids (particles as vertex cells,
//! meshes as simplices) and `.pvd` time collections.
//!
//! Written here rather than with `vtkio`: the format is a few dozen lines of XML, and
//! `vtkio` 0.6 pulls an old dependency tree that today's compilers warn about. The tests
//! read every file back with `vtkio` as an independent parser.

mod grid;
mod pvd;
mod xml;

pub use grid::{CellType, Field, FieldValues, UnstructuredGrid, pad_tensor, pad_vector};
pub use pvd::Collection;
pub use xml::Encoding;
