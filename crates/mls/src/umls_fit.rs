//! A UMLS fit kept in factored form: what an MPM engine stores per particle instead of
//! the stencil's entries, and rebuilds the entries from where it uses them.
//!
//! A reconstructed-gradient fit at x is fixed by the ring's weights w_v, the inverse
//! moment matrix M⁻¹ and the scale s: N_v = w_v (M⁻¹e₀)ᵀ p_v and
//! ∇̃_k N_v = w_v (M⁻¹e_{k+1})ᵀ p_v / s with p_v = p((x_v − x)/s). Stored that way a
//! 3D linear fit takes 8 bytes per ring vertex plus 136 per particle, against 36 per
//! ring vertex for the entries; rebuilding an entry costs one (N × N)·p product.

use nalgebra::{SMatrix, SVector};
use umls_mesh::SimplexMesh;

use crate::basis::PolynomialBasis;
use crate::error::MlsError;
use crate::solve::shape_function;

/// The factors of one reconstructed-gradient UMLS fit besides its weights
/// ([`crate::UmlsKernel::fit_into`]): M⁻¹ and 1/s. [`Self::visit`] rebuilds the
/// stencil's entries bit for bit as [`crate::UmlsKernel::evaluate_into`] gives them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UmlsFit<const N: usize> {
    /// (M⁻¹)ᵀ, whose columns are the rows of M⁻¹: the form an entry is evaluated from.
    inverse_transpose: SMatrix<f64, N, N>,
    inv_scale: f64,
}

impl<const N: usize> UmlsFit<N> {
    /// The number of `f64`s [`Self::write`] writes: N² + 1.
    pub const LEN: usize = N * N + 1;

    /// The fit of inverse moment matrix `inverse` with offsets scaled by 1/`inv_scale`.
    pub fn new(inverse: &SMatrix<f64, N, N>, inv_scale: f64) -> Self {
        Self {
            inverse_transpose: inverse.transpose(),
            inv_scale,
        }
    }

    /// The inverse of the scaled moment matrix, M⁻¹.
    pub fn inverse(&self) -> SMatrix<f64, N, N> {
        self.inverse_transpose.transpose()
    }

    /// 1/s, the inverse of the length the offsets are scaled by.
    pub fn inv_scale(&self) -> f64 {
        self.inv_scale
    }

    /// Writes the fit into `out` (length [`Self::LEN`]): M⁻¹ row by row, then 1/s.
    ///
    /// # Errors
    /// [`MlsError::InvalidParameter`] when `out` has another length.
    pub fn write(&self, out: &mut [f64]) -> Result<(), MlsError> {
        check_len::<N>(out.len())?;
        out[..N * N].copy_from_slice(self.inverse_transpose.as_slice());
        out[N * N] = self.inv_scale;
        Ok(())
    }

    /// Reads a fit that [`Self::write`] wrote.
    ///
    /// # Errors
    /// [`MlsError::InvalidParameter`] when `data` has another length than [`Self::LEN`].
    #[inline]
    pub fn read(data: &[f64]) -> Result<Self, MlsError> {
        check_len::<N>(data.len())?;
        Ok(Self {
            inverse_transpose: SMatrix::from_column_slice(&data[..N * N]),
            inv_scale: data[N * N],
        })
    }

    /// N_v and ∇̃N_v of a ring vertex with weight `weight` at offset x_v − x.
    #[inline(always)]
    pub fn shape_function<const D: usize, B: PolynomialBasis<D, N>>(
        &self,
        weight: f64,
        offset: &SVector<f64, D>,
    ) -> (f64, SVector<f64, D>) {
        shape_function::<D, N, B>(
            &self.inverse_transpose,
            self.inv_scale,
            weight,
            &(offset * self.inv_scale),
        )
    }

    /// Calls `visit(v, N_v, ∇̃N_v, x_v − x)` for every vertex v of the 1-ring of `host`,
    /// in ring order, with the weights `weights` that [`crate::UmlsKernel::fit_into`]
    /// wrote for the same host and `x`.
    ///
    /// # Errors
    /// [`MlsError::NoSuchSimplex`] for a host outside the mesh, [`MlsError::OutputLength`]
    /// when `weights` is not the ring's length.
    // Always inlined: `visit` is an engine's per-entry sum, which must stay in registers.
    #[inline(always)]
    pub fn visit<const D: usize, B: PolynomialBasis<D, N>>(
        &self,
        mesh: &SimplexMesh<D>,
        host: u32,
        x: &SVector<f64, D>,
        weights: &[f64],
        mut visit: impl FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    ) -> Result<(), MlsError> {
        if host as usize >= mesh.simplex_count() {
            return Err(MlsError::NoSuchSimplex {
                simplex: host,
                count: mesh.simplex_count(),
            });
        }
        let ring = mesh.topology().one_ring(host as usize);
        if weights.len() != ring.len() {
            return Err(MlsError::OutputLength {
                simplex: host,
                ring: ring.len(),
                nodes: ring.len(),
                values: weights.len(),
                gradients: ring.len(),
            });
        }
        for (&v, &w) in ring.vertices.iter().zip(weights) {
            let offset = mesh.vertex(v as usize) - x;
            let (value, gradient) = self.shape_function::<D, B>(w, &offset);
            visit(v, value, &gradient, &offset);
        }
        Ok(())
    }
}

fn check_len<const N: usize>(len: usize) -> Result<(), MlsError> {
    if len == UmlsFit::<N>::LEN {
        return Ok(());
    }
    Err(MlsError::InvalidParameter {
        parameter: "factored fit length",
        value: len as f64,
        reason: "differs from N² + 1 for the basis size N",
    })
}
