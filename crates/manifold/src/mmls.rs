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
    /// The [`Bandwidth::Neighbours`] rule's σ times a growth g ∈ {1, 1.5, 2.25, …} ≤
    /// `max_growth`, chosen by leave-one-out cross-validation when the approximation is
    /// built: one g for clean data (the rule's σ wins), and on noisy data the g best over
    /// the cross-validation samples nearest each query, since a wider neighbourhood
    /// averages more noise. See [`ManifoldMls::growth`].
    Adaptive {
        /// c in K* = c · C(d+m, d) + 1.
        factor: f64,
        /// σ over the K*-th neighbour distance.
        scale: f64,
        /// Largest growth tried.
        max_growth: f64,
    },
    /// A fixed σ for every query (never widened).
    Fixed(f64),
}

impl Default for Bandwidth {
    fn default() -> Self {
        Self::Adaptive {
            factor: 3.0,
            scale: 2.0,
            max_growth: 5.0,
        }
    }
}

impl Bandwidth {
    /// The neighbour rule's (c, scale), if σ follows the sample spacing.
    fn neighbour_rule(&self) -> Option<(f64, f64)> {
        match *self {
            Self::Neighbours { factor, scale } | Self::Adaptive { factor, scale, .. } => {
                Some((factor, scale))
            }
            Self::Fixed(_) => None,
        }
    }
}

/// Largest polynomial basis C(d + m, d) a fit may have.
const MAX_COEFFICIENTS: usize = 200;

/// Samples of the cross-validation's first stage, which tells clean data from noisy.
const SCREENING_SAMPLES: usize = 200;

/// Samples of its second stage. 4,000: fewer leave the choice to chance, since the mean
/// squared error being compared is 10–20 % of the noise variance that dominates each
/// prediction's error.
const CROSS_VALIDATION_SAMPLES: usize = 4000;

/// Fraction of the left-out samples, the best predicted, whose errors are averaged: the
/// worst 5 % sit where a wider σ reaches past an edge of the manifold, and would choose
/// the growth for the edges alone.
const CROSS_VALIDATION_KEPT: f64 = 0.95;

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
    /// Whether a fit with any [`Concerns`] fails with [`ManifoldError::Untrustworthy`]
    /// instead of returning an estimate whose [`FitQuality::concerns`] say why it is
    /// doubtful (the default: the caller decides).
    pub refuse_untrustworthy: bool,
}

