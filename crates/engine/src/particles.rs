//! Particle state, structure of arrays.

use nalgebra::{SMatrix, SVector};

/// The material points: positions, velocities, affine matrices, deformation gradients,
/// reference volumes, masses, per-particle material state and kernel location cache.
#[derive(Debug, Clone)]
pub struct Particles<const D: usize, S, C> {
    /// Positions x_p.
    pub position: Vec<SVector<f64, D>>,
    /// Velocities v_p.
    pub velocity: Vec<SVector<f64, D>>,
    /// Affine velocity matrices C_p (APIC / affine transfers; zero for PIC and FLIP).
    pub affine: Vec<SMatrix<f64, D, D>>,
    /// tr(C_p D_p C_pᵀ) with D_p = Σ N_i (x_i − x_p)(x_i − x_p)ᵀ where G2P set C_p: twice
    /// the kinetic energy per unit mass of the affine motion, which the next P2G may not
    /// exceed (infinite until the first G2P: a C_p given by the user is kept).
    pub affine_moment: Vec<f64>,
    /// Quadratic-mode coefficients Q_p ([`crate::QuadraticApic`]): empty unless the
    /// transfer carries them, then one per particle (zero where not given).
    pub quadratic: Vec<crate::QuadraticModes<D>>,
    /// Deformation gradients F_p.
    pub deformation: Vec<SMatrix<f64, D, D>>,
    /// Reference volumes V_p⁰.
    pub volume: Vec<f64>,
    /// Masses m_p.
    pub mass: Vec<f64>,
    /// Material state (plastic variables).
    pub state: Vec<S>,
    /// Kernel location cache (host simplex or cell).
    pub cache: Vec<C>,
}

impl<const D: usize, S: Clone, C: Copy + Default> Particles<D, S, C> {
    /// Particles at rest at `positions` with reference volumes `volumes`, density `density`
    /// and the material's initial state.
    pub fn at_rest(
        positions: Vec<SVector<f64, D>>,
        volumes: Vec<f64>,
        density: f64,
        state: S,
    ) -> Self {
        let n = positions.len();
        Self {
            velocity: vec![SVector::zeros(); n],
            affine: vec![SMatrix::zeros(); n],
            affine_moment: vec![f64::INFINITY; n],
            quadratic: Vec::new(),
            deformation: vec![SMatrix::identity(); n],
            mass: volumes.iter().map(|v| v * density).collect(),
            volume: volumes,
            state: vec![state; n],
            cache: vec![C::default(); n],
            position: positions,
        }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}
