//! Exact k-nearest-neighbour and radius search that stays fast for large ambient n.
//!
//! For n ≤ [`TREE_DIM`] a kiddo k-d tree indexes the raw coordinates. For larger n a
//! k-d tree in n dimensions degenerates to a near-full scan, so the samples are first
//! projected onto their leading [`TREE_DIM`] principal directions (randomised PCA with
//! faer) and the tree indexes the projections. A projection never increases distances,
//! so candidates are re-ranked exactly: the k nearest in the projection give an upper
//! bound ρ on the true k-th distance, and a radius-ρ query in the projection returns a
//! superset of the true k nearest. For data near a low-dimensional manifold the
//! projection keeps almost all of the spread and the superset is small; the answer is
//! exact in every case.
//!
//! When the data spread over many more directions than [`TREE_DIM`], that superset
//! approaches the whole cloud and the tree costs more than a plain scan. The index
//! measures this when it is built (probe queries from evenly spread samples) and then
//! scans instead, with partial distances that stop as soon as a sample cannot qualify:
//! never slower than brute force.

use std::num::NonZero;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::cloud::PointCloud;
use crate::dense::distance_squared;
use crate::error::ManifoldError;
use crate::pca::principal_directions;

/// Dimension of the searched space: the raw coordinates when n ≤ TREE_DIM, else the
/// leading principal components.
pub const TREE_DIM: usize = 4;

/// Probe queries used to choose between the projected tree and a scan.
const PROBES: usize = 24;

#[derive(Debug, Clone)]
enum Tree {
    D1(ImmutableKdTree<f64, 1>),
    D2(ImmutableKdTree<f64, 2>),
    D3(ImmutableKdTree<f64, 3>),
    D4(ImmutableKdTree<f64, 4>),
}

/// How queries are answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchStrategy {
    /// A k-d tree on the raw coordinates (n ≤ [`TREE_DIM`]).
    Tree,
    /// A k-d tree on the leading principal components, candidates re-ranked in Rⁿ.
    ProjectedTree,
    /// A scan over every sample with early-terminated distances: chosen when the
    /// projected tree would return most of the cloud as candidates.
    Scan,
}

/// A neighbour: sample index and Euclidean distance in Rⁿ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Sample index.
    pub index: usize,
    /// Distance to the query.
    pub distance: f64,
}

/// Exact neighbour search over a [`PointCloud`] (or over a subset of its samples).
#[derive(Debug, Clone)]
pub struct NeighbourIndex {
    tree: Tree,
    /// Mean and principal directions when projecting (n > TREE_DIM).
    projection: Option<(Vec<f64>, Vec<Vec<f64>>)>,
    /// Sample index of each tree item; `None` when the items are all samples in order.
    items: Option<Vec<usize>>,
    strategy: SearchStrategy,
    cloud_id: u64,
    ambient: usize,
}

/// Runs `$body` with `$tree` bound to the k-d tree and `$q` to the first K coordinates of
/// `$y` as the `[f64; K]` query that tree takes.
macro_rules! with_tree {
    ($tree_enum:expr, $tree:ident, $q:ident = $y:expr => $body:expr) => {
        match $tree_enum {
            Tree::D1($tree) => {
                let $q: [f64; 1] = std::array::from_fn(|i| $y[i]);
                $body
            }
            Tree::D2($tree) => {
                let $q: [f64; 2] = std::array::from_fn(|i| $y[i]);
                $body
            }
            Tree::D3($tree) => {
                let $q: [f64; 3] = std::array::from_fn(|i| $y[i]);
                $body
            }
            Tree::D4($tree) => {
                let $q: [f64; 4] = std::array::from_fn(|i| $y[i]);
                $body
            }
        }
    };
}

macro_rules! build_tree {
    ($k:literal, $rows:expr) => {{
        let rows: Vec<[f64; $k]> = $rows
            .iter()
            .map(|r| std::array::from_fn(|i| r[i]))
            .collect();
        ImmutableKdTree::<f64, $k>::new_from_slice(&rows)
    }};
}

