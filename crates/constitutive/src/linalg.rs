//! Small dense linear algebra for D ≤ 3 without leaking nalgebra's dimension bounds:
//! generic matrices are copied into the concrete `Matrix2`/`Matrix3`, which have every
//! decomposition, and back.

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector};

use crate::error::ConstitutiveError;

/// A D×D matrix.
pub type Matrix<const D: usize> = SMatrix<f64, D, D>;

fn to_concrete<const D: usize, const K: usize>(m: &Matrix<D>) -> SMatrix<f64, K, K> {
    SMatrix::<f64, K, K>::from_fn(|i, j| m[(i, j)])
}

fn from_concrete<const D: usize, const K: usize>(m: &SMatrix<f64, K, K>) -> Matrix<D> {
    Matrix::<D>::from_fn(|i, j| m[(i, j)])
}

/// det M.
pub fn determinant<const D: usize>(m: &Matrix<D>) -> f64 {
    match D {
        1 => m[(0, 0)],
        2 => to_concrete::<D, 2>(m).determinant(),
        _ => to_concrete::<D, 3>(m).determinant(),
    }
}

/// Singular value decomposition M = U diag(σ) Vᵀ with U, V proper rotations (det +1): the
/// sign of det M goes into the smallest singular value, so σ is negative only for
/// inverted M ("sign-fixed" SVD, as needed by polar decompositions of inverted elements).
pub fn signed_svd<const D: usize>(m: &Matrix<D>) -> (Matrix<D>, SVector<f64, D>, Matrix<D>) {
    let (mut u, mut sigma, mut v): (Matrix<D>, SVector<f64, D>, Matrix<D>) = match D {
        1 => (
            Matrix::<D>::identity(),
            SVector::<f64, D>::from_element(m[(0, 0)]),
            Matrix::<D>::identity(),
        ),
        2 => {
            let svd = Matrix2::from(to_concrete::<D, 2>(m)).svd(true, true);
            let u = svd.u.expect("requested");
            let vt = svd.v_t.expect("requested");
            (
                from_concrete(&u),
                SVector::<f64, D>::from_fn(|i, _| svd.singular_values[i]),
                from_concrete(&vt.transpose()),
            )
        }
        _ => {
            let svd = Matrix3::from(to_concrete::<D, 3>(m)).svd(true, true);
            let u = svd.u.expect("requested");
            let vt = svd.v_t.expect("requested");
            (
                from_concrete(&u),
                SVector::<f64, D>::from_fn(|i, _| svd.singular_values[i]),
                from_concrete(&vt.transpose()),
            )
        }
    };
    if D > 1 {
        // nalgebra sorts singular values in decreasing order: the last is the smallest.
        let last = D - 1;
        if determinant(&u) < 0.0 {
            u.column_mut(last).neg_mut();
            sigma[last] = -sigma[last];
        }
        if determinant(&v) < 0.0 {
            v.column_mut(last).neg_mut();
            sigma[last] = -sigma[last];
        }
    }
    (u, sigma, v)
}

/// M⁻ᵀ, or `None` when M is singular.
pub fn inverse_transpose<const D: usize>(m: &Matrix<D>) -> Option<Matrix<D>> {
    m.try_inverse().map(|inv| inv.transpose())
}

/// det F, checked finite and positive.
pub fn positive_jacobian<const D: usize>(
    model: &'static str,
    f: &Matrix<D>,
) -> Result<f64, ConstitutiveError> {
    if f.iter().any(|x| !x.is_finite()) {
        return Err(ConstitutiveError::NonFiniteDeformation { model });
    }
    let det = determinant(f);
    if det > 0.0 {
        Ok(det)
    } else {
        Err(ConstitutiveError::NonPositiveJacobian { model, det })
    }
}

/// Checks F is finite (models that accept any det F).
pub fn finite<const D: usize>(model: &'static str, f: &Matrix<D>) -> Result<(), ConstitutiveError> {
    if f.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ConstitutiveError::NonFiniteDeformation { model })
    }
}
