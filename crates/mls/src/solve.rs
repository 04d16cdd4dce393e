//! The MLS solve: moment matrix, conditioning, shape functions and their gradients.
//!
//! With the basis centred at the evaluation point x and scaled by s,
//! p_v = p((x_v − x)/s), M = Σ_v w_v p_v p_vᵀ and a = M⁻¹ e₀:
//!
//! - N_v = w_v aᵀ p_v,
//! - reconstructed gradient ∇̃_k N_v = w_v (M⁻¹ e_{k+1})ᵀ p_v / s,
//! - full gradient ∂_k N_v = ∇̃_k N_v + ∂_k w_v g_v − r_kᵀ c_v, with g_v = aᵀ p_v,
//!   c_v = M⁻¹ w_v p_v and r_k = Σ_u ∂_k w_u g_u p_u.
//!
//! The full gradient follows from differentiating N_v with the basis centre held fixed
//! (MLS shape functions do not depend on where a complete basis is centred), so that only
//! the weights depend on x; the terms are then evaluated with the centre at x.

use nalgebra::{SMatrix, SVector};

use crate::basis::PolynomialBasis;
use crate::cholesky::spd_inverse;
use crate::error::MlsError;
use crate::stencil::{GradientKind, MAX_STENCIL, Stencil};

/// What to do when the moment matrix is ill-conditioned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IllConditionedPolicy {
    /// Return [`MlsError::IllConditioned`].
    Fail,
    /// Add `strength · tr(M)/N` to the diagonal entries of the non-constant monomials and
    /// solve again (Tikhonov regularisation that leaves the constant unpenalised, so
    /// partition of unity still holds exactly; linear reproduction degrades by O(strength)).
    Regularize {
        /// Relative regularisation strength, e.g. 1e-6.
        strength: f64,
    },
}

/// Conditioning limit and policy for the moment matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conditioning {
    /// Largest accepted 1-norm condition number of the scaled moment matrix.
    pub max_condition: f64,
    /// What to do beyond it.
    pub policy: IllConditionedPolicy,
    /// Ridge on the monomials of degree two and more, relative to Σw·ℓ⁴ with ℓ the
    /// weighted spread of the samples, added on every evaluation (default 0; values ≤ 0
    /// disable it). It keeps a quadratic fit solvable where fewer
    /// samples than monomials carry weight (a vertex on a wall, a corner) while linear
    /// fields stay reproduced exactly (their fit has no higher-order coefficients to
    /// penalise), and, being always on and continuous in x, it keeps the shape functions
    /// continuous, which a switch at `max_condition` would not.
    pub higher_order_ridge: f64,
}

impl Default for Conditioning {
    /// Limit 1e8 (well-shaped stencils measure 10¹–10³ with the scaled basis), fail beyond.
    fn default() -> Self {
        Self {
            max_condition: 1e8,
            policy: IllConditionedPolicy::Fail,
            higher_order_ridge: 0.0,
        }
    }
}

/// Samples for one MLS evaluation at a point x.
#[derive(Debug, Clone, Copy)]
pub struct Samples<'a, const D: usize> {
    /// Node indices reported in the stencil.
    pub nodes: &'a [u32],
    /// Sample positions x_v.
    pub positions: &'a [SVector<f64, D>],
    /// Weights w_v(x) ≥ 0.
    pub weights: &'a [f64],
    /// Weight gradients ∇w_v(x); only read for [`GradientKind::Full`] and
    /// [`GradientKind::FrozenEta`] (may be empty otherwise).
    pub weight_gradients: &'a [SVector<f64, D>],
}

