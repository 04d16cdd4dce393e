//! Manifold moving least squares: the chart, then a degree-m polynomial fit in it.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::chart::{Chart, Neighbourhood, fit_chart, theta};
use crate::cloud::PointCloud;
use crate::error::ManifoldError;
use crate::neighbors::NeighbourIndex;
use crate::polynomial::{Monomials, weighted_fit};

/// How the bandwidth σ of θ is chosen per query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bandwidth {
    /// σ = `scale` × (distance to the K*-th nearest sample), K* = ⌈c · C(d+m, d)⌉ + 1.
    /// θ falls to e⁻¹ at σ/2, so with scale 2 about K* samples carry real weight:
    /// σ follows the local sample spacing h, which the O(h^{m+1}) rate needs.
    Neighbours {
        /// c in K* = c · C(d+m, d) + 1.
        factor: f64,
        /// σ over the K*-th neighbour distance.
        scale: f64,
    },
    /// A fixed σ for every query.
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
    /// Chart iteration cap.
    pub max_iterations: usize,
}

impl Settings {
    /// Degree-`degree` approximation of a `intrinsic_dim`-manifold with default bandwidth,
    /// tolerance 10⁻¹⁰ and at most 200 chart iterations.
    pub fn new(intrinsic_dim: usize, degree: usize) -> Self {
        Self {
            intrinsic_dim,
            degree,
            bandwidth: Bandwidth::default(),
            tolerance: 1e-10,
            max_iterations: 200,
        }
    }
}

/// The result of one query.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// f̃(r), k values.
    pub value: Vec<f64>,
    /// Gradient in chart coordinates, k×d.
    pub gradient: DMatrix<f64>,
    /// The chart the fit used.
    pub chart: Chart,
    /// Samples with positive weight.
    pub neighbours: usize,
}

impl Estimate {
    /// Gradient as tangent vectors in Rⁿ (n×k): U times the chart gradient.
    pub fn ambient_gradient(&self) -> DMatrix<f64> {
        &self.chart.basis * self.gradient.transpose()
    }
}

/// A manifold MLS approximation over a point cloud.
#[derive(Debug, Clone)]
pub struct ManifoldMls {
    cloud: PointCloud,
    index: NeighbourIndex,
    settings: Settings,
    monomials: Monomials,
}

impl ManifoldMls {
    /// Indexes `cloud` and validates `settings`.
    pub fn new(cloud: PointCloud, settings: Settings) -> Result<Self, ManifoldError> {
        let (d, n) = (settings.intrinsic_dim, cloud.ambient_dim());
        if d == 0 || d >= n {
            return Err(ManifoldError::IntrinsicDimension {
                intrinsic: d,
                ambient: n,
            });
        }
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
        let index = NeighbourIndex::new(&cloud);
        let monomials = Monomials::new(d, settings.degree);
        Ok(Self {
            cloud,
            index,
            settings,
            monomials,
        })
    }

    /// The samples.
    pub fn cloud(&self) -> &PointCloud {
        &self.cloud
    }

    /// The neighbour index.
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

    /// σ and the samples within it.
    fn neighbourhood(&self, r: &[f64]) -> (f64, Vec<usize>) {
        let sigma = match self.settings.bandwidth {
            Bandwidth::Fixed(sigma) => sigma,
            Bandwidth::Neighbours { factor, scale } => {
                let k = (factor * self.monomials.len() as f64).ceil() as usize + 1;
                let nearest = self.index.nearest(&self.cloud, r, k);
                scale * nearest.last().map_or(0.0, |n| n.distance)
            }
        };
        let within = self.index.within(&self.cloud, r, sigma);
        (sigma, within.into_iter().map(|n| n.index).collect())
    }

    /// The local chart of `r`.
    pub fn chart(&self, r: &[f64]) -> Result<Chart, ManifoldError> {
        self.check_query(r)?;
        let (sigma, indices) = self.neighbourhood(r);
        self.chart_of(r, sigma, &indices)
    }

    fn chart_of(&self, r: &[f64], sigma: f64, indices: &[usize]) -> Result<Chart, ManifoldError> {
        if !(sigma.is_finite() && sigma > 0.0) || indices.len() <= self.settings.intrinsic_dim {
            return Err(ManifoldError::TooFewNeighbours {
                found: indices.len(),
                needed: self.monomials.len(),
                degree: self.settings.degree,
                intrinsic: self.settings.intrinsic_dim,
            });
        }
        let n = self.cloud.ambient_dim();
        let hood = Neighbourhood {
            points: DMatrix::from_fn(n, indices.len(), |j, i| self.cloud.point(indices[i])[j]),
        };
        fit_chart(
            &hood,
            &DVector::from_column_slice(r),
            self.settings.intrinsic_dim,
            sigma,
            self.settings.tolerance,
            self.settings.max_iterations,
        )
    }