impl Settings {
    /// Degree-`degree` approximation of a `intrinsic_dim`-manifold with the default
    /// bandwidth, tolerance 10⁻¹⁰, at most 100 chart iterations, condition limit 100,
    /// widening up to 16×, queries up to 3σ from the samples, and doubtful fits returned
    /// with their concerns.
    pub fn new(intrinsic_dim: usize, degree: usize) -> Self {
        Self {
            intrinsic_dim,
            degree,
            bandwidth: Bandwidth::default(),
            tolerance: 1e-10,
            max_iterations: 100,
            max_condition: 100.0,
            max_widening: 16.0,
            max_offset: 3.0,
            refuse_untrustworthy: false,
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
    /// Standard deviation of the noise in the values, estimated from the fit's
    /// residual (RMS over value components; 0 for a cloud without values; ∞ when the fit
    /// leaves no residual freedom).
    pub noise: f64,
    /// Standard deviation of the samples' offsets from the fitted manifold, estimated the
    /// same way.
    pub position_noise: f64,
    /// Standard error of the value from that noise: `noise` × the norm of the fit's
    /// equivalent kernel.
    pub standard_error: f64,
    /// σ times the largest curvature of the fitted manifold: σ over its local reach.
    /// For m ≥ 2 from the fitted second derivatives (the norm over normal directions of
    /// each direction's largest); for m < 2 from a weighted fit of the offsets to
    /// a + κ|x|²/2 (isotropic curvature).
    pub reach: f64,
    /// `noise` over the cloud's typical residual ([`ManifoldMls::cloud_noise`]): far
    /// above 1 where the fit's residual is more than the noise seen elsewhere. `None`
    /// for bandwidths other than [`Bandwidth::Adaptive`].
    pub noise_ratio: Option<f64>,
    /// What makes the answer doubtful, by the documented thresholds.
    pub concerns: Concerns,
}

/// Reasons to doubt a fit. Thresholds: [`Concerns::NOISE_DOMINATED`],
/// [`Concerns::UNRESOLVED`], [`Concerns::BEYOND_REACH`] and, for few samples, fewer
/// effective samples than coefficients + 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Concerns {
    /// The samples scatter about the fitted manifold by more than
    /// [`Concerns::NOISE_DOMINATED`] × σ: chart and projection are mostly noise.
    pub noise_dominated: bool,
    /// The value residual exceeds [`Concerns::UNRESOLVED`] × the cloud's typical
    /// residual: something here (detail finer than σ, an outlier, an edge) is not the
    /// noise seen elsewhere.
    pub unresolved: bool,
    /// Kish's effective number of samples is below the coefficients + 1: the fit
    /// interpolates and averages no noise.
    pub few_samples: bool,
    /// σ exceeds the local reach ([`FitQuality::reach`] > [`Concerns::BEYOND_REACH`]), or
    /// half the cloud's extent: the neighbourhood wraps around the manifold, as with a
    /// handful of samples of a sphere.
    pub beyond_reach: bool,
}

impl Concerns {
    /// Position residual over σ above which a fit is noise-dominated.
    pub const NOISE_DOMINATED: f64 = 0.5;
    /// Value noise over the cloud's typical residual above which a fit is unresolved.
    pub const UNRESOLVED: f64 = 4.0;
    /// σ over the local reach above which the neighbourhood wraps around.
    pub const BEYOND_REACH: f64 = 1.0;

    /// Whether any concern is raised.
    pub fn any(&self) -> bool {
        self.noise_dominated || self.unresolved || self.few_samples || self.beyond_reach
    }

    /// The first concern's name, as [`ManifoldError::Untrustworthy`] reports it.
    pub fn first(&self) -> Option<&'static str> {
        [
            (self.beyond_reach, "σ exceeds the local reach of the data"),
            (
                self.noise_dominated,
                "the samples scatter by more than σ/2 about the fit",
            ),
            (
                self.few_samples,
                "fewer effective samples than coefficients + 1",
            ),
            (
                self.unresolved,
                "the residual is 4× the cloud's typical residual",
            ),
        ]
        .into_iter()
        .find_map(|(raised, name)| raised.then_some(name))
    }
}

impl FitQuality {
    /// Whether no concern is raised.
    pub fn is_trustworthy(&self) -> bool {
        !self.concerns.any()
    }
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
    /// Tangent vectors of the reconstructed manifold at the projection, n×d: ∂g/∂x_j(0)
    /// of the offset fit. The chart's plane H is tilted from them by O(σ²); they are
    /// accurate to the fit's order.
    pub tangent: DMatrix<f64>,
    /// The chart the fit used.
    pub chart: Chart,
    /// How far to trust the answer.
    pub quality: FitQuality,
}

