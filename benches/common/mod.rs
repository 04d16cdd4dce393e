//! What the step benches share: one simulation per thread count, stepped inside its own
//! rayon pool.

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId};
use umls::constitutive::Constitutive;
use umls::engine::{Simulation, TransferScheme};
use umls::transfer::Kernel;

/// Benchmarks one step of the simulation `make` builds, with 1 and 2 threads, as
/// `name/1thread` and `name/2thread` in `group`.
pub fn step_with_threads<const D: usize, K, M, T>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    mut make: impl FnMut() -> Simulation<D, K, M, T>,
) where
    K: Kernel<D>,
    M: Constitutive<D>,
    T: TransferScheme,
{
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut sim = make();
        group.bench_function(BenchmarkId::new(name, format!("{threads}thread")), |b| {
            b.iter(|| pool.install(|| sim.step().expect("stable")))
        });
    }
}
