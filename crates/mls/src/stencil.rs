//! The result of one MLS evaluation: node indices, shape functions and gradients,
//! in fixed-capacity arrays on the stack.

use nalgebra::{SMatrix, SVector};

use crate::error::MlsError;

/// Largest number of samples one evaluation can take (a 3D 1-ring is ~30 on Kuhn meshes,
/// up to ~50 on irregular ones).
pub const MAX_STENCIL: usize = 64;

/// Which derivative of the shape functions to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GradientKind {
    /// The fit's own linear coefficients, ∇̃N_v = [0 I] M⁻¹ w_v p(x_v − x) / s. Continuous
    /// wherever M and the weights are (so across facets for UMLS), exact for linear fields,
    /// and cheaper. The default, and what MPM uses.
    #[default]
    Reconstructed,
    /// The full derivative ∇N_v, including the weights' gradients. Exact derivative of the
    /// shape function; for UMLS it inherits the jump of ∇η across facets.
    Full,
    /// For UMLS: the derivative of N_v with the diminishing factors η held at their values
    /// at x, so only the distance weights d_v vary (∇w_v = η_v ∇d_v). Continuous across
    /// facets, since η is continuous and a vertex whose η vanishes there enters with zero
    /// weight and zero weight gradient, and exact for linear fields, like the
    /// reconstructed gradient; it keeps the part of the full derivative that comes from
    /// the smooth distance weights and leaves out ∇η, the part that jumps. For other
    /// evaluations the caller's weight gradients are used, as with [`Self::Full`].
    FrozenEta,
}

impl GradientKind {
    /// Whether the weights' gradients enter the shape-function gradient (every kind but
    /// [`Self::Reconstructed`]).
    pub fn uses_weight_gradients(self) -> bool {
        self != Self::Reconstructed
    }
}

/// Shape functions of one evaluation point: stencil nodes, N_v and a gradient of N_v.
#[derive(Debug, Clone)]
pub struct Stencil<const D: usize> {
    pub(crate) len: usize,
    pub(crate) nodes: [u32; MAX_STENCIL],
    pub(crate) values: [f64; MAX_STENCIL],
    pub(crate) gradients: [SVector<f64, D>; MAX_STENCIL],
    pub(crate) condition: f64,
    pub(crate) gradient_kind: GradientKind,
}

impl<const D: usize> Default for Stencil<D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const D: usize> Stencil<D> {
    /// An empty stencil, to be filled by an evaluation.
    pub fn new() -> Self {
        Self {
            len: 0,
            nodes: [0; MAX_STENCIL],
            values: [0.0; MAX_STENCIL],
            gradients: [SVector::zeros(); MAX_STENCIL],
            condition: f64::NAN,
            gradient_kind: GradientKind::Reconstructed,
        }
    }

    /// Empties the stencil for refilling with [`Self::push`].
    #[inline]
    pub fn clear(&mut self) {
        self.len = 0;
        self.condition = f64::NAN;
    }

    /// Appends a node with its shape function value and gradient (for kernels that do not
    /// go through the MLS solve, such as finite elements and B-splines).
    #[inline]
    pub fn push(
        &mut self,
        node: u32,
        value: f64,
        gradient: SVector<f64, D>,
    ) -> Result<(), MlsError> {
        if self.len == MAX_STENCIL {
            return Err(MlsError::StencilOverflow {
                simplex: None,
                samples: self.len + 1,
                capacity: MAX_STENCIL,
            });
        }
        self.nodes[self.len] = node;
        self.values[self.len] = value;
        self.gradients[self.len] = gradient;
        self.len += 1;
        Ok(())
    }

    /// Number of nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the stencil has no nodes.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Node (sample) indices.
    #[inline]
    pub fn nodes(&self) -> &[u32] {
        &self.nodes[..self.len]
    }

    /// Shape function values N_v, one per node.
    #[inline]
    pub fn values(&self) -> &[f64] {
        &self.values[..self.len]
    }

    /// Shape function gradients, one per node, of the kind in [`Self::gradient_kind`].
    #[inline]
    pub fn gradients(&self) -> &[SVector<f64, D>] {
        &self.gradients[..self.len]
    }

    /// Which gradient [`Self::gradients`] holds.
    pub fn gradient_kind(&self) -> GradientKind {
        self.gradient_kind
    }

    /// 1-norm condition number of the (scaled) moment matrix of this evaluation.
    pub fn condition_number(&self) -> f64 {
        self.condition
    }

    /// Iterator over (node, N_v, ∇N_v).
    pub fn iter(&self) -> impl Iterator<Item = (u32, f64, &SVector<f64, D>)> + '_ {
        self.nodes()
            .iter()
            .zip(self.values())
            .zip(self.gradients())
            .map(|((&n, &v), g)| (n, v, g))
    }

    /// Value and gradient of a scalar nodal field: Σ N_v u_v and Σ u_v ∇N_v.
    pub fn interpolate(&self, field: &[f64]) -> Result<(f64, SVector<f64, D>), MlsError> {
        let mut value = 0.0;
        let mut gradient = SVector::<f64, D>::zeros();
        for (node, n, g) in self.iter() {
            let u = *field.get(node as usize).ok_or(MlsError::FieldTooShort {
                len: field.len(),
                node,
            })?;
            value += n * u;
            gradient += g * u;
        }
        Ok((value, gradient))
    }

    /// Value and gradient (M×D, ∂u_i/∂x_j) of a vector nodal field.
    pub fn interpolate_vector<const M: usize>(
        &self,
        field: &[SVector<f64, M>],
    ) -> Result<(SVector<f64, M>, SMatrix<f64, M, D>), MlsError> {
        let mut value = SVector::<f64, M>::zeros();
        let mut gradient = SMatrix::<f64, M, D>::zeros();
        for (node, n, g) in self.iter() {
            let u = field.get(node as usize).ok_or(MlsError::FieldTooShort {
                len: field.len(),
                node,
            })?;
            value += u * n;
            gradient += u * g.transpose();
        }
        Ok((value, gradient))
    }
}
