//! The UMLS kernels' integration correction: per node ξ_i = ∫(∂N_i − ∇N_i) / ∫N_i over
//! the mesh, so that the force's gradient ∇N_i + N_i ξ_i integrates like the derivative.
//!
//! A body at constant stress σ gives node i the force −σ ∫∇N_i. With the derivative ∂N_i
//! that integral vanishes for a node whose support lies inside the body (it is the
//! boundary term ∮N_i n), so the body is in equilibrium. The MLS fit's reconstructed
//! gradient is the slope of the local fit, not the derivative, and on unstructured
//! meshes its integral differs from the derivative's node by node, by an amount that does
//! not shrink with the mesh or with more particles (docs/umls-kernel.md measures it): a
//! constant stress then pushes the nodes. Adding N_i ξ_i restores the derivative's
//! integral over every node's support (variationally consistent integration, after Chen
//! et al., with the correction fitted once over the mesh instead of per step over the
//! particles), and between the nodes the gradient stays the continuous reconstructed one.
//!
//! The integrals are exact up to quadrature and independent of where particles sit:
//! ∫∂N_i is the boundary integral ∮N_i n over the mesh's boundary facets (N_i is
//! continuous, so the interior facets' terms cancel, and with them the derivative's jumps
//! across facets); ∫∇N_i and ∫N_i are taken simplex by simplex, where the fit is smooth,
//! with conical-product Gauss rules. Only the kernel's own fit is evaluated, no full
//! derivative. Integrating over the particles each step instead imports their
//! quadrature error of the jumping derivative, which on lattices with particles in rows
//! is the larger error (docs/umls-kernel.md, *Integration correction*).

use nalgebra::SVector;
use umls_mesh::{Barycentric, Located, SimplexMesh};
use umls_mls::{PolynomialBasis, WeightFunction};
use umls_transfer::{KernelError, Stencil};

use crate::UmlsMeshKernel;

/// Gauss–Jacobi points per axis of the conical-product rules in `dim` dimensions: 3 on
/// segments and triangles (9 points per triangle, exact for quintics), 2 on tetrahedra
/// (8 points, exact for cubics), where the points cost most. On jittered triangles 3
/// points put ξ within 0.5 % of an independent fine integration and 2 points within
/// 2 % (`crates/kernels/tests/integration_correction.rs`). The column results have
/// converged with 2: the Gmsh columns' interior stress error is 0.02370 / 0.01648 /
/// 0.01642 / 0.01645 (3D) and 0.00459 / 0.00417 / 0.00414 / 0.00415 (2D) with 1 / 2 /
/// 3 / 4 points per axis. On the 1.57 M-tetrahedron lattice 2 points take 2.9 s on two
/// threads, 3 points 8.5 s.
pub(crate) fn points_per_axis(dim: usize) -> usize {
    if dim >= 3 { 2 } else { 3 }
}

