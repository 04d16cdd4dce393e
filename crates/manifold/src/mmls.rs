//! Manifold moving least squares: per query, the bandwidth, the local frame, the chart,
//! then one degree-m fit of the values and of the offsets in it.

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::chart::{Chart, ChartProblem, ChartScratch, FrameChart};
use crate::cloud::{Distinct, PointCloud};
use crate::error::ManifoldError;
use crate::frame::Frame;
use crate::neighbors::{Neighbour, NeighbourIndex};
use crate::polynomial::{FitScratch, Monomials, fit_values_and_offsets};

/// Factor by which the bandwidth grows when a fit is untrustworthy.
const WIDENING_STEP: f64 = 1.5;

/// How the bandwidth σ of θ is chosen per query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bandwidth {
    /// σ = `scale` × (distance from the query's nearest sample to its K*-th nearest
    /// distinct sample), K* = ⌈c · C(d+m, d)⌉ + 1. θ falls to e⁻¹ at σ/2, so with scale 2
    /// about K* samples carry real weight: σ follows the local sample spacing h, which
    /// the O(h^{m+1}) rate needs. Measured from the nearest sample rather than from the
    /// query, σ does not grow with the query's distance from the manifold, so projections
    /// of off-manifold points keep the order. Widened by 1.5× steps, up to
    /// [`Settings::max_widening`], while the fit is untrustworthy.
    Neighbours {
        /// c in K* = c · C(d+m, d) + 1.
        factor: f64,
        /// σ over the K*-th neighbour distance.
        scale: f64,
    },
    /// A fixed σ for every query (never widened).
    Fixed(f64),
}

impl Default for Bandwidth {
    fn default() -> Self {
        Self::Neighbours {
            factor: 3.0,
            scale: 2.0,
        }
    }
}

/// Settings of a manifold MLS approximation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Intrinsic dimension d (1 ≤ d < n).
    pub intrinsic_dim: usize,
    /// Polynomial degree m (0 to 3 tested; any is accepted).
    pub degree: usize,
    /// Bandwidth rule.
    pub bandwidth: Bandwidth,
    /// Chart iteration stops when ‖Δq‖ < tolerance · σ.
    pub tolerance: f64,
    /// Chart iteration cap (per bandwidth tried).
    pub max_iterations: usize,
    /// A fit whose column-equilibrated weighted design has a larger condition number is
    /// untrustworthy: the bandwidth is widened, and if that does not help the query fails
    /// with [`ManifoldError::IllConditioned`].
    pub max_condition: f64,
    /// Largest factor by which a [`Bandwidth::Neighbours`] σ may be widened.
    pub max_widening: f64,
    /// Queries farther than this many σ from every sample are refused
    /// ([`ManifoldError::QueryTooFar`]): the data do not determine their chart.
    pub max_offset: f64,
}

impl Settings {
    /// Degree-`degree` approximation of a `intrinsic_dim`-manifold with the default
    /// bandwidth, tolerance 10⁻¹⁰, at most 100 chart iterations, condition limit 100,
    /// widening up to 4× and queries up to 3σ from the samples.
    pub fn new(intrinsic_dim: usize, degree: usize) -> Self {
        Self {
            intrinsic_dim,
            degree,
            bandwidth: Bandwidth::default(),
            tolerance: 1e-10,
            max_iterations: 100,
            max_condition: 100.0,
            max_widening: 4.0,
            max_offset: 3.0,
        }
    }
}

/// How much a query's answer can be trusted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitQuality {
    /// 2-norm condition number of the column-equilibrated weighted design √W P: how well
    /// the samples pin down every coefficient (≤ [`Settings::max_condition`]).
    pub condition: f64,
    /// Distinct samples with positive weight.
    pub neighbours: usize,
    /// Kish's effective number of samples (Σw)² / Σw²: how many carry real weight.
    pub effective_neighbours: f64,
    /// Chart iterations, over all bandwidths tried.
    pub iterations: usize,
    /// σ over the bandwidth rule's σ (1 unless the fit needed a wider neighbourhood).
    pub widening: f64,
    /// Distance from the query to its projection, over σ.
    pub offset: f64,
}

/// The result of one query.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// f̃(r), k values.
    pub value: Vec<f64>,
    /// Gradient in chart coordinates, k×d.
    pub gradient: DMatrix<f64>,
    /// Projection of r onto the reconstructed manifold, q + g(0).
    pub projection: Vec<f64>,
    /// The chart the fit used.
    pub chart: Chart,
    /// How far to trust the answer.
    pub quality: FitQuality,
}