/// Computes MLS shape functions at `x` into `out`.
///
/// `scale` is a length of the order of the sample spacing: coordinates are divided by it
/// so the moment matrix is O(1) and its condition number means something. It does not
/// change the result (beyond round-off).
pub fn shape_functions<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    x: &SVector<f64, D>,
    samples: &Samples<'_, D>,
    scale: f64,
    gradient: GradientKind,
    conditioning: &Conditioning,
    out: &mut Stencil<D>,
) -> Result<(), MlsError> {
    let n = samples.positions.len();
    let needs_weight_gradients = gradient.uses_weight_gradients();
    if samples.weights.len() != n
        || samples.nodes.len() != n
        || (needs_weight_gradients && samples.weight_gradients.len() != n)
    {
        return Err(MlsError::LengthMismatch {
            positions: n,
            weights: samples.weights.len(),
            gradients: samples.weight_gradients.len(),
        });
    }
    if n > MAX_STENCIL {
        return Err(MlsError::StencilOverflow {
            simplex: None,
            samples: n,
            capacity: MAX_STENCIL,
        });
    }
    let inv_scale = inverse_scale(scale)?;
    let basis = |v: usize| B::evaluate(&((samples.positions[v] - x) * inv_scale));

    out.len = n;
    out.nodes[..n].copy_from_slice(samples.nodes);
    out.values[..n].copy_from_slice(samples.weights);
    for (xi, position) in out.gradients[..n].iter_mut().zip(samples.positions) {
        *xi = (position - x) * inv_scale;
    }
    let solved = shape_functions_in_place::<D, N, B>(
        &mut out.values[..n],
        &mut out.gradients[..n],
        inv_scale,
        conditioning,
    );
    let (inverse, condition) = match solved {
        Ok(solved) => solved,
        Err(error) => {
            out.clear();
            return Err(error);
        }
    };
    out.condition = condition;
    out.gradient_kind = gradient;
    let a = inverse.column(0).into_owned();
    if needs_weight_gradients {
        // r_k = Σ_u ∂_k w_u g_u p_u, stored as the columns of an N×D matrix.
        let mut r = SMatrix::<f64, N, D>::zeros();
        for u in 0..n {
            let p = basis(u);
            let g = a.dot(&p);
            r += p * (samples.weight_gradients[u] * g).transpose();
        }
        for v in 0..n {
            let p = basis(v);
            let g = a.dot(&p);
            let c = inverse * p * samples.weights[v];
            out.gradients[v] += samples.weight_gradients[v] * g - r.transpose() * c;
        }
    }
    Ok(())
}

/// The MLS solve with the reconstructed gradient, written over its own input so that an
/// evaluation needs no sample arrays besides the stencil it fills.
///
/// On entry `values[v]` holds the weight w_v ≥ 0 and `gradients[v]` the scaled offset
/// ξ_v = (x_v − x)/s; on return they hold N_v and the reconstructed gradient ∇̃N_v.
/// `inv_scale` is 1/s. Returns M⁻¹ and its 1-norm condition number. [`shape_functions`]
/// calls it, so both give the same bits.
pub(crate) fn shape_functions_in_place<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    values: &mut [f64],
    gradients: &mut [SVector<f64, D>],
    inv_scale: f64,
    conditioning: &Conditioning,
) -> Result<(SMatrix<f64, N, N>, f64), MlsError> {
    let (inverse, condition) = moment_inverse::<D, N, B>(values, gradients, conditioning)?;
    let inverse_transpose = inverse.transpose();
    for (value, gradient) in values.iter_mut().zip(gradients.iter_mut()) {
        (*value, *gradient) =
            shape_function::<D, N, B>(&inverse_transpose, inv_scale, *value, gradient);
    }
    Ok((inverse, condition))
}

/// The inverse of the moment matrix M = Σ_v w_v p(ξ_v) p(ξ_v)ᵀ of the weights `weights`
/// and scaled offsets `scaled_offsets` ξ_v, with the conditioning policy applied, and
/// its 1-norm condition number.
pub(crate) fn moment_inverse<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    weights: &[f64],
    scaled_offsets: &[SVector<f64, D>],
    conditioning: &Conditioning,
) -> Result<(SMatrix<f64, N, N>, f64), MlsError> {
    let mut moment = SMatrix::<f64, N, N>::zeros();
    let mut positive = 0;
    for (v, (&w, xi)) in weights.iter().zip(scaled_offsets).enumerate() {
        if !(w.is_finite() && w >= 0.0) {
            return Err(MlsError::InvalidWeight {
                sample: v,
                weight: w,
            });
        }
        if w > 0.0 {
            let p = B::evaluate(xi);
            moment.ger(w, &p, &p, 1.0);
            positive += 1;
        }
    }
    if conditioning.higher_order_ridge > 0.0 && moment[(0, 0)] > 0.0 {
        // The ridge must not depend on the scale s (it differs between neighbouring
        // hosts): with ℓ² = Σw|ξ|² / Σw, the weighted spread of the samples, the shift
        // Σw · ℓ⁴ scales like the quadratic monomials' entries (s⁻⁴), so the regularised
        // fit is the same for every s and stays continuous across facets.
        let spread: f64 = (1..=D).map(|i| moment[(i, i)]).sum();
        let shift = conditioning.higher_order_ridge * spread * spread / moment[(0, 0)];
        for i in D + 1..N {
            moment[(i, i)] += shift;
        }
    }
    invert(moment, positive, conditioning)
}

