//! Monomials of total degree ≤ m in d variables, and the weighted least-squares fit of
//! values and offsets in a chart.

use crate::chart::{FrameChart, theta};
use crate::dense::{NoiseResponse, dot, least_squares, noise_response};
use crate::error::ManifoldError;
use crate::frame::Frame;

/// The monomial basis x^α, |α| ≤ m, ordered by total degree: 1, then x₁ … x_d, then the
/// higher degrees. So coefficient 0 is the value at 0 and coefficients 1..=d the gradient.
/// With d = 0 the basis is the constant alone.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Monomials {
    intrinsic: usize,
    degree: usize,
    exponents: Vec<Vec<u32>>,
}

impl Monomials {
    /// All monomials of total degree ≤ `degree` in `intrinsic` variables.
    ///
    /// Fails with [`ManifoldError::InvalidParameter`] when the basis would have more than
    /// [`Monomials::MAX_LEN`] members (C(d + m, d) grows fast: no least-squares fit of that
    /// size is meant).
    pub fn new(intrinsic: usize, degree: usize) -> Result<Self, ManifoldError> {
        if basis_size(intrinsic, degree).is_none_or(|len| len > Self::MAX_LEN) {
            return Err(ManifoldError::InvalidParameter {
                parameter: "degree",
                value: degree as f64,
                reason: "C(d + m, d) monomials exceed 10⁵",
            });
        }
        let mut exponents = Vec::new();
        if intrinsic == 0 {
            exponents.push(Vec::new());
        } else {
            for total in 0..=degree as u32 {
                let mut current = vec![0u32; intrinsic];
                push_with_total(&mut exponents, &mut current, 0, total);
            }
        }
        Ok(Self {
            intrinsic,
            degree,
            exponents,
        })
    }

    /// Largest basis [`Monomials::new`] builds.
    pub const MAX_LEN: usize = 100_000;

    /// Number of monomials, C(d + m, d).
    pub fn len(&self) -> usize {
        self.exponents.len()
    }

    /// Whether the basis is empty (never).
    pub fn is_empty(&self) -> bool {
        self.exponents.is_empty()
    }

    /// Polynomial degree m.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Number of variables d.
    pub fn intrinsic_dim(&self) -> usize {
        self.intrinsic
    }

    /// Exponent vectors α, one per monomial, in basis order.
    pub fn exponents(&self) -> &[Vec<u32>] {
        &self.exponents
    }

    /// Writes the monomials at `x` (d values) into `out` (len values).
    pub fn evaluate(&self, x: &[f64], out: &mut [f64]) {
        for (o, alpha) in out.iter_mut().zip(&self.exponents) {
            *o = alpha
                .iter()
                .zip(x)
                .map(|(&a, &xi)| xi.powi(a as i32))
                .product();
        }
    }
}

/// C(d + m, d), `None` on overflow.
fn basis_size(d: usize, m: usize) -> Option<usize> {
    let mut size: usize = 1;
    for i in 1..=d.min(m) {
        size = size.checked_mul(d.max(m).checked_add(i)?)? / i;
        // Already too large to build: stop before counting to the end.
        if size > Monomials::MAX_LEN {
            return None;
        }
    }
    Some(size)
}

/// Exponent vectors with the given total, in lexicographic order from the first variable.
fn push_with_total(out: &mut Vec<Vec<u32>>, current: &mut Vec<u32>, var: usize, remaining: u32) {
    if var + 1 == current.len() {
        current[var] = remaining;
        out.push(current.clone());
        return;
    }
    for k in (0..=remaining).rev() {
        current[var] = k;
        push_with_total(out, current, var + 1, remaining - k);
    }
    current[var] = 0;
}

/// Scratch buffers of [`fit_values_and_offsets`].
#[derive(Debug, Default)]
pub(crate) struct FitScratch {
    design: Vec<f64>,
    pub(crate) solution: Vec<f64>,
    row: Vec<f64>,
    x: Vec<f64>,
    lsq: Vec<f64>,
    used: Vec<(usize, f64)>,
    /// √W P before the factorisation, for the fit's response to noise.
    unscaled: Vec<f64>,
    weights: Vec<f64>,
    buffer: Vec<f64>,
}

/// What a fit in the chart produced.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FitSummary {
    /// Rows of the solution (leading dimension of `FitScratch::solution`): the
    /// neighbours with positive weight.
    pub rows: usize,
    /// Condition number of the column-equilibrated weighted design.
    pub condition: f64,
    /// Kish's effective sample size (Σw)² / Σw².
    pub effective: f64,
    /// How noise in the samples propagates to the fit.
    pub noise: NoiseResponse,
}