/// Gauss–Jacobi nodes and weights on [0, 1] for the weight (1 − u)^α: the `n` points
/// that integrate f(u) (1 − u)^α exactly for polynomials f of degree ≤ 2n − 1, with the
/// weights summing to ∫(1 − u)^α = 1/(α + 1). Golub–Welsch: the nodes are the
/// eigenvalues of the Jacobi polynomials' tridiagonal recurrence matrix (on [−1, 1], for
/// the weight (1 − x)^α), the weights the squared first components of its eigenvectors.
pub(crate) fn gauss_jacobi(n: usize, alpha: f64) -> Vec<(f64, f64)> {
    let mut matrix = nalgebra::DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        let kf = k as f64;
        let s = 2.0 * kf + alpha;
        // Diagonal: (β² − α²) / ((2k + α + β)(2k + α + β + 2)) with β = 0.
        matrix[(k, k)] = if k == 0 {
            -alpha / (alpha + 2.0)
        } else {
            -alpha * alpha / (s * (s + 2.0))
        };
        if k + 1 < n {
            let j = kf + 1.0;
            let t = 2.0 * j + alpha;
            let off =
                (4.0 * j * (j + alpha) * j * (j + alpha) / (t * t * (t + 1.0) * (t - 1.0))).sqrt();
            matrix[(k, k + 1)] = off;
            matrix[(k + 1, k)] = off;
        }
    }
    let eigen = nalgebra::SymmetricEigen::new(matrix);
    let total = 1.0 / (alpha + 1.0);
    let mut out: Vec<(f64, f64)> = (0..n)
        .map(|j| {
            let v = eigen.eigenvectors[(0, j)];
            ((1.0 + eigen.eigenvalues[j]) / 2.0, v * v * total)
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// A quadrature rule on the `dim`-simplex (dim ≤ 3): barycentric coordinates λ_0..λ_dim
/// (the rest zero) and weights summing to 1, Stroud's conical product of `n`-point
/// Gauss–Jacobi rules, exact for polynomials of degree ≤ 2n − 1.
pub(crate) fn simplex_rule(dim: usize, n: usize) -> Vec<([f64; 4], f64)> {
    // λ_1 = u_1, λ_2 = u_2 (1 − u_1), λ_3 = u_3 (1 − u_1)(1 − u_2): the Jacobian is
    // Π_k (1 − u_k)^(dim − 1 − k), which axis k's Gauss–Jacobi weight carries.
    let lines: Vec<Vec<(f64, f64)>> = (0..dim)
        .map(|k| gauss_jacobi(n, (dim - 1 - k) as f64))
        .collect();
    let factorial: f64 = (1..=dim).map(|k| k as f64).product();
    let mut out = Vec::new();
    let mut index = [0usize; 3];
    loop {
        let (mut rest, mut weight) = (1.0, factorial);
        let mut lambda = [0.0; 4];
        for (k, &i) in index.iter().enumerate().take(dim) {
            let (u, w) = lines[k][i];
            lambda[k + 1] = u * rest;
            weight *= w;
            rest *= 1.0 - u;
        }
        lambda[0] = rest;
        out.push((lambda, weight));
        // Next index (odometer over dim digits).
        let mut k = 0;
        loop {
            if k == dim {
                return out;
            }
            index[k] += 1;
            if index[k] < n {
                break;
            }
            index[k] = 0;
            k += 1;
        }
    }
}

/// Simplices per parallel work item of [`node_corrections`]; fixed, so that the sums,
/// merged block by block in order, do not depend on the number of threads.
const BLOCK: usize = 2048;

/// One vertex's integrals: ∫(∂N_i − ∇N_i), ∫N_i and ∫|N_i|.
#[derive(Debug, Clone, Copy)]
struct NodeIntegrals<const D: usize> {
    defect: SVector<f64, D>,
    weight: f64,
    abs_weight: f64,
}

impl<const D: usize> NodeIntegrals<D> {
    const ZERO: Self = Self {
        defect: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
        weight: 0.0,
        abs_weight: 0.0,
    };
}

/// ξ_i for every vertex of `kernel`'s mesh with its fit and gradient (reconstructed or
/// frozen-η; [`UmlsMeshKernel::with_integration_correction`] asks for none with the full
/// derivative), integrated with `points_per_axis` Gauss points per axis in every simplex. A vertex whose ∫N_i
/// has cancelled (negative MLS values) to below 10⁻³ of ∫|N_i| gets none. Blocks of
/// simplices are integrated in parallel and merged in block order.
pub(crate) fn node_corrections<const D: usize, const N: usize, B, W>(
    kernel: &UmlsMeshKernel<D, N, B, W>,
    points_per_axis: usize,
) -> Result<Vec<SVector<f64, D>>, KernelError>
where
    B: PolynomialBasis<D, N>,
    W: WeightFunction,
{
    use rayon::prelude::*;
    let mesh: &SimplexMesh<D> = kernel.mesh();
    let nodes = mesh.vertex_count();
    let volume_rule: Vec<(Barycentric<D>, f64)> = simplex_rule(D, points_per_axis)
        .into_iter()
        .filter_map(|(l, w)| Some((Barycentric::<D>::from_slice(&l[..=D])?, w)))
        .collect();
    let facet_rule = simplex_rule(D - 1, points_per_axis);
    let boundary = mesh.topology().boundary_facets();
    let fit = |simplex: usize, lambda: &Barycentric<D>, out: &mut Stencil<D>| {
        let located = Located {
            simplex: simplex as u32,
            barycentric: *lambda,
        };
        kernel.fit_into(&located, &mesh.point_at(simplex, lambda), out)
    };
    // Each block's integrals per vertex it reaches, in ascending vertex order.
    // Work items: blocks of simplices, then blocks of boundary facets.
    let simplex_blocks = mesh.simplex_count().div_ceil(BLOCK);
    let items = simplex_blocks + boundary.len().div_ceil(BLOCK);
    let blocks: Vec<Vec<(u32, NodeIntegrals<D>)>> = (0..items)
        .into_par_iter()
        .map(|b| {
            let mut st = Stencil::<D>::new();
            let mut sums = Vec::new();
            if b < simplex_blocks {
                // −∫∇N_i, ∫N_i and ∫|N_i| over the simplices. Every point of a simplex
                // has the same ring in the same order, so its terms are summed per
                // simplex first.
                let mut local: Vec<NodeIntegrals<D>> = Vec::new();
                for s in b * BLOCK..((b + 1) * BLOCK).min(mesh.simplex_count()) {
                    let volume = mesh.volume(s);
                    local.clear();
                    for (lambda, w) in &volume_rule {
                        fit(s, lambda, &mut st)?;
                        local.resize(st.len(), NodeIntegrals::ZERO);
                        let dv = volume * w;
                        for (e, total) in local.iter_mut().enumerate() {
                            let n = st.values()[e];
                            total.defect -= st.gradients()[e] * dv;
                            total.weight += n * dv;
                            total.abs_weight += n.abs() * dv;
                        }
                    }
                    sums.extend(st.nodes().iter().copied().zip(local.iter().copied()));
                }
            } else {
                // ∫∂N_i = ∮N_i n over the boundary facets: N_i is continuous, so the
                // interior facets' terms cancel (and the derivative's jumps with them).
                let first = (b - simplex_blocks) * BLOCK;
                for facet in &boundary[first..(first + BLOCK).min(boundary.len())] {
                    let opposite = facet.opposite as usize;
                    for (l, w) in &facet_rule {
                        // The facet's coordinates, spread over the simplex's other vertices.
                        let mut coords = [0.0; 4];
                        let mut k = 0;
                        for (j, c) in coords.iter_mut().enumerate().take(D + 1) {
                            if j != opposite {
                                *c = l[k];
                                k += 1;
                            }
                        }
                        let Some(lambda) = Barycentric::<D>::from_slice(&coords[..=D]) else {
                            continue;
                        };
                        fit(facet.simplex as usize, &lambda, &mut st)?;
                        let da = facet.measure * w;
                        for e in 0..st.len() {
                            sums.push((
                                st.nodes()[e],
                                NodeIntegrals {
                                    defect: facet.normal * (st.values()[e] * da),
                                    weight: 0.0,
                                    abs_weight: 0.0,
                                },
                            ));
                        }
                    }
                }
            }
            // A stable sort keeps each vertex's terms in the order they were made.
            sums.sort_by_key(|(node, _)| *node);
            let mut merged: Vec<(u32, NodeIntegrals<D>)> = Vec::new();
            for (node, term) in sums {
                match merged.last_mut() {
                    Some((last, total)) if *last == node => {
                        total.defect += term.defect;
                        total.weight += term.weight;
                        total.abs_weight += term.abs_weight;
                    }
                    _ => merged.push((node, term)),
                }
            }
            Ok(merged)
        })
        .collect::<Result<_, KernelError>>()?;
    let mut defect = vec![SVector::<f64, D>::zeros(); nodes];
    let (mut weight, mut abs_weight) = (vec![0.0; nodes], vec![0.0; nodes]);
    for (node, term) in blocks.into_iter().flatten() {
        let i = node as usize;
        defect[i] += term.defect;
        weight[i] += term.weight;
        abs_weight[i] += term.abs_weight;
    }
    for ((d, &m), &a) in defect.iter_mut().zip(&weight).zip(&abs_weight) {
        *d = if a > 0.0 && m > 1e-3 * a {
            *d / m
        } else {
            SVector::zeros()
        };
    }
    Ok(defect)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ λ_0^a λ_1^b … over the unit-measure simplex: a! b! … dim! / (a + b + … + dim)!.
    fn monomial_mean(powers: &[u32]) -> f64 {
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        let dim = powers.len() as u32 - 1;
        powers.iter().map(|&p| fact(p)).product::<f64>() * fact(dim)
            / fact(powers.iter().sum::<u32>() + dim)
    }

    #[test]
    fn gauss_jacobi_integrates_polynomials_to_degree_2n_minus_1() {
        // ∫_0^1 u^d (1 − u)^α du = d! α! / (d + α + 1)! (the beta function).
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        for alpha in 0..=2u32 {
            for n in 1..=6 {
                let rule = gauss_jacobi(n, f64::from(alpha));
                let moment =
                    |d: u32| -> f64 { rule.iter().map(|(u, w)| w * u.powi(d as i32)).sum() };
                for d in 0..2 * n as u32 {
                    let exact = fact(d) * fact(alpha) / fact(d + alpha + 1);
                    assert!(
                        (moment(d) - exact).abs() < 1e-14,
                        "α {alpha}, n {n}, degree {d}"
                    );
                }
                // And not beyond: the rule is Gaussian, not more.
                let d = 2 * n as u32;
                let exact = fact(d) * fact(alpha) / fact(d + alpha + 1);
                assert!((moment(d) - exact).abs() > 1e-10, "α {alpha}, n {n}");
            }
        }
    }

    #[test]
    fn simplex_rules_integrate_barycentric_monomials_exactly() {
        for dim in 0..=3usize {
            for n in 1..=4usize {
                let rule = simplex_rule(dim, n);
                assert_eq!(rule.len(), n.pow(dim as u32));
                // Every monomial of total degree ≤ 2n − 1 in λ_0..λ_dim.
                let max = 2 * n as u32 - 1;
                let mut powers = vec![0u32; dim + 1];
                loop {
                    if powers.iter().sum::<u32>() <= max {
                        let sum: f64 = rule
                            .iter()
                            .map(|(l, w)| {
                                w * powers
                                    .iter()
                                    .enumerate()
                                    .map(|(k, &p)| l[k].powi(p as i32))
                                    .product::<f64>()
                            })
                            .sum();
                        let exact = monomial_mean(&powers);
                        assert!(
                            (sum - exact).abs() < 1e-13,
                            "dim {dim}, n {n}, powers {powers:?}: {sum} against {exact}"
                        );
                    }
                    let mut k = 0;
                    loop {
                        if k > dim {
                            break;
                        }
                        powers[k] += 1;
                        if powers[k] <= max {
                            break;
                        }
                        powers[k] = 0;
                        k += 1;
                    }
                    if k > dim {
                        break;
                    }
                }
                // Points inside the simplex, coordinates summing to one.
                for (l, w) in &rule {
                    assert!(*w > 0.0);
                    assert!(l[..=dim].iter().all(|&c| (0.0..=1.0).contains(&c)));
                    assert!((l[..=dim].iter().sum::<f64>() - 1.0).abs() < 1e-14);
                }
            }
        }
    }
}
