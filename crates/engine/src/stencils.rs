//! Per-step stencils of all particles, computed in parallel with a result that does not
//! depend on the number of threads, into buffers that are reused from step to step.

use nalgebra::SVector;
use rayon::prelude::*;
use umls_transfer::{Kernel, KernelError, Stencil};

use crate::parallel::lowest_failure;

/// Particles per parallel work item; fixed so that the work split, and hence every
/// result, is the same for any number of threads.
pub(crate) const CHUNK: usize = 512;

/// The stencils of one chunk of [`CHUNK`] particles: particle k of the chunk owns entries
/// `offsets[k]..offsets[k + 1]`. Each chunk keeps its vectors between steps, so once they
/// have grown a step allocates nothing, and no serial pass copies chunks into one array.
#[derive(Debug, Clone, Default)]
struct ChunkStencils<const D: usize> {
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    values: Vec<f64>,
    gradients: Vec<SVector<f64, D>>,
}

/// One particle's stencil: node indices, shape-function values and gradients.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParticleStencil<'a, const D: usize> {
    pub nodes: &'a [u32],
    pub values: &'a [f64],
    pub gradients: &'a [SVector<f64, D>],
}

impl<const D: usize> ParticleStencil<'_, D> {
    /// Number of nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
}

/// The stencils of all particles, by chunk.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stencils<const D: usize> {
    chunks: Vec<ChunkStencils<D>>,
}

impl<const D: usize> Stencils<D> {
    /// The stencil of particle `p`.
    #[inline]
    pub fn of(&self, p: usize) -> ParticleStencil<'_, D> {
        let chunk = &self.chunks[p / CHUNK];
        let k = p % CHUNK;
        let range = chunk.offsets[k]..chunk.offsets[k + 1];
        ParticleStencil {
            nodes: &chunk.nodes[range.clone()],
            values: &chunk.values[range.clone()],
            gradients: &chunk.gradients[range],
        }
    }

    /// Evaluates every particle's stencil (updating its location cache). Among failures
    /// the lowest particle index is reported, whatever the thread count.
    pub fn compute<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        positions: &[SVector<f64, D>],
        caches: &mut [K::Cache],
    ) -> Result<(), (usize, KernelError)> {
        self.chunks
            .resize_with(positions.len().div_ceil(CHUNK), ChunkStencils::default);
        self.chunks
            .par_iter_mut()
            .zip(positions.par_chunks(CHUNK))
            .zip(caches.par_chunks_mut(CHUNK))
            .enumerate()
            .map(
                |(c, ((local, xs), cs))| -> Result<(), (usize, KernelError)> {
                    local.offsets.clear();
                    local.nodes.clear();
                    local.values.clear();
                    local.gradients.clear();
                    let mut st = Stencil::new();
                    for (i, (x, cache)) in xs.iter().zip(cs.iter_mut()).enumerate() {
                        kernel
                            .stencil(x, cache, &mut st)
                            .map_err(|e| (c * CHUNK + i, e))?;
                        local.offsets.push(local.nodes.len());
                        local.nodes.extend_from_slice(st.nodes());
                        local.values.extend_from_slice(st.values());
                        local.gradients.extend_from_slice(st.gradients());
                    }
                    local.offsets.push(local.nodes.len());
                    Ok(())
                },
            )
            .reduce(|| Ok(()), |a, b| lowest_failure(a, b, |(), ()| ()))
    }
}
