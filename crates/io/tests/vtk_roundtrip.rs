//! Files written by umls-io read back with independent parsers: `vtkio` for `.vtu`,
//! `roxmltree` for `.pvd`, the `csv` crate for histories.

use std::path::PathBuf;

use nalgebra::{Matrix2, Vector2};
use umls_io::csv::HistoryWriter;
use umls_io::vtk::{Collection, Encoding, UnstructuredGrid};
use umls_mesh::generate::{Diagonal, Lattice};
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece, VertexNumbers};

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umls-io-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// (points, connectivity, offsets, types, point arrays, cell arrays) as vtkio reads them.
type Read = (
    Vec<f64>,
    Vec<u64>,
    Vec<u64>,
    Vec<u8>,
    Vec<(String, usize, IOBuffer)>,
    Vec<(String, usize, IOBuffer)>,
);

fn read_back(path: &PathBuf) -> Read {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = pieces.into_iter().next().unwrap() else {
        panic!("not inline")
    };
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = piece.cells.cell_verts
    else {
        panic!("legacy cells")
    };
    let arrays = |attrs: Vec<Attribute>| {
        attrs
            .into_iter()
            .map(|a| match a {
                Attribute::DataArray(d) => (d.name, d.elem.num_comp() as usize, d.data),
                Attribute::Field { .. } => panic!("field attribute"),
            })
            .collect::<Vec<_>>()
    };
    (
        piece.points.into_vec::<f64>().unwrap(),
        connectivity,
        offsets,
        piece.cells.types.iter().map(|t| *t as u8).collect(),
        arrays(piece.data.point),
        arrays(piece.data.cell),
    )
}

/// A particle cloud and the velocity, stress and id fields written into it.
type Cloud = (
    UnstructuredGrid,
    Vec<Vector2<f64>>,
    Vec<Matrix2<f64>>,
    Vec<i32>,
);

fn particles() -> Cloud {
    // Values that need all 17 digits: thirds, tiny and huge magnitudes, negative zero.
    let n = 7i32;
    let x: Vec<[f64; 3]> = (0..n)
        .map(|i| [i as f64 / 3.0, -(i as f64).powi(5) * 1e-300, 0.0])
        .collect();
    let v: Vec<Vector2<f64>> = (0..n)
        .map(|i| Vector2::new(1e200 * i as f64, -0.0))
        .collect();
    let s: Vec<Matrix2<f64>> = (0..n)
        .map(|i| Matrix2::new(1.0 / 7.0, i as f64, -(i as f64), std::f64::consts::PI))
        .collect();
    let ids: Vec<i32> = (0..n).map(|i| i % 3 - 1).collect();
    let mut grid = UnstructuredGrid::point_cloud(x);
    grid.add_point_vectors("velocity", &v).unwrap();
    grid.add_point_tensors("stress", &s).unwrap();
    grid.add_point_ids("material", ids.clone()).unwrap();
    (grid, v, s, ids)
}

#[test]
fn particle_clouds_read_back_exactly() {
    for encoding in [Encoding::Ascii, Encoding::Binary] {
        let (grid, v, s, ids) = particles();
        let path = scratch(&format!("particles-{encoding:?}.vtu"));
        grid.write_vtu(&path, encoding).unwrap();
        let (points, connectivity, offsets, types, data, _) = read_back(&path);
        let expected: Vec<f64> = grid.points.iter().flatten().copied().collect();
        assert_eq!(
            points.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            expected.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            "{encoding:?}"
        );
        assert_eq!(connectivity, (0..7).collect::<Vec<u64>>());
        assert_eq!(offsets, (1..=7).collect::<Vec<u64>>());
        assert_eq!(types, vec![1; 7]);
        let (name, comps, values) = &data[0];
        assert_eq!((name.as_str(), *comps), ("velocity", 3));
        let values = values.clone().into_vec::<f64>().unwrap();
        for (i, v) in v.iter().enumerate() {
            assert_eq!(values[3 * i..3 * i + 3], [v[0], v[1], 0.0]);
            assert!(values[3 * i + 1].is_sign_negative(), "−0 survives");
        }
        let (name, comps, values) = &data[1];
        assert_eq!((name.as_str(), *comps), ("stress", 9));
        let values = values.clone().into_vec::<f64>().unwrap();
        for (i, s) in s.iter().enumerate() {
            let t = &values[9 * i..9 * i + 9];
            assert_eq!(
                t,
                [
                    s[(0, 0)],
                    s[(0, 1)],
                    0.0,
                    s[(1, 0)],
                    s[(1, 1)],
                    0.0,
                    0.0,
                    0.0,
                    0.0
                ]
            );
        }
        let (name, _, values) = &data[2];
        assert_eq!(name, "material");
        assert_eq!(values.clone().into_vec::<i32>().unwrap(), ids);
    }
}