impl Estimate {
    /// Gradient as tangent vectors in Rⁿ (n×k): U times the chart gradient.
    pub fn ambient_gradient(&self) -> DMatrix<f64> {
        &self.chart.basis * self.gradient.transpose()
    }
}

/// Per-thread buffers: a query allocates only its result once they have grown.
#[derive(Debug, Default)]
struct Workspace {
    found: Vec<Neighbour>,
    indices: Vec<usize>,
    mass: Vec<f64>,
    frame: Frame,
    chart: FrameChart,
    chart_scratch: ChartScratch,
    fit: FitScratch,
}

thread_local! {
    static WORKSPACE: RefCell<Workspace> = RefCell::new(Workspace::default());
}

/// A manifold MLS approximation over a point cloud.
#[derive(Debug, Clone)]
pub struct ManifoldMls {
    cloud: PointCloud,
    distinct: Option<Distinct>,
    index: NeighbourIndex,
    settings: Settings,
    monomials: Monomials,
}

impl ManifoldMls {
    /// Indexes `cloud` (samples at repeated positions merged, their values averaged and
    /// weighted by multiplicity) and validates `settings`.
    pub fn new(cloud: PointCloud, settings: Settings) -> Result<Self, ManifoldError> {
        let (d, n) = (settings.intrinsic_dim, cloud.ambient_dim());
        if d == 0 || d >= n {
            return Err(ManifoldError::IntrinsicDimension {
                intrinsic: d,
                ambient: n,
            });
        }
        validate(&settings)?;
        let monomials = Monomials::new(d, settings.degree)?;
        let distinct = cloud.distinct();
        let positions = distinct
            .as_ref()
            .map_or(cloud.len(), |group| group.representatives.len());
        if monomials.len() > positions {
            return Err(ManifoldError::InvalidParameter {
                parameter: "degree",
                value: settings.degree as f64,
                reason: "the polynomial has more coefficients than the cloud has distinct samples",
            });
        }
        // K* = ⌈c · C(d + m, d)⌉ + 1 neighbours per query, checked in floating point
        // before it becomes a count: a huge c must be an error here, not an overflow at
        // the first query, and a K* beyond the cloud would make every σ the cloud's
        // diameter (a global fit whose cost grows with the cloud at each query).
        if let Bandwidth::Neighbours { factor, .. } = settings.bandwidth {
            if (factor * monomials.len() as f64).ceil() + 1.0 > positions as f64 {
                return Err(ManifoldError::InvalidParameter {
                    parameter: "bandwidth factor c",
                    value: factor,
                    reason: "K* = c · C(d + m, d) + 1 neighbours exceed the cloud's distinct \
                             samples: lower c or the degree m, or give more samples",
                });
            }
        }
        let index = NeighbourIndex::over(
            &cloud,
            distinct.as_ref().map(|group| group.representatives.clone()),
        );
        Ok(Self {
            cloud,
            distinct,
            index,
            settings,
            monomials,
        })
    }

    /// The samples.
    pub fn cloud(&self) -> &PointCloud {
        &self.cloud
    }

    /// The neighbour index (over distinct sample positions).
    pub fn index(&self) -> &NeighbourIndex {
        &self.index
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    fn check_query(&self, r: &[f64]) -> Result<(), ManifoldError> {
        if r.len() != self.cloud.ambient_dim() {
            return Err(ManifoldError::LengthMismatch {
                what: "query",
                expected: self.cloud.ambient_dim(),
                found: r.len(),
            });
        }
        match r.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(ManifoldError::NonFinite {
                what: "query coordinate",
                index: i,
            }),
            None => Ok(()),
        }
    }

    /// f̃(r), its gradient, the projection of r and the chart, from one fit.
    pub fn evaluate(&self, r: &[f64]) -> Result<Estimate, ManifoldError> {
        self.check_query(r)?;
        WORKSPACE.with(|cell| self.query(r, &mut cell.borrow_mut()))
    }

    /// The local chart of `r`.
    pub fn chart(&self, r: &[f64]) -> Result<Chart, ManifoldError> {
        self.evaluate(r).map(|estimate| estimate.chart)
    }

    /// The projection of `r` onto the reconstructed manifold: q + g(0), with g the
    /// degree-m fit of r_i − q in the chart.
    pub fn project(&self, r: &[f64]) -> Result<Vec<f64>, ManifoldError> {
        self.evaluate(r).map(|estimate| estimate.projection)
    }