    /// Weighted degree-m fit of `rhs` (one row per neighbour) in the chart; returns the
    /// coefficients and the number of weighted samples.
    fn fit_in_chart(
        &self,
        chart: &Chart,
        indices: &[usize],
        rhs: &DMatrix<f64>,
    ) -> Result<(DMatrix<f64>, usize), ManifoldError> {
        let d = self.settings.intrinsic_dim;
        let mut coords = DMatrix::<f64>::zeros(indices.len(), d);
        let mut weights = vec![0.0; indices.len()];
        for (row, &i) in indices.iter().enumerate() {
            let p = DVector::from_column_slice(self.cloud.point(i));
            let offset = &p - &chart.origin;
            weights[row] = theta(offset.norm(), chart.sigma);
            let x = chart.basis.transpose() * offset / chart.sigma;
            coords.set_row(row, &x.transpose());
        }
        let coefficients = weighted_fit(&self.monomials, &coords, &weights, rhs)?;
        Ok((coefficients, weights.iter().filter(|&&w| w > 0.0).count()))
    }

    /// f̃(r) and its gradient in chart coordinates.
    pub fn evaluate(&self, r: &[f64]) -> Result<Estimate, ManifoldError> {
        self.check_query(r)?;
        let (sigma, indices) = self.neighbourhood(r);
        let chart = self.chart_of(r, sigma, &indices)?;
        let k = self.cloud.value_dim();
        let rhs = DMatrix::from_fn(indices.len(), k, |row, c| self.cloud.value(indices[row])[c]);
        let (coefficients, neighbours) = self.fit_in_chart(&chart, &indices, &rhs)?;
        let value = coefficients.row(0).iter().copied().collect();
        let d = self.settings.intrinsic_dim;
        let gradient = if self.settings.degree >= 1 {
            DMatrix::from_fn(k, d, |c, j| coefficients[(1 + j, c)] / chart.sigma)
        } else {
            DMatrix::zeros(k, d)
        };
        Ok(Estimate {
            value,
            gradient,
            chart,
            neighbours,
        })
    }

    /// The projection of `r` onto the reconstructed manifold: q + g(0), with g the
    /// degree-m fit of r_i − q in the chart.
    pub fn project(&self, r: &[f64]) -> Result<Vec<f64>, ManifoldError> {
        self.check_query(r)?;
        let (sigma, indices) = self.neighbourhood(r);
        let chart = self.chart_of(r, sigma, &indices)?;
        let n = self.cloud.ambient_dim();
        let rhs = DMatrix::from_fn(indices.len(), n, |row, c| {
            self.cloud.point(indices[row])[c] - chart.origin[c]
        });
        let (coefficients, _) = self.fit_in_chart(&chart, &indices, &rhs)?;
        Ok((0..n)
            .map(|c| chart.origin[c] + coefficients[(0, c)])
            .collect())
    }

    /// [`Self::evaluate`] for many queries (rows of `queries`, n each) in parallel. Results
    /// are in query order and do not depend on the thread count or the order of queries.
    pub fn evaluate_batch(
        &self,
        queries: &[f64],
    ) -> Result<Vec<Result<Estimate, ManifoldError>>, ManifoldError> {
        Ok(self
            .query_rows(queries)?
            .map(|r| self.evaluate(r))
            .collect())
    }

    /// [`Self::project`] for many queries in parallel.
    pub fn project_batch(
        &self,
        queries: &[f64],
    ) -> Result<Vec<Result<Vec<f64>, ManifoldError>>, ManifoldError> {
        Ok(self.query_rows(queries)?.map(|r| self.project(r)).collect())
    }

    /// The rows of a flat Q × n query array, as a parallel iterator.
    fn query_rows<'q>(
        &self,
        queries: &'q [f64],
    ) -> Result<rayon::slice::ChunksExact<'q, f64>, ManifoldError> {
        let n = self.cloud.ambient_dim();
        if queries.len() % n != 0 {
            return Err(ManifoldError::LengthMismatch {
                what: "queries (Q × n)",
                expected: queries.len() / n * n,
                found: queries.len(),
            });
        }
        Ok(queries.par_chunks_exact(n))
    }
}