/// Weighted degree-m fit in the chart of the `k` values of every neighbour (from
/// `value_of`) and of its offset y_i − q (frame dimension columns): minimises
/// Σ_i w_i ‖P(x_i) c − b_i‖² by Householder QR of √W P. Coefficients are in
/// `scratch.solution`, column j at `j·rows`, coefficient order as in [`Monomials`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_values_and_offsets<'v>(
    frame: &Frame,
    chart: &FrameChart,
    mass: &[f64],
    monomials: &Monomials,
    sigma: f64,
    k: usize,
    value_of: impl Fn(usize) -> &'v [f64],
    scratch: &mut FitScratch,
) -> Result<FitSummary, ManifoldError> {
    let (dim, d, m) = (frame.dim, monomials.intrinsic, monomials.len());
    scratch.used.clear();
    for (i, (y, mass)) in frame.coords.chunks_exact(dim).zip(mass).enumerate() {
        let t = y
            .iter()
            .zip(&chart.q)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        let w = mass * theta(t, sigma);
        if w > 0.0 {
            scratch.used.push((i, w));
        }
    }
    let rows = scratch.used.len();
    let (sum, sum2) = scratch
        .used
        .iter()
        .fold((0.0, 0.0), |(s, s2), (_, w)| (s + w, s2 + w * w));
    if rows < m {
        return Err(ManifoldError::TooFewNeighbours {
            found: rows,
            needed: m,
            degree: monomials.degree,
            intrinsic: d,
        });
    }
    let columns = k + dim;
    scratch.design.clear();
    scratch.design.resize(rows * m, 0.0);
    scratch.solution.clear();
    scratch.solution.resize(rows * columns, 0.0);
    scratch.row.resize(m, 0.0);
    scratch.x.resize(d, 0.0);
    for (r, &(i, w)) in scratch.used.iter().enumerate() {
        let sw = w.sqrt();
        let y = &frame.coords[i * dim..(i + 1) * dim];
        for (a, x) in scratch.x.iter_mut().enumerate() {
            let u = &chart.u[a * dim..(a + 1) * dim];
            *x = (dot(u, y) - dot(u, &chart.q)) / sigma;
        }
        monomials.evaluate(&scratch.x, &mut scratch.row);
        for (c, v) in scratch.row.iter().enumerate() {
            scratch.design[r + c * rows] = sw * v;
        }
        for (c, v) in value_of(i).iter().enumerate() {
            scratch.solution[r + c * rows] = sw * v;
        }
        for (c, (y, q)) in y.iter().zip(&chart.q).enumerate() {
            scratch.solution[r + (k + c) * rows] = sw * (y - q);
        }
    }
    scratch.unscaled.clone_from(&scratch.design);
    scratch.weights.clear();
    scratch.weights.extend(scratch.used.iter().map(|&(_, w)| w));
    let conditioning = least_squares(
        &mut scratch.design,
        rows,
        m,
        &mut scratch.solution,
        columns,
        &mut scratch.lsq,
    );
    let noise = if conditioning.condition.is_finite() {
        noise_response(
            &scratch.design,
            rows,
            m,
            &scratch.unscaled,
            &scratch.lsq[m * m..m * m + m],
            &scratch.weights,
            &mut scratch.buffer,
        )
    } else {
        NoiseResponse {
            residual_dof: 0.0,
            kernel_norm: f64::INFINITY,
        }
    };
    Ok(FitSummary {
        rows,
        condition: conditioning.condition,
        effective: sum * sum / sum2,
        noise,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_order() {
        assert_eq!(Monomials::new(2, 3).unwrap().len(), 10);
        assert_eq!(Monomials::new(3, 2).unwrap().len(), 10);
        assert_eq!(Monomials::new(1, 0).unwrap().len(), 1);
        let m = Monomials::new(2, 2).unwrap();
        let mut out = vec![0.0; 6];
        m.evaluate(&[2.0, 3.0], &mut out);
        assert_eq!(out, vec![1.0, 2.0, 3.0, 4.0, 6.0, 9.0]);
    }

    #[test]
    fn edges_of_the_basis() {
        // d = 0: the constant alone, whatever the degree.
        let constant = Monomials::new(0, 3).unwrap();
        assert_eq!(constant.len(), 1);
        let mut out = [0.0];
        constant.evaluate(&[], &mut out);
        assert_eq!(out, [1.0]);
        // Degrees past 255 no longer wrap: x^300 is x^300.
        let high = Monomials::new(1, 300).unwrap();
        assert_eq!(high.len(), 301);
        let mut out = vec![0.0; 301];
        high.evaluate(&[1.001], &mut out);
        assert!((out[300] - 1.001f64.powi(300)).abs() < 1e-12 * out[300]);
        // A basis too large to fit is refused, not allocated.
        assert!(matches!(
            Monomials::new(10, 50),
            Err(ManifoldError::InvalidParameter {
                parameter: "degree",
                ..
            })
        ));
        assert!(Monomials::new(usize::MAX, usize::MAX).is_err());
    }
}
