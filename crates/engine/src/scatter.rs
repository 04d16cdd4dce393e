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

use crate::parallel::lowest_failure;

/// Particles per block.
pub(crate) const BLOCK: usize = 4096;

/// The windows may span together at most this many times the node count.
const MAX_SPAN: usize = 4;

/// One node's sums in a window, kept together so that a stencil entry's contribution
/// touches one place in memory rather than five arrays. `A` is 1 where Σ|N| m_p is
/// summed apart from the mass, 0 for a kernel whose values are never negative (then it
/// is the mass bit for bit, and a record is 64 bytes in 3D instead of 72).
#[derive(Debug, Clone, Copy)]
struct NodeSums<const D: usize, const A: usize> {
    mass: f64,
    abs_mass: [f64; A],
    stiffness: f64,
    momentum: SVector<f64, D>,
    force: SVector<f64, D>,
}

impl<const D: usize, const A: usize> NodeSums<D, A> {
    const ZERO: Self = Self {
        mass: 0.0,
        abs_mass: [0.0; A],
        stiffness: 0.0,
        momentum: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
        force: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
    };

    #[inline(always)]
    fn add(
        &mut self,
        mass: f64,
        abs_mass: f64,
        stiffness: f64,
        momentum: SVector<f64, D>,
        force: SVector<f64, D>,
    ) {
        self.mass += mass;
        for sum in &mut self.abs_mass {
            *sum += abs_mass;
        }
        self.stiffness += stiffness;
        self.momentum += momentum;
        self.force += force;
    }
}

/// One node's sums in a window of a momentum-only scatter (MLS-MPM): 40 bytes in 3D
/// instead of 72, so the window's clearing, the entries and the merge move less memory;
/// 32 without the |N|-mass (`A` = 0, as for [`NodeSums`]).
#[derive(Debug, Clone, Copy)]
struct MomentumSums<const D: usize, const A: usize> {
    mass: f64,
    abs_mass: [f64; A],
    momentum: SVector<f64, D>,
}

impl<const D: usize, const A: usize> MomentumSums<D, A> {
    const ZERO: Self = Self {
        mass: 0.0,
        abs_mass: [0.0; A],
        momentum: SVector::from_array_storage(nalgebra::ArrayStorage([[0.0; D]; 1])),
    };

    #[inline(always)]
    fn add(&mut self, mass: f64, abs_mass: f64, momentum: SVector<f64, D>) {
        self.mass += mass;
        for sum in &mut self.abs_mass {
            *sum += abs_mass;
        }
        self.momentum += momentum;
    }
}

/// Where a window keeps its records of one kind.
trait InWindow<const D: usize>: Sized {
    /// The window's records of this kind.
    fn records(window: &Window<D>) -> &[Self];
}

impl<const D: usize> InWindow<D> for NodeSums<D, 1> {
    fn records(window: &Window<D>) -> &[Self] {
        &window.sums
    }
}

impl<const D: usize> InWindow<D> for NodeSums<D, 0> {
    fn records(window: &Window<D>) -> &[Self] {
        &window.nonnegative_sums
    }
}

impl<const D: usize> InWindow<D> for MomentumSums<D, 1> {
    fn records(window: &Window<D>) -> &[Self] {
        &window.momentum_sums
    }
}

impl<const D: usize> InWindow<D> for MomentumSums<D, 0> {
    fn records(window: &Window<D>) -> &[Self] {
        &window.nonnegative_momentum_sums
    }
}

