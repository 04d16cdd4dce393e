//! Per-simplex affine geometry: signed volume and the inverse of the edge matrix.

use nalgebra::{SMatrix, SVector};

/// D! for D ≤ 3, the factor between det(edge matrix) and simplex volume.
pub(crate) const fn factorial(d: usize) -> f64 {
    match d {
        0 | 1 => 1.0,
        2 => 2.0,
        _ => 6.0,
    }
}

/// Edge matrix T = [x₁ − x₀, …, x_D − x₀] of a simplex given its vertex coordinates.
pub(crate) fn edge_matrix<const D: usize>(corners: &[SVector<f64, D>]) -> SMatrix<f64, D, D> {
    SMatrix::<f64, D, D>::from_fn(|row, col| corners[col + 1][row] - corners[0][row])
}

/// Longest edge length of a simplex.
pub(crate) fn longest_edge<const D: usize>(corners: &[SVector<f64, D>]) -> f64 {
    let mut longest: f64 = 0.0;
    for (i, a) in corners.iter().enumerate() {
        for b in &corners[i + 1..] {
            longest = longest.max((a - b).norm());
        }
    }
    longest
}

/// Shortest edge length of a simplex.
pub(crate) fn shortest_edge<const D: usize>(corners: &[SVector<f64, D>]) -> f64 {
    let mut shortest = f64::INFINITY;
    for (i, a) in corners.iter().enumerate() {
        for b in &corners[i + 1..] {
            shortest = shortest.min((a - b).norm());
        }
    }
    shortest
}

/// Signed volume of a simplex: det(T) / D!.
pub(crate) fn signed_volume<const D: usize>(corners: &[SVector<f64, D>]) -> f64 {
    determinant(&edge_matrix(corners)) / factorial(D)
}

/// Determinant of a D×D matrix for D ≤ 3, by cofactor expansion.
///
/// nalgebra's generic `determinant` needs `DimMin` bounds on `Const<D>` that would leak
/// into every generic signature of the workspace; D ≤ 3 makes the closed form trivial.
pub fn determinant<const D: usize>(m: &SMatrix<f64, D, D>) -> f64 {
    match D {
        1 => m[(0, 0)],
        2 => m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)],
        3 => {
            m[(0, 0)] * (m[(1, 1)] * m[(2, 2)] - m[(1, 2)] * m[(2, 1)])
                - m[(0, 1)] * (m[(1, 0)] * m[(2, 2)] - m[(1, 2)] * m[(2, 0)])
                + m[(0, 2)] * (m[(1, 0)] * m[(2, 1)] - m[(1, 1)] * m[(2, 0)])
        }
        _ => unreachable!("dimension {D} is rejected at compile time by SimplexMesh"),
    }
}
