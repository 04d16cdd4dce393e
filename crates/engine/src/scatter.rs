//! The P2G scatter without per-thread copies of the grid.
//!
//! Particles are ordered by the lowest node of their stencil (ties by index), so that
//! consecutive particles touch neighbouring nodes, and cut into blocks of [`BLOCK`]
//! particles. Each block scatters into its own *window*: dense arrays over the node
//! indices `lo..hi` its particles touch, or, where the kernel numbers its nodes on a
//! lattice ([`Lattice`]), over the box of the lattice they touch. Blocks run in parallel;
//! then every node sums the windows that cover it in block order, in parallel over
//! chunks of nodes.
//!
//! Why boxes: in 3D a block of particles spans a few planes of cells, and the index range
//! of those planes holds every node of them, most of which no particle of the block
//! reaches (in the 64³ fluid box, 17,000 nodes per window against some 4,000 in the
//! block's box). Clearing and merging the range moved that much memory every step.
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

impl<const D: usize> ChunkSums<'_, D> {
    /// The nodes `range` of the chunk (the arrays a layout leaves empty stay empty).
    fn part(&mut self, range: std::ops::Range<usize>) -> ChunkSums<'_, D> {
        fn slice<'s, T>(a: &'s mut [T], range: &std::ops::Range<usize>) -> &'s mut [T] {
            if a.is_empty() {
                a
            } else {
                &mut a[range.clone()]
            }
        }
        ChunkSums {
            mass: slice(self.mass, &range),
            abs_mass: slice(self.abs_mass, &range),
            stiffness: slice(self.stiffness, &range),
            momentum: slice(self.momentum, &range),
            force: slice(self.force, &range),
        }
    }
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

/// A node lattice, numbered axis 0 fastest ([`umls_transfer::Kernel::node_lattice`]),
/// whose boxes the windows are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Lattice<const D: usize> {
    counts: [usize; D],
    strides: [usize; D],
    /// 1 / counts, for [`Self::coordinates`].
    inverse: [f64; D],
}

impl<const D: usize> Lattice<D> {
    /// The lattice of `counts` nodes per axis.
    pub fn new(counts: [usize; D]) -> Self {
        Self {
            counts,
            strides: std::array::from_fn(|k| counts[..k].iter().product()),
            inverse: counts.map(|n| 1.0 / n as f64),
        }
    }

    /// The coordinates of node `node`. Divided through the reciprocal and corrected, as
    /// integer division by a count known only at run time took 2 % of a B-spline step:
    /// for quotients below 2⁵⁰ (a lattice of u32 node indices) the product is within 1
    /// of the quotient, which the correction settles.
    #[inline]
    fn coordinates(&self, node: usize) -> [usize; D] {
        let mut rest = node;
        std::array::from_fn(|k| {
            if k + 1 == D {
                return rest;
            }
            let n = self.counts[k];
            let mut q = (rest as f64 * self.inverse[k]) as usize;
            if q * n > rest {
                q -= 1;
            } else if (q + 1) * n <= rest {
                q += 1;
            }
            let c = rest - q * n;
            rest = q;
            c
        })
    }

    /// The index of the node at `coordinates`.
    fn index(&self, coordinates: &[usize; D]) -> usize {
        (0..D).map(|k| coordinates[k] * self.strides[k]).sum()
    }
}

/// A window's box of the lattice: its lowest node's coordinates, its nodes per axis, the
/// strides of its records (axis 0 fastest) and those of the lattice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct BoxShape<const D: usize> {
    corner: [usize; D],
    extent: [usize; D],
    strides: [usize; D],
    lattice_strides: [usize; D],
}

impl<const D: usize> BoxShape<D> {
    /// The box from `corner` to `top` (inclusive) of `lattice`.
    fn new(lattice: &Lattice<D>, corner: [usize; D], top: [usize; D]) -> Self {
        let extent: [usize; D] = std::array::from_fn(|k| top[k] + 1 - corner[k]);
        Self {
            corner,
            extent,
            strides: std::array::from_fn(|k| extent[..k].iter().product()),
            lattice_strides: lattice.strides,
        }
    }

    fn nodes(&self) -> usize {
        self.extent.iter().product()
    }
}

