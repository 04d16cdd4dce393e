//! Real Gmsh files (written by Gmsh 4.15 from `fixtures/make_fixtures.py`) in the three
//! formats: the readers must agree with each other and with the geometry.

use std::path::PathBuf;

use umls_io::IoError;
use umls_io::gmsh::{GmshMesh, MshVersion, ReadOptions, read_msh};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn all_formats<const D: usize>(stem: &str) -> Vec<GmshMesh<D>> {
    let meshes: Vec<GmshMesh<D>> = ["v41", "v41-binary", "v22"]
        .iter()
        .map(|suffix| {
            read_msh::<D>(
                fixture(&format!("{stem}-{suffix}.msh")),
                ReadOptions::default(),
            )
            .unwrap_or_else(|e| panic!("{stem}-{suffix}: {e}"))
        })
        .collect();
    assert_eq!(
        meshes.iter().map(|m| m.version).collect::<Vec<_>>(),
        [MshVersion::V41Ascii, MshVersion::V41Binary, MshVersion::V22]
    );
    // The three formats describe the same mesh: same vertices, cells and groups. Gmsh
    // writes ASCII coordinates with 16 significant digits, binary ones exactly.
    assert_eq!(meshes[2].mesh.vertices(), meshes[0].mesh.vertices());
    for (a, b) in meshes[1]
        .mesh
        .vertices()
        .iter()
        .zip(meshes[0].mesh.vertices())
    {
        assert!((a - b).norm() <= 1e-15 * a.norm().max(1.0), "{a} vs {b}");
    }
    for other in &meshes[1..] {
        assert_eq!(other.mesh.connectivity(), meshes[0].mesh.connectivity());
        assert_eq!(other.groups, meshes[0].groups);
        assert_eq!(other.vertex_tags, meshes[0].vertex_tags);
        assert_eq!(other.cell_tags, meshes[0].cell_tags);
    }
    meshes
}

/// Every element of a facet group is a boundary facet of the mesh.
fn facets_on_boundary<const D: usize>(m: &GmshMesh<D>, group: &str) -> usize {
    let g = m.group(group).expect("group exists");
    assert_eq!(g.dimension, D - 1);
    let boundary: Vec<Vec<u32>> = m
        .mesh
        .topology()
        .boundary_facets()
        .iter()
        .map(|f| {
            let simplex = m.mesh.simplex(f.simplex as usize);
            let mut v: Vec<u32> = (0..=D)
                .filter(|&k| k != f.opposite as usize)
                .map(|k| simplex[k])
                .collect();
            v.sort_unstable();
            v
        })
        .collect();
    for facet in g.elements.chunks(D) {
        let mut facet = facet.to_vec();
        facet.sort_unstable();
        assert!(
            boundary.contains(&facet),
            "{group}: {facet:?} is not a boundary facet"
        );
    }
    g.elements.len() / D
}

#[test]
fn square_in_three_formats() {
    let meshes = all_formats::<2>("square");
    let m = &meshes[0];
    assert_eq!(m.mesh.vertex_count(), 31);
    assert_eq!(m.mesh.simplex_count(), 44);
    assert!((m.mesh.total_volume() - 1.0).abs() < 1e-12);
    assert_eq!(m.mesh.entity_counts().euler_characteristic(), 1);
    let names: Vec<&str> = m.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["corner", "left", "bottom", "domain"]);
    for (group, axis) in [("left", 0), ("bottom", 1)] {
        let g = m.group(group).unwrap();
        assert_eq!(g.vertices.len(), 5);
        assert!(
            g.vertices
                .iter()
                .all(|&v| m.mesh.vertex(v as usize)[axis] == 0.0)
        );
        assert_eq!(facets_on_boundary(m, group), 4);
    }
    let corner = m.group("corner").unwrap();
    assert_eq!(corner.dimension, 0);
    assert_eq!(
        m.mesh.vertex(corner.vertices[0] as usize).as_slice(),
        [0.0, 0.0]
    );
    let domain = m.group("domain").unwrap();
    assert_eq!(domain.cells, (0..44).collect::<Vec<u32>>());
    assert_eq!(domain.vertices.len(), 31);
}