impl Estimate {
    /// Gradient as tangent vectors in Rⁿ (n×k): the vectors of the reconstructed tangent
    /// space whose derivatives along the manifold's coordinates are the chart gradient,
    /// T (TᵀT)⁻¹ ∇ₓf̃ with T = [`Estimate::tangent`]. Using the chart's plane U instead
    /// would cost an order: its O(σ²) tilt caps the gradient's error at O(h²).
    pub fn ambient_gradient(&self) -> DMatrix<f64> {
        let t = &self.tangent;
        match (t.transpose() * t).cholesky() {
            Some(gram) => t * gram.solve(&self.gradient.transpose()),
            None => &self.chart.basis * self.gradient.transpose(),
        }
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

/// Where a query's fits start: the nearest sample, its distance, and the sample left out
/// (cross-validation).
#[derive(Debug, Clone, Copy)]
struct Anchor {
    centre: usize,
    gap: f64,
    exclude: Option<usize>,
}

/// A manifold MLS approximation over a point cloud.
#[derive(Debug, Clone)]
pub struct ManifoldMls {
    cloud: PointCloud,
    distinct: Option<Distinct>,
    index: NeighbourIndex,
    settings: Settings,
    monomials: Monomials,
    growth: f64,
    /// Median value noise of the fits at evenly spread samples (adaptive bandwidth).
    cloud_noise: Option<f64>,
    /// The cloud's bounding-box diagonal.
    extent: f64,
    /// Leave-one-out errors by place, for a growth chosen per query (noisy clouds).
    local: Option<LocalGrowth>,
    /// The basis's second-order monomials: (index, a, b) for x_a x_b.
    second_order: Vec<(usize, usize, usize)>,
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
        // A fit costs O(K · C²) and its condition check O(C³) per attempt: beyond a few
        // hundred coefficients one query takes minutes, and monomials of such degree in
        // σ-scaled coordinates are too ill-conditioned to fit anyway. 200 allows m = 18
        // for surfaces and m = 5 in four variables.
        if monomials.len() > MAX_COEFFICIENTS {
            return Err(ManifoldError::InvalidParameter {
                parameter: "degree",
                value: settings.degree as f64,
                reason: "C(d + m, d) coefficients exceed 200: lower the degree m",
            });
        }
        if let Bandwidth::Fixed(sigma) = settings.bandwidth {
            // Chart coordinates are offsets over σ: a σ 10¹⁵ times the cloud's extent
            // leaves them below round-off, and every fit would be rank deficient.
            let extent = cloud.extent();
            if sigma > 1e15 * extent {
                return Err(ManifoldError::InvalidParameter {
                    parameter: "σ",
                    value: sigma,
                    reason: "exceeds 10¹⁵ × the cloud's extent (its bounding-box diagonal): \
                             chart coordinates x / σ would vanish in round-off",
                });
            }
        }
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
        if let Some((factor, _)) = settings.bandwidth.neighbour_rule() {
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
        let extent = cloud.extent();
        let second_order = monomials
            .exponents()
            .iter()
            .enumerate()
            .filter(|(_, alpha)| alpha.iter().sum::<u32>() == 2)
            .map(|(j, alpha)| {
                let a = alpha.iter().position(|&e| e > 0).unwrap_or(0);
                let b = alpha.iter().rposition(|&e| e > 0).unwrap_or(a);
                (j, a, b)
            })
            .collect();
        let mut mls = Self {
            cloud,
            distinct,
            index,
            settings,
            monomials,
            growth: 1.0,
            cloud_noise: None,
            extent,
            local: None,
            second_order,
        };
        if let Bandwidth::Adaptive { max_growth, .. } = settings.bandwidth {
            (mls.growth, mls.local) = mls.cross_validated_growth(max_growth);
            mls.cloud_noise = mls.typical_noise();
        }
        Ok(mls)
    }

    /// The cloud's growth of the neighbour rule's σ: chosen by cross-validation for
    /// [`Bandwidth::Adaptive`] (on noisy data each query then takes the growth best near
    /// it), 1 otherwise.
    pub fn growth(&self) -> f64 {
        self.growth
    }

    /// The median of [`FitQuality::noise`] over fits at evenly spread samples, for
    /// [`Bandwidth::Adaptive`] on a cloud with values: the cloud's typical residual, the
    /// yardstick of [`FitQuality::noise_ratio`].
    pub fn cloud_noise(&self) -> Option<f64> {
        self.cloud_noise
    }

    /// The growth for a query at `r`: where cross-validation ran on noisy data, the one
    /// whose leave-one-out error is lowest over the [`LOCAL_POOL`] cross-validation
    /// samples nearest `r`; else the cloud's.
    fn growth_at(&self, r: &[f64], ws: &mut Workspace) -> f64 {
        match &self.local {
            Some(local) => local.at(r, &mut ws.found),
            None => self.growth,
        }
    }

    /// Median value noise of the fits at [`SCREENING_SAMPLES`] spread samples.
    fn typical_noise(&self) -> Option<f64> {
        if self.cloud.value_dim() == 0 {
            return None;
        }
        let mut noise: Vec<f64> = self
            .spread_samples(SCREENING_SAMPLES)
            .par_iter()
            .filter_map(|&i| {
                let r = self.cloud.point(i);
                WORKSPACE
                    .with(|cell| {
                        let ws = &mut cell.borrow_mut();
                        let growth = self.growth_at(r, ws);
                        self.query(r, growth, None, ws)
                    })
                    .ok()
                    .map(|estimate| estimate.quality.noise)
            })
            .filter(|noise| noise.is_finite())
            .collect();
        noise.sort_by(f64::total_cmp);
        noise
            .get(noise.len() / 2)
            .copied()
            .filter(|median| *median > 0.0)
    }

    /// The growth g ≤ `max_growth` (powers of 1.5) whose leave-one-out error is lowest.
    /// Evenly spread samples are each predicted from the others, the values when the
    /// cloud has any (else the positions, by projection). The expected squared error is
    /// the noise's variance plus the fit's mean squared error, so its minimum is the
    /// latter's; the smallest g within 1 % of it is taken.
    ///
    /// Two stages keep clean data cheap: 200 samples at g = 1 and 1.5 first; when the
    /// wider σ is clearly worse (25 %), bias dominates and g = 1. Otherwise
    /// [`CROSS_VALIDATION_SAMPLES`] samples try g = 1, 1.5, … in turn until one is 10 %
    /// worse than the best so far.
    fn cross_validated_growth(&self, max_growth: f64) -> (f64, Option<LocalGrowth>) {
        if max_growth < WIDENING_STEP {
            return (1.0, None);
        }
        let screening = self.spread_samples(SCREENING_SAMPLES);
        let narrow = self.leave_one_out(&screening, 1.0);
        let wide = self.leave_one_out(&screening, WIDENING_STEP);
        let first = mean_squared_errors(&[narrow, wide]);
        if first[1] > 1.25 * first[0] {
            return (1.0, None);
        }
        // Growths in turn, until one is clearly worse than the best so far: past the
        // optimum the bias grows like g^{2(m+1)}, and the widest fits cost the most.
        let chosen = self.spread_samples(CROSS_VALIDATION_SAMPLES);
        let (mut growths, mut columns) = (vec![1.0], vec![self.leave_one_out(&chosen, 1.0)]);
        loop {
            let next = growths[growths.len() - 1] * WIDENING_STEP;
            if next > max_growth * (1.0 + 1e-12) {
                break;
            }
            growths.push(next);
            columns.push(self.leave_one_out(&chosen, next));
            let totals = mean_squared_errors(&columns);
            let best = totals.iter().copied().fold(f64::INFINITY, f64::min);
            if totals[totals.len() - 1] > 1.1 * best {
                break;
            }
        }
        let growth = pick_growth(&growths, &mean_squared_errors(&columns));
        (
            growth,
            LocalGrowth::new(&self.cloud, &chosen, growths, &columns),
        )
    }

    /// Up to `count` evenly spread distinct samples.
    fn spread_samples(&self, count: usize) -> Vec<usize> {
        let positions: Vec<usize> = match &self.distinct {
            Some(group) => group.representatives.clone(),
            None => (0..self.cloud.len()).collect(),
        };
        let count = positions.len().min(count);
        (0..count)
            .map(|j| positions[j * positions.len() / count])
            .collect()
    }

    /// The squared error of predicting each of `chosen` from the other samples at
    /// `growth` × the rule's σ: of the values when the cloud has any, else of the
    /// position by projection (`None` where the query failed).
    fn leave_one_out(&self, chosen: &[usize], growth: f64) -> Vec<Option<f64>> {
        let k = self.cloud.value_dim();
        chosen
            .par_iter()
            .map(|&i| {
                let r = self.cloud.point(i);
                let estimate = WORKSPACE
                    .with(|cell| self.query(r, growth, Some(i), &mut cell.borrow_mut()))
                    .ok()?;
                Some(if k > 0 {
                    estimate
                        .value
                        .iter()
                        .zip(self.values(i))
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum()
                } else {
                    crate::dense::distance_squared(&estimate.projection, r)
                })
            })
            .collect()
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
        WORKSPACE.with(|cell| {
            let ws = &mut cell.borrow_mut();
            let growth = self.growth_at(r, ws);
            self.query(r, growth, None, ws)
        })
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
    fn bandwidth(
        &self,
        r: &[f64],
        growth: f64,
        ws: &mut Workspace,
    ) -> Result<(f64, usize, f64), ManifoldError> {
        self.index.nearest_into(&self.cloud, r, 1, &mut ws.found);
        let nearest = ws.found[0];
        let sigma = match self.settings.bandwidth {
            Bandwidth::Fixed(sigma) => sigma,
            Bandwidth::Neighbours { factor, scale } | Bandwidth::Adaptive { factor, scale, .. } => {
                let k = (factor * self.monomials.len() as f64).ceil() as usize + 1;
                let centre = self.cloud.point(nearest.index);
                self.index
                    .nearest_into(&self.cloud, centre, k, &mut ws.found);
                let sigma = growth * scale * ws.found.last().map_or(0.0, |n| n.distance);
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

    /// One query at `growth` × the rule's σ, without sample `exclude` (cross-validation).
    fn query(
        &self,
        r: &[f64],
        growth: f64,
        exclude: Option<usize>,
        ws: &mut Workspace,
    ) -> Result<Estimate, ManifoldError> {
        let (rule, centre, gap) = self.bandwidth(r, growth, ws)?;
        let anchor = Anchor {
            centre,
            gap,
            exclude,
        };
        let widest = match self.settings.bandwidth {
            Bandwidth::Fixed(_) => rule,
            _ => rule * self.settings.max_widening,
        };
        let mut sigma = rule;
        let mut iterations = 0;
        loop {
            let failure = match self.attempt(r, anchor, sigma, ws, &mut iterations) {
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
        anchor: Anchor,
        sigma: f64,
        ws: &mut Workspace,
        iterations: &mut usize,
    ) -> Result<Estimate, ManifoldError> {
        let Anchor {
            centre,
            gap,
            exclude,
        } = anchor;
        // Samples within σ of q are within σ + ‖r − q‖ of r; ‖r − q‖ is about the distance
        // to the nearest sample, and the search widens if the chart lands farther away.
        let mut radius = sigma + gap;
        for _ in 0..3 {
            self.index
                .within_into(&self.cloud, r, radius, &mut ws.found);
            if let Some(left_out) = exclude {
                ws.found.retain(|n| n.index != left_out);
            }
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
        let (noise, position_noise) = residual_noise(
            solution,
            rows,
            self.monomials.len(),
            k,
            dim - d.min(dim),
            fit.noise.residual_dof,
        );
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
        let reach = sigma
            * if self.settings.degree >= 2 {
                self.largest_curvature(solution, rows, k, dim, sigma)
            } else {
                let kappa = curvature_vector(&ws.frame, &ws.chart, &ws.mass, sigma, d);
                crate::dense::dot(&kappa, &kappa).sqrt()
            };
        let noise_ratio = self.cloud_noise.map(|cloud| noise / cloud);
        let concerns = Concerns {
            noise_dominated: position_noise > Concerns::NOISE_DOMINATED * sigma,
            unresolved: noise_ratio.is_some_and(|ratio| ratio > Concerns::UNRESOLVED),
            few_samples: fit.effective < (self.monomials.len() + 1) as f64,
            beyond_reach: reach.is_nan()
                || reach > Concerns::BEYOND_REACH
                || 2.0 * sigma > self.extent,
        };
        if self.settings.refuse_untrustworthy {
            if let Some(concern) = concerns.first() {
                return Err(ManifoldError::Untrustworthy { concern, sigma });
            }
        }
        let projection = ws.frame.point(&foot);
        let offset = crate::dense::distance_squared(r, &projection).sqrt() / sigma;
        let n = self.cloud.ambient_dim();
        let mut basis = DMatrix::<f64>::zeros(n, d);
        for j in 0..d {
            let column = ws.frame.direction(&ws.chart.u[j * dim..(j + 1) * dim]);
            basis.set_column(j, &DVector::from_vec(column));
        }
        let tangent = if self.settings.degree >= 1 {
            let mut tangent = DMatrix::<f64>::zeros(n, d);
            let mut along = vec![0.0; dim];
            for j in 0..d {
                for (c, a) in along.iter_mut().enumerate() {
                    *a = solution[1 + j + (k + c) * rows] / sigma;
                }
                tangent.set_column(j, &DVector::from_vec(ws.frame.direction(&along)));
            }
            tangent
        } else {
            basis.clone()
        };
        Ok(Estimate {
            value,
            gradient,
            projection,
            tangent,
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
                noise,
                position_noise,
                standard_error: noise * fit.noise.kernel_norm,
                reach,
                noise_ratio,
                concerns,
            },
        })
    }
}

impl ManifoldMls {
    /// Largest curvature of the fitted offsets (m ≥ 2): per frame coordinate the spectral
    /// radius of its Hessian, combined over coordinates in the 2-norm (exact for a
    /// hypersurface, at most √(n − d) high otherwise).
    fn largest_curvature(
        &self,
        solution: &[f64],
        rows: usize,
        k: usize,
        dim: usize,
        sigma: f64,
    ) -> f64 {
        let d = self.settings.intrinsic_dim;
        let mut hessian = DMatrix::<f64>::zeros(d, d);
        let mut total = 0.0;
        for c in 0..dim {
            self.second_order_hessian(
                |j| solution[j + (k + c) * rows] / (sigma * sigma),
                &mut hessian,
            );
            let radius = spectral_radius(&hessian);
            total += radius * radius;
        }
        total.sqrt()
    }

    /// The Hessian of a polynomial in the basis, from its second-order coefficients
    /// (`coefficient(j)` of monomial j, in physical units), written over `out`.
    fn second_order_hessian(&self, coefficient: impl Fn(usize) -> f64, out: &mut DMatrix<f64>) {
        out.fill(0.0);
        for &(j, a, b) in &self.second_order {
            let c = coefficient(j);
            if a == b {
                out[(a, a)] += 2.0 * c;
            } else {
                out[(a, b)] += c;
                out[(b, a)] += c;
            }
        }
    }

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
            // ν · (coefficient of x^α) in physical units.
            self.second_order_hessian(
                |j| {
                    (0..dim)
                        .map(|i| normal[i] * solution[j + (k + i) * rows])
                        .sum::<f64>()
                        / (sigma * sigma)
                },
                &mut shape,
            );
            shape.symmetric_eigenvalues().max()
        } else {
            crate::dense::dot(&normal, &curvature_vector(frame, chart, mass, sigma, d))
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

/// The smallest growth whose error is within 1 % of the lowest (1 when none is finite).
fn pick_growth(growths: &[f64], totals: &[f64]) -> f64 {
    let best = totals.iter().copied().fold(f64::INFINITY, f64::min);
    if !best.is_finite() {
        return 1.0;
    }
    growths
        .iter()
        .zip(totals)
        .find(|(_, total)| **total <= best * 1.01)
        .map_or(1.0, |(g, _)| *g)
}

/// Cross-validation samples nearest a query whose errors choose its growth: 400 of the
/// 4,000. Measured on the noisy cases: 200 chose by chance where the cloud is uniform
/// (S², s = 0.1, m = 1: 1.15× manapprox's error against 0.97× with one growth), 800
/// blurred the Swiss roll's edges (1.17×); 400 keeps both within 1.1×.
const LOCAL_POOL: usize = 400;

/// The cross-validation's samples, indexed, with their leave-one-out errors per growth:
/// a growth per place, so that one cloud can be noise-dominated in a dense cluster and
/// bias-dominated where it is sparse.
#[derive(Debug, Clone)]
struct LocalGrowth {
    samples: PointCloud,
    index: NeighbourIndex,
    growths: Vec<f64>,
    /// Per sample, its squared errors at every growth (samples some growth failed on
    /// are left out).
    errors: Vec<Vec<f64>>,
}

impl LocalGrowth {
    fn new(
        cloud: &PointCloud,
        chosen: &[usize],
        growths: Vec<f64>,
        columns: &[Vec<Option<f64>>],
    ) -> Option<Self> {
        let answered: Vec<usize> = (0..chosen.len())
            .filter(|&i| columns.iter().all(|column| column[i].is_some()))
            .collect();
        if answered.len() < LOCAL_POOL || growths.len() < 2 {
            return None;
        }
        let coords: Vec<f64> = answered
            .iter()
            .flat_map(|&i| cloud.point(chosen[i]).to_vec())
            .collect();
        let samples = PointCloud::from_points(cloud.ambient_dim(), coords).ok()?;
        let index = NeighbourIndex::over(&samples, None);
        let errors = answered
            .iter()
            .map(|&i| {
                columns
                    .iter()
                    .map(|column| column[i].unwrap_or(0.0))
                    .collect()
            })
            .collect();
        Some(Self {
            samples,
            index,
            growths,
            errors,
        })
    }

    fn at(&self, r: &[f64], found: &mut Vec<Neighbour>) -> f64 {
        self.index.nearest_into(&self.samples, r, LOCAL_POOL, found);
        let totals: Vec<f64> = (0..self.growths.len())
            .map(|j| found.iter().map(|n| self.errors[n.index][j]).sum())
            .collect();
        pick_growth(&self.growths, &totals)
    }
}

/// Per column of leave-one-out errors, the mean over the samples every column answered,
/// of the best-predicted [`CROSS_VALIDATION_KEPT`] of them (∞ when none answered).
fn mean_squared_errors(columns: &[Vec<Option<f64>>]) -> Vec<f64> {
    let rows = columns.first().map_or(0, Vec::len);
    let answered: Vec<usize> = (0..rows)
        .filter(|&i| columns.iter().all(|column| column[i].is_some()))
        .collect();
    columns
        .iter()
        .map(|column| {
            let mut errors: Vec<f64> = answered.iter().filter_map(|&i| column[i]).collect();
            errors.sort_by(f64::total_cmp);
            let kept = (errors.len() as f64 * CROSS_VALIDATION_KEPT).ceil() as usize;
            if kept == 0 {
                return f64::INFINITY;
            }
            errors[..kept].iter().sum::<f64>() / kept as f64
        })
        .collect()
}

/// Largest |eigenvalue| of a small symmetric matrix: closed forms for d ≤ 2, where every
/// query of a curve or a surface lands.
fn spectral_radius(h: &DMatrix<f64>) -> f64 {
    match h.nrows() {
        0 => 0.0,
        1 => h[(0, 0)].abs(),
        2 => {
            let (mean, half) = ((h[(0, 0)] + h[(1, 1)]) / 2.0, (h[(0, 0)] - h[(1, 1)]) / 2.0);
            mean.abs() + (half * half + h[(0, 1)] * h[(0, 1)]).sqrt()
        }
        _ => h
            .clone()
            .symmetric_eigenvalues()
            .iter()
            .fold(0.0f64, |m, e| m.max(e.abs())),
    }
}

/// Noise standard deviations of the values (RMS over the `k` value columns) and of the
/// offsets (pooled over the `codim` normal directions of the frame's `k..` columns) from
/// the tail of Qᵀ√W b that [`crate::dense::least_squares`] leaves below the coefficients.
fn residual_noise(
    solution: &[f64],
    rows: usize,
    coefficients: usize,
    k: usize,
    codim: usize,
    residual_dof: f64,
) -> (f64, f64) {
    let squares = |c: usize| -> f64 {
        solution[c * rows + coefficients..(c + 1) * rows]
            .iter()
            .map(|x| x * x)
            .sum()
    };
    if residual_dof <= 0.0 || rows <= coefficients {
        return (f64::INFINITY, f64::INFINITY);
    }
    let value = if k == 0 {
        0.0
    } else {
        ((0..k).map(squares).sum::<f64>() / (k as f64 * residual_dof)).sqrt()
    };
    let columns = solution.len() / rows;
    let position = if codim == 0 {
        0.0
    } else {
        ((k..columns).map(squares).sum::<f64>() / (codim as f64 * residual_dof)).sqrt()
    };
    (value, position)
}

/// Isotropic curvature vector of the neighbourhood: per frame coordinate c, κ_c of the
/// weighted fit (y_i − q)_c ≈ a_c + κ_c · |Uᵀ(y_i − q)|² / 2, projected onto the normal
/// space (the chart's affine fit leaves normal offsets orthogonal to 1 and x, so no
/// linear terms are needed there). Along a unit normal ν the
/// curvature is ν · κ (the fit is linear in the offsets); its norm is the largest
/// isotropic curvature. Noise in the offsets adds variance, not bias. Zero where
/// undetermined.
fn curvature_vector(
    frame: &Frame,
    chart: &FrameChart,
    mass: &[f64],
    sigma: f64,
    d: usize,
) -> Vec<f64> {
    let dim = frame.dim;
    let (mut s00, mut s01, mut s11) = (0.0, 0.0, 0.0);
    let (mut b0, mut b1) = (vec![0.0; dim], vec![0.0; dim]);
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
        s00 += w;
        s01 += w * t2;
        s11 += w * t2 * t2;
        for c in 0..dim {
            let offset = y[c] - chart.q[c];
            b0[c] += w * offset;
            b1[c] += w * t2 * offset;
        }
    }
    let det = s00 * s11 - s01 * s01;
    if det.is_nan() || det <= 1e-12 * s00 * s11 {
        return vec![0.0; dim];
    }
    let mut kappa: Vec<f64> = (0..dim)
        .map(|c| (s00 * b1[c] - s01 * b0[c]) / det)
        .collect();
    // Tangential offsets are linear in x; on a one-sided neighbourhood x and |x|² correlate
    // and would read as curvature. Only the normal part is.
    for a in 0..d {
        let u = &chart.u[a * dim..(a + 1) * dim];
        let along = crate::dense::dot(u, &kappa);
        kappa.iter_mut().zip(u).for_each(|(k, u)| *k -= along * u);
    }
    kappa
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
    if let Bandwidth::Adaptive { max_growth, .. } = settings.bandwidth {
        if !(max_growth.is_finite() && max_growth >= 1.0) {
            return invalid(
                "bandwidth max_growth",
                max_growth,
                "must be finite and at least 1",
            );
        }
    }
    match settings.bandwidth {
        Bandwidth::Neighbours { factor, scale } | Bandwidth::Adaptive { factor, scale, .. } => {
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