impl NeighbourIndex {
    /// Indexes the samples of `cloud`.
    pub fn new(cloud: &PointCloud) -> Self {
        Self::over(cloud, None)
    }

    /// Indexes the samples `items` of `cloud` (all when `None`).
    pub(crate) fn over(cloud: &PointCloud, items: Option<Vec<usize>>) -> Self {
        let n = cloud.ambient_dim();
        let count = items.as_ref().map_or(cloud.len(), Vec::len);
        let sample = |item: usize| items.as_ref().map_or(item, |list| list[item]);
        let projection = (n > TREE_DIM).then(|| principal_directions(cloud.points(), n, TREE_DIM));
        let dim = n.min(TREE_DIM);
        let rows: Vec<Vec<f64>> = (0..count)
            .map(|i| project(projection.as_ref(), cloud.point(sample(i)), dim))
            .collect();
        let tree = match dim {
            1 => Tree::D1(build_tree!(1, rows)),
            2 => Tree::D2(build_tree!(2, rows)),
            3 => Tree::D3(build_tree!(3, rows)),
            _ => Tree::D4(build_tree!(4, rows)),
        };
        let mut index = Self {
            tree,
            strategy: if projection.is_some() {
                SearchStrategy::ProjectedTree
            } else {
                SearchStrategy::Tree
            },
            projection,
            items,
            cloud_id: cloud.id(),
            ambient: n,
        };
        if index.strategy == SearchStrategy::ProjectedTree && index.projected_tree_is_slow(cloud) {
            index.strategy = SearchStrategy::Scan;
        }
        index
    }

    /// How this index answers queries.
    pub fn strategy(&self) -> SearchStrategy {
        self.strategy
    }

    /// Number of indexed samples.
    pub fn len(&self) -> usize {
        match &self.tree {
            Tree::D1(t) => t.size(),
            Tree::D2(t) => t.size(),
            Tree::D3(t) => t.size(),
            Tree::D4(t) => t.size(),
        }
    }

    /// Whether nothing is indexed (never for an index of a valid cloud).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Probe queries from evenly spread samples: the re-ranked candidates cost n each, a
    /// scan N·n at most; a tree that returns more than a quarter of the cloud per probe
    /// (the tree's own traversal costs about as much again) loses to the scan.
    fn projected_tree_is_slow(&self, cloud: &PointCloud) -> bool {
        let count = self.len();
        if count < 4 * PROBES {
            return true;
        }
        let k = NonZero::new(16.min(count)).unwrap_or(NonZero::<usize>::MIN);
        let mut candidates = 0usize;
        for p in 0..PROBES {
            let query = cloud.point(self.sample(p * count / PROBES));
            let y = project(self.projection.as_ref(), query, self.dim());
            let bound = self
                .nearest_projected(&y, k)
                .into_iter()
                .map(|item| distance_squared(cloud.point(self.sample(item)), query))
                .fold(0.0, f64::max);
            candidates += self.within_projected(&y, bound * (1.0 + 1e-12)).len();
        }
        candidates * 4 > count * PROBES
    }

    #[inline]
    fn sample(&self, item: usize) -> usize {
        self.items.as_ref().map_or(item, |list| list[item])
    }

    fn dim(&self) -> usize {
        match self.tree {
            Tree::D1(_) => 1,
            Tree::D2(_) => 2,
            Tree::D3(_) => 3,
            Tree::D4(_) => 4,
        }
    }

    fn check(&self, cloud: &PointCloud, query: &[f64]) -> Result<(), ManifoldError> {
        if cloud.id() != self.cloud_id {
            return Err(ManifoldError::ForeignCloud);
        }
        if query.len() != self.ambient {
            return Err(ManifoldError::LengthMismatch {
                what: "query",
                expected: self.ambient,
                found: query.len(),
            });
        }
        match query.iter().position(|x| !x.is_finite()) {
            Some(index) => Err(ManifoldError::NonFinite {
                what: "query coordinate",
                index,
            }),
            None => Ok(()),
        }
    }

