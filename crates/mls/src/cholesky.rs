//! The inverse of a small symmetric positive definite matrix by Cholesky factorisation,
//! on fixed-size arrays.
//!
//! Every MLS evaluation inverts its moment matrix (4 × 4 for the linear basis in 3D).
//! `nalgebra::Cholesky::inverse` does it through dynamically sized views (a loop and a
//! bounds computation per column slice), which took about a fifth of a UMLS stencil; the
//! same operations unrolled over `[[f64; N]; N]` take a fraction of that. The arithmetic
//! is nalgebra's operation for operation — the same factorisation (left-looking, column
//! by column), the same forward and backward substitutions against the identity, the same
//! summation order — so the result is the same to the last bit (the tests compare them),
//! and a simulation run with either gives the same history.

use nalgebra::SMatrix;

/// M⁻¹ of a symmetric positive definite `m` (only its lower triangle is read), or `None`
/// where the factorisation meets a pivot that is zero, negative or not a number, exactly
/// where `nalgebra::Cholesky::new` returns `None`.
#[inline]
pub(crate) fn spd_inverse<const N: usize>(m: &SMatrix<f64, N, N>) -> Option<SMatrix<f64, N, N>> {
    // l[c][r]: column-major like nalgebra, so each step below mirrors its column loops.
    let mut l = [[0.0f64; N]; N];
    for (c, column) in l.iter_mut().enumerate() {
        for (r, entry) in column.iter_mut().enumerate() {
            *entry = m[(r, c)];
        }
    }
    for j in 0..N {
        let (done, rest) = l.split_at_mut(j);
        let column = &mut rest[0];
        for previous in done.iter() {
            let factor = -previous[j];
            for (y, x) in column[j..].iter_mut().zip(&previous[j..]) {
                *y += factor * x;
            }
        }
        let diag = column[j];
        // nalgebra's `try_sqrt`: a zero, negative or NaN pivot ends the factorisation.
        if diag.is_nan() || diag <= 0.0 {
            return None;
        }
        let denom = diag.sqrt();
        column[j] = denom;
        for y in &mut column[j + 1..] {
            *y /= denom;
        }
    }
    let mut inverse = SMatrix::<f64, N, N>::zeros();
    for c in 0..N {
        let mut b = [0.0f64; N];
        b[c] = 1.0;
        // L y = e_c.
        for (i, column) in l.iter().enumerate() {
            let coeff = b[i] / column[i];
            b[i] = coeff;
            for (y, x) in b[i + 1..].iter_mut().zip(&column[i + 1..]) {
                *y += -coeff * x;
            }
        }
        // Lᵀ x = y.
        for (i, column) in l.iter().enumerate().rev() {
            let dot = view_dot(&column[i + 1..], &b[i + 1..]);
            b[i] = (b[i] - dot) / column[i];
        }
        for (r, value) in b.iter().enumerate() {
            inverse[(r, c)] = *value;
        }
    }
    Some(inverse)
}

/// The dot product of two equally long slices in the order nalgebra sums a dynamically
/// sized vector view: eight interleaved partial sums over whole blocks of eight, combined
/// pairwise, then the remaining entries one by one.
#[inline]
fn view_dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let blocks = a.len() / 8 * 8;
    for (x, y) in a[..blocks].chunks_exact(8).zip(b[..blocks].chunks_exact(8)) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut res = 0.0;
    res += acc[0] + acc[4];
    res += acc[1] + acc[5];
    res += acc[2] + acc[6];
    res += acc[3] + acc[7];
    for (x, y) in a[blocks..].iter().zip(&b[blocks..]) {
        res += x * y;
    }
    res
}

#[cfg(test)]
mod tests {
    use nalgebra::{Cholesky, SMatrix};
    use proptest::prelude::*;

    use super::spd_inverse;

    fn same_bits<const N: usize>(m: SMatrix<f64, N, N>) -> Result<(), TestCaseError> {
        let ours = spd_inverse(&m);
        let theirs = Cholesky::new(m).map(|c| c.inverse());
        match (ours, theirs) {
            (Some(a), Some(b)) => {
                for (x, y) in a.iter().zip(b.iter()) {
                    prop_assert_eq!(x.to_bits(), y.to_bits(), "{} against {}", x, y);
                }
            }
            (None, None) => {}
            (a, b) => prop_assert!(false, "ours {:?}, nalgebra {:?}", a, b),
        }
        Ok(())
    }

    /// Σ w p pᵀ over random samples: the moment matrices the solve inverts, from well
    /// conditioned to nearly singular (few samples, tiny weights).
    fn moment<const N: usize>(samples: &[(f64, [f64; 9])]) -> SMatrix<f64, N, N> {
        let mut m = SMatrix::<f64, N, N>::zeros();
        for (w, coords) in samples {
            let mut p = nalgebra::SVector::<f64, N>::zeros();
            p[0] = 1.0;
            for k in 1..N {
                p[k] = coords[k - 1];
            }
            m.ger(*w, &p, &p, 1.0);
        }
        m
    }

    proptest! {
        #[test]
        fn the_inverse_is_nalgebras_to_the_last_bit(
            samples in prop::collection::vec(
                (0.0f64..2.0, prop::array::uniform9(-1.5f64..1.5)), 1..40),
        ) {
            same_bits::<2>(moment(&samples))?;
            same_bits::<3>(moment(&samples))?;
            same_bits::<4>(moment(&samples))?;
            same_bits::<6>(moment(&samples))?;
            same_bits::<10>(moment(&samples))?;
        }

        #[test]
        fn indefinite_and_arbitrary_matrices_fail_where_nalgebras_fails(
            entries in prop::array::uniform16(-2.0f64..2.0),
        ) {
            same_bits::<4>(SMatrix::<f64, 4, 4>::from_row_slice(&entries))?;
        }
    }

    #[test]
    fn singular_and_not_a_number_pivots_give_none() {
        assert!(spd_inverse(&SMatrix::<f64, 2, 2>::zeros()).is_none());
        assert!(spd_inverse(&SMatrix::<f64, 2, 2>::new(1.0, 1.0, 1.0, 1.0)).is_none());
        assert!(spd_inverse(&SMatrix::<f64, 2, 2>::new(f64::NAN, 0.0, 0.0, 1.0)).is_none());
        assert!(spd_inverse(&SMatrix::<f64, 2, 2>::new(-1.0, 0.0, 0.0, 1.0)).is_none());
        let inverse = spd_inverse(&SMatrix::<f64, 2, 2>::new(4.0, 2.0, 2.0, 3.0)).unwrap();
        let expected = SMatrix::<f64, 2, 2>::new(3.0, -2.0, -2.0, 4.0) / 8.0;
        assert!((inverse - expected).norm() < 1e-15);
    }
}
