//! Taichi's `mpm3d` scene, the `fluid-box-3d` built-in (scenes/fluid-box-3d.toml): a
//! weakly compressible fluid block of 64,000 particles in [0.15, 0.55]³ falls in a unit
//! box of slip walls three cells in from its faces, APIC, Δt = 2·10⁻⁴. One step per
//! iteration, in particle-steps per second, with 1 and 2 threads, for quadratic B-splines
//! on the 64³ grid and UMLS on the 64³-cell Kuhn lattice of tetrahedra (1.57 M tets, the
//! same node spacing), both also with MLS-MPM (Taichi's own transfer: the force folded
//! into the affine momentum; UMLS with each particle's own D_p); UMLS once more with its
//! stencils kept as the fits' factors (`kernel.stencils = "factored"`: half the memory,
//! rebuilt in P2G and G2P).
//!
//! The scene is set up by the runner, as `umls run fluid-box-3d` sets it up; this bench
//! isolates the step from the set-up and the output.

mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use umls::runner::{Prepared, RunOptions, Scene, prepare, schema::KernelKind};

/// The built-in scene with `edits` (`--set` assignments), set up for `kernel`.
fn scene(kernel: KernelKind, edits: &[(&str, &str)]) -> Prepared<3> {
    let edits: Vec<(String, String)> = edits
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let scene = Scene::load_with("fluid-box-3d", &edits).expect("the built-in scene");
    let options = RunOptions {
        kernel: Some(kernel),
        ..RunOptions::default()
    };
    prepare::<3>(&scene, &options).expect("set up")
}

fn bench(c: &mut Criterion, name: &str, kernel: KernelKind, edits: &[(&str, &str)]) {
    let mut g = c.benchmark_group("fluid_box_3d_64k");
    let particles = scene(kernel, edits).simulation().positions().len();
    g.throughput(Throughput::Elements(particles as u64));
    g.sample_size(10);
    common::step_with_threads(&mut g, name, || scene(kernel, edits));
    g.finish();
}

fn fluid_box(c: &mut Criterion) {
    let mls_mpm = [("transfer.kind", "mls-mpm")];
    bench(c, "bspline2", KernelKind::Bspline2, &[]);
    bench(c, "bspline2_mls_mpm", KernelKind::Bspline2, &mls_mpm);
    bench(c, "umls_tet", KernelKind::Umls, &[]);
    // MLS-MPM with each particle's own D_p.
    bench(c, "umls_tet_mls_mpm", KernelKind::Umls, &mls_mpm);
    let factored = [("kernel.stencils", "factored")];
    bench(c, "umls_tet_factored", KernelKind::Umls, &factored);
}

criterion_group!(benches, fluid_box);
criterion_main!(benches);
