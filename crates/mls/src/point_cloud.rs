//! MLS on a user's own point set: radial weights from a [`WeightFunction`].

use nalgebra::SVector;

use crate::basis::PolynomialBasis;
use crate::error::MlsError;
use crate::solve::{Conditioning, Samples, shape_functions};
use crate::stencil::{GradientKind, MAX_STENCIL, Stencil};
use crate::weight::WeightFunction;

/// MLS with radial weights w_v = W(|x − x_v| / radius), for point sets without a mesh.
///
/// The caller passes the neighbour positions (at most [`MAX_STENCIL`]); stencil node `i`
/// is the `i`-th position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointCloudMls<W: WeightFunction> {
    /// Support radius h: samples farther than `W::SUPPORT · h` get zero weight.
    pub radius: f64,
    /// The weight profile.
    pub weight: W,
    /// Conditioning limit and policy.
    pub conditioning: Conditioning,
}

impl<W: WeightFunction> PointCloudMls<W> {
    /// MLS with the given support radius and weight profile, default conditioning.
    pub fn new(radius: f64, weight: W) -> Result<Self, MlsError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(MlsError::InvalidParameter {
                parameter: "radius",
                value: radius,
                reason: "must be finite and positive",
            });
        }
        Ok(Self {
            radius,
            weight,
            conditioning: Conditioning::default(),
        })
    }

    /// Shape functions at `x` over `positions`.
    pub fn evaluate<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
        &self,
        x: &SVector<f64, D>,
        positions: &[SVector<f64, D>],
        gradient: GradientKind,
        out: &mut Stencil<D>,
    ) -> Result<(), MlsError> {
        let n = positions.len();
        if n > MAX_STENCIL {
            return Err(MlsError::StencilOverflow {
                simplex: None,
                samples: n,
                capacity: MAX_STENCIL,
            });
        }
        let mut nodes = [0u32; MAX_STENCIL];
        let mut weights = [0.0; MAX_STENCIL];
        let mut weight_gradients = [SVector::<f64, D>::zeros(); MAX_STENCIL];
        for (i, xv) in positions.iter().enumerate() {
            nodes[i] = i as u32;
            let (w, dw) = radial_weight(&self.weight, x, xv, self.radius);
            weights[i] = w;
            weight_gradients[i] = dw;
        }
        let samples = Samples {
            nodes: &nodes[..n],
            positions,
            weights: &weights[..n],
            weight_gradients: &weight_gradients[..n],
        };
        shape_functions::<D, N, B>(x, &samples, self.radius, gradient, &self.conditioning, out)
    }
}

/// W(|x − x_v| / h) and its gradient with respect to x.
#[inline]
pub(crate) fn radial_weight<const D: usize, W: WeightFunction>(
    weight: &W,
    x: &SVector<f64, D>,
    xv: &SVector<f64, D>,
    h: f64,
) -> (f64, SVector<f64, D>) {
    let dx = x - xv;
    let dist = dx.norm();
    let (w, dw_dr) = weight.evaluate(dist / h);
    // Both profiles have W'(0) = 0, so the gradient is zero (not 0/0) at the sample itself.
    let grad = if dist > 0.0 {
        dx * (dw_dr / (h * dist))
    } else {
        SVector::zeros()
    };
    (w, grad)
}