/// The nodes one block touches: the index range `lo..hi`, and within it the box `shape`
/// where the scatter has a lattice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Extent<const D: usize> {
    lo: usize,
    hi: usize,
    shape: Option<BoxShape<D>>,
}

impl<const D: usize> Extent<D> {
    /// The records a window over it holds.
    fn nodes(&self) -> usize {
        self.shape.map_or(self.hi - self.lo, |b| b.nodes())
    }

    /// Calls `f(node, record, len)` for every run of consecutive nodes of the extent
    /// within `start..end`, in increasing node order: a box's runs are its rows along
    /// axis 0, a range is one run.
    #[inline]
    // The axis index runs over the digits and two stride arrays at once.
    #[allow(clippy::needless_range_loop)]
    fn for_each_run(&self, start: usize, end: usize, mut f: impl FnMut(usize, usize, usize)) {
        let Some(b) = &self.shape else {
            let (a, z) = (self.lo.max(start), self.hi.min(end));
            if a < z {
                f(a, a - self.lo, z - a);
            }
            return;
        };
        let rows: usize = b.extent[1..].iter().product();
        let mut digits = [0usize; D];
        for _ in 0..rows {
            let (mut node, mut record) = (self.lo, 0);
            for k in 1..D {
                node += digits[k] * b.lattice_strides[k];
                record += digits[k] * b.strides[k];
            }
            if node >= end {
                return;
            }
            let (a, z) = (node.max(start), (node + b.extent[0]).min(end));
            if a < z {
                f(a, record + (a - node), z - a);
            }
            for k in 1..D {
                digits[k] += 1;
                if digits[k] < b.extent[k] {
                    break;
                }
                digits[k] = 0;
            }
        }
    }
}

/// One block's share of the nodal sums, over the nodes of its [`Extent`], in the records
/// of the scatter's layout ([`NodalSums::momentum_only`], [`NodalSums::nonnegative`]);
/// the other vectors are empty.
#[derive(Debug, Clone)]
pub(crate) struct Window<const D: usize> {
    extent: Extent<D>,
    sums: Vec<NodeSums<D, 1>>,
    nonnegative_sums: Vec<NodeSums<D, 0>>,
    momentum_sums: Vec<MomentumSums<D, 1>>,
    nonnegative_momentum_sums: Vec<MomentumSums<D, 0>>,
}

impl<const D: usize> Default for Window<D> {
    fn default() -> Self {
        Self {
            extent: Extent {
                lo: 0,
                hi: 0,
                shape: None,
            },
            sums: Vec::new(),
            nonnegative_sums: Vec::new(),
            momentum_sums: Vec::new(),
            nonnegative_momentum_sums: Vec::new(),
        }
    }
}

