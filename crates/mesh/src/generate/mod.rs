//! Mesh generators for tests and scenes: intervals, rectangles and boxes on a
//! (possibly graded, jittered, rotated) lattice.
//!
//! All three are one generic [`Lattice`] of vertices; the dimension-specific
//! part is only how each lattice cell is split into simplices.

mod lattice;
mod rng;
mod split;

pub use lattice::{Lattice, MAX_JITTER, MAX_JITTER_PLANAR, Spacing};
pub use split::Diagonal;
