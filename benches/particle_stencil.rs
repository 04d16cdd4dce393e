//! The per-particle pipeline of an MPM step across crates: relocate a particle that moved
//! a fraction of an element (walk from its previous host) and evaluate its UMLS stencil,
//! against the same with linear FE shape functions.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Vector2;
use umls::mesh::generate::{Diagonal, Lattice};
use umls::mls::{GradientKind, Linear, Stencil, UmlsKernel};

fn particle_stencil(c: &mut Criterion) {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [100, 100])
        .jitter(0.2, 1)
        .triangles(Diagonal::Alternating)
        .expect("mesh");
    let kernel = UmlsKernel::new(&mesh);
    let h = mesh.max_edge_length();
    // Four particles per triangle at its centroid, moved by 0.3 h in a fixed direction.
    let particles: Vec<(u32, Vector2<f64>)> = (0..mesh.simplex_count())
        .flat_map(|s| {
            let c = mesh.centroid(s);
            (0..4).map(move |k| {
                (
                    s as u32,
                    c + Vector2::new(
                        0.3 * h * (k as f64 * 1.3).cos(),
                        0.3 * h * (k as f64 * 1.3).sin(),
                    ),
                )
            })
        })
        .filter(|(_, x)| x.x > 0.0 && x.y > 0.0 && x.x < 1.0 && x.y < 1.0)
        .collect();
    let mut group = c.benchmark_group("particle_stencil_2d");
    group.throughput(Throughput::Elements(particles.len() as u64));
    group.sample_size(10);
    group.bench_function("walk_then_umls", |b| {
        let mut st = Stencil::new();
        b.iter(|| {
            let mut acc = 0.0;
            for (hint, x) in &particles {
                let host = mesh.locate_from(x, *hint).expect("inside").simplex;
                kernel
                    .evaluate::<3, Linear>(&mesh, host, x, GradientKind::Reconstructed, &mut st)
                    .expect("well conditioned");
                acc += st.values()[0];
            }
            acc
        })
    });
    group.bench_function("walk_then_linear_fe", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (hint, x) in &particles {
                let found = mesh.locate_from(x, *hint).expect("inside");
                acc += found.barycentric.as_slice()[0]
                    + mesh
                        .barycentric_gradients(found.simplex as usize)
                        .as_slice()[0]
                        .x;
            }
            acc
        })
    });
    group.finish();
}

criterion_group!(benches, particle_stencil);
criterion_main!(benches);