#[test]
fn cube_in_three_formats() {
    let meshes = all_formats::<3>("cube");
    let m = &meshes[0];
    assert!((m.mesh.total_volume() - 1.0).abs() < 1e-12);
    assert_eq!(m.mesh.entity_counts().euler_characteristic(), 1);
    let base = m.group("base").unwrap();
    assert!(
        base.vertices
            .iter()
            .all(|&v| m.mesh.vertex(v as usize)[2] == 0.0)
    );
    let facets = facets_on_boundary(m, "base");
    let area: f64 = base
        .elements
        .chunks(3)
        .map(|f| {
            let [a, b, c] = [0, 1, 2].map(|k| m.mesh.vertex(f[k] as usize));
            (b - a).cross(&(c - a)).norm() / 2.0
        })
        .sum();
    assert!(
        (area - 1.0).abs() < 1e-12,
        "base area {area} from {facets} facets"
    );
    assert_eq!(
        m.group("solid").unwrap().cells.len(),
        m.mesh.simplex_count()
    );
}

#[test]
fn bar_in_three_formats() {
    let meshes = all_formats::<1>("bar");
    let m = &meshes[0];
    assert_eq!((m.mesh.vertex_count(), m.mesh.simplex_count()), (9, 8));
    assert!((m.mesh.total_volume() - 2.0).abs() < 1e-12);
    let x = |name: &str| m.mesh.vertex(m.group(name).unwrap().vertices[0] as usize)[0];
    assert_eq!((x("left"), x("right")), (0.0, 2.0));
}

#[test]
fn wrong_dimension_is_named() {
    let err = read_msh::<3>(fixture("square-v41.msh"), ReadOptions::default()).unwrap_err();
    assert!(
        matches!(err, IoError::NoCells { dimension: 3, .. }),
        "{err}"
    );
    let err = read_msh::<2>(fixture("cube-v22.msh"), ReadOptions::default()).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::DimensionTooHigh {
                found: 3,
                requested: 2,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn quadrangles_are_rejected_with_their_line() {
    let err = read_msh::<2>(fixture("quads-v41.msh"), ReadOptions::default()).unwrap_err();
    let text = std::fs::read_to_string(fixture("quads-v41.msh")).unwrap();
    // The block header "2 1 3 n" announces the quadrangles; the error points at it.
    let line = text
        .lines()
        .position(|l| l.split_whitespace().nth(2) == Some("3") && l.starts_with("2 1 "))
        .unwrap()
        + 1;
    match err {
        IoError::UnsupportedElement {
            at,
            type_id: 3,
            name,
            ..
        } => {
            assert_eq!(at, umls_io::Position::Line(line));
            assert_eq!(name, "4-node quadrangle");
        }
        other => panic!("unexpected {other}"),
    }
}

#[test]
fn missing_file_names_the_path() {
    let err = read_msh::<2>("no/such/file.msh", ReadOptions::default()).unwrap_err();
    assert!(err.to_string().starts_with("no/such/file.msh"), "{err}");
}

#[test]
fn partitioned_files_keep_their_physical_groups() {
    let whole = read_msh::<2>(fixture("square-v41.msh"), ReadOptions::default()).unwrap();
    for suffix in ["v41", "v41-binary"] {
        let name = format!("square-partitioned-{suffix}.msh");
        let parts = read_msh::<2>(fixture(&name), ReadOptions::default()).unwrap();
        // The same triangles (listed per partition, so in another order) and groups.
        assert_eq!(parts.mesh.simplex_count(), whole.mesh.simplex_count());
        assert!((parts.mesh.total_volume() - 1.0).abs() < 1e-12);
        for g in &whole.groups {
            let p = parts
                .group(&g.name)
                .unwrap_or_else(|| panic!("{name}: no {}", g.name));
            assert_eq!((p.dimension, p.tag), (g.dimension, g.tag));
            assert_eq!(p.vertices.len(), g.vertices.len(), "{name}: {}", g.name);
            assert_eq!(p.cells.len(), g.cells.len(), "{name}: {}", g.name);
            assert_eq!(p.elements.len(), g.elements.len(), "{name}: {}", g.name);
            // Coordinates on a 1e-12 grid: ASCII files carry 16 digits, binary ones all.
            let coordinates = |m: &GmshMesh<2>, group: &umls_io::gmsh::PhysicalGroup| {
                let mut xs: Vec<(i64, i64)> = group
                    .vertices
                    .iter()
                    .map(|&v| {
                        let x = m.mesh.vertex(v as usize);
                        ((x[0] * 1e12).round() as i64, (x[1] * 1e12).round() as i64)
                    })
                    .collect();
                xs.sort_unstable();
                xs
            };
            assert_eq!(
                coordinates(&parts, p),
                coordinates(&whole, g),
                "{name}: {}",
                g.name
            );
        }
    }
}
