//! Per-step stencils of all particles in compact arrays, computed in parallel with a
//! result that does not depend on the number of threads.

use nalgebra::SVector;
use rayon::prelude::*;
use umls_transfer::{Kernel, KernelError, Stencil};

/// Particles per parallel work item; fixed so that the work split, and hence every
/// result, is the same for any number of threads.
pub(crate) const CHUNK: usize = 512;

/// Stencil of particle p: entries `offsets[p]..offsets[p + 1]` of the flat arrays.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stencils<const D: usize> {
    pub offsets: Vec<usize>,
    pub nodes: Vec<u32>,
    pub values: Vec<f64>,
    pub gradients: Vec<SVector<f64, D>>,
}

impl<const D: usize> Stencils<D> {
    #[inline]
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        self.offsets[p]..self.offsets[p + 1]
    }

    /// Evaluates every particle's stencil (updating its location cache).
    pub fn compute<K: Kernel<D>>(
        &mut self,
        kernel: &K,
        positions: &[SVector<f64, D>],
        caches: &mut [K::Cache],
    ) -> Result<(), (usize, KernelError)> {
        let chunks: Vec<Result<Stencils<D>, (usize, KernelError)>> = positions
            .par_chunks(CHUNK)
            .zip(caches.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, (xs, cs))| {
                let mut local = Stencils {
                    offsets: Vec::with_capacity(xs.len()),
                    ..Default::default()
                };
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
                Ok(local)
            })
            .collect();
        self.offsets.clear();
        self.nodes.clear();
        self.values.clear();
        self.gradients.clear();
        for chunk in chunks {
            let chunk = chunk?;
            let base = self.nodes.len();
            self.offsets.extend(chunk.offsets.iter().map(|o| o + base));
            self.nodes.extend_from_slice(&chunk.nodes);
            self.values.extend_from_slice(&chunk.values);
            self.gradients.extend_from_slice(&chunk.gradients);
        }
        self.offsets.push(self.nodes.len());
        Ok(())
    }
}
