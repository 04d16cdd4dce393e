//! Stage 1 of the step: every particle's stencil, stored for the step as entries or as
//! the kernel's factors, or recomputed where P2G and G2P use it ([`StencilStorage`]),
//! with each particle's node range, which orders the P2G scatter.
//!
//! Computed in parallel over fixed chunks, so the result does not depend on the number
//! of threads; the buffers are reused from step to step.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;
use umls_transfer::{FactorLayout, Kernel, KernelError, Stencil, node_range};

use crate::parallel::lowest_failure;
use crate::settings::StencilStorage;

/// Particles per parallel work item; fixed so that the work split, and hence every
/// result, is the same for any number of threads.
pub(crate) const CHUNK: usize = 512;

/// The stored stencils of one chunk of [`CHUNK`] particles: particle k of the chunk owns
/// entries `offsets[k]..offsets[k + 1]` (of the entry arrays, or of `entry_factors`) and
/// per-particle factors `k·n..(k + 1)·n` with n = [`FactorLayout::per_particle`]. Each
/// chunk keeps its vectors between steps, so once they have grown a step allocates
/// nothing, and no serial pass copies chunks into one array.
#[derive(Debug, Clone, Default)]
struct ChunkStencils<const D: usize> {
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    values: Vec<f64>,
    gradients: Vec<SVector<f64, D>>,
    particle_factors: Vec<f64>,
    entry_factors: Vec<f64>,
    /// Second moments D_p = Σ N_i r_i r_iᵀ of the chunk's stored stencils, when asked
    /// for ([`Stencils::compute`]).
    moments: Vec<SMatrix<f64, D, D>>,
    /// ξ̄_p = Σ N_i ξ_i of the chunk's stored stencils under the kernel's integration
    /// correction ξ, when it has one ([`Stencils::compute`]).
    correction_means: Vec<SVector<f64, D>>,
    /// The kernel writes here before the entries are appended (or only the range read).
    scratch: Stencil<D>,
}

impl<const D: usize> ChunkStencils<D> {
    /// Empties the arrays for a step of `mode` (the per-particle factors are sized by
    /// `compute` instead), giving back those it does not use (what an earlier step of
    /// another mode held).
    fn clear_for(&mut self, mode: Mode) {
        let entries = matches!(mode, Mode::Entries | Mode::EntriesWithMoments);
        let factors = matches!(mode, Mode::Factored(_));
        clear_or_release(&mut self.nodes, entries);
        clear_or_release(&mut self.values, entries);
        clear_or_release(&mut self.gradients, entries);
        // The per-particle factors keep their length: `compute` resizes them to the chunk,
        // and every slot is written before it is read, so they need no zero-fill a step.
        if !factors {
            self.particle_factors = Vec::new();
        }
        clear_or_release(&mut self.entry_factors, factors);
        clear_or_release(&mut self.offsets, mode != Mode::Recompute);
        clear_or_release(&mut self.moments, mode == Mode::EntriesWithMoments);
        // Cleared here, filled by `compute` when the kernel has a correction.
        self.correction_means.clear();
    }
}

/// Empties `v`, keeping its storage if it is `used`.
fn clear_or_release<T>(v: &mut Vec<T>, used: bool) {
    if used {
        v.clear();
    } else {
        *v = Vec::new();
    }
}

/// How this step's stencils are kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum Mode {
    /// Node, N and ∇N of every entry.
    #[default]
    Entries,
    /// The same, and each particle's second moment D_p, which the affine transfers read
    /// twice a step with a kernel whose D_p varies (P2G's limiter, G2P's C_p): summed
    /// once here, while the entries and their offsets are in cache, instead of in two
    /// passes over the stored entries that fetch every node's position again.
    EntriesWithMoments,
    /// The kernel's factors ([`Kernel::factor_stencil`]).
    Factored(FactorLayout),
    /// Nothing but the node ranges: evaluated where used.
    Recompute,
}

/// One particle's stencil: node indices, shape-function values and gradients, and the
/// node offsets x_i − x_p where the kernel gave them (recomputed stencils; stored ones
/// leave them out, which saves 8·D bytes per entry).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParticleStencil<'a, const D: usize> {
    pub nodes: &'a [u32],
    pub values: &'a [f64],
    pub gradients: &'a [SVector<f64, D>],
    offsets: &'a [SVector<f64, D>],
}

impl<'a, const D: usize> ParticleStencil<'a, D> {
    /// The entries a kernel evaluated into `st`, offsets included.
    #[inline]
    fn of(st: &'a Stencil<D>) -> Self {
        Self {
            nodes: st.nodes(),
            values: st.values(),
            gradients: st.gradients(),
            offsets: st.offsets(),
        }
    }

