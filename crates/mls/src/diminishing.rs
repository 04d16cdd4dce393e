//! The diminishing factor η_v = Σ_{n ∈ host} λ_n A_{v,n} of the UMLS kernel.
//!
//! Pure functions of a vertex's adjacency bitmask and the host's barycentric
//! coordinates (and their gradients), so they serve any mesh representation.

use nalgebra::SVector;

/// η_v for a ring vertex whose bit n is set iff it equals or is edge-adjacent to host vertex n.
///
/// Inside the host every λ_n ≥ 0 so η ∈ [0, 1]; η = 1 for vertices adjacent to the whole
/// host, and η → 0 for a vertex that leaves or enters the 1-ring as the point crosses a
/// facet (its only host neighbour is the vertex opposite that facet, whose λ vanishes there).
/// Round-off can make λ slightly negative on a facet; η is clamped at 0 so no weight is
/// ever negative.
#[inline]
pub fn diminishing_factor(mask: u8, lambda: &[f64]) -> f64 {
    let mut eta = 0.0;
    for (n, &l) in lambda.iter().enumerate() {
        if mask & (1 << n) != 0 {
            eta += l;
        }
    }
    eta.max(0.0)
}

/// η^p, the diminishing factor raised to the kernel's exponent p ≥ 1
/// ([`crate::UmlsKernel::with_diminishing_exponent`]).
///
/// η is linear in the barycentric coordinates, so η^p is a polynomial of them, continuous
/// across facets like η, and a vertex entering the ring at η = 0 enters with zero weight
/// and, for p ≥ 2, zero weight gradient. Raising η to p > 1 weights the host's vertices
/// (η = 1) above the farther ring vertices (η < 1), the more the farther the point is
/// from them: a narrower stencil built from the mesh's adjacency rather than from
/// distance. p = 1 returns η itself, bit for bit.
#[inline]
pub fn powered_diminishing(eta: f64, exponent: u32) -> f64 {
    match exponent {
        1 => eta,
        2 => eta * eta,
        _ => eta.powi(exponent as i32),
    }
}

/// d(η^p)/dη = p η^{p−1}, for the full derivative of a powered weight.
#[inline]
pub fn powered_diminishing_slope(eta: f64, exponent: u32) -> f64 {
    match exponent {
        1 => 1.0,
        _ => f64::from(exponent) * powered_diminishing(eta, exponent - 1),
    }
}

/// ∇η_v = Σ_n A_{v,n} ∇λ_n: constant on the host, and discontinuous across facets.
#[inline]
pub fn diminishing_gradient<const D: usize>(
    mask: u8,
    lambda_gradients: &[SVector<f64, D>],
) -> SVector<f64, D> {
    let mut grad = SVector::<f64, D>::zeros();
    for (n, g) in lambda_gradients.iter().enumerate() {
        if mask & (1 << n) != 0 {
            grad += g;
        }
    }
    grad
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1D: η of a vertex two to the left of the host's right vertex is a trapezoid that
    /// falls linearly to 0 (theory digest §1).
    #[test]
    fn one_dimensional_trapezoid() {
        // Host [x1, x2]; ring vertex x0 is adjacent only to host vertex 0 (= x1): mask 0b01.
        for t in [0.0, 0.25, 0.5, 1.0] {
            let lambda = [1.0 - t, t];
            assert_eq!(diminishing_factor(0b01, &lambda), 1.0 - t);
            assert_eq!(diminishing_factor(0b11, &lambda), 1.0);
        }
        assert_eq!(diminishing_factor(0b10, &[1.0 + 1e-17, -1e-17]), 0.0);
        let g = diminishing_gradient::<1>(0b01, &[SVector::from([-1.0]), SVector::from([1.0])]);
        assert_eq!(g[0], -1.0);
    }

    /// η^p and its slope against direct evaluation and central differences.
    #[test]
    fn powered_factor_and_slope() {
        for p in 1..=6u32 {
            for eta in [0.0, 0.1, 0.37, 0.8, 1.0] {
                let value = powered_diminishing(eta, p);
                assert!(
                    (value - f64::powf(eta, f64::from(p))).abs() <= 1e-15,
                    "p {p}, η {eta}"
                );
                if eta > 0.0 && eta < 1.0 {
                    let step = 1e-6;
                    let fd = (powered_diminishing(eta + step, p)
                        - powered_diminishing(eta - step, p))
                        / (2.0 * step);
                    let slope = powered_diminishing_slope(eta, p);
                    assert!(
                        (slope - fd).abs() <= 1e-8,
                        "p {p}, η {eta}: {slope} vs {fd}"
                    );
                }
            }
            assert_eq!(
                powered_diminishing_slope(0.0, p),
                if p == 1 { 1.0 } else { 0.0 }
            );
        }
        assert_eq!(powered_diminishing(0.123_456_789, 1), 0.123_456_789);
    }
}
