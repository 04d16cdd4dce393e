//! Stage 1 of the step: every particle's stencil, either stored for the step or
//! recomputed where P2G and G2P use it ([`StencilStorage`]), with each particle's node
//! range, which orders the P2G scatter.
//!
//! Computed in parallel over fixed chunks, so the result does not depend on the number
//! of threads; the buffers are reused from step to step.

use nalgebra::SVector;
use rayon::prelude::*;
use umls_transfer::{Kernel, KernelError, Stencil};

use crate::parallel::lowest_failure;
use crate::settings::StencilStorage;

/// Particles per parallel work item; fixed so that the work split, and hence every
/// result, is the same for any number of threads.
pub(crate) const CHUNK: usize = 512;

/// The stored stencils of one chunk of [`CHUNK`] particles: particle k of the chunk owns
/// entries `offsets[k]..offsets[k + 1]`. Each chunk keeps its vectors between steps, so
/// once they have grown a step allocates nothing, and no serial pass copies chunks into
/// one array.
#[derive(Debug, Clone, Default)]
struct ChunkStencils<const D: usize> {
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    values: Vec<f64>,
    gradients: Vec<SVector<f64, D>>,
    /// The kernel writes here before the entries are appended (or only the range read).
    scratch: Stencil<D>,
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

impl<const D: usize> ParticleStencil<'_, D> {
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

/// What a transfer does with one stencil entry ([`Stencils::visit`]); implementors
/// mark `entry` `#[inline(always)]`, it runs 9 to 64 times per particle.
pub(crate) trait EntrySink<const D: usize> {
    /// Node `node` with N, ∇N and the offset x_node − x_p.
    fn entry(&mut self, node: u32, n: f64, gradient: &SVector<f64, D>, offset: &SVector<f64, D>);
}

/// The stencils of all particles (stored by chunk, or to be recomputed) and their node
/// ranges.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stencils<const D: usize> {
    stored: bool,
    chunks: Vec<ChunkStencils<D>>,
    ranges: Vec<(u32, u32)>,
}

impl<const D: usize> Stencils<D> {
    /// Locates every particle (updating its cache) and stores its stencil, or with
    /// recomputed stencils only its node range. Among failures the lowest particle index
    /// is reported, whatever the thread count.
    pub fn compute<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        storage: StencilStorage,
        positions: &[SVector<f64, D>],
        caches: &mut [K::Cache],
    ) -> Result<(), (usize, KernelError)> {
        self.stored = match storage {
            StencilStorage::KernelChoice => !kernel.recompute_stencils(),
            StencilStorage::Store => true,
            StencilStorage::Recompute => false,
        };
        let stored = self.stored;
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
                    if !stored && local.nodes.capacity() > 0 {
                        // Give back what an earlier stored step held (the scratch stays).
                        let scratch = std::mem::take(&mut local.scratch);
                        *local = ChunkStencils {
                            scratch,
                            ..ChunkStencils::default()
                        };
                    }
                    local.offsets.clear();
                    local.nodes.clear();
                    local.values.clear();
                    local.gradients.clear();
                    let st = &mut local.scratch;
                    for (i, ((x, cache), range)) in
                        xs.iter().zip(cs.iter_mut()).zip(ranges).enumerate()
                    {
                        let fail = |e| (c * CHUNK + i, e);
                        if !stored {
                            *range = kernel.node_range(x, cache, st).map_err(fail)?;
                            continue;
                        }
                        kernel.stencil(x, cache, st).map_err(fail)?;
                        *range = st.node_range().unwrap_or((0, 0));
                        local.offsets.push(local.nodes.len());
                        local.nodes.extend_from_slice(st.nodes());
                        local.values.extend_from_slice(st.values());
                        local.gradients.extend_from_slice(st.gradients());
                    }
                    if stored {
                        local.offsets.push(local.nodes.len());
                    }
                    Ok(())
                },
            )
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))
    }

    /// Bytes of the stored stencils, and of the node ranges.
    pub fn bytes(&self) -> (usize, usize) {
        use crate::memory::bytes;
        let stored = self
            .chunks
            .iter()
            .map(|c| bytes(&c.offsets) + bytes(&c.nodes) + bytes(&c.values) + bytes(&c.gradients))
            .sum();
        (stored, bytes(&self.ranges))
    }

    /// The smallest and largest node of each particle's stencil.
    pub fn ranges(&self) -> &[(u32, u32)] {
        &self.ranges
    }

    /// The chunk holding particle `p`'s stored stencil, and its entries' range there.
    #[inline(always)]
    fn stored_entries(&self, p: usize) -> (&ChunkStencils<D>, std::ops::Range<usize>) {
        let chunk = &self.chunks[p / CHUNK];
        let k = p % CHUNK;
        (chunk, chunk.offsets[k]..chunk.offsets[k + 1])
    }

    /// Hands every entry of particle `p`'s stencil to `sink`: the stored one, or the
    /// kernel's [`Kernel::visit_stencil`] at `x` from `cache` (same entries, same bits,
    /// and for a closed-form kernel no arrays written and read back). Stored stencils
    /// have no offsets: with `offsets` they are recomputed from the node positions,
    /// without it zeros are passed.
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
        if self.stored {
            let (chunk, range) = self.stored_entries(p);
            for e in range {
                let node = chunk.nodes[e];
                let offset = if offsets {
                    kernel.node_position(node as usize) - x
                } else {
                    SVector::zeros()
                };
                sink.entry(node, chunk.values[e], &chunk.gradients[e], &offset);
            }
            return Ok(());
        }
        let mut cache = *cache;
        // A closure with this one call site, so the kernel's loop inlines it (a closure
        // called from two places stays a call, and its sums leave the registers).
        kernel
            .visit_stencil(x, &mut cache, scratch, |node, n, gradient, offset| {
                sink.entry(node, n, gradient, offset)
            })
            .map_err(|e| (p, e))
    }

    /// Calls `f` with particle `p`'s stencil: the stored one, or evaluated into `scratch`
    /// at `x` from `cache` (the particle's position and location of this step, which
    /// give the same stencil as [`Self::compute`] evaluated, bit for bit).
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
        if self.stored {
            let (chunk, range) = self.stored_entries(p);
            return Ok(f(ParticleStencil {
                nodes: &chunk.nodes[range.clone()],
                values: &chunk.values[range.clone()],
                gradients: &chunk.gradients[range],
                offsets: &[],
            }));
        }
        let mut cache = *cache;
        kernel.stencil(x, &mut cache, scratch).map_err(|e| (p, e))?;
        Ok(f(ParticleStencil {
            nodes: scratch.nodes(),
            values: scratch.values(),
            gradients: scratch.gradients(),
            offsets: scratch.offsets(),
        }))
    }
}