    /// Tree items within squared distance `r2` of `y` in the searched space.
    fn within_projected(&self, y: &[f64], r2: f64) -> Vec<usize> {
        with_tree!(&self.tree, tree, q = y => tree
            .within_unsorted::<SquaredEuclidean>(&q, r2)
            .into_iter()
            .map(|n| n.item as usize)
            .collect())
    }

    fn nearest_projected(&self, y: &[f64], k: NonZero<usize>) -> Vec<usize> {
        self.nearest_projected_with_distances(y, k)
            .into_iter()
            .map(|(item, _)| item)
            .collect()
    }

    /// The `k` nearest in the tree's coordinates, with their squared distances there.
    fn nearest_projected_with_distances(&self, y: &[f64], k: NonZero<usize>) -> Vec<(usize, f64)> {
        with_tree!(&self.tree, tree, q = y => tree
            .nearest_n::<SquaredEuclidean>(&q, k)
            .into_iter()
            .map(|n| (n.item as usize, n.distance))
            .collect())
    }

    /// The `k` samples nearest to `query` (exact), nearest first; ties by index.
    pub fn nearest(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        k: usize,
    ) -> Result<Vec<Neighbour>, ManifoldError> {
        self.check(cloud, query)?;
        let mut found = Vec::new();
        self.nearest_into(cloud, query, k, &mut found);
        Ok(found)
    }

    /// All samples within `radius` of `query` (exact), nearest first; ties by index.
    pub fn within(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        radius: f64,
    ) -> Result<Vec<Neighbour>, ManifoldError> {
        self.check(cloud, query)?;
        let mut found = Vec::new();
        self.within_into(cloud, query, radius, &mut found);
        Ok(found)
    }

    /// [`Self::nearest`] into a reused buffer, for a query already checked.
    pub(crate) fn nearest_into(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        k: usize,
        found: &mut Vec<Neighbour>,
    ) {
        found.clear();
        let Some(k) = NonZero::new(k.min(self.len())) else {
            return;
        };
        match self.strategy {
            SearchStrategy::Tree => {
                let items = self.nearest_projected(query, k);
                self.push_exact(cloud, query, items, f64::INFINITY, found);
            }
            SearchStrategy::ProjectedTree => {
                let y = project(self.projection.as_ref(), query, self.dim());
                // Every true k-nearest neighbour is within the k-th candidate's true
                // distance, and projection never lengthens a distance. The tree search
                // reaches at least as far as the candidates' projected distances too: in
                // round-off a projected distance can exceed the true one (a query on a
                // sample has true distance 0 and projected distance 1e-30), and the
                // candidates themselves must not be lost.
                let (bound, reach) = self
                    .nearest_projected_with_distances(&y, k)
                    .into_iter()
                    .map(|(item, projected)| {
                        (
                            distance_squared(cloud.point(self.sample(item)), query),
                            projected,
                        )
                    })
                    .fold((0.0, 0.0), |(b, r), (d, p)| {
                        (f64::max(b, d), f64::max(r, p))
                    });
                let items = self.within_projected(&y, bound.max(reach) * (1.0 + 1e-12));
                self.push_exact(cloud, query, items, bound * (1.0 + 1e-12), found);
            }
            SearchStrategy::Scan => self.scan_nearest(cloud, query, k.get(), found),
        }
        sort_neighbours(found);
        found.truncate(k.get());
    }