/// A window record's share of the nodal sums, added into the chunk of nodes it falls in.
trait Record<const D: usize>: InWindow<D> + Copy + Send + Sync {
    /// Zeroes the fields these records sum, over a chunk.
    fn clear(chunk: &mut ChunkSums<'_, D>);
    /// Adds the record to node `j` of the chunk.
    fn add_into(&self, chunk: &mut ChunkSums<'_, D>, j: usize);
}

/// One chunk of [`NodalSums`]' arrays (those a layout does not sum are left alone).
struct ChunkSums<'a, const D: usize> {
    mass: &'a mut [f64],
    abs_mass: &'a mut [f64],
    stiffness: &'a mut [f64],
    momentum: &'a mut [SVector<f64, D>],
    force: &'a mut [SVector<f64, D>],
}

impl<const D: usize, const A: usize> Record<D> for NodeSums<D, A>
where
    Self: InWindow<D>,
{
    fn clear(chunk: &mut ChunkSums<'_, D>) {
        chunk.mass.fill(0.0);
        if A > 0 {
            chunk.abs_mass.fill(0.0);
        }
        chunk.stiffness.fill(0.0);
        chunk.momentum.fill(SVector::zeros());
        chunk.force.fill(SVector::zeros());
    }
    #[inline(always)]
    fn add_into(&self, chunk: &mut ChunkSums<'_, D>, j: usize) {
        chunk.mass[j] += self.mass;
        for sum in &self.abs_mass {
            chunk.abs_mass[j] += sum;
        }
        chunk.stiffness[j] += self.stiffness;
        chunk.momentum[j] += self.momentum;
        chunk.force[j] += self.force;
    }
}

impl<const D: usize, const A: usize> Record<D> for MomentumSums<D, A>
where
    Self: InWindow<D>,
{
    fn clear(chunk: &mut ChunkSums<'_, D>) {
        chunk.mass.fill(0.0);
        if A > 0 {
            chunk.abs_mass.fill(0.0);
        }
        chunk.momentum.fill(SVector::zeros());
    }
    #[inline(always)]
    fn add_into(&self, chunk: &mut ChunkSums<'_, D>, j: usize) {
        chunk.mass[j] += self.mass;
        for sum in &self.abs_mass {
            chunk.abs_mass[j] += sum;
        }
        chunk.momentum[j] += self.momentum;
    }
}

/// One block's share of the nodal sums, over nodes `lo..hi`, in the records of the
/// scatter's layout ([`NodalSums::momentum_only`], [`NodalSums::nonnegative`]); the
/// other vectors are empty.
#[derive(Debug, Clone, Default)]
pub(crate) struct Window<const D: usize> {
    lo: usize,
    hi: usize,
    sums: Vec<NodeSums<D, 1>>,
    nonnegative_sums: Vec<NodeSums<D, 0>>,
    momentum_sums: Vec<MomentumSums<D, 1>>,
    nonnegative_momentum_sums: Vec<MomentumSums<D, 0>>,
}

impl<const D: usize> Window<D> {
    fn reset(&mut self, lo: usize, hi: usize, momentum_only: bool, nonnegative: bool) {
        let len = hi.saturating_sub(lo);
        self.lo = lo;
        self.hi = lo + len;
        self.sums.clear();
        self.nonnegative_sums.clear();
        self.momentum_sums.clear();
        self.nonnegative_momentum_sums.clear();
        match (momentum_only, nonnegative) {
            (false, false) => self.sums.resize(len, NodeSums::ZERO),
            (false, true) => self.nonnegative_sums.resize(len, NodeSums::ZERO),
            (true, false) => self.momentum_sums.resize(len, MomentumSums::ZERO),
            (true, true) => self
                .nonnegative_momentum_sums
                .resize(len, MomentumSums::ZERO),
        }
    }

    fn hi(&self) -> usize {
        self.hi
    }

    /// Bytes of the records.
    fn bytes(&self) -> usize {
        use crate::memory::bytes;
        bytes(&self.sums)
            + bytes(&self.nonnegative_sums)
            + bytes(&self.momentum_sums)
            + bytes(&self.nonnegative_momentum_sums)
    }

    /// Adds one stencil entry's contributions to `node`, in a window of a full scatter
    /// ([`NodalSums::momentum_only`] false); `A` is 0 where [`NodalSums::nonnegative`]
    /// holds (`abs_mass` is then not summed), else 1.
    #[inline(always)]
    pub fn add<const A: usize>(
        &mut self,
        node: usize,
        mass: f64,
        abs_mass: f64,
        stiffness: f64,
        momentum: SVector<f64, D>,
        force: SVector<f64, D>,
    ) {
        let k = node - self.lo;
        if A == 0 {
            self.nonnegative_sums[k].add(mass, abs_mass, stiffness, momentum, force);
        } else {
            self.sums[k].add(mass, abs_mass, stiffness, momentum, force);
        }
    }