    /// Number of nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// x_i − x_p for entry `e` of the particle at `x`.
    #[inline]
    pub fn offset<K: Kernel<D>>(
        &self,
        e: usize,
        kernel: &K,
        x: &SVector<f64, D>,
    ) -> SVector<f64, D> {
        match self.offsets.get(e) {
            Some(r) => *r,
            None => kernel.node_position(self.nodes[e] as usize) - x,
        }
    }
}

/// The second moment D_p = Σ N_i r_i r_iᵀ of a particle's stencil at `x`, summed in
/// entry order (P2G's affine limiter and G2P's C_p both use it, and must agree bit for
/// bit).
#[inline]
pub(crate) fn second_moment<const D: usize, K: Kernel<D>>(
    st: &ParticleStencil<'_, D>,
    kernel: &K,
    x: &SVector<f64, D>,
) -> SMatrix<f64, D, D> {
    let mut d = SMatrix::<f64, D, D>::zeros();
    for e in 0..st.len() {
        let r = st.offset(e, kernel, x);
        d += r * r.transpose() * st.values[e];
    }
    d
}

/// ξ̄_p = Σ_i N_i ξ_i over a particle's stencil, the mean the integration correction
/// subtracts ([`Kernel::force_gradient_correction`]), summed in entry order wherever it
/// is taken (the stencil stage for stored entries, P2G otherwise: the same bits).
#[inline]
pub(crate) fn correction_mean<const D: usize>(
    st: &ParticleStencil<'_, D>,
    xi: &[SVector<f64, D>],
) -> SVector<f64, D> {
    let mut mean = SVector::<f64, D>::zeros();
    for e in 0..st.len() {
        mean += xi[st.nodes[e] as usize] * st.values[e];
    }
    mean
}

/// What a transfer does with one stencil entry ([`Stencils::visit`]); implementors
/// mark `entry` `#[inline(always)]`, it runs 9 to 64 times per particle.
pub(crate) trait EntrySink<const D: usize> {
    /// Node `node` with N, ∇N and the offset x_node − x_p.
    fn entry(&mut self, node: u32, n: f64, gradient: &SVector<f64, D>, offset: &SVector<f64, D>);
}

/// The stencils of all particles (stored by chunk as entries or factors, or to be
/// recomputed) and their node ranges.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stencils<const D: usize> {
    mode: Mode,
    chunks: Vec<ChunkStencils<D>>,
    ranges: Vec<(u32, u32)>,
}

