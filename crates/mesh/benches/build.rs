//! Building a tetrahedral mesh with everything it carries: validation, inverse maps,
//! topology (adjacency, facets, 1-rings) and the BVH. The Kuhn lattice of 64³ cubes
//! (1.57 M tetrahedra, 65³ vertices) is the mesh of the `fluid-box-3d` scene's UMLS run;
//! 32³ cubes show how the cost grows. One and two threads, in tetrahedra per second.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use umls_mesh::generate::Lattice;

fn build(c: &mut Criterion) {
    let mut group = c.benchmark_group("kuhn_lattice_build");
    group.sample_size(10);
    for cells in [32usize, 64] {
        let lattice = Lattice::new([0.0; 3], [1.0; 3], [cells; 3]);
        group.throughput(Throughput::Elements((6 * cells.pow(3)) as u64));
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            group.bench_function(
                BenchmarkId::new(format!("{cells}^3_cells"), format!("{threads}_threads")),
                |b| {
                    b.iter(|| {
                        pool.install(|| lattice.tetrahedra().expect("valid mesh").simplex_count())
                    })
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, build);
criterion_main!(benches);
