//! Sample points with volumes inside every simplex: where material points are seeded.

use crate::barycentric::{Barycentric, MAX_SIMPLEX_VERTICES};
use crate::mesh::{Point, SimplexMesh};

/// Where the points of one simplex go, with equal volume shares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleRule {
    /// One point at the centroid (exact for linear integrands).
    Centroid,
    /// D + 1 points of the symmetric degree-2 Gauss rule (exact for quadratic integrands):
    /// λ = a at one vertex, b elsewhere, with (a, b) = ((1 ± 1/√3)/2) on segments,
    /// (2/3, 1/6) on triangles, ((5 + 3√5)/20, (5 − √5)/20) on tetrahedra.
    Gauss2,
}

impl SampleRule {
    /// Points per simplex in D dimensions.
    pub fn count(self, dim: usize) -> usize {
        match self {
            SampleRule::Centroid => 1,
            SampleRule::Gauss2 => dim + 1,
        }
    }
}

impl<const D: usize> SimplexMesh<D> {
    /// Sample points of every simplex under `rule`, each with its share of the simplex
    /// volume (the volumes sum to the mesh volume), simplex by simplex.
    pub fn sample_points(&self, rule: SampleRule) -> Vec<(Point<D>, f64)> {
        let (a, b) = match D {
            1 => (0.5 + 0.5 / 3f64.sqrt(), 0.5 - 0.5 / 3f64.sqrt()),
            2 => (2.0 / 3.0, 1.0 / 6.0),
            _ => ((5.0 + 3.0 * 5f64.sqrt()) / 20.0, (5.0 - 5f64.sqrt()) / 20.0),
        };
        let count = rule.count(D);
        let mut out = Vec::with_capacity(self.simplex_count() * count);
        for s in 0..self.simplex_count() {
            let share = self.volume(s) / count as f64;
            match rule {
                SampleRule::Centroid => out.push((self.centroid(s), share)),
                SampleRule::Gauss2 => {
                    for k in 0..=D {
                        let mut lambda = [0.0; MAX_SIMPLEX_VERTICES];
                        for (n, l) in lambda.iter_mut().enumerate().take(D + 1) {
                            *l = if n == k { a } else { b };
                        }
                        out.push((self.point_at(s, &Barycentric(lambda)), share));
                    }
                }
            }
        }
        out
    }
}
