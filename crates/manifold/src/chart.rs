//! The local chart (q, H) of a query r: an affine d-plane fitted to the weighted
//! neighbours with r − q ⊥ H (step 1 of Sober–Aizenbud–Levin), computed in the query's
//! [`Frame`].
//!
//! The plain iteration (weighted affine fit of r_i − q against the chart coordinates,
//! then the re-projection r − q ⊥ H) converges linearly, and on noisy data slowly: the
//! contraction factor measured 0.93–0.98 per step, so 150–330 steps for a 10⁻¹⁰σ
//! tolerance. Anderson acceleration (Walker & Ni 2011) on the state (q/σ, U) with a
//! memory of [`ANDERSON_MEMORY`] steps turns that into a handful of steps: it
//! extrapolates from the last few residuals, re-orthonormalises U and re-projects q after
//! each mixed step, and falls back to the plain step whenever the mixing is
//! ill-conditioned or the residual grows.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::dense::{cholesky_solve, dot, least_squares, orthonormalise};
use crate::error::ManifoldError;
use crate::frame::Frame;

/// Residual differences Anderson acceleration keeps.
pub const ANDERSON_MEMORY: usize = 5;

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
    /// Iterations the fit took (all bandwidths tried).
    pub iterations: usize,
}

impl Chart {
    /// Chart coordinates Uᵀ(p − q) of a point.
    pub fn coordinates(&self, p: &DVector<f64>) -> DVector<f64> {
        self.basis.transpose() * (p - &self.origin)
    }
}

/// A chart in frame coordinates: q (dim) and U (dim × d, column-major).
#[derive(Debug, Default)]
pub(crate) struct FrameChart {
    pub q: Vec<f64>,
    pub u: Vec<f64>,
    pub iterations: usize,
}

/// Scratch buffers of the chart iteration.
#[derive(Debug, Default)]
pub(crate) struct ChartScratch {
    weights: Vec<f64>,
    normal: Vec<f64>,
    rhs: Vec<f64>,
    z: Vec<f64>,
    g: Vec<f64>,
    f: Vec<f64>,
    g_prev: Vec<f64>,
    f_prev: Vec<f64>,
    delta_f: Vec<f64>,
    delta_g: Vec<f64>,
    mix: Vec<f64>,
    gamma: Vec<f64>,
    lsq: Vec<f64>,
    q: Vec<f64>,
    monomial: Vec<f64>,
    offset: Vec<f64>,
    scaled_query: Vec<f64>,
}