    /// Adds one stencil entry's mass and momentum to `node`, in a window of a
    /// momentum-only scatter (MLS-MPM, whose momentum carries the force impulse: no
    /// separate force or stiffness); `A` as for [`Self::add`].
    #[inline(always)]
    pub fn add_momentum<const A: usize>(
        &mut self,
        node: usize,
        mass: f64,
        abs_mass: f64,
        momentum: SVector<f64, D>,
    ) {
        let k = node - self.lo;
        if A == 0 {
            self.nonnegative_momentum_sums[k].add(mass, abs_mass, momentum);
        } else {
            self.momentum_sums[k].add(mass, abs_mass, momentum);
        }
    }
}

/// The nodal sums P2G produces.
pub(crate) struct NodalSums<'a, const D: usize> {
    pub mass: &'a mut [f64],
    pub abs_mass: &'a mut [f64],
    pub stiffness: &'a mut [f64],
    pub momentum: &'a mut [SVector<f64, D>],
    pub force: &'a mut [SVector<f64, D>],
    /// Per chunk of [`NODE_CHUNK`] nodes: whether it may hold non-zero values this step
    /// (a block's window reaches it now, or reached it in the last step, whose values
    /// must be cleared). Written by [`Scatter::scatter`].
    pub live: &'a mut [bool],
    /// Only mass, |N|-mass and momentum are scattered (MLS-MPM, whose momentum carries
    /// the force): the stiffness and force arrays are neither cleared nor summed, and
    /// stay as they are (zero, as no step of such a simulation writes them).
    pub momentum_only: bool,
    /// Every shape-function value is ≥ 0 (`Kernel::nonnegative_values`), so Σ|N| m_p is
    /// the mass: `abs_mass` is neither cleared nor summed, and the contributions must
    /// come through `Window::add::<0>` / `add_momentum::<0>`.
    pub nonnegative: bool,
}

/// Nodes per chunk of the merge and of the grid update (fixed, so that sums taken per
/// chunk do not depend on the thread count).
pub(crate) const NODE_CHUNK: usize = 4096;

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
    /// Chunks of [`NODE_CHUNK`] nodes the last scatter's windows reached.
    reached: Vec<bool>,
}

impl<const D: usize> Scatter<D> {
    /// Bytes of the particle ordering (grows with the particles) and of the blocks and
    /// their windows (grows with the nodes).
    pub fn bytes(&self) -> (usize, usize) {
        use crate::memory::bytes;
        let windows: usize = self.windows.iter().map(Window::bytes).sum();
        (
            bytes(&self.keys) + bytes(&self.order),
            windows
                + bytes(&self.windows)
                + bytes(&self.bounds)
                + bytes(&self.ranges)
                + bytes(&self.reached),
        )
    }

    /// Orders the particles by the lowest node of their stencil and cuts them into
    /// blocks; `ranges` holds each particle's lowest and highest node.
    fn plan(&mut self, ranges: &[(u32, u32)], nodes: usize) {
        let particles = ranges.len();
        self.keys.clear();
        if self.order.len() == particles {
            // In the last step's order, which particles that moved a little keep nearly
            // sorted: the merge sort below finds the sorted runs and has little to do.
            let order = &self.order;
            self.keys
                .par_extend(order.par_iter().map(|&p| (ranges[p as usize].0, p)));
        } else {
            self.keys.par_extend(
                ranges
                    .par_iter()
                    .enumerate()
                    .map(|(p, &(lo, _))| (lo, p as u32)),
            );
        }
        // Keys are unique (the index breaks ties), so the order they end in depends on
        // the keys alone, not on where the sort started.
        self.keys.par_sort();
        self.order.clear();
        self.order.extend(self.keys.iter().map(|&(_, p)| p));
        let order = &self.order;
        let range = |b: &[usize]| {
            let (lo, hi) = order[b[0]..b[1]]
                .iter()
                .map(|&p| ranges[p as usize])
                .fold((u32::MAX, 0u32), |(lo, hi), (a, z)| {
                    (lo.min(a), hi.max(z + 1))
                });
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

    /// Scatters the particles through `contribute(block, window)`, where `block` lists
    /// one block's particles in order, and sums the windows into `sums` (every node of a
    /// live chunk written, nodes no particle touches with zero; chunks neither reached
    /// now nor in the last step are zero already and are skipped). `ranges` holds each particle's
    /// lowest and highest stencil node. Among failing blocks the lowest particle index
    /// wins, whatever the thread count; on failure `sums` is left as it was.
    pub fn scatter<F, E>(
        &mut self,
        ranges: &[(u32, u32)],
        sums: NodalSums<'_, D>,
        contribute: F,
    ) -> Result<(), (usize, E)>
    where
        F: Fn(&[u32], &mut Window<D>) -> Result<(), (usize, E)> + Sync,
        E: Send,
    {
        let nodes = sums.mass.len();
        let (momentum_only, nonnegative) = (sums.momentum_only, sums.nonnegative);
        self.plan(ranges, nodes);
        let blocks = self.bounds.len() - 1;
        self.windows.resize_with(blocks, Window::default);
        let (order, bounds, block_ranges) = (&self.order, &self.bounds, &self.ranges);
        self.windows
            .par_iter_mut()
            .enumerate()
            .map(|(b, window)| {
                let (lo, hi) = block_ranges[b];
                window.reset(lo, hi, momentum_only, nonnegative);
                contribute(&order[bounds[b]..bounds[b + 1]], window)
            })
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))?;
        // Live: the chunks reached now, and those reached last time, whose values must
        // be cleared.
        self.reached.resize(sums.live.len(), false);
        sums.live.copy_from_slice(&self.reached);
        self.reached.fill(false);
        for &(lo, hi) in block_ranges.iter().filter(|(lo, hi)| hi > lo) {
            for c in lo / NODE_CHUNK..=(hi - 1) / NODE_CHUNK {
                self.reached[c] = true;
                sums.live[c] = true;
            }
        }
        let windows = &self.windows[..blocks];
        match (momentum_only, nonnegative) {
            (false, false) => merge::<D, NodeSums<D, 1>>(sums, windows),
            (false, true) => merge::<D, NodeSums<D, 0>>(sums, windows),
            (true, false) => merge::<D, MomentumSums<D, 1>>(sums, windows),
            (true, true) => merge::<D, MomentumSums<D, 0>>(sums, windows),
        }
        Ok(())
    }
}

