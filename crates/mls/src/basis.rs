//! Polynomial bases for MLS, generic over dimension.

use nalgebra::SVector;

/// A complete polynomial basis p(ξ) of size `N` in `D` variables.
///
/// Contract (relied on by the solver's gradient formulas and checked by the tests):
/// the basis is complete to its degree, `p(0) = e₀` (the constant comes first) and
/// `∂p/∂ξ_k(0) = e_{k+1}` (the D linear monomials come next, in axis order). Further
/// monomials must vanish with their first derivatives at 0, as every monomial of degree ≥ 2
/// does.
///
/// The size is a const parameter rather than an associated constant because stable Rust
/// cannot size arrays by `D + 1`; each basis implements the trait once per dimension, so
/// `N` is inferred from the basis type and `D`.
pub trait PolynomialBasis<const D: usize, const N: usize>: Copy + Send + Sync + 'static {
    /// Total degree of the basis.
    const DEGREE: usize;
    /// Evaluates p(ξ).
    fn evaluate(xi: &SVector<f64, D>) -> SVector<f64, N>;
}

/// The linear basis [1, ξ₁, …, ξ_D] (size D+1): reproduces linear fields exactly.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Linear;

/// The quadratic basis [1, ξ, ξ_i ξ_j (i ≤ j)] (size (D+1)(D+2)/2): reproduces quadratics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Quadratic;

fn linear<const D: usize, const N: usize>(xi: &SVector<f64, D>) -> SVector<f64, N> {
    let mut p = SVector::<f64, N>::zeros();
    p[0] = 1.0;
    for k in 0..D {
        p[k + 1] = xi[k];
    }
    p
}

fn quadratic<const D: usize, const N: usize>(xi: &SVector<f64, D>) -> SVector<f64, N> {
    let mut p = linear::<D, N>(xi);
    let mut m = D + 1;
    for i in 0..D {
        for j in i..D {
            p[m] = xi[i] * xi[j];
            m += 1;
        }
    }
    p
}

macro_rules! impl_basis {
    ($basis:ty, $degree:expr, $f:ident, $(($d:literal, $n:literal)),*) => {$(
        impl PolynomialBasis<$d, $n> for $basis {
            const DEGREE: usize = $degree;
            #[inline]
            fn evaluate(xi: &SVector<f64, $d>) -> SVector<f64, $n> {
                $f::<$d, $n>(xi)
            }
        }
    )*};
}

impl_basis!(Linear, 1, linear, (1, 2), (2, 3), (3, 4));
impl_basis!(Quadratic, 2, quadratic, (1, 3), (2, 6), (3, 10));
