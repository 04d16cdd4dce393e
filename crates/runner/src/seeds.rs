//! Particles as the set-up seeds them: plain arrays, before they meet a kernel's cache
//! and a material table's state.

use nalgebra::{SMatrix, SVector};

/// Particles as plain arrays, before they meet a kernel and a material type.
#[derive(Debug, Clone, Default)]
pub struct Seeds<const D: usize> {
    /// Positions.
    pub position: Vec<SVector<f64, D>>,
    /// Reference volumes.
    pub volume: Vec<f64>,
    /// Masses.
    pub mass: Vec<f64>,
    /// Initial velocities.
    pub velocity: Vec<SVector<f64, D>>,
    /// Initial affine matrices C_p (zero unless a body's `affine` says otherwise).
    pub affine: Vec<SMatrix<f64, D, D>>,
    /// Material index.
    pub material: Vec<u16>,
    /// The body (index into `[[bodies]]`) that seeded each particle.
    pub body: Vec<u32>,
}
