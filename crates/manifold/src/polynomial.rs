//! Monomials of total degree ≤ m in d variables, and weighted least-squares fits by QR.

use nalgebra::DMatrix;

use crate::error::ManifoldError;

/// The monomial basis x^α, |α| ≤ m, ordered by total degree: 1, then x₁ … x_d, then the
/// higher degrees. So coefficient 0 is the value at 0 and coefficients 1..=d the gradient.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Monomials {
    intrinsic: usize,
    degree: usize,
    exponents: Vec<Vec<u8>>,
}

impl Monomials {
    /// All monomials of total degree ≤ `degree` in `intrinsic` variables.
    pub fn new(intrinsic: usize, degree: usize) -> Self {
        let mut exponents = Vec::new();
        for total in 0..=degree {
            let mut current = vec![0u8; intrinsic];
            push_with_total(&mut exponents, &mut current, 0, total);
        }
        Self {
            intrinsic,
            degree,
            exponents,
        }
    }

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

    /// Writes the monomials at `x` into `out`.
    pub fn evaluate(&self, x: &[f64], out: &mut [f64]) {
        for (o, alpha) in out.iter_mut().zip(&self.exponents) {
            *o = alpha
                .iter()
                .zip(x)
                .map(|(&a, &xi)| xi.powi(i32::from(a)))
                .product();
        }
    }
}

/// Exponent vectors with the given total, in lexicographic order from the first variable.
fn push_with_total(out: &mut Vec<Vec<u8>>, current: &mut Vec<u8>, var: usize, remaining: usize) {
    if var + 1 == current.len() {
        current[var] = remaining as u8;
        out.push(current.clone());
        return;
    }
    for k in (0..=remaining).rev() {
        current[var] = k as u8;
        push_with_total(out, current, var + 1, remaining - k);
    }
    current[var] = 0;
}

/// Minimises Σ_i w_i ‖P(x_i) c − b_i‖² by QR of √W P (never the normal equations).
///
/// `coords` is K×d (scaled chart coordinates), `rhs` K×k; returns the M×k coefficients.
/// Rows with zero weight are dropped first.
pub fn weighted_fit(
    monomials: &Monomials,
    coords: &DMatrix<f64>,
    weights: &[f64],
    rhs: &DMatrix<f64>,
) -> Result<DMatrix<f64>, ManifoldError> {
    let used: Vec<usize> = (0..weights.len()).filter(|&i| weights[i] > 0.0).collect();
    let m = monomials.len();
    if used.len() < m {
        return Err(ManifoldError::TooFewNeighbours {
            found: used.len(),
            needed: m,
            degree: monomials.degree,
            intrinsic: monomials.intrinsic,
        });
    }
    let mut design = DMatrix::<f64>::zeros(used.len(), m);
    let mut target = DMatrix::<f64>::zeros(used.len(), rhs.ncols());
    let mut row = vec![0.0; m];
    let mut x = vec![0.0; coords.ncols()];
    for (r, &i) in used.iter().enumerate() {
        let sw = weights[i].sqrt();
        for (k, xk) in x.iter_mut().enumerate() {
            *xk = coords[(i, k)];
        }
        monomials.evaluate(&x, &mut row);
        for (c, v) in row.iter().enumerate() {
            design[(r, c)] = sw * v;
        }
        for c in 0..rhs.ncols() {
            target[(r, c)] = sw * rhs[(i, c)];
        }
    }
    let qr = design.qr();
    let r = qr.r();
    let diag: Vec<f64> = (0..m).map(|i| r[(i, i)].abs()).collect();
    let (lo, hi) = diag.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &d| {
        (lo.min(d), hi.max(d))
    });
    let ratio = lo / hi;
    if ratio.is_nan() || ratio <= 1e-12 {
        return Err(ManifoldError::RankDeficient { ratio });
    }
    let qt_b = qr.q().transpose() * target;
    r.solve_upper_triangular(&qt_b)
        .ok_or(ManifoldError::RankDeficient { ratio })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_order() {
        assert_eq!(Monomials::new(2, 3).len(), 10);
        assert_eq!(Monomials::new(3, 2).len(), 10);
        assert_eq!(Monomials::new(1, 0).len(), 1);
        let m = Monomials::new(2, 2);
        let mut out = vec![0.0; 6];
        m.evaluate(&[2.0, 3.0], &mut out);
        assert_eq!(out, vec![1.0, 2.0, 3.0, 4.0, 6.0, 9.0]);
    }
}
