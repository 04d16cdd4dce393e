//! Small dense kernels that work in caller-owned buffers, so a query allocates nothing
//! once its workspace has grown: Householder least squares with column equilibration and
//! a condition estimate, a tiny Cholesky solve, and Gram–Schmidt orthonormalisation.
//!
//! Matrices are column-major slices: entry (i, j) of a `rows`-row matrix is `a[i + j·rows]`.

/// Result of [`least_squares`]: the 2-norm condition number of the column-equilibrated
/// design (∞ when a column is zero), which measures how well the samples pin down every
/// coefficient independently of the units of the columns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Conditioning {
    pub condition: f64,
}

/// Minimises ‖A X − B‖ by Householder QR of A after scaling its columns to unit length
/// (never the normal equations). On return the first `cols` rows of `b` hold X.
/// `scratch` needs `cols·cols + cols` entries.
pub(crate) fn least_squares(
    a: &mut [f64],
    rows: usize,
    cols: usize,
    b: &mut [f64],
    rhs: usize,
    scratch: &mut Vec<f64>,
) -> Conditioning {
    debug_assert!(rows >= cols && a.len() >= rows * cols && b.len() >= rows * rhs);
    scratch.clear();
    scratch.resize(cols * cols + cols, 0.0);
    let (r_copy, scale) = scratch.split_at_mut(cols * cols);
    for (j, s) in scale.iter_mut().enumerate() {
        let column = &mut a[j * rows..(j + 1) * rows];
        let norm = column.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return Conditioning {
                condition: f64::INFINITY,
            };
        }
        column.iter_mut().for_each(|x| *x /= norm);
        *s = norm;
    }
    for k in 0..cols {
        let (head, tail) = a.split_at_mut((k + 1) * rows);
        let v = &mut head[k * rows + k..(k + 1) * rows];
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 {
            continue;
        }
        let alpha = if v[0] > 0.0 { -norm } else { norm };
        v[0] -= alpha;
        let vv = v.iter().map(|x| x * x).sum::<f64>();
        let reflect = |column: &mut [f64]| {
            let dot: f64 = v.iter().zip(column.iter()).map(|(x, y)| x * y).sum();
            let f = 2.0 * dot / vv;
            column
                .iter_mut()
                .zip(v.iter())
                .for_each(|(y, x)| *y -= f * x);
        };
        for j in 0..cols - k - 1 {
            reflect(&mut tail[j * rows + k..(j + 1) * rows]);
        }
        for j in 0..rhs {
            reflect(&mut b[j * rows + k..(j + 1) * rows]);
        }
        // The reflector is no longer needed: keep R's diagonal in its place.
        v[0] = alpha;
    }
    for j in 0..cols {
        for i in 0..cols {
            r_copy[i + j * cols] = if i <= j { a[i + j * rows] } else { 0.0 };
        }
    }
    let condition = condition_number(r_copy, cols);
    if condition.is_finite() {
        for j in 0..rhs {
            let x = &mut b[j * rows..j * rows + cols];
            for i in (0..cols).rev() {
                let mut s = x[i];
                for c in i + 1..cols {
                    s -= a[i + c * rows] * x[c];
                }
                x[i] = s / a[i + i * rows];
            }
            x.iter_mut().zip(scale.iter()).for_each(|(x, s)| *x /= s);
        }
    }
    Conditioning { condition }
}

/// What the noise in a weighted fit does, for a fit [`least_squares`] solved: with
/// √W P = Q₁ R S (S the column scaling), leverages h_i = ‖Q₁ row i‖² and the value
/// coefficient's equivalent kernel l_i = √w_i (Q₁ R⁻ᵀ e₀)_i / s₀.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NoiseResponse {
    /// Σ w_i (1 − h_i): a residual's expected weighted sum of squares over the variance
    /// of homoscedastic noise, E Σ w_i r_i² = s² Σ w_i (1 − h_i).
    pub residual_dof: f64,
    /// ‖l‖: the standard deviation of the fitted value over the noise's.
    pub kernel_norm: f64,
}