impl<const D: usize> Stencils<D> {
    /// Locates every particle (updating its cache) and stores its stencil (entries or
    /// factors), or with recomputed stencils only its node range. With `moments`, stored
    /// entries come with each particle's second moment D_p
    /// ([`Self::stored_second_moment`]), and with `corrected` under a kernel's
    /// integration correction with each particle's ξ̄_p ([`Self::stored_correction_mean`];
    /// MLS-MPM, whose force gradient is not the kernel's, does not read it). Among
    /// failures the lowest particle index is reported, whatever the thread count.
    pub fn compute<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        storage: StencilStorage,
        (moments, corrected): (bool, bool),
        positions: &[SVector<f64, D>],
        caches: &mut [K::Cache],
    ) -> Result<(), (usize, KernelError)> {
        self.mode = match storage {
            StencilStorage::KernelChoice if kernel.recompute_stencils() => Mode::Recompute,
            StencilStorage::KernelChoice | StencilStorage::Store => Mode::Entries,
            StencilStorage::Factored => {
                kernel.factor_layout().map_or(Mode::Entries, Mode::Factored)
            }
            StencilStorage::Recompute => Mode::Recompute,
        };
        if self.mode == Mode::Entries && moments {
            self.mode = Mode::EntriesWithMoments;
        }
        let mode = self.mode;
        let correction = kernel.force_gradient_correction().filter(|_| corrected);
        self.chunks
            .resize_with(positions.len().div_ceil(CHUNK), ChunkStencils::default);
        self.ranges.resize(positions.len(), (0, 0));
        self.chunks
            .par_iter_mut()
            .zip(positions.par_chunks(CHUNK))
            .zip(caches.par_chunks_mut(CHUNK))
            .zip(self.ranges.par_chunks_mut(CHUNK))
            .enumerate()
            .map(
                |(c, (((local, xs), cs), ranges))| -> Result<(), (usize, KernelError)> {
                    local.clear_for(mode);
                    if let Mode::Factored(layout) = mode {
                        local
                            .particle_factors
                            .resize(xs.len() * layout.per_particle, 0.0);
                    }
                    let ChunkStencils {
                        offsets,
                        nodes,
                        values,
                        gradients,
                        particle_factors,
                        entry_factors,
                        moments,
                        correction_means,
                        scratch: st,
                    } = local;
                    for (i, ((x, cache), range)) in
                        xs.iter().zip(cs.iter_mut()).zip(ranges).enumerate()
                    {
                        let fail = |e| (c * CHUNK + i, e);
                        match mode {
                            Mode::Recompute => {
                                *range = kernel.node_range(x, cache, st).map_err(fail)?;
                            }
                            Mode::Factored(layout) => {
                                let n = layout.per_particle;
                                offsets.push(entry_factors.len());
                                *range = kernel
                                    .factor_stencil(
                                        x,
                                        cache,
                                        st,
                                        &mut particle_factors[i * n..(i + 1) * n],
                                        entry_factors,
                                    )
                                    .map_err(fail)?;
                            }
                            Mode::Entries | Mode::EntriesWithMoments => {
                                let start = nodes.len();
                                kernel
                                    .append_stencil(x, cache, st, nodes, values, gradients)
                                    .map_err(fail)?;
                                offsets.push(start);
                                // Read back from the arrays' ends, still in cache; the
                                // offsets are node_position − x, as P2G and G2P take
                                // them for stored entries.
                                let stored = ParticleStencil {
                                    nodes: &nodes[start..],
                                    values: &values[start..],
                                    gradients: &gradients[start..],
                                    offsets: &[],
                                };
                                *range = node_range(stored.nodes).unwrap_or((0, 0));
                                if mode == Mode::EntriesWithMoments {
                                    moments.push(second_moment(&stored, kernel, x));
                                }
                                if let Some(xi) = correction {
                                    correction_means.push(correction_mean(&stored, xi));
                                }
                            }
                        }
                    }
                    match mode {
                        Mode::Factored(_) => offsets.push(entry_factors.len()),
                        Mode::Entries | Mode::EntriesWithMoments => offsets.push(nodes.len()),
                        Mode::Recompute => {}
                    }
                    Ok(())
                },
            )
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))
    }

    /// Bytes of the stored stencils (entries or factors), and of the node ranges.
    pub fn bytes(&self) -> (usize, usize) {
        use crate::memory::bytes;
        let stored = self
            .chunks
            .iter()
            .map(|c| {
                bytes(&c.offsets)
                    + bytes(&c.nodes)
                    + bytes(&c.values)
                    + bytes(&c.gradients)
                    + bytes(&c.particle_factors)
                    + bytes(&c.entry_factors)
                    + bytes(&c.moments)
                    + bytes(&c.correction_means)
            })
            .sum();
        (stored, bytes(&self.ranges))
    }

    /// Particle `p`'s second moment D_p = Σ N_i r_i r_iᵀ, if [`Self::compute`] stored it:
    /// the same bits as [`second_moment`] of the particle's stencil.
    #[inline]
    pub fn stored_second_moment(&self, p: usize) -> Option<&SMatrix<f64, D, D>> {
        if self.mode != Mode::EntriesWithMoments {
            return None;
        }
        Some(&self.chunks[p / CHUNK].moments[p % CHUNK])
    }

    /// Particle `p`'s ξ̄_p under the kernel's integration correction, if [`Self::compute`]
    /// stored it (stored entries of a kernel with a correction): the same bits as
    /// [`correction_mean`] of the particle's stencil.
    #[inline]
    pub fn stored_correction_mean(&self, p: usize) -> Option<&SVector<f64, D>> {
        self.chunks[p / CHUNK].correction_means.get(p % CHUNK)
    }

    /// The smallest and largest node of each particle's stencil.
    pub fn ranges(&self) -> &[(u32, u32)] {
        &self.ranges
    }

    /// The chunk holding particle `p`'s stored stencil, its index there, and its entries'
    /// range there.
    #[inline(always)]
    fn stored_entries(&self, p: usize) -> (&ChunkStencils<D>, usize, std::ops::Range<usize>) {
        let chunk = &self.chunks[p / CHUNK];
        let k = p % CHUNK;
        (chunk, k, chunk.offsets[k]..chunk.offsets[k + 1])
    }

    /// Hands every entry of particle `p`'s factored stencil to `visit`.
    #[inline(always)]
    fn visit_factored<K: Kernel<D>>(
        &self,
        p: usize,
        layout: FactorLayout,
        kernel: &K,
        x: &SVector<f64, D>,
        cache: &K::Cache,
        visit: impl FnMut(u32, f64, &SVector<f64, D>, &SVector<f64, D>),
    ) -> Result<(), (usize, KernelError)> {
        let (chunk, k, range) = self.stored_entries(p);
        let n = layout.per_particle;
        kernel
            .visit_factored(
                x,
                cache,
                &chunk.particle_factors[k * n..(k + 1) * n],
                &chunk.entry_factors[range],
                visit,
            )
            .map_err(|e| (p, e))
    }

    /// Whether the stencils are recomputed where they are used (neither entries nor
    /// factors stored).
    #[inline]
    pub fn recomputed(&self) -> bool {
        self.mode == Mode::Recompute
    }

    /// Whether the stencils are stored as entries ([`Self::visit_entries`] visits them).
    #[inline]
    pub fn stores_entries(&self) -> bool {
        matches!(self.mode, Mode::Entries | Mode::EntriesWithMoments)
    }

    /// [`Self::visit`] of a stored stencil ([`Self::stores_entries`]): no call takes
    /// the sink, so a caller that keeps its sums in a sink of its own for this case gets
    /// them kept in registers (behind [`Self::visit`]'s other modes, whose kernel calls
    /// take the sink's address, the sums lived in memory).
    #[inline(always)]
    pub fn visit_entries<K: Kernel<D>, S: EntrySink<D>>(
        &self,
        p: usize,
        kernel: &K,
        x: &SVector<f64, D>,
        offsets: bool,
        sink: &mut S,
    ) {
        let (chunk, _, range) = self.stored_entries(p);
        for e in range {
            let node = chunk.nodes[e];
            let offset = if offsets {
                kernel.node_position(node as usize) - x
            } else {
                SVector::zeros()
            };
            sink.entry(node, chunk.values[e], &chunk.gradients[e], &offset);
        }
    }

    /// Hands every entry of particle `p`'s stencil to `sink`: the stored one, rebuilt
    /// from its factors, or the kernel's [`Kernel::visit_stencil`] at `x` from `cache`
    /// (same entries, same bits, and for a closed-form kernel no arrays written and read
    /// back). Stored entries have no offsets: with `offsets` they are recomputed from
    /// the node positions, without it zeros are passed.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn visit<K: Kernel<D>, S: EntrySink<D>>(
        &self,
        p: usize,
        kernel: &K,
        x: &SVector<f64, D>,
        cache: &K::Cache,
        scratch: &mut Stencil<D>,
        offsets: bool,
        sink: &mut S,
    ) -> Result<(), (usize, KernelError)> {
        match self.mode {
            Mode::Entries | Mode::EntriesWithMoments => {
                self.visit_entries(p, kernel, x, offsets, sink);
                Ok(())
            }
            Mode::Factored(layout) => {
                // Inlined by force: left to itself the compiler keeps the sink's entry a
                // call per rebuilt entry, with the sums in memory.
                self.visit_factored(
                    p,
                    layout,
                    kernel,
                    x,
                    cache,
                    #[inline(always)]
                    |node, n, gradient, offset| sink.entry(node, n, gradient, offset),
                )
            }
            Mode::Recompute => {
                let mut cache = *cache;
                // Inlined by force: a kernel may instantiate its loop more than once (a
                // B-spline grid once per order), and a closure called from two places
                // otherwise stays a call, its sums out of the registers.
                kernel
                    .visit_stencil(
                        x,
                        &mut cache,
                        scratch,
                        #[inline(always)]
                        |node, n, gradient, offset| sink.entry(node, n, gradient, offset),
                    )
                    .map_err(|e| (p, e))
            }
        }
    }

    /// Calls `f` with particle `p`'s stencil: the stored entries, or the entries rebuilt
    /// from the stored factors or evaluated into `scratch` at `x` from `cache` (the
    /// particle's position and location of this step, which give the same stencil as
    /// [`Self::compute`] evaluated, bit for bit).
    #[inline]
    pub fn with<K: Kernel<D>, R>(
        &self,
        p: usize,
        kernel: &K,
        x: &SVector<f64, D>,
        cache: &K::Cache,
        scratch: &mut Stencil<D>,
        f: impl FnOnce(ParticleStencil<'_, D>) -> R,
    ) -> Result<R, (usize, KernelError)> {
        match self.mode {
            Mode::Entries | Mode::EntriesWithMoments => {
                let (chunk, _, range) = self.stored_entries(p);
                return Ok(f(ParticleStencil {
                    nodes: &chunk.nodes[range.clone()],
                    values: &chunk.values[range.clone()],
                    gradients: &chunk.gradients[range],
                    offsets: &[],
                }));
            }
            Mode::Factored(layout) => {
                scratch.clear();
                self.visit_factored(
                    p,
                    layout,
                    kernel,
                    x,
                    cache,
                    #[inline(always)]
                    |node, n, gradient, offset| scratch.push(node, n, *gradient, *offset),
                )?;
            }
            Mode::Recompute => {
                let mut cache = *cache;
                kernel.stencil(x, &mut cache, scratch).map_err(|e| (p, e))?;
            }
        }
        Ok(f(ParticleStencil::of(scratch)))
    }
}
