//! The transfers' sums over a tensor-product stencil ([`TensorStencil`], B-spline grids),
//! taken row by row along axis 0.
//!
//! Per entry, the generic transfers form N = Π_k w_k, ∇N and the affine momentum
//! C (x_i − x) = Σ_k C_k r_k anew. Along a row only axis 0's factors change, so the
//! other axes' share of each is formed once per row (a 3D quadratic stencil has 9 rows
//! of 3 entries): their weight product, their gradient components and stress products,
//! their offsets' share of C r (P2G) and of B = Σ N v_i r_iᵀ and ∇v (G2P). The sums are
//! kept in plain arrays: in nalgebra's column views the compiler shuffled them between
//! vector lanes at every entry. They are grouped differently from the entry-by-entry
//! loops, and G2P's are fused multiply-adds where the CPU has FMA ([`fma`]), so results
//! agree with those to round-off, not bit for bit.

use nalgebra::{SMatrix, SVector};
use umls_transfer::{Kernel, TensorStencil};

use crate::scatter::Window;
use crate::transfer::TransferShape;

/// The width of `kernel`'s tensor-product stencils where P2G and G2P sum them row by row:
/// 3 or 4 nodes per axis (quadratic and cubic B-splines), the widths they dispatch on.
#[inline]
pub(super) fn row_width<const D: usize, K: Kernel<D>>(kernel: &K) -> Option<usize> {
    kernel.tensor_width().filter(|w| matches!(w, 3 | 4))
}

/// Advances `digits` (the row's node along each axis 1..D) to the next row; false after
/// the last.
#[inline(always)]
fn next_row<const D: usize, const W: usize>(digits: &mut [usize; D]) -> bool {
    for digit in digits.iter_mut().skip(1) {
        *digit += 1;
        if *digit < W {
            return true;
        }
        *digit = 0;
    }
    false
}

/// A row's first node (counted from `first` with `strides`: the grid's, or a P2G
/// window's records'), the product of its weights along axes 1..D, and for each axis
/// j ≥ 1 the product with axis j's derivative in place of its weight (∂N/∂x_j = w₀ times
/// it; entry 0 unused).
#[inline(always)]
// The axis index runs over several per-axis arrays at once.
#[allow(clippy::needless_range_loop)]
fn row_factors<const D: usize, const W: usize>(
    t: &TensorStencil<D, W>,
    (first, strides): (usize, &[usize; D]),
    digits: &[usize; D],
) -> (usize, f64, [f64; D]) {
    let mut node = first;
    let mut weight = 1.0;
    for k in 1..D {
        node += digits[k] * strides[k];
        weight *= t.values[k][digits[k]];
    }
    let gradient = std::array::from_fn(|j| {
        let mut g = if j == 0 {
            0.0
        } else {
            t.derivatives[j][digits[j]]
        };
        for k in 1..D {
            if k != j && j != 0 {
                g *= t.values[k][digits[k]];
            }
        }
        g
    });
    (node, weight, gradient)
}

