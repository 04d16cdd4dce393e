//! The test a second moment D_p = Σ N_i r_i r_iᵀ must pass before a transfer inverts it:
//! what [`crate::Kernel::regular_second_moment`] promises, shared by the engine (APIC's
//! C_p = B_p D_p⁻¹, MLS-MPM's force) and the kernels' conformance suite.

use nalgebra::SMatrix;

/// D⁻¹ of a second moment that is positive definite (its Cholesky factorisation
/// succeeds) and not near singular (det D > 10⁻⁶ (tr D / D)^D); `None` otherwise.
#[inline]
pub fn regular_inverse<const D: usize>(d: &SMatrix<f64, D, D>) -> Option<SMatrix<f64, D, D>> {
    let cholesky = d.cholesky()?;
    let scale = (d.trace() / D as f64).powi(D as i32);
    let det = cholesky.l_dirty().diagonal().product().powi(2);
    if det.is_nan() || det <= 1e-6 * scale {
        return None;
    }
    Some(cholesky.inverse())
}

#[cfg(test)]
mod tests {
    use nalgebra::Matrix2;

    use super::regular_inverse;

    #[test]
    fn inverts_regular_moments_and_refuses_the_others() {
        let d = Matrix2::new(2.0, 0.5, 0.5, 1.0);
        let inverse = regular_inverse(&d).expect("positive definite");
        assert!((inverse * d - Matrix2::identity()).norm() < 1e-14);
        // Indefinite (a one-sided MLS fit at a mesh corner), zero, and near singular.
        assert!(regular_inverse(&Matrix2::new(-1e-4, -1e-3, -1e-3, 4e-5)).is_none());
        assert!(regular_inverse(&Matrix2::<f64>::zeros()).is_none());
        assert!(regular_inverse(&Matrix2::new(1.0, 0.0, 0.0, 1e-7)).is_none());
        assert!(regular_inverse(&Matrix2::new(1.0, 0.0, 0.0, 1e-5)).is_some());
    }
}
