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

use std::num::NonZero;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::cloud::{PointCloud, distance};
use crate::pca::principal_directions;

/// Dimension of the searched space: the raw coordinates when n ≤ TREE_DIM, else the
/// leading principal components.
pub const TREE_DIM: usize = 4;

#[derive(Debug, Clone)]
enum Tree {
    D1(ImmutableKdTree<f64, 1>),
    D2(ImmutableKdTree<f64, 2>),
    D3(ImmutableKdTree<f64, 3>),
    D4(ImmutableKdTree<f64, 4>),
}

/// A neighbour: sample index and Euclidean distance in Rⁿ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Sample index.
    pub index: usize,
    /// Distance to the query.
    pub distance: f64,
}

/// Exact neighbour search over a [`PointCloud`].
#[derive(Debug, Clone)]
pub struct NeighbourIndex {
    tree: Tree,
    /// Mean and principal directions when projecting (n > TREE_DIM).
    projection: Option<(Vec<f64>, Vec<Vec<f64>>)>,
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
        let n = cloud.ambient_dim();
        let projection = (n > TREE_DIM).then(|| principal_directions(cloud.points(), n, TREE_DIM));
        let dim = n.min(TREE_DIM);
        let rows: Vec<Vec<f64>> = (0..cloud.len())
            .map(|i| project(projection.as_ref(), cloud.point(i), dim))
            .collect();
        let tree = match dim {
            1 => Tree::D1(build_tree!(1, rows)),
            2 => Tree::D2(build_tree!(2, rows)),
            3 => Tree::D3(build_tree!(3, rows)),
            _ => Tree::D4(build_tree!(4, rows)),
        };
        Self { tree, projection }
    }

    fn dim(&self) -> usize {
        match self.tree {
            Tree::D1(_) => 1,
            Tree::D2(_) => 2,
            Tree::D3(_) => 3,
            Tree::D4(_) => 4,
        }
    }

    /// Indices within squared distance `r2` of `y` in the searched space.
    fn within_projected(&self, y: &[f64], r2: f64) -> Vec<usize> {
        macro_rules! within {
            ($t:expr, $k:literal) => {{
                let q: [f64; $k] = std::array::from_fn(|i| y[i]);
                $t.within_unsorted::<SquaredEuclidean>(&q, r2)
                    .into_iter()
                    .map(|n| n.item as usize)
                    .collect()
            }};
        }
        match &self.tree {
            Tree::D1(t) => within!(t, 1),
            Tree::D2(t) => within!(t, 2),
            Tree::D3(t) => within!(t, 3),
            Tree::D4(t) => within!(t, 4),
        }
    }

    fn nearest_projected(&self, y: &[f64], k: NonZero<usize>) -> Vec<usize> {
        macro_rules! nearest {
            ($t:expr, $k:literal) => {{
                let q: [f64; $k] = std::array::from_fn(|i| y[i]);
                $t.nearest_n::<SquaredEuclidean>(&q, k)
                    .into_iter()
                    .map(|n| n.item as usize)
                    .collect()
            }};
        }
        match &self.tree {
            Tree::D1(t) => nearest!(t, 1),
            Tree::D2(t) => nearest!(t, 2),
            Tree::D3(t) => nearest!(t, 3),
            Tree::D4(t) => nearest!(t, 4),
        }
    }

    /// The `k` samples nearest to `query` (exact), nearest first.
    pub fn nearest(&self, cloud: &PointCloud, query: &[f64], k: usize) -> Vec<Neighbour> {
        let Some(k) = NonZero::new(k.min(cloud.len())) else {
            return Vec::new();
        };
        let y = project(self.projection.as_ref(), query, self.dim());
        let mut found = self.with_distances(cloud, query, self.nearest_projected(&y, k));
        if self.projection.is_some() {
            // Every true k-nearest neighbour is within the k-th candidate's true distance.
            let bound = found.iter().map(|n| n.distance).fold(0.0, f64::max);
            found = self.with_distances(
                cloud,
                query,
                self.within_projected(&y, bound * bound * (1.0 + 1e-12)),
            );
        }
        found.sort_by(|a, b| {
            a.distance
                .total_cmp(&b.distance)
                .then(a.index.cmp(&b.index))
        });
        found.truncate(k.get());
        found
    }

    /// All samples within `radius` of `query` (exact), nearest first.
    pub fn within(&self, cloud: &PointCloud, query: &[f64], radius: f64) -> Vec<Neighbour> {
        let y = project(self.projection.as_ref(), query, self.dim());
        let mut found: Vec<Neighbour> = self
            .with_distances(
                cloud,
                query,
                self.within_projected(&y, radius * radius * (1.0 + 1e-12)),
            )
            .into_iter()
            .filter(|n| n.distance <= radius)
            .collect();
        found.sort_by(|a, b| {
            a.distance
                .total_cmp(&b.distance)
                .then(a.index.cmp(&b.index))
        });
        found
    }

    fn with_distances(
        &self,
        cloud: &PointCloud,
        query: &[f64],
        indices: Vec<usize>,
    ) -> Vec<Neighbour> {
        indices
            .into_iter()
            .map(|index| Neighbour {
                index,
                distance: distance(cloud.point(index), query),
            })
            .collect()
    }
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