/// Sums the windows' records of kind `R` into `sums`, in parallel over the chunks of
/// nodes; each node adds the windows covering it in block order.
fn merge<const D: usize, R: Record<D>>(sums: NodalSums<'_, D>, windows: &[Window<D>]) {
    let live: &[bool] = sums.live;
    if sums.momentum_only {
        // The stiffness and force arrays may be empty (the mass matrix's scatter).
        sums.mass
            .par_chunks_mut(NODE_CHUNK)
            .zip(sums.abs_mass.par_chunks_mut(NODE_CHUNK))
            .zip(sums.momentum.par_chunks_mut(NODE_CHUNK))
            .enumerate()
            .for_each(|(c, ((mass, abs_mass), momentum))| {
                let chunk = ChunkSums {
                    mass,
                    abs_mass,
                    stiffness: &mut [],
                    momentum,
                    force: &mut [],
                };
                merge_chunk::<D, R>(c, chunk, live, windows);
            });
        return;
    }
    sums.mass
        .par_chunks_mut(NODE_CHUNK)
        .zip(sums.abs_mass.par_chunks_mut(NODE_CHUNK))
        .zip(sums.stiffness.par_chunks_mut(NODE_CHUNK))
        .zip(sums.momentum.par_chunks_mut(NODE_CHUNK))
        .zip(sums.force.par_chunks_mut(NODE_CHUNK))
        .enumerate()
        .for_each(|(c, ((((mass, abs_mass), stiffness), momentum), force))| {
            let chunk = ChunkSums {
                mass,
                abs_mass,
                stiffness,
                momentum,
                force,
            };
            merge_chunk::<D, R>(c, chunk, live, windows);
        });
}

/// Chunk `c` of the merge: cleared and summed if live, skipped otherwise.
#[inline(always)]
fn merge_chunk<const D: usize, R: Record<D>>(
    c: usize,
    mut chunk: ChunkSums<'_, D>,
    live: &[bool],
    windows: &[Window<D>],
) {
    if !live[c] {
        return;
    }
    R::clear(&mut chunk);
    let start = c * NODE_CHUNK;
    let end = start + chunk.mass.len();
    for_each_covered(windows, start, end, |j, k, w| {
        R::records(w)[k].add_into(&mut chunk, j);
    });
}

/// Calls `add(j, k, window)` for every node `start + j` of `start..end` a window covers
/// (`k` its index in the window), window by window in block order, so that each node's
/// sum runs in the same order on any number of threads.
#[inline(always)]
fn for_each_covered<const D: usize>(
    windows: &[Window<D>],
    start: usize,
    end: usize,
    mut add: impl FnMut(usize, usize, &Window<D>),
) {
    for w in windows {
        for node in w.lo.max(start)..w.hi().min(end) {
            add(node - start, node - w.lo, w);
        }
    }
}