/// [`NoiseResponse`] of a fit: `r` is the matrix [`least_squares`] left (R in its upper
/// triangle), `scale` its column scaling, `design` the unscaled √W P it factored, and
/// `weights` the w_i. `buffer` needs `2·cols` entries.
pub(crate) fn noise_response(
    r: &[f64],
    rows: usize,
    cols: usize,
    design: &[f64],
    scale: &[f64],
    weights: &[f64],
    buffer: &mut Vec<f64>,
) -> NoiseResponse {
    buffer.clear();
    buffer.resize(2 * cols, 0.0);
    let (z, q) = buffer.split_at_mut(cols);
    // Rᵀ z = e₀ by forward substitution.
    for j in 0..cols {
        let mut s = if j == 0 { 1.0 } else { 0.0 };
        for l in 0..j {
            s -= r[l + j * rows] * z[l];
        }
        z[j] = s / r[j + j * rows];
    }
    let (mut residual_dof, mut kernel) = (0.0, 0.0);
    for (i, w) in weights.iter().enumerate().take(rows) {
        // Row i of Q₁: Rᵀ q = S⁻¹ (row i of √W P).
        let mut leverage = 0.0;
        let mut along = 0.0;
        for j in 0..cols {
            let mut s = design[i + j * rows] / scale[j];
            for l in 0..j {
                s -= r[l + j * rows] * q[l];
            }
            q[j] = s / r[j + j * rows];
            leverage += q[j] * q[j];
            along += q[j] * z[j];
        }
        residual_dof += w * (1.0 - leverage);
        kernel += w * along * along;
    }
    NoiseResponse {
        residual_dof,
        kernel_norm: kernel.sqrt() / scale[0],
    }
}

/// σ_max / σ_min of a square `n`×`n` matrix by one-sided Jacobi (the matrix is destroyed).
pub(crate) fn condition_number(g: &mut [f64], n: usize) -> f64 {
    for _sweep in 0..60 {
        let mut rotated = false;
        for p in 0..n {
            for q in p + 1..n {
                let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
                for i in 0..n {
                    let (x, y) = (g[i + p * n], g[i + q * n]);
                    alpha += x * x;
                    beta += y * y;
                    gamma += x * y;
                }
                if gamma.abs() <= 1e-15 * (alpha * beta).sqrt() || gamma == 0.0 {
                    continue;
                }
                rotated = true;
                let zeta = (beta - alpha) / (2.0 * gamma);
                let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = c * t;
                for i in 0..n {
                    let (x, y) = (g[i + p * n], g[i + q * n]);
                    g[i + p * n] = c * x - s * y;
                    g[i + q * n] = s * x + c * y;
                }
            }
        }
        if !rotated {
            break;
        }
    }
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for j in 0..n {
        let norm = g[j * n..(j + 1) * n]
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        lo = lo.min(norm);
        hi = hi.max(norm);
    }
    if lo > 0.0 && hi.is_finite() {
        hi / lo
    } else {
        f64::INFINITY
    }
}

/// Solves the symmetric positive definite `n`×`n` system A X = B (`rhs` columns) in place
/// by Cholesky; `false` when A is not numerically positive definite.
pub(crate) fn cholesky_solve(a: &mut [f64], n: usize, b: &mut [f64], rhs: usize) -> bool {
    let scale = (0..n).map(|i| a[i + i * n].abs()).fold(0.0, f64::max);
    for j in 0..n {
        let mut d = a[j + j * n];
        for k in 0..j {
            d -= a[j + k * n] * a[j + k * n];
        }
        if d.is_nan() || d <= 1e-14 * scale {
            return false;
        }
        let d = d.sqrt();
        a[j + j * n] = d;
        for i in j + 1..n {
            let mut s = a[i + j * n];
            for k in 0..j {
                s -= a[i + k * n] * a[j + k * n];
            }
            a[i + j * n] = s / d;
        }
    }
    for c in 0..rhs {
        let x = &mut b[c * n..(c + 1) * n];
        for i in 0..n {
            let mut s = x[i];
            for k in 0..i {
                s -= a[i + k * n] * x[k];
            }
            x[i] = s / a[i + i * n];
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..n {
                s -= a[k + i * n] * x[k];
            }
            x[i] = s / a[i + i * n];
        }
    }
    true
}

