//! Reading Gmsh files and writing particle frames: the I/O cost per output step.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Matrix2, Vector2};
use umls_io::gmsh::{ReadOptions, parse_msh};
use umls_io::vtk::{Encoding, UnstructuredGrid};

fn fixture(path: &str) -> Vec<u8> {
    std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)).expect("file exists")
}

fn read(c: &mut Criterion) {
    let mut group = c.benchmark_group("gmsh_read");
    // 1187 nodes, 2236 triangles (ASCII 4.1), and the 3D fixture in ASCII and binary.
    for (name, path) in [
        (
            "cantilever_v41_ascii_2d",
            "../../scenes/meshes/cantilever.msh",
        ),
        ("cube_v41_ascii_3d", "tests/fixtures/cube-v41.msh"),
        ("cube_v41_binary_3d", "tests/fixtures/cube-v41-binary.msh"),
        ("cube_v22_ascii_3d", "tests/fixtures/cube-v22.msh"),
    ] {
        let bytes = fixture(path);
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        if name.ends_with("2d") {
            group.bench_function(name, |b| {
                b.iter(|| parse_msh::<2>(black_box(&bytes), ReadOptions::default()).unwrap())
            });
        } else {
            group.bench_function(name, |b| {
                b.iter(|| parse_msh::<3>(black_box(&bytes), ReadOptions::default()).unwrap())
            });
        }
    }
    group.finish();
}

fn write(c: &mut Criterion) {
    let n = 20_000;
    let x: Vec<[f64; 3]> = (0..n)
        .map(|i| [i as f64 * 1e-3, (i % 7) as f64 / 3.0, 0.0])
        .collect();
    let v: Vec<Vector2<f64>> = (0..n)
        .map(|i| Vector2::new(i as f64 / 7.0, -1.0 / 3.0))
        .collect();
    let s: Vec<Matrix2<f64>> = (0..n)
        .map(|i| Matrix2::new(1.0 / 3.0, i as f64, 2.0, 0.1))
        .collect();
    let mut grid = UnstructuredGrid::point_cloud(x);
    grid.add_point_vectors("velocity", &v).unwrap();
    grid.add_point_tensors("stress", &s).unwrap();
    grid.add_point_tensors("deformation_gradient", &s).unwrap();
    let mut group = c.benchmark_group("vtu_particle_frame_20k");
    group.throughput(Throughput::Elements(n as u64));
    for encoding in [Encoding::Binary, Encoding::Ascii] {
        group.bench_function(format!("{encoding:?}").to_lowercase(), |b| {
            b.iter(|| black_box(grid.to_vtu(encoding)).len())
        });
    }
    group.finish();
}

criterion_group!(benches, read, write);
criterion_main!(benches);