    /// [`Self::within`] into a reused buffer, for a query already checked.
    pub(crate) fn within_into(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        radius: f64,
        found: &mut Vec<Neighbour>,
    ) {
        found.clear();
        // Squared distances are compared with a little slack, then the distances
        // themselves with the radius: √ and squaring must not lose a sample on the sphere.
        let r2 = radius * radius * (1.0 + 1e-12);
        match self.strategy {
            SearchStrategy::Scan => {
                for item in 0..self.len() {
                    let index = self.sample(item);
                    if let Some(d2) = partial_distance(cloud.point(index), query, r2) {
                        found.push(Neighbour {
                            index,
                            distance: d2.sqrt(),
                        });
                    }
                }
            }
            _ => {
                let y = project(self.projection.as_ref(), query, self.dim());
                // The tree search gets an absolute slack of the projection's round-off,
                // so a sample at (or within round-off of) the radius is not lost to it;
                // the exact distances decide.
                let slack = (1e-13 * y.iter().map(|c| c * c).sum::<f64>().sqrt()).powi(2);
                let items = self.within_projected(&y, r2 + slack);
                self.push_exact(cloud, query, items, r2, found);
            }
        }
        found.retain(|n| n.distance <= radius);
        sort_neighbours(found);
    }

    /// Exact distances of tree items, keeping those within squared distance `limit`.
    fn push_exact(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        items: Vec<usize>,
        limit: f64,
        found: &mut Vec<Neighbour>,
    ) {
        for item in items {
            let index = self.sample(item);
            if let Some(d2) = partial_distance(cloud.point(index), query, limit) {
                found.push(Neighbour {
                    index,
                    distance: d2.sqrt(),
                });
            }
        }
    }

    /// k nearest by a scan: a bounded max-list of the best k so far prunes the rest.
    fn scan_nearest(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        k: usize,
        found: &mut Vec<Neighbour>,
    ) {
        // `found` holds squared distances while scanning, worst last.
        let mut worst = f64::INFINITY;
        for item in 0..self.len() {
            let index = self.sample(item);
            let Some(d2) = partial_distance(cloud.point(index), query, worst) else {
                continue;
            };
            let candidate = Neighbour {
                index,
                distance: d2,
            };
            let at =
                found.partition_point(|n| n.distance < d2 || (n.distance == d2 && n.index < index));
            if found.len() < k {
                found.insert(at, candidate);
            } else if at < k {
                found.insert(at, candidate);
                found.truncate(k);
            }
            if found.len() == k {
                worst = found[k - 1].distance;
            }
        }
        found
            .iter_mut()
            .for_each(|n| n.distance = n.distance.sqrt());
    }
}

/// Squared distance if it is ≤ `limit`, summed in blocks so hopeless samples stop early.
#[inline]
fn partial_distance(point: &[f64], query: &[f64], limit: f64) -> Option<f64> {
    // One running sum in coordinate order: the same rounding as a plain loop, so the
    // distances agree bit for bit with a brute-force search.
    let mut sum = 0.0;
    for (p, q) in point.chunks(16).zip(query.chunks(16)) {
        sum = p.iter().zip(q).fold(sum, |s, (a, b)| s + (a - b) * (a - b));
        if sum > limit {
            return None;
        }
    }
    Some(sum)
}

fn sort_neighbours(found: &mut [Neighbour]) {
    found.sort_unstable_by(|a, b| {
        a.distance
            .total_cmp(&b.distance)
            .then(a.index.cmp(&b.index))
    });
}

/// Coordinates in the searched space: raw, or principal components.
fn project(projection: Option<&(Vec<f64>, Vec<Vec<f64>>)>, x: &[f64], dim: usize) -> Vec<f64> {
    match projection {
        None => x.to_vec(),
        Some((mean, directions)) => {
            let mut y: Vec<f64> = directions
                .iter()
                .map(|v| {
                    v.iter()
                        .zip(x)
                        .zip(mean)
                        .map(|((v, x), m)| v * (x - m))
                        .sum()
                })
                .collect();
            y.resize(dim, 0.0);
            y
        }
    }
}
