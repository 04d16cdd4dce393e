//! The local chart (q, H) of a query r: an affine d-plane fitted to the weighted
//! neighbours with r − q ⊥ H (step 1 of Sober–Aizenbud–Levin).

use nalgebra::{DMatrix, DVector};

use crate::error::ManifoldError;
use crate::polynomial::{Monomials, weighted_fit};

/// θ(t) = exp(−t² / (t − σ)²) for t < σ, 0 beyond: smooth, compactly supported.
#[inline]
pub fn theta(t: f64, sigma: f64) -> f64 {
    if t < sigma {
        (-(t * t) / ((t - sigma) * (t - sigma))).exp()
    } else {
        0.0
    }
}

/// A local chart: origin q ∈ Rⁿ and an orthonormal basis U (n×d) of the tangent plane H.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Origin q, the foot of the query on the fitted plane.
    pub origin: DVector<f64>,
    /// Orthonormal basis of H, one column per intrinsic direction.
    pub basis: DMatrix<f64>,
    /// Bandwidth σ of the weights.
    pub sigma: f64,
    /// Iterations the fit took.
    pub iterations: usize,
}

impl Chart {
    /// Chart coordinates Uᵀ(p − q) of a point.
    pub fn coordinates(&self, p: &DVector<f64>) -> DVector<f64> {
        self.basis.transpose() * (p - &self.origin)
    }
}

/// Neighbour coordinates as the columns of an n×K matrix.
pub(crate) struct Neighbourhood {
    pub points: DMatrix<f64>,
}

/// Fits the chart by the iteration of the theory digest §4: start from the weighted mean
/// and weighted PCA, then alternate a weighted affine fit of r_i − q against the chart
/// coordinates (new q and H) with the re-projection r − q ⊥ H, until ‖Δq‖ < tol·σ.
pub(crate) fn fit_chart(
    hood: &Neighbourhood,
    query: &DVector<f64>,
    intrinsic: usize,
    sigma: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<Chart, ManifoldError> {
    let (n, count) = hood.points.shape();
    let weights_about = |q: &DVector<f64>| -> Vec<f64> {
        (0..count)
            .map(|i| theta((hood.points.column(i) - q).norm(), sigma))
            .collect()
    };

    // Start: weighted mean and the leading left singular vectors of the weighted, centred
    // n×K neighbour matrix (cost O(n K²), linear in n). An SVD rather than an eigensolver
    // on the K×K Gram matrix: that matrix has rank ≤ n and, for n ≪ K, a large null space
    // on which symmetric eigensolvers lose accuracy.
    let w0 = weights_about(query);
    let total: f64 = w0.iter().sum();
    if !(total.is_finite() && total > 0.0) {
        return Err(ManifoldError::TooFewNeighbours {
            found: 0,
            needed: intrinsic + 1,
            degree: 1,
            intrinsic,
        });
    }
    let mut q = DVector::<f64>::zeros(n);
    for (point, w) in hood.points.column_iter().zip(&w0) {
        q += point * (w / total);
    }
    let mut centred = DMatrix::<f64>::zeros(n, count);
    for (i, (point, w)) in hood.points.column_iter().zip(&w0).enumerate() {
        centred.set_column(i, &((point - &q) * w.sqrt()));
    }
    let svd = centred.svd(true, false);
    let u = svd.u.ok_or(ManifoldError::RankDeficient { ratio: 0.0 })?;
    let sigma_max = svd.singular_values.max();
    if u.ncols() < intrinsic
        || svd.singular_values[intrinsic - 1] <= 1e-12 * sigma_max
        || sigma_max.is_nan()
    {
        let ratio = if u.ncols() < intrinsic {
            0.0
        } else {
            svd.singular_values[intrinsic - 1] / sigma_max
        };
        return Err(ManifoldError::RankDeficient { ratio });
    }
    let mut basis = u.columns(0, intrinsic).into_owned();
    fix_signs(&mut basis);
    q += &basis * (basis.transpose() * (query - &q));

    let linear = Monomials::new(intrinsic, 1);
    let mut step = f64::INFINITY;
    for iteration in 1..=max_iterations {
        let w = weights_about(&q);
        let mut coords = DMatrix::<f64>::zeros(count, intrinsic);
        let mut offsets = DMatrix::<f64>::zeros(count, n);
        for i in 0..count {
            let d = hood.points.column(i) - &q;
            let x = basis.transpose() * &d / sigma;
            coords.set_row(i, &x.transpose());
            offsets.set_row(i, &d.transpose());
        }
        // (r_i − q) ≈ a + B x_i: a moves the origin, the columns of B span the new plane.
        let coefficients = weighted_fit(&linear, &coords, &w, &offsets)?;
        let shift = coefficients.row(0).transpose();
        let spanning = coefficients.rows(1, intrinsic).transpose();
        let mut new_basis = spanning.qr().q();
        // Keep the orientation of the previous basis (QR may flip columns).
        for k in 0..intrinsic {
            if new_basis.column(k).dot(&basis.column(k)) < 0.0 {
                new_basis.column_mut(k).neg_mut();
            }
        }
        let mut new_q = &q + shift;
        new_q += &new_basis * (new_basis.transpose() * (query - &new_q));
        step = (&new_q - &q).norm() / sigma;
        q = new_q;
        basis = new_basis;
        if step < tolerance {
            return Ok(Chart {
                origin: q,
                basis,
                sigma,
                iterations: iteration,
            });
        }
    }
    Err(ManifoldError::NotConverged {
        iterations: max_iterations,
        step,
    })
}

/// Makes the largest-magnitude entry of each column positive, so the chart's orientation
/// does not depend on the eigen-solver's sign choices.
fn fix_signs(basis: &mut DMatrix<f64>) {
    for mut column in basis.column_iter_mut() {
        let pivot =
            column.iter().copied().fold(
                0.0f64,
                |best, x| if x.abs() > best.abs() { x } else { best },
            );
        if pivot < 0.0 {
            column.neg_mut();
        }
    }
}