    /// [`Self::evaluate`] for many queries in parallel. Results are in query order and do
    /// not depend on the thread count or the order of queries.
    pub fn evaluate_batch<Q: AsRef<[f64]> + Sync>(
        &self,
        queries: &[Q],
    ) -> Vec<Result<Estimate, ManifoldError>> {
        queries
            .par_iter()
            .map(|r| self.evaluate(r.as_ref()))
            .collect()
    }

    /// [`Self::project`] for many queries in parallel.
    pub fn project_batch<Q: AsRef<[f64]> + Sync>(
        &self,
        queries: &[Q],
    ) -> Vec<Result<Vec<f64>, ManifoldError>> {
        queries
            .par_iter()
            .map(|r| self.project(r.as_ref()))
            .collect()
    }

    /// Multiplicity of a (distinct) sample.
    fn mass(&self, i: usize) -> f64 {
        self.distinct.as_ref().map_or(1.0, |group| group.mass[i])
    }

    /// Values of a (distinct) sample: the group mean when positions repeat.
    fn values(&self, i: usize) -> &[f64] {
        let k = self.cloud.value_dim();
        match &self.distinct {
            Some(group) => &group.values[i * k..(i + 1) * k],
            None => self.cloud.value(i),
        }
    }

    /// The rule's σ and the nearest sample (index, distance).
    fn bandwidth(&self, r: &[f64], ws: &mut Workspace) -> Result<(f64, usize, f64), ManifoldError> {
        self.index.nearest_into(&self.cloud, r, 1, &mut ws.found);
        let nearest = ws.found[0];
        let sigma = match self.settings.bandwidth {
            Bandwidth::Fixed(sigma) => sigma,
            Bandwidth::Neighbours { factor, scale } => {
                let k = (factor * self.monomials.len() as f64).ceil() as usize + 1;
                let centre = self.cloud.point(nearest.index);
                self.index
                    .nearest_into(&self.cloud, centre, k, &mut ws.found);
                let sigma = scale * ws.found.last().map_or(0.0, |n| n.distance);
                if !(sigma.is_finite() && sigma > 0.0) {
                    return Err(ManifoldError::BandwidthUndefined {
                        sigma,
                        neighbours: k,
                    });
                }
                sigma
            }
        };
        if nearest.distance > self.settings.max_offset * sigma {
            return Err(ManifoldError::QueryTooFar {
                distance: nearest.distance,
                limit: self.settings.max_offset * sigma,
            });
        }
        Ok((sigma, nearest.index, nearest.distance))
    }

    fn query(&self, r: &[f64], ws: &mut Workspace) -> Result<Estimate, ManifoldError> {
        let (rule, centre, gap) = self.bandwidth(r, ws)?;
        let widest = match self.settings.bandwidth {
            Bandwidth::Fixed(_) => rule,
            Bandwidth::Neighbours { .. } => rule * self.settings.max_widening,
        };
        let mut sigma = rule;
        let mut iterations = 0;
        loop {
            let failure = match self.attempt(r, centre, gap, sigma, ws, &mut iterations) {
                Ok(mut estimate) if estimate.quality.condition <= self.settings.max_condition => {
                    estimate.quality.widening = sigma / rule;
                    return Ok(estimate);
                }
                Ok(estimate) => ManifoldError::IllConditioned {
                    condition: estimate.quality.condition,
                    limit: self.settings.max_condition,
                    sigma,
                },
                Err(
                    error @ (ManifoldError::TooFewNeighbours { .. }
                    | ManifoldError::RankDeficient { .. }
                    | ManifoldError::NotConverged { .. }),
                ) => error,
                Err(error) => return Err(error),
            };
            if sigma * WIDENING_STEP > widest * (1.0 + 1e-12) {
                return Err(failure);
            }
            sigma *= WIDENING_STEP;
        }
    }