#[test]
fn meshes_read_back_with_cell_fields() {
    let mesh = Lattice::new([0.0, 0.0], [1.0, 2.0], [3, 2])
        .jitter(0.1, 3)
        .triangles(Diagonal::Alternating)
        .unwrap();
    let mut grid = UnstructuredGrid::from_mesh(&mesh);
    let areas: Vec<f64> = (0..mesh.simplex_count()).map(|s| mesh.volume(s)).collect();
    grid.add_cell_field("area", 1, areas.clone()).unwrap();
    grid.add_point_field("x", 1, mesh.vertices().iter().map(|p| p[0]).collect())
        .unwrap();
    let path = scratch("mesh.vtu");
    grid.write_vtu(&path, Encoding::Binary).unwrap();
    let (points, connectivity, offsets, types, point_data, cell_data) = read_back(&path);
    assert_eq!(points.len(), 3 * mesh.vertex_count());
    assert_eq!(
        connectivity,
        mesh.connectivity()
            .iter()
            .map(|&v| v as u64)
            .collect::<Vec<_>>()
    );
    assert_eq!(offsets.last(), Some(&(3 * mesh.simplex_count() as u64)));
    assert!(types.iter().all(|&t| t == 5));
    // Independent check: the areas computed from the points read back.
    let read_areas = cell_data[0].2.clone().into_vec::<f64>().unwrap();
    assert_eq!(read_areas, areas);
    for (c, area) in connectivity.chunks(3).zip(&read_areas) {
        let p = |k: usize| Vector2::new(points[3 * c[k] as usize], points[3 * c[k] as usize + 1]);
        let (a, b, d) = (p(0), p(1), p(2));
        let computed = ((b - a).perp(&(d - a)) / 2.0).abs();
        assert!((computed - area).abs() < 1e-15);
    }
    assert_eq!(point_data[0].0, "x");
    assert_eq!(read_areas.iter().sum::<f64>(), mesh.total_volume());
}

#[test]
fn wrong_field_length_is_an_error() {
    let (mut grid, ..) = particles();
    let err = grid.add_point_field("bad", 3, vec![0.0; 20]).unwrap_err();
    assert_eq!(err.to_string(), "field `bad` has 20 values, expected 21");
}

#[test]
fn collections_list_frames_with_times() {
    let mut pvd = Collection::default();
    for (k, t) in [0.0, 0.125, 1.0 / 3.0].into_iter().enumerate() {
        pvd.push(t, format!("frames/p_{k}&<>.vtu"));
    }
    let path = scratch("series.pvd");
    pvd.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let frames: Vec<(f64, String)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("DataSet"))
        .map(|n| {
            (
                n.attribute("timestep").unwrap().parse().unwrap(),
                n.attribute("file").unwrap().to_string(),
            )
        })
        .collect();
    assert_eq!(frames, pvd.frames);
    assert_eq!(doc.root_element().attribute("type"), Some("Collection"));
}

#[test]
fn histories_read_back_with_their_header() {
    let path = scratch("history.csv");
    let mut w = HistoryWriter::create(&path, &["step", "time", "energy"]).unwrap();
    let rows: Vec<[f64; 3]> = (0..5)
        .map(|i| [i as f64, 0.1 * i as f64, 1.0 / (i as f64 + 3.0)])
        .collect();
    for r in &rows {
        w.row(r).unwrap();
    }
    assert!(w.row(&[1.0]).is_err());
    w.flush().unwrap();
    let mut reader = csv::Reader::from_path(&path).unwrap();
    assert_eq!(reader.headers().unwrap(), vec!["step", "time", "energy"]);
    let read: Vec<Vec<f64>> = reader
        .records()
        .map(|r| r.unwrap().iter().map(|f| f.parse().unwrap()).collect())
        .collect();
    assert_eq!(read, rows.iter().map(|r| r.to_vec()).collect::<Vec<_>>());
    assert!(HistoryWriter::create(scratch("bad.csv"), &["a,b"]).is_err());
}

/// The binary writer streams base64 in chunks of 12 kB: arrays many chunks long, of every
/// length modulo 3 bytes (the header is 8 bytes, values 8, 4 or 1), read back bit for bit.
#[test]
fn large_frames_stream_and_read_back_exactly() {
    for n in [4999usize, 5000, 5001] {
        let x: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = i as f64;
                [t / 7.0, (t * 0.37).sin(), -t * 1e-9]
            })
            .collect();
        let ids: Vec<i32> = (0..n as i32).map(|i| i * 7919 % 1013 - 500).collect();
        let mut grid = UnstructuredGrid::point_cloud(x);
        grid.add_point_ids("material", ids.clone()).unwrap();
        for encoding in [Encoding::Binary, Encoding::Ascii] {
            let path = scratch(&format!("large-{n}-{encoding:?}.vtu"));
            grid.write_vtu(&path, encoding).unwrap();
            // The file is the in-memory document.
            assert_eq!(
                std::fs::read_to_string(&path).unwrap(),
                grid.to_vtu(encoding)
            );
            let (points, connectivity, offsets, types, data, _) = read_back(&path);
            let expected: Vec<u64> = grid.points.iter().flatten().map(|x| x.to_bits()).collect();
            assert_eq!(
                points.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                expected
            );
            assert_eq!(connectivity, grid.connectivity);
            assert_eq!(offsets, grid.offsets);
            assert_eq!(types, vec![1u8; n]);
            assert_eq!(data[0].2.clone().into_vec::<i32>().unwrap(), ids);
        }
    }
}
