//! What the step benches share: one simulation per thread count, stepped inside its own
//! rayon pool.

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId};
use umls::constitutive::Constitutive;
use umls::engine::{Simulation, TransferScheme};
use umls::runner::Prepared;
use umls::transfer::Kernel;

/// A simulation a bench steps: a typed one, or a scene's set up by the runner.
pub trait Steps: Send {
    /// One step; a bench's scene is stable, so an error is a bug.
    fn step_once(&mut self);
}

impl<const D: usize, K, M, T> Steps for Simulation<D, K, M, T>
where
    K: Kernel<D>,
    M: Constitutive<D>,
    T: TransferScheme,
{
    fn step_once(&mut self) {
        self.step().expect("stable");
    }
}

impl<const D: usize> Steps for Prepared<D> {
    fn step_once(&mut self) {
        self.simulation().step().expect("stable");
    }
}

/// Benchmarks one step of the simulation `make` builds, with 1 and 2 threads, as
/// `name/1thread` and `name/2thread` in `group`.
pub fn step_with_threads<S: Steps>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    mut make: impl FnMut() -> S,
) {
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut sim = make();
        group.bench_function(BenchmarkId::new(name, format!("{threads}thread")), |b| {
            b.iter(|| pool.install(|| sim.step_once()))
        });
    }
}