/// One sample's shape function N_v = w_v (M⁻¹e₀)ᵀ p(ξ_v) and reconstructed gradient
/// ∇̃_k N_v = w_v (M⁻¹e_{k+1})ᵀ p(ξ_v) / s, from the transposed inverse moment matrix
/// (M⁻¹)ᵀ, 1/s, the weight and the scaled offset. Every evaluation of a
/// reconstructed-gradient fit goes through it, so a fit kept as (M⁻¹, w) and evaluated
/// later gives the same bits.
#[inline(always)]
pub(crate) fn shape_function<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    inverse_transpose: &SMatrix<f64, N, N>,
    inv_scale: f64,
    weight: f64,
    scaled_offset: &SVector<f64, D>,
) -> (f64, SVector<f64, D>) {
    let p = B::evaluate(scaled_offset);
    let dots = column_dots::<D, N>(inverse_transpose, &p);
    let value = weight * dots[0];
    let gradient = SVector::<f64, D>::from_fn(|k, _| weight * dots[k + 1] * inv_scale);
    (value, gradient)
}

/// (M⁻¹e_k)ᵀ p for k = 0..=D (zero beyond), from t = (M⁻¹)ᵀ, whose columns are M⁻¹'s
/// rows. For N ≤ 4 the sums are nalgebra's `dot` of a column with p, term for term and in
/// its order ((a + b) + c for three terms, (a + c) + (b + d) for four), but formed lane by
/// lane over k as sums of t's columns, which vectorises; beyond, the columns' dots.
#[inline(always)]
fn column_dots<const D: usize, const N: usize>(
    t: &SMatrix<f64, N, N>,
    p: &SVector<f64, N>,
) -> SVector<f64, N> {
    let term = |j: usize| t.column(j) * p[j];
    match N {
        2 => term(0) + term(1),
        3 => (term(0) + term(1)) + term(2),
        4 => (term(0) + term(2)) + (term(1) + term(3)),
        _ => SVector::from_fn(|k, _| {
            if k <= D {
                t.row(k).transpose().dot(p)
            } else {
                0.0
            }
        }),
    }
}

/// Inverts the SPD moment matrix, estimating κ₁ = ‖M‖₁‖M⁻¹‖₁ and applying the policy.
fn invert<const N: usize>(
    moment: SMatrix<f64, N, N>,
    positive: usize,
    conditioning: &Conditioning,
) -> Result<(SMatrix<f64, N, N>, f64), MlsError> {
    let attempt = |m: SMatrix<f64, N, N>| -> (Option<SMatrix<f64, N, N>>, f64) {
        match spd_inverse(&m) {
            Some(inverse) => {
                let condition = one_norm(&m) * one_norm(&inverse);
                (
                    Some(inverse),
                    if condition.is_finite() {
                        condition
                    } else {
                        f64::INFINITY
                    },
                )
            }
            None => (None, f64::INFINITY),
        }
    };
    let fail = |condition| MlsError::IllConditioned {
        simplex: None,
        condition,
        limit: conditioning.max_condition,
        samples: positive,
        basis: N,
    };
    let (inverse, condition) = attempt(moment);
    if let Some(inverse) = inverse {
        if condition <= conditioning.max_condition {
            return Ok((inverse, condition));
        }
    }
    match conditioning.policy {
        IllConditionedPolicy::Fail => Err(fail(condition)),
        IllConditionedPolicy::Regularize { strength } => {
            let mut regularized = moment;
            let shift = strength * moment.trace() / N as f64;
            for i in 1..N {
                regularized[(i, i)] += shift;
            }
            match attempt(regularized) {
                (Some(inverse), c) if c.is_finite() => Ok((inverse, c)),
                (_, c) => Err(fail(c)),
            }
        }
    }
}

/// Maximum absolute column sum.
fn one_norm<const N: usize>(m: &SMatrix<f64, N, N>) -> f64 {
    m.column_iter().map(|c| c.abs().sum()).fold(0.0, f64::max)
}

/// 1 / `scale`, the factor the offsets are scaled by, after checking `scale` is a
/// usable length.
pub(crate) fn inverse_scale(scale: f64) -> Result<f64, MlsError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(MlsError::InvalidParameter {
            parameter: "scale",
            value: scale,
            reason: "must be finite and positive",
        });
    }
    Ok(1.0 / scale)
}
