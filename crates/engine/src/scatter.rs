//! The P2G scatter without per-thread copies of the grid.
//!
//! Particles are ordered by the lowest node of their stencil (ties by index), so that
//! consecutive particles touch neighbouring nodes, and cut into blocks of [`BLOCK`]
//! particles. Each block scatters into its own *window*: dense arrays over the node
//! indices `lo..hi` its particles touch, which for a lattice numbering is the block's few
//! cells plus the stencil's reach, not the whole grid. Blocks run in parallel; then
//! every node sums the windows that cover it in block order, in parallel over chunks of
//! nodes.
//!
//! The blocks depend on the particle count and positions only, and each node's sum runs
//! in block order, so the result is bitwise the same on any number of threads. Where a
//! numbering makes windows wide (a mesh file numbered without locality), neighbouring
//! blocks are merged until the windows together span at most [`MAX_SPAN`] times the
//! node count, which bounds the memory traffic by that of a few grid copies.

use nalgebra::SVector;
use rayon::prelude::*;

use crate::stencils::Stencils;

/// Particles per block.
pub(crate) const BLOCK: usize = 4096;

/// The windows may span together at most this many times the node count.
const MAX_SPAN: usize = 4;

/// Nodes per parallel work item of the merge.
const MERGE_CHUNK: usize = 4096;

/// One block's share of the nodal sums, over nodes `lo..lo + len`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Window<const D: usize> {
    lo: usize,
    mass: Vec<f64>,
    abs_mass: Vec<f64>,
    stiffness: Vec<f64>,
    momentum: Vec<SVector<f64, D>>,
    force: Vec<SVector<f64, D>>,
}

impl<const D: usize> Window<D> {
    fn reset(&mut self, lo: usize, hi: usize) {
        self.lo = lo;
        let len = hi.saturating_sub(lo);
        for field in [&mut self.mass, &mut self.abs_mass, &mut self.stiffness] {
            field.clear();
            field.resize(len, 0.0);
        }
        for field in [&mut self.momentum, &mut self.force] {
            field.clear();
            field.resize(len, SVector::zeros());
        }
    }

    fn hi(&self) -> usize {
        self.lo + self.mass.len()
    }

    /// Adds one stencil entry's contributions to `node`.
    #[inline]
    pub fn add(
        &mut self,
        node: usize,
        mass: f64,
        abs_mass: f64,
        stiffness: f64,
        momentum: SVector<f64, D>,
        force: SVector<f64, D>,
    ) {
        let k = node - self.lo;
        self.mass[k] += mass;
        self.abs_mass[k] += abs_mass;
        self.stiffness[k] += stiffness;
        self.momentum[k] += momentum;
        self.force[k] += force;
    }
}

/// The nodal sums P2G produces.
pub(crate) struct NodalSums<'a, const D: usize> {
    pub mass: &'a mut [f64],
    pub abs_mass: &'a mut [f64],
    pub stiffness: &'a mut [f64],
    pub momentum: &'a mut [SVector<f64, D>],
    pub force: &'a mut [SVector<f64, D>],
}

/// The particle order, the blocks and their windows, reused from step to step.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scatter<const D: usize> {
    keys: Vec<(u32, u32)>,
    order: Vec<u32>,
    /// Start of each block in `order` (and its end, last).
    bounds: Vec<usize>,
    /// The node range `lo..hi` each block touches.
    ranges: Vec<(usize, usize)>,
    windows: Vec<Window<D>>,
}

impl<const D: usize> Scatter<D> {
    /// Orders the particles and cuts them into blocks.
    fn plan(&mut self, stencils: &Stencils<D>, particles: usize, nodes: usize) {
        self.keys.clear();
        self.keys
            .par_extend((0..particles).into_par_iter().map(|p| {
                let first = stencils.of(p).nodes.iter().copied().min().unwrap_or(0);
                (first, p as u32)
            }));
        // Keys are unique (the index breaks ties), so the unstable sort is deterministic.
        self.keys.par_sort_unstable();
        self.order.clear();
        self.order.extend(self.keys.iter().map(|&(_, p)| p));
        let order = &self.order;
        let range = |b: &[usize]| {
            let (lo, hi) = order[b[0]..b[1]]
                .iter()
                .flat_map(|&p| stencils.of(p as usize).nodes.iter().copied())
                .fold((u32::MAX, 0u32), |(lo, hi), n| (lo.min(n), hi.max(n + 1)));
            (lo as usize, (hi as usize).max(lo as usize))
        };
        let mut size = BLOCK;
        loop {
            self.bounds.clear();
            self.bounds.extend((0..particles).step_by(size));
            self.bounds.push(particles);
            self.ranges.clear();
            self.ranges
                .par_extend(self.bounds.par_windows(2).map(range));
            let span: usize = self.ranges.iter().map(|(lo, hi)| hi - lo).sum();
            if span <= MAX_SPAN * nodes || size >= particles {
                break;
            }
            size *= 2;
        }
    }

    /// Scatters every particle through `contribute(particle, window)` and sums the
    /// windows into `sums` (every node written; nodes no particle touches get zero).
    pub fn scatter<F>(
        &mut self,
        stencils: &Stencils<D>,
        particles: usize,
        sums: NodalSums<'_, D>,
        contribute: F,
    ) where
        F: Fn(usize, &mut Window<D>) + Sync,
    {
        let nodes = sums.mass.len();
        self.plan(stencils, particles, nodes);
        let blocks = self.bounds.len() - 1;
        self.windows.resize_with(blocks, Window::default);
        let (order, bounds, ranges) = (&self.order, &self.bounds, &self.ranges);
        self.windows
            .par_iter_mut()
            .enumerate()
            .for_each(|(b, window)| {
                let (lo, hi) = ranges[b];
                window.reset(lo, hi);
                for &p in &order[bounds[b]..bounds[b + 1]] {
                    contribute(p as usize, window);
                }
            });
        let windows = &self.windows[..blocks];
        sums.mass
            .par_chunks_mut(MERGE_CHUNK)
            .zip(sums.abs_mass.par_chunks_mut(MERGE_CHUNK))
            .zip(sums.stiffness.par_chunks_mut(MERGE_CHUNK))
            .zip(sums.momentum.par_chunks_mut(MERGE_CHUNK))
            .zip(sums.force.par_chunks_mut(MERGE_CHUNK))
            .enumerate()
            .for_each(|(c, ((((mass, abs_mass), stiffness), momentum), force))| {
                mass.fill(0.0);
                abs_mass.fill(0.0);
                stiffness.fill(0.0);
                momentum.fill(SVector::zeros());
                force.fill(SVector::zeros());
                let start = c * MERGE_CHUNK;
                let end = start + mass.len();
                // In block order, so each node's sum has the same order on any threads.
                for w in windows {
                    let (from, to) = (w.lo.max(start), w.hi().min(end));
                    for node in from..to {
                        let (k, j) = (node - w.lo, node - start);
                        mass[j] += w.mass[k];
                        abs_mass[j] += w.abs_mass[k];
                        stiffness[j] += w.stiffness[k];
                        momentum[j] += w.momentum[k];
                        force[j] += w.force[k];
                    }
                }
            });
    }
}