/// Orthonormalises the `count` columns (length `len`) of `u` in place by modified
/// Gram–Schmidt with one re-orthogonalisation; `false` if a column is (numerically) in
/// the span of the previous ones.
pub(crate) fn orthonormalise(u: &mut [f64], len: usize, count: usize) -> bool {
    for k in 0..count {
        let (done, rest) = u.split_at_mut(k * len);
        let column = &mut rest[..len];
        let original = column.iter().map(|x| x * x).sum::<f64>().sqrt();
        for _pass in 0..2 {
            for j in 0..k {
                let previous = &done[j * len..(j + 1) * len];
                let dot: f64 = previous.iter().zip(column.iter()).map(|(a, b)| a * b).sum();
                column
                    .iter_mut()
                    .zip(previous)
                    .for_each(|(c, p)| *c -= dot * p);
            }
        }
        let norm = column.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm.is_nan() || norm <= 1e-10 * original {
            return false;
        }
        column.iter_mut().for_each(|x| *x /= norm);
    }
    true
}

/// Dot product.
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Squared Euclidean distance.
#[inline]
pub(crate) fn distance_squared(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_an_exact_fit_and_the_condition() {
        // Columns 1, x, x² on x = 0..5 with widely different scales; b = 2 − x + 3x².
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let mut a: Vec<f64> = xs
            .iter()
            .map(|_| 1.0)
            .chain(xs.iter().map(|x| 1e3 * x))
            .chain(xs.iter().map(|x| x * x))
            .collect();
        let mut b: Vec<f64> = xs.iter().map(|x| 2.0 - x + 3.0 * x * x).collect();
        let design = nalgebra::DMatrix::from_column_slice(6, 3, &a);
        let mut scratch = Vec::new();
        let c = least_squares(&mut a, 6, 3, &mut b, 1, &mut scratch);
        assert!((b[0] - 2.0).abs() < 1e-12 && (b[1] + 1e-3).abs() < 1e-15);
        assert!((b[2] - 3.0).abs() < 1e-12);
        // Independent: singular values of the column-scaled design by nalgebra.
        let mut scaled = design.clone();
        for mut col in scaled.column_iter_mut() {
            let n = col.norm();
            col /= n;
        }
        let s = scaled.singular_values();
        let expected = s.max() / s.min();
        assert!(
            (c.condition - expected).abs() < 1e-10 * expected,
            "{c:?} vs {expected}"
        );
    }

    #[test]
    fn rank_deficiency_shows_as_infinite_or_huge_condition() {
        let mut a = vec![1.0, 2.0, 3.0, 2.0, 4.0, 6.0];
        let mut b = vec![1.0, 1.0, 1.0];
        let c = least_squares(&mut a, 3, 2, &mut b, 1, &mut Vec::new());
        assert!(c.condition > 1e14, "{c:?}");
    }

    #[test]
    fn cholesky_and_gram_schmidt() {
        let mut a = vec![4.0, 2.0, 2.0, 3.0];
        let mut b = vec![2.0, 1.0];
        assert!(cholesky_solve(&mut a, 2, &mut b, 1));
        assert!((4.0 * b[0] + 2.0 * b[1] - 2.0).abs() < 1e-14);
        assert!((2.0 * b[0] + 3.0 * b[1] - 1.0).abs() < 1e-14);
        assert!(!cholesky_solve(
            &mut [1.0, 1.0, 1.0, 1.0],
            2,
            &mut [0.0, 0.0],
            1
        ));
        let mut u = vec![1.0, 1.0, 0.0, 1.0, 0.0, 1.0];
        assert!(orthonormalise(&mut u, 3, 2));
        assert!(dot(&u[..3], &u[3..]).abs() < 1e-15);
        assert!((dot(&u[3..], &u[3..]) - 1.0).abs() < 1e-15);
        let mut dependent = vec![1.0, 2.0, 3.0, 2.0, 4.0, 6.0];
        assert!(!orthonormalise(&mut dependent, 3, 2));
    }
}