/// a·b + c, rounded once where the build's CPU has FMA (one instruction, which shortens
/// the chains of G2P's row sums: G2P 15 % faster on the fluid box), else multiplied and
/// added as written (`f64::mul_add` without FMA is a library call).
#[inline(always)]
fn fma(a: f64, b: f64, c: f64) -> f64 {
    if cfg!(target_feature = "fma") {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// A matrix's columns as plain arrays.
#[inline(always)]
fn columns<const D: usize>(m: &SMatrix<f64, D, D>) -> [[f64; D]; D] {
    std::array::from_fn(|k| std::array::from_fn(|j| m[(j, k)]))
}

/// What one particle spreads in P2G.
pub(super) struct ParticleLoad<const D: usize> {
    /// m_p.
    pub mass: f64,
    /// v_p; under MLS-MPM m (v + Δt a).
    pub velocity: SVector<f64, D>,
    /// C_p (zero without an affine transfer); under MLS-MPM m C − Δt V τ D⁻¹.
    pub affine: SMatrix<f64, D, D>,
    /// V_p.
    pub volume: f64,
    /// V_p τ_p.
    pub stress_volume: SMatrix<f64, D, D>,
    /// The body acceleration at the particle.
    pub acceleration: SVector<f64, D>,
}

/// [`scatter_rows`] compiled for the transfer's shape: a branch per particle here
/// rather than per node in the rows.
#[inline(always)]
pub(super) fn scatter_rows_for<const D: usize, const W: usize>(
    shape: TransferShape,
    t: &TensorStencil<D, W>,
    window: &mut Window<D>,
    load: &ParticleLoad<D>,
) {
    match (shape.affine, shape.fused_force) {
        (true, true) => scatter_rows::<D, W, true, true>(t, window, load),
        (false, true) => scatter_rows::<D, W, false, true>(t, window, load),
        (true, false) => scatter_rows::<D, W, true, false>(t, window, load),
        (false, false) => scatter_rows::<D, W, false, false>(t, window, load),
    }
}

/// P2G of one particle over `t` into `window` (a kernel with values ≥ 0: no |N|-mass
/// apart). Under MLS-MPM (`FUSED`) the mass N m and the momentum N (p + A (x_i − x));
/// otherwise the mass, the stiffness V |∇N|², the momentum N m (v + C (x_i − x)) and
/// the force N m a − V τ ∇N. `AFFINE`: whether C enters the momentum.
#[inline(always)]
fn scatter_rows<const D: usize, const W: usize, const AFFINE: bool, const FUSED: bool>(
    t: &TensorStencil<D, W>,
    window: &mut Window<D>,
    load: &ParticleLoad<D>,
) {
    let c = columns(&load.affine);
    let s = columns(&load.stress_volume);
    let m = load.mass;
    let (first, strides) = window.place(t.first, &t.corner, &t.strides);
    let mut digits = [0usize; D];
    loop {
        let (node, weight, gradient) = row_factors(t, (first, &strides), &digits);
        // The momentum (per unit N m, or per unit N under MLS-MPM) without axis 0's
        // share of C r.
        let mut base: [f64; D] = std::array::from_fn(|j| load.velocity[j]);
        if AFFINE {
            for k in 1..D {
                let r = t.offsets[k][digits[k]];
                for j in 0..D {
                    base[j] += c[k][j] * r;
                }
            }
        }
        if FUSED {
            for a in 0..W {
                let n = t.values[0][a] * weight;
                let nm = n * m;
                let r = t.offsets[0][a];
                let p = SVector::<f64, D>::from_fn(|j, _| (base[j] + c[0][j] * r) * n);
                window.add_momentum::<0>(node + a, nm, nm, p);
            }
        } else {
            // Axes 1..D's share of V τ ∇N (per unit w₀) and of |∇N|² (per unit w₀²).
            let mut stress_row = [0.0; D];
            let mut squares = 0.0;
            for k in 1..D {
                squares += gradient[k] * gradient[k];
                for j in 0..D {
                    stress_row[j] += s[k][j] * gradient[k];
                }
            }
            for a in 0..W {
                let w = t.values[0][a];
                let n = w * weight;
                let nm = n * m;
                let g0 = t.derivatives[0][a] * weight;
                let r = t.offsets[0][a];
                let momentum = SVector::<f64, D>::from_fn(|j, _| {
                    if AFFINE {
                        (base[j] + c[0][j] * r) * nm
                    } else {
                        base[j] * nm
                    }
                });
                let force = SVector::<f64, D>::from_fn(|j, _| {
                    load.acceleration[j] * nm - (s[0][j] * g0 + stress_row[j] * w)
                });
                let stiffness = load.volume * (g0 * g0 + w * w * squares);
                window.add::<0>(node + a, nm, nm, stiffness, momentum, force);
            }
        }
        if !next_row::<D, W>(&mut digits) {
            return;
        }
    }
}

/// G2P's sums over `t` from the grid velocities before (`old`) and after (`new`) the
/// grid update: Σ N ṽ_i; Σ N (ṽ_i − v_i) if the scheme uses FLIP (`FLIP`, else zero);
/// ∇v = Σ ṽ_i ∇N_iᵀ unless it is MLS-MPM (`FUSED`, else zero); B = Σ N ṽ_i (x_i − x)ᵀ
/// if it uses moments (`MOMENTS`, else zero).
#[inline(always)]
#[allow(clippy::type_complexity)]
pub(super) fn gather_rows<
    const D: usize,
    const W: usize,
    const MOMENTS: bool,
    const FUSED: bool,
    const FLIP: bool,
>(
    t: &TensorStencil<D, W>,
    new: &[SVector<f64, D>],
    old: &[SVector<f64, D>],
) -> (
    SVector<f64, D>,
    SVector<f64, D>,
    SMatrix<f64, D, D>,
    SMatrix<f64, D, D>,
) {
    let mut pic = [0.0; D];
    let mut flip = [0.0; D];
    let mut grad_v = [[0.0; D]; D];
    let mut b = [[0.0; D]; D];
    let mut digits = [0usize; D];
    loop {
        let (node, weight, gradient) = row_factors(t, (t.first, &t.strides), &digits);
        let velocities = &new[node..node + W];
        // The row's Σ w₀ ṽ, Σ w₀ r₀ ṽ, Σ w₀' ṽ and Σ w₀ (ṽ − v).
        let mut row = [0.0; D];
        let mut row_moment = [0.0; D];
        let mut row_derivative = [0.0; D];
        let mut row_flip = [0.0; D];
        for a in 0..W {
            let w = t.values[0][a];
            let wr = w * t.offsets[0][a];
            let dw = t.derivatives[0][a];
            for j in 0..D {
                let v = velocities[a][j];
                row[j] = fma(v, w, row[j]);
                if MOMENTS {
                    row_moment[j] = fma(v, wr, row_moment[j]);
                }
                if !FUSED {
                    row_derivative[j] = fma(v, dw, row_derivative[j]);
                }
                if FLIP {
                    row_flip[j] = fma(v - old[node + a][j], w, row_flip[j]);
                }
            }
        }
        for j in 0..D {
            pic[j] = fma(row[j], weight, pic[j]);
            if FLIP {
                flip[j] = fma(row_flip[j], weight, flip[j]);
            }
            if MOMENTS {
                b[0][j] = fma(row_moment[j], weight, b[0][j]);
            }
            if !FUSED {
                grad_v[0][j] = fma(row_derivative[j], weight, grad_v[0][j]);
            }
        }
        for k in 1..D {
            let offset = weight * t.offsets[k][digits[k]];
            for j in 0..D {
                if MOMENTS {
                    b[k][j] = fma(row[j], offset, b[k][j]);
                }
                if !FUSED {
                    grad_v[k][j] = fma(row[j], gradient[k], grad_v[k][j]);
                }
            }
        }
        if !next_row::<D, W>(&mut digits) {
            return (
                SVector::from(pic),
                SVector::from(flip),
                SMatrix::from_fn(|j, k| grad_v[k][j]),
                SMatrix::from_fn(|j, k| b[k][j]),
            );
        }
    }
}