/// The settings of one chart fit.
pub(crate) struct ChartProblem<'a> {
    pub frame: &'a Frame,
    /// Multiplicity of each neighbour.
    pub mass: &'a [f64],
    pub intrinsic: usize,
    pub sigma: f64,
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl ChartProblem<'_> {
    fn weights_about(&self, q: &[f64], weights: &mut Vec<f64>) -> f64 {
        let dim = self.frame.dim;
        weights.clear();
        weights.extend(
            self.frame
                .coords
                .chunks_exact(dim.max(1))
                .zip(self.mass)
                .map(|(y, m)| {
                    let t = y
                        .iter()
                        .zip(q)
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum::<f64>()
                        .sqrt();
                    m * theta(t, self.sigma)
                }),
        );
        weights.iter().sum()
    }

    /// Start: θ-weighted mean about the frame centre (the nearest sample) and the leading
    /// d principal directions of the weighted neighbours; then r − q ⊥ H.
    fn start(&self, s: &mut ChartScratch, chart: &mut FrameChart) -> Result<(), ManifoldError> {
        let (dim, d) = (self.frame.dim, self.intrinsic);
        s.q.clear();
        s.q.resize(dim, 0.0);
        let total = self.weights_about(&s.q, &mut s.weights);
        if total.is_nan() || total <= 0.0 || dim < d {
            return Err(ManifoldError::RankDeficient { ratio: 0.0 });
        }
        chart.q.clear();
        chart.q.resize(dim, 0.0);
        for (y, w) in self.frame.coords.chunks_exact(dim).zip(&s.weights) {
            chart
                .q
                .iter_mut()
                .zip(y)
                .for_each(|(q, y)| *q += w / total * y);
        }
        let mut covariance = DMatrix::<f64>::zeros(dim, dim);
        for (y, w) in self.frame.coords.chunks_exact(dim).zip(&s.weights) {
            for b in 0..dim {
                let yb = w * (y[b] - chart.q[b]);
                for a in 0..dim {
                    covariance[(a, b)] += (y[a] - chart.q[a]) * yb;
                }
            }
        }
        let eigen = SymmetricEigen::new(covariance);
        let mut order: Vec<usize> = (0..dim).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        let largest = eigen.eigenvalues[order[0]];
        let smallest_kept = eigen.eigenvalues[order[d - 1]];
        if smallest_kept.is_nan() || smallest_kept <= 1e-24 * largest {
            return Err(ManifoldError::RankDeficient {
                ratio: (smallest_kept.max(0.0) / largest).sqrt(),
            });
        }
        chart.u.clear();
        for &k in &order[..d] {
            let column = eigen.eigenvectors.column(k);
            // Largest entry positive: the orientation does not depend on the solver.
            let pivot =
                column.iter().copied().fold(
                    0.0f64,
                    |best, x| if x.abs() > best.abs() { x } else { best },
                );
            let sign = if pivot < 0.0 { -1.0 } else { 1.0 };
            chart.u.extend(column.iter().map(|x| sign * x));
        }
        reproject(&mut chart.q, &chart.u, &self.frame.query, d);
        Ok(())
    }

    /// One plain step G(z) of the state z = (q/σ, U) into `g`; returns ‖Δq‖/σ.
    fn step(
        &self,
        z: &[f64],
        g: &mut Vec<f64>,
        s: &mut ChartScratch,
    ) -> Result<f64, ManifoldError> {
        let (dim, d) = (self.frame.dim, self.intrinsic);
        let mut q = std::mem::take(&mut s.q);
        q.clear();
        q.extend(z[..dim].iter().map(|x| x * self.sigma));
        let u = &z[dim..];
        self.weights_about(&q, &mut s.weights);
        // Normal equations of the affine fit (r_i − q) ≈ a + B x_i, x_i = Uᵀ(r_i − q)/σ:
        // d + 1 well-scaled columns, so squaring their condition costs nothing measurable.
        let p = d + 1;
        s.normal.clear();
        s.normal.resize(p * p, 0.0);
        s.rhs.clear();
        s.rhs.resize(p * dim, 0.0);
        let mut basis = std::mem::take(&mut s.monomial);
        basis.clear();
        basis.resize(p, 0.0);
        let mut offset = std::mem::take(&mut s.offset);
        offset.clear();
        offset.resize(dim, 0.0);
        let mut used = 0usize;
        for (y, &w) in self.frame.coords.chunks_exact(dim).zip(&s.weights) {
            if w <= 0.0 {
                continue;
            }
            used += 1;
            offset
                .iter_mut()
                .zip(y)
                .zip(&q)
                .for_each(|((o, y), q)| *o = y - q);
            basis[0] = 1.0;
            for k in 0..d {
                basis[1 + k] = dot(&u[k * dim..(k + 1) * dim], &offset) / self.sigma;
            }
            for a in 0..p {
                for b in 0..p {
                    s.normal[a + b * p] += w * basis[a] * basis[b];
                }
            }
            for (c, o) in offset.iter().enumerate() {
                let wo = w * o;
                for (a, b) in basis.iter().enumerate() {
                    s.rhs[a + c * p] += b * wo;
                }
            }
        }
        s.monomial = basis;
        s.offset = offset;
        if used <= d || !cholesky_solve(&mut s.normal, p, &mut s.rhs, dim) {
            s.q = q;
            return Err(ManifoldError::RankDeficient { ratio: 0.0 });
        }
        g.clear();
        g.resize(dim * (1 + d), 0.0);
        let (g_q, g_u) = g.split_at_mut(dim);
        for c in 0..dim {
            g_q[c] = q[c] + s.rhs[c * p];
            for k in 0..d {
                g_u[k * dim + c] = s.rhs[1 + k + c * p];
            }
        }
        s.q = q;
        if !orthonormalise(g_u, dim, d) {
            return Err(ManifoldError::RankDeficient { ratio: 0.0 });
        }
        for k in 0..d {
            if dot(&g_u[k * dim..(k + 1) * dim], &u[k * dim..(k + 1) * dim]) < 0.0 {
                g_u[k * dim..(k + 1) * dim]
                    .iter_mut()
                    .for_each(|x| *x = -*x);
            }
        }
        reproject(g_q, g_u, &self.frame.query, d);
        g_q.iter_mut().for_each(|x| *x /= self.sigma);
        Ok(g_q
            .iter()
            .zip(&z[..dim])
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt())
    }

    /// Fits the chart: the plain iteration accelerated by Anderson mixing.
    pub fn solve(&self, s: &mut ChartScratch, chart: &mut FrameChart) -> Result<(), ManifoldError> {
        let (dim, d) = (self.frame.dim, self.intrinsic);
        self.start(s, chart)?;
        let len = dim * (1 + d);
        let mut z = std::mem::take(&mut s.z);
        let mut g = std::mem::take(&mut s.g);
        z.clear();
        z.extend(chart.q.iter().map(|x| x / self.sigma));
        z.extend_from_slice(&chart.u);
        s.scaled_query.clear();
        s.scaled_query
            .extend(self.frame.query.iter().map(|x| x / self.sigma));
        let mut history = 0usize;
        let mut previous_residual = f64::INFINITY;
        let mut result = Err(ManifoldError::NotConverged {
            iterations: self.max_iterations,
            step: f64::INFINITY,
        });
        for iteration in 1..=self.max_iterations {
            let step = match self.step(&z, &mut g, s) {
                Ok(step) => step,
                Err(error) => {
                    result = Err(error);
                    break;
                }
            };
            if step < self.tolerance {
                chart.q.clear();
                chart.q.extend(g[..dim].iter().map(|x| x * self.sigma));
                chart.u.clear();
                chart.u.extend_from_slice(&g[dim..]);
                chart.iterations = iteration;
                result = Ok(());
                break;
            }
            if let Err(ManifoldError::NotConverged { step: last, .. }) = &mut result {
                *last = step;
            }
            s.f.clear();
            s.f.extend(g.iter().zip(&z).map(|(g, z)| g - z));
            let residual = dot(&s.f, &s.f).sqrt();
            if iteration > 1 {
                if residual > 2.0 * previous_residual {
                    history = 0;
                } else {
                    // Append Δf, Δg as the newest columns, dropping the oldest.
                    if history == ANDERSON_MEMORY {
                        s.delta_f.drain(..len);
                        s.delta_g.drain(..len);
                        history -= 1;
                    }
                    s.delta_f.truncate(history * len);
                    s.delta_g.truncate(history * len);
                    s.delta_f
                        .extend(s.f.iter().zip(&s.f_prev).map(|(a, b)| a - b));
                    s.delta_g
                        .extend(g.iter().zip(&s.g_prev).map(|(a, b)| a - b));
                    history += 1;
                }
            }
            s.f_prev.clone_from(&s.f);
            s.g_prev.clone_from(&g);
            previous_residual = residual;
            z.clone_from(&g);
            if history > 0 && len > history {
                if self.mix(history, len, &mut z, s) {
                    let (z_q, z_u) = z.split_at_mut(dim);
                    reproject(z_q, z_u, &s.scaled_query, d);
                } else {
                    // A failed mix may have changed z: fall back to the plain step.
                    z.clone_from(&g);
                }
            }
        }
        // The buffers go back to the workspace on every path, failures included.
        s.z = z;
        s.g = g;
        result
    }

    /// z ← g − ΔG γ with γ = argmin ‖f − ΔF γ‖, then U re-orthonormalised; `false` (and z
    /// untouched in meaning) when the mixing is ill-conditioned or breaks U.
    fn mix(&self, history: usize, len: usize, z: &mut [f64], s: &mut ChartScratch) -> bool {
        let (dim, d) = (self.frame.dim, self.intrinsic);
        s.mix.clone_from(&s.delta_f);
        s.gamma.clear();
        s.gamma.extend_from_slice(&s.f);
        let conditioning = least_squares(&mut s.mix, len, history, &mut s.gamma, 1, &mut s.lsq);
        if conditioning.condition.is_nan() || conditioning.condition >= 1e10 {
            return false;
        }
        for (j, &gamma) in s.gamma[..history].iter().enumerate() {
            z.iter_mut()
                .zip(&s.delta_g[j * len..(j + 1) * len])
                .for_each(|(z, dg)| *z -= gamma * dg);
        }
        orthonormalise(&mut z[dim..], dim, d)
    }
}

/// q ← q + U Uᵀ (r − q): the foot of r on the plane through q spanned by U.
fn reproject(q: &mut [f64], u: &[f64], r: &[f64], d: usize) {
    let dim = q.len();
    for k in 0..d {
        let column = &u[k * dim..(k + 1) * dim];
        let c: f64 = column
            .iter()
            .zip(r.iter().zip(q.iter()))
            .map(|(u, (r, q))| u * (r - q))
            .sum();
        q.iter_mut().zip(column).for_each(|(q, u)| *q += c * u);
    }
}