    /// One fit at bandwidth σ.
    fn attempt(
        &self,
        r: &[f64],
        centre: usize,
        gap: f64,
        sigma: f64,
        ws: &mut Workspace,
        iterations: &mut usize,
    ) -> Result<Estimate, ManifoldError> {
        // Samples within σ of q are within σ + ‖r − q‖ of r; ‖r − q‖ is about the distance
        // to the nearest sample, and the search widens if the chart lands farther away.
        let mut radius = sigma + gap;
        for _ in 0..3 {
            self.index
                .within_into(&self.cloud, r, radius, &mut ws.found);
            ws.indices.clear();
            ws.indices.extend(ws.found.iter().map(|n| n.index));
            ws.mass.clear();
            ws.mass.extend(ws.indices.iter().map(|&i| self.mass(i)));
            ws.frame.build(&self.cloud, &ws.indices, centre, r);
            let problem = ChartProblem {
                frame: &ws.frame,
                mass: &ws.mass,
                intrinsic: self.settings.intrinsic_dim,
                sigma,
                tolerance: self.settings.tolerance,
                max_iterations: self.settings.max_iterations,
            };
            let solved = problem.solve(&mut ws.chart_scratch, &mut ws.chart);
            *iterations += match solved {
                Ok(()) => ws.chart.iterations,
                Err(_) => self.settings.max_iterations,
            };
            solved?;
            let offset = crate::dense::distance_squared(&ws.frame.query, &ws.chart.q).sqrt();
            if offset + sigma <= radius * (1.0 + 1e-12) {
                break;
            }
            radius = sigma + 1.25 * offset;
        }
        let k = self.cloud.value_dim();
        let indices = &ws.indices;
        let fit = fit_values_and_offsets(
            &ws.frame,
            &ws.chart,
            &ws.mass,
            &self.monomials,
            sigma,
            k,
            |row| self.values(indices[row]),
            &mut ws.fit,
        )?;
        let (dim, d, rows) = (ws.frame.dim, self.settings.intrinsic_dim, fit.rows);
        let solution = &ws.fit.solution;
        let value = (0..k).map(|c| solution[c * rows]).collect();
        let gradient = if self.settings.degree >= 1 {
            DMatrix::from_fn(k, d, |c, j| solution[1 + j + c * rows] / sigma)
        } else {
            DMatrix::zeros(k, d)
        };
        let foot: Vec<f64> = (0..dim)
            .map(|c| ws.chart.q[c] + solution[(k + c) * rows])
            .collect();
        self.check_focal(
            &ws.frame, &ws.chart, &ws.mass, &foot, solution, rows, k, sigma,
        )?;
        let projection = ws.frame.point(&foot);
        let offset = crate::dense::distance_squared(r, &projection).sqrt() / sigma;
        let n = self.cloud.ambient_dim();
        let mut basis = DMatrix::<f64>::zeros(n, d);
        for j in 0..d {
            let column = ws.frame.direction(&ws.chart.u[j * dim..(j + 1) * dim]);
            basis.set_column(j, &DVector::from_vec(column));
        }
        Ok(Estimate {
            value,
            gradient,
            projection,
            chart: Chart {
                origin: DVector::from_vec(ws.frame.point(&ws.chart.q)),
                basis,
                sigma,
                iterations: *iterations,
            },
            quality: FitQuality {
                condition: fit.condition,
                neighbours: fit.rows,
                effective_neighbours: fit.effective,
                iterations: *iterations,
                widening: 1.0,
                offset,
            },
        })
    }
}

impl ManifoldMls {
    /// Refuses a query near a centre of curvature of the fitted manifold, where its
    /// projection is not unique (the centre of a sampled sphere): with δ the distance to
    /// the projection, ν the unit normal towards the query and S the shape operator along
    /// ν, the closest point is stable while I − δS stays positive definite; checked for
    /// queries farther than σ from the reconstruction. S = ν · ∇²g
    /// from the degree-m fit when m ≥ 2; for m < 2 (a plane has no curvature) an
    /// isotropic estimate from a weighted fit of ν · (r_i − p) ≈ a + κ/2 · |x_i|².
    #[allow(clippy::too_many_arguments)]
    fn check_focal(
        &self,
        frame: &Frame,
        chart: &FrameChart,
        mass: &[f64],
        foot: &[f64],
        solution: &[f64],
        rows: usize,
        k: usize,
        sigma: f64,
    ) -> Result<(), ManifoldError> {
        let (d, dim) = (self.settings.intrinsic_dim, frame.dim);
        let query = &frame.query;
        let delta = crate::dense::distance_squared(query, foot).sqrt();
        // Within σ of the reconstruction the neighbourhood decides the foot; beyond it a
        // centre of curvature makes the foot ambiguous. Noise can fake a small curvature
        // radius near the samples, never at a distance σ.
        if delta.is_nan() || delta <= sigma {
            return Ok(());
        }
        let normal: Vec<f64> = (0..dim).map(|i| (query[i] - foot[i]) / delta).collect();
        let largest = if self.settings.degree >= 2 {
            let mut shape = DMatrix::<f64>::zeros(d, d);
            for (j, alpha) in self.monomials.exponents().iter().enumerate() {
                if alpha.iter().sum::<u32>() != 2 {
                    continue;
                }
                // ν · (coefficient of x^α) in physical units, then x^α's Hessian entries.
                let c: f64 = (0..dim)
                    .map(|i| normal[i] * solution[j + (k + i) * rows])
                    .sum::<f64>()
                    / (sigma * sigma);
                let active: Vec<usize> = (0..d).filter(|&a| alpha[a] > 0).collect();
                match active.as_slice() {
                    [a] => shape[(*a, *a)] += 2.0 * c,
                    [a, b] => {
                        shape[(*a, *b)] += c;
                        shape[(*b, *a)] += c;
                    }
                    _ => {}
                }
            }
            shape.symmetric_eigenvalues().max()
        } else {
            isotropic_curvature(frame, chart, mass, foot, &normal, sigma, d)
        };
        if delta * largest > FOCAL_LIMIT {
            return Err(ManifoldError::FocalQuery {
                distance: delta,
                radius: 1.0 / largest,
            });
        }
        Ok(())
    }
}