impl<const D: usize> Window<D> {
    fn reset(&mut self, extent: Extent<D>, momentum_only: bool, nonnegative: bool) {
        let len = extent.nodes();
        self.extent = extent;
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

    /// Where a tensor-product stencil whose first node is `first`, at `corner` of the
    /// lattice, with the lattice's `strides`, falls among the records: its first node's
    /// record and the records' strides per axis.
    #[inline(always)]
    pub fn place(
        &self,
        first: usize,
        corner: &[usize; D],
        strides: &[usize; D],
    ) -> (usize, [usize; D]) {
        match &self.extent.shape {
            Some(b) => (
                (0..D)
                    .map(|k| (corner[k] - b.corner[k]) * b.strides[k])
                    .sum(),
                b.strides,
            ),
            None => (first - self.extent.lo, *strides),
        }
    }

    /// Bytes of the records.
    fn bytes(&self) -> usize {
        use crate::memory::bytes;
        bytes(&self.sums)
            + bytes(&self.nonnegative_sums)
            + bytes(&self.momentum_sums)
            + bytes(&self.nonnegative_momentum_sums)
    }

    /// The record of `node` in a range window (a box window's records come from
    /// [`Self::place`]).
    #[inline(always)]
    pub fn record(&self, node: usize) -> usize {
        debug_assert!(self.extent.shape.is_none(), "a box window takes records");
        node - self.extent.lo
    }

    /// Adds one stencil entry's contributions to record `k` ([`Self::record`],
    /// [`Self::place`]), in a window of a full scatter ([`NodalSums::momentum_only`]
    /// false); `A` is 0 where [`NodalSums::nonnegative`] holds (`abs_mass` is then not
    /// summed), else 1.
    #[inline(always)]
    pub fn add<const A: usize>(
        &mut self,
        k: usize,
        mass: f64,
        abs_mass: f64,
        stiffness: f64,
        momentum: SVector<f64, D>,
        force: SVector<f64, D>,
    ) {
        if A == 0 {
            self.nonnegative_sums[k].add(mass, abs_mass, stiffness, momentum, force);
        } else {
            self.sums[k].add(mass, abs_mass, stiffness, momentum, force);
        }
    }

    /// Adds one stencil entry's mass and momentum to record `k`, in a window of a
    /// momentum-only scatter (MLS-MPM, whose momentum carries the force impulse: no
    /// separate force or stiffness); `A` as for [`Self::add`].
    #[inline(always)]
    pub fn add_momentum<const A: usize>(
        &mut self,
        k: usize,
        mass: f64,
        abs_mass: f64,
        momentum: SVector<f64, D>,
    ) {
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
    /// Per segment of [`LIVE_SEGMENT`] nodes: whether it may hold non-zero values this
    /// step (a block's window reaches it now, or reached it in the last step, whose
    /// values must be cleared). Written by [`Scatter::scatter`].
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

/// Nodes per segment of the grid's live flags: fine enough that a row of a box window
/// (the body's width along axis 0) marks little more than itself live, so that the
/// merge and the grid update skip the empty rest of the grid's rows.
pub(crate) const LIVE_SEGMENT: usize = 16;

/// Live flags per chunk of [`NODE_CHUNK`] nodes.
pub(crate) const SEGMENTS_PER_CHUNK: usize = NODE_CHUNK / LIVE_SEGMENT;

/// The live flags `nodes` nodes need.
pub(crate) fn live_segments(nodes: usize) -> usize {
    nodes.div_ceil(LIVE_SEGMENT)
}

/// The node ranges of a chunk's live segments, given the chunk's flags (`live`, one per
/// segment) and its `nodes` (the last chunk may end inside a segment), counted from the
/// chunk's first node, in increasing order.
pub(crate) fn live_ranges(
    live: &[bool],
    nodes: usize,
) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    live.iter()
        .enumerate()
        .filter(|(_, l)| **l)
        .map(move |(s, _)| s * LIVE_SEGMENT..nodes.min((s + 1) * LIVE_SEGMENT))
}

/// The particle order, the blocks and their windows, reused from step to step.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scatter<const D: usize> {
    /// Per particle: the lowest node of its stencil, its id (the tie-break) and its slot.
    keys: Vec<(u32, u32, u32)>,
    order: Vec<u32>,
    /// Start of each block in `order` (and its end, last).
    bounds: Vec<usize>,
    /// The nodes each block touches.
    ranges: Vec<Extent<D>>,
    windows: Vec<Window<D>>,
    /// Segments of [`LIVE_SEGMENT`] nodes the last scatter's windows reached.
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

    /// The last scatter's particle order (empty before the first).
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// Takes the last scatter's order, for storing the particles in it
    /// ([`Self::restore_sorted_order`] gives the buffer back).
    pub fn take_order(&mut self) -> Vec<u32> {
        std::mem::take(&mut self.order)
    }

    /// Gives back the buffer of [`Self::take_order`] once the particles are stored in
    /// that order, which is then the identity.
    pub fn restore_sorted_order(&mut self, mut order: Vec<u32>) {
        let n = order.len() as u32;
        order.clear();
        order.extend(0..n);
        self.order = order;
    }

    /// Orders the particles by the lowest node of their stencil, ties by their ids
    /// (`ids[p]`, or p beyond them: the index a particle had before any sort, so that the
    /// order does not depend on where the particles are stored), and cuts them into
    /// blocks; `ranges` holds each particle's lowest and highest node, which on a
    /// `lattice` are the corners of the box its stencil covers.
    fn plan(
        &mut self,
        ranges: &[(u32, u32)],
        ids: &[u32],
        nodes: usize,
        lattice: Option<&Lattice<D>>,
    ) {
        let particles = ranges.len();
        let key = |p: u32| {
            (
                ranges[p as usize].0,
                crate::simulation::id_in(ids, p as usize) as u32,
                p,
            )
        };
        self.keys.clear();
        if self.order.len() == particles {
            // In the last step's order, which particles that moved a little keep nearly
            // sorted: the merge sort below finds the sorted runs and has little to do.
            self.keys.par_extend(self.order.par_iter().map(|&p| key(p)));
        } else {
            self.keys
                .par_extend((0..particles as u32).into_par_iter().map(key));
        }
        // Keys are unique (the id breaks ties), so the order they end in depends on the
        // keys alone, not on where the sort started.
        self.keys.par_sort();
        self.order.clear();
        self.order.extend(self.keys.iter().map(|&(_, _, p)| p));
        let order = &self.order;
        let range = |b: &[usize]| {
            let block = order[b[0]..b[1]].iter().map(|&p| ranges[p as usize]);
            if let Some(lattice) = lattice {
                let (corner, top) = block.fold(
                    ([usize::MAX; D], [0; D]),
                    |(mut corner, mut top), (a, z)| {
                        let (a, z) = (
                            lattice.coordinates(a as usize),
                            lattice.coordinates(z as usize),
                        );
                        for k in 0..D {
                            corner[k] = corner[k].min(a[k]);
                            top[k] = top[k].max(z[k]);
                        }
                        (corner, top)
                    },
                );
                if b[0] == b[1] {
                    return Extent {
                        lo: 0,
                        hi: 0,
                        shape: None,
                    };
                }
                return Extent {
                    lo: lattice.index(&corner),
                    hi: lattice.index(&top) + 1,
                    shape: Some(BoxShape::new(lattice, corner, top)),
                };
            }
            let (lo, hi) = block.fold((u32::MAX, 0u32), |(lo, hi), (a, z)| {
                (lo.min(a), hi.max(z + 1))
            });
            Extent {
                lo: lo as usize,
                hi: (hi as usize).max(lo as usize),
                shape: None,
            }
        };
        let mut size = BLOCK;
        loop {
            self.bounds.clear();
            self.bounds.extend((0..particles).step_by(size));
            self.bounds.push(particles);
            self.ranges.clear();
            self.ranges
                .par_extend(self.bounds.par_windows(2).map(range));
            let span: usize = self.ranges.iter().map(Extent::nodes).sum();
            if span <= MAX_SPAN * nodes || size >= particles {
                break;
            }
            size *= 2;
        }
    }

    /// Scatters the particles through `contribute(block, window)`, where `block` lists
    /// one block's particles in order, and sums the windows into `sums` (every node of a
    /// live chunk written, nodes no particle touches with zero; chunks neither reached
    /// now nor in the last step are zero already and are skipped; the same per segment
    /// of a chunk). `ranges` holds each particle's lowest and highest stencil node, `ids`
    /// the particles' ids ([`Self::plan`]; empty: their slots). Given the kernel's
    /// `lattice`, the windows are boxes of it, and `contribute` must add through
    /// [`Window::place`]'s records (tensor-product stencils). Among failing blocks the
    /// lowest particle index wins, whatever the thread count; on failure `sums` is left
    /// as it was.
    pub fn scatter<F, E>(
        &mut self,
        ranges: &[(u32, u32)],
        ids: &[u32],
        sums: NodalSums<'_, D>,
        lattice: Option<&Lattice<D>>,
        contribute: F,
    ) -> Result<(), (usize, E)>
    where
        F: Fn(&[u32], &mut Window<D>) -> Result<(), (usize, E)> + Sync,
        E: Send,
    {
        let nodes = sums.mass.len();
        let (momentum_only, nonnegative) = (sums.momentum_only, sums.nonnegative);
        self.plan(ranges, ids, nodes, lattice);
        let blocks = self.bounds.len() - 1;
        self.windows.resize_with(blocks, Window::default);
        let (order, bounds, block_ranges) = (&self.order, &self.bounds, &self.ranges);
        self.windows
            .par_iter_mut()
            .enumerate()
            .map(|(b, window)| {
                window.reset(block_ranges[b], momentum_only, nonnegative);
                contribute(&order[bounds[b]..bounds[b + 1]], window)
            })
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))?;
        // Live: the chunks reached now, and those reached last time, whose values must
        // be cleared.
        self.reached.resize(sums.live.len(), false);
        sums.live.copy_from_slice(&self.reached);
        self.reached.fill(false);
        for extent in block_ranges.iter() {
            extent.for_each_run(0, nodes, |node, _, len| {
                for c in node / LIVE_SEGMENT..=(node + len - 1) / LIVE_SEGMENT {
                    self.reached[c] = true;
                    sums.live[c] = true;
                }
            });
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

/// Chunk `c` of the merge: its live segments cleared, then summed (windows reach live
/// segments only); skipped if none is live.
#[inline(always)]
fn merge_chunk<const D: usize, R: Record<D>>(
    c: usize,
    mut chunk: ChunkSums<'_, D>,
    live: &[bool],
    windows: &[Window<D>],
) {
    let live = &live[c * SEGMENTS_PER_CHUNK..live.len().min((c + 1) * SEGMENTS_PER_CHUNK)];
    if !live.iter().any(|&l| l) {
        return;
    }
    for range in live_ranges(live, chunk.mass.len()) {
        R::clear(&mut chunk.part(range));
    }
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
        if w.extent.hi <= start || w.extent.lo >= end {
            continue;
        }
        w.extent.for_each_run(start, end, |node, record, len| {
            for i in 0..len {
                add(node - start + i, record + i, w);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A xorshift stream, for reproducible pseudo-random cases.
    fn stream(mut seed: u64) -> impl FnMut() -> u64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        }
    }

    /// The reciprocal division gives every node's coordinates exactly: the first and
    /// last nodes, random ones, and the quotients' edges, on awkward counts and on a 2D
    /// lattice of nearly 2³² nodes.
    #[test]
    fn lattice_coordinates_invert_the_numbering() {
        let mut next = stream(11);
        let cases: [[usize; 3]; 4] = [[65, 65, 65], [1, 7, 3], [4097, 3, 1], [69, 1, 2]];
        for counts in cases {
            let lattice = Lattice::new(counts);
            let nodes: usize = counts.iter().product();
            let edges = (1..nodes).step_by(counts[0]).flat_map(|n| [n - 1, n]);
            let random = (0..2000).map(|_| next() as usize % nodes);
            for node in [0, nodes - 1].into_iter().chain(edges).chain(random) {
                let c = lattice.coordinates(node);
                assert!((0..3).all(|k| c[k] < counts[k]), "{counts:?} {node}: {c:?}");
                assert_eq!(lattice.index(&c), node, "{counts:?}: {c:?}");
            }
        }
        let lattice = Lattice::new([65_521, 65_537]);
        let nodes = 65_521 * 65_537;
        for node in (0..4000)
            .map(|_| next() as usize % nodes)
            .chain([nodes - 1, 65_520, 65_521])
        {
            let c = lattice.coordinates(node);
            assert!(c[0] < 65_521 && c[1] < 65_537, "{node}: {c:?}");
            assert_eq!(lattice.index(&c), node);
        }
    }

    /// Random 3×3×3 stencils on a 3D lattice, scattered through box windows and through
    /// range windows over two steps (the second elsewhere, so that the first's nodes must
    /// be cleared): the same sums bit for bit, with both record layouts, equal to a serial
    /// sum to round-off; nodes no stencil reaches hold zero, and only live segments
    /// hold anything.
    #[test]
    fn box_windows_sum_what_range_windows_sum() {
        let counts = [23, 17, 19];
        let lattice = Lattice::new(counts);
        let nodes: usize = counts.iter().product();
        let mut next = stream(5);
        for momentum_only in [false, true] {
            let mut scatters = [Scatter::<3>::default(), Scatter::<3>::default()];
            let mut grids: Vec<[Vec<f64>; 2]> = vec![Default::default(), Default::default()];
            let mut moms: Vec<Vec<SVector<f64, 3>>> = vec![Vec::new(), Vec::new()];
            let mut lives = vec![vec![false; live_segments(nodes)]; 2];
            let mut forces = vec![vec![SVector::zeros(); nodes]; 2];
            let mut stiffs = vec![vec![0.0; nodes]; 2];
            for g in 0..2 {
                grids[g] = [vec![0.0; nodes], vec![0.0; nodes]];
                moms[g] = vec![SVector::zeros(); nodes];
            }
            for step in 0..2 {
                // Particles in one half of the lattice per step, 9000 of them (three
                // blocks).
                let half = if step == 0 { 0 } else { counts[2] / 2 };
                let corners: Vec<[usize; 3]> = (0..9000)
                    .map(|_| {
                        [
                            next() as usize % (counts[0] - 2),
                            next() as usize % (counts[1] - 2),
                            half + next() as usize % (counts[2] / 2 - 2),
                        ]
                    })
                    .collect();
                let values: Vec<f64> = (0..corners.len() * 27)
                    .map(|_| (next() % 1000) as f64 / 999.0)
                    .collect();
                let ranges: Vec<(u32, u32)> = corners
                    .iter()
                    .map(|c| {
                        let top = [c[0] + 2, c[1] + 2, c[2] + 2];
                        (lattice.index(c) as u32, lattice.index(&top) as u32)
                    })
                    .collect();
                for (g, boxed) in [(0, false), (1, true)] {
                    let [mass, abs_mass] = &mut grids[g];
                    let sums = NodalSums {
                        mass,
                        abs_mass,
                        stiffness: &mut stiffs[g],
                        momentum: &mut moms[g],
                        force: &mut forces[g],
                        live: &mut lives[g],
                        momentum_only,
                        nonnegative: true,
                    };
                    let on = boxed.then_some(&lattice);
                    scatters[g]
                        .scatter(&ranges, &[], sums, on, |block, window| {
                            for &p in block {
                                let c = corners[p as usize];
                                let first = lattice.index(&c);
                                let (record, strides) = window.place(first, &c, &lattice.strides);
                                for e in 0..27 {
                                    let a = [e % 3, (e / 3) % 3, e / 9];
                                    let n = values[p as usize * 27 + e];
                                    let node = first
                                        + (0..3).map(|k| a[k] * lattice.strides[k]).sum::<usize>();
                                    let k =
                                        record + (0..3).map(|k| a[k] * strides[k]).sum::<usize>();
                                    let v = SVector::from([n, 2.0 * n, -n]);
                                    match (momentum_only, boxed) {
                                        (true, true) => window.add_momentum::<0>(k, n, n, v),
                                        (true, false) => {
                                            window.add_momentum::<0>(window.record(node), n, n, v)
                                        }
                                        (false, true) => window.add::<0>(k, n, n, n * n, v, -v),
                                        (false, false) => {
                                            window.add::<0>(window.record(node), n, n, n * n, v, -v)
                                        }
                                    }
                                }
                            }
                            Ok::<(), (usize, ())>(())
                        })
                        .unwrap();
                }
                let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&grids[0][0]), bits(&grids[1][0]), "mass, step {step}");
                assert_eq!(moms[0], moms[1], "momentum, step {step}");
                assert_eq!(bits(&stiffs[0]), bits(&stiffs[1]), "stiffness, step {step}");
                assert_eq!(forces[0], forces[1], "force, step {step}");
                // A serial sum: the same to round-off; zero where nothing reaches.
                let mut serial = vec![0.0; nodes];
                for (p, c) in corners.iter().enumerate() {
                    for e in 0..27 {
                        let a = [c[0] + e % 3, c[1] + (e / 3) % 3, c[2] + e / 9];
                        serial[lattice.index(&a)] += values[p * 27 + e];
                    }
                }
                for (node, (s, m)) in serial.iter().zip(&grids[1][0]).enumerate() {
                    assert!(
                        (s - m).abs() <= 1e-12 * s.abs(),
                        "node {node}: {m} against {s}"
                    );
                    if *m != 0.0 {
                        assert!(lives[1][node / LIVE_SEGMENT], "node {node} not live");
                    }
                }
            }
        }
    }
}