/// κ of the weighted fit ν · (r_i − p) ≈ a + κ/2 · |Uᵀ(r_i − q)|² (0 if undetermined).
fn isotropic_curvature(
    frame: &Frame,
    chart: &FrameChart,
    mass: &[f64],
    foot: &[f64],
    normal: &[f64],
    sigma: f64,
    d: usize,
) -> f64 {
    let dim = frame.dim;
    let (mut s00, mut s01, mut s11, mut b0, mut b1) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (y, m) in frame.coords.chunks_exact(dim).zip(mass) {
        let w = m * crate::chart::theta(crate::dense::distance_squared(y, &chart.q).sqrt(), sigma);
        if w <= 0.0 {
            continue;
        }
        let t2: f64 = (0..d)
            .map(|a| {
                let u = &chart.u[a * dim..(a + 1) * dim];
                let x = crate::dense::dot(u, y) - crate::dense::dot(u, &chart.q);
                x * x
            })
            .sum::<f64>()
            / 2.0;
        let n: f64 = (0..dim).map(|i| normal[i] * (y[i] - foot[i])).sum();
        s00 += w;
        s01 += w * t2;
        s11 += w * t2 * t2;
        b0 += w * n;
        b1 += w * t2 * n;
    }
    let det = s00 * s11 - s01 * s01;
    if det > 1e-12 * s00 * s11 {
        (s00 * b1 - s01 * b0) / det
    } else {
        0.0
    }
}

/// δκ above which a query counts as at a centre of curvature (I − δS has an eigenvalue
/// below 1 − FOCAL_LIMIT).
const FOCAL_LIMIT: f64 = 0.75;

fn validate(settings: &Settings) -> Result<(), ManifoldError> {
    let invalid = |parameter, value: f64, reason| {
        Err(ManifoldError::InvalidParameter {
            parameter,
            value,
            reason,
        })
    };
    match settings.bandwidth {
        Bandwidth::Neighbours { factor, scale } => {
            if !(factor.is_finite() && factor > 0.0) {
                return invalid("bandwidth factor c", factor, "must be finite and positive");
            }
            if !(scale.is_finite() && scale > 0.0) {
                return invalid("bandwidth scale", scale, "must be finite and positive");
            }
        }
        Bandwidth::Fixed(sigma) => {
            if !(sigma.is_finite() && sigma > 0.0) {
                return invalid("σ", sigma, "must be finite and positive");
            }
        }
    }
    if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) {
        return invalid(
            "tolerance",
            settings.tolerance,
            "must be finite and positive",
        );
    }
    if settings.max_iterations == 0 {
        return invalid("max_iterations", 0.0, "must be at least 1");
    }
    if !(settings.max_condition.is_finite() && settings.max_condition >= 1.0) {
        return invalid(
            "max_condition",
            settings.max_condition,
            "must be finite and at least 1",
        );
    }
    if !(settings.max_offset.is_finite() && settings.max_offset > 0.0) {
        return invalid(
            "max_offset",
            settings.max_offset,
            "must be finite and positive",
        );
    }
    if !(settings.max_widening.is_finite() && settings.max_widening >= 1.0) {
        return invalid(
            "max_widening",
            settings.max_widening,
            "must be finite and at least 1",
        );
    }
    Ok(())
}
