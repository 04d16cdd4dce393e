//! Topology invariants on random jittered, rotated meshes in 1D, 2D and 3D.

use umls_mesh::strategies as common;

use std::collections::HashMap;

use proptest::prelude::*;
use umls_mesh::SimplexMesh;

/// Adjacency is symmetric, has no self loops, and equals "shares a simplex".
fn check_adjacency<const D: usize>(mesh: &SimplexMesh<D>) -> Result<(), TestCaseError> {
    let topo = mesh.topology();
    for v in 0..mesh.vertex_count() {
        for &w in topo.adjacent_vertices(v) {
            prop_assert_ne!(w as usize, v);
            prop_assert!(topo.adjacent_vertices(w as usize).contains(&(v as u32)));
            let share = topo
                .vertex_simplices(v)
                .iter()
                .any(|&s| mesh.simplex(s as usize).contains(&w));
            prop_assert!(share);
        }
        for &s in topo.vertex_simplices(v) {
            prop_assert!(mesh.simplex(s as usize).contains(&(v as u32)));
        }
        // Rows ascending, without repeats.
        prop_assert!(topo.adjacent_vertices(v).windows(2).all(|w| w[0] < w[1]));
        prop_assert!(topo.vertex_simplices(v).windows(2).all(|w| w[0] < w[1]));
    }
    // Complete: every simplex is in its vertices' incidence rows, and its vertices are
    // pairwise adjacent.
    for s in 0..mesh.simplex_count() {
        for &a in mesh.simplex(s) {
            prop_assert!(topo.vertex_simplices(a as usize).contains(&(s as u32)));
            for &b in mesh.simplex(s) {
                prop_assert!(a == b || topo.adjacent_vertices(a as usize).contains(&b));
            }
        }
    }
    Ok(())
}

/// Boundary facets are exactly the facets with one incident simplex (counted independently),
/// face neighbours are mutual and share D vertices.
fn check_boundary<const D: usize>(mesh: &SimplexMesh<D>) -> Result<(), TestCaseError> {
    let mut count: HashMap<Vec<u32>, usize> = HashMap::new();
    for verts in mesh.simplices() {
        for skip in 0..=D {
            let mut facet: Vec<u32> = verts
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != skip)
                .map(|(_, &v)| v)
                .collect();
            facet.sort_unstable();
            *count.entry(facet).or_default() += 1;
        }
    }
    let mut expected: Vec<Vec<u32>> = count
        .into_iter()
        .filter(|(_, c)| *c == 1)
        .map(|(f, _)| f)
        .collect();
    expected.sort();
    let mut found: Vec<Vec<u32>> = mesh
        .topology()
        .boundary_facets()
        .iter()
        .map(|f| {
            let verts = mesh.simplex(f.simplex as usize);
            let mut facet: Vec<u32> = verts
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != f.opposite as usize)
                .map(|(_, &v)| v)
                .collect();
            facet.sort_unstable();
            facet
        })
        .collect();
    found.sort();
    prop_assert_eq!(found, expected);
    for s in 0..mesh.simplex_count() {
        for local in 0..=D {
            if let Some(t) = mesh.topology().neighbor(s, local) {
                let shared = mesh
                    .simplex(t as usize)
                    .iter()
                    .filter(|v| mesh.simplex(s).contains(v))
                    .count();
                prop_assert_eq!(shared, D);
                prop_assert!(
                    (0..=D).any(|k| mesh.topology().neighbor(t as usize, k) == Some(s as u32))
                );
            }
        }
    }
    // Outward normals point away from the simplex: the opposite vertex lies behind the facet.
    for f in mesh.topology().boundary_facets() {
        let s = f.simplex as usize;
        let verts = mesh.simplex(s);
        let on_facet = mesh.vertex(verts[(f.opposite as usize + 1) % (D + 1)] as usize);
        let opposite = mesh.vertex(verts[f.opposite as usize] as usize);
        prop_assert!(f.normal.dot(&(opposite - on_facet)) < 0.0);
        prop_assert!((f.normal.norm() - 1.0).abs() < 1e-12);
    }
    Ok(())
}

/// 1-ring = host vertices ∪ their neighbours, masks = adjacency to each host vertex.
fn check_one_rings<const D: usize>(mesh: &SimplexMesh<D>) -> Result<(), TestCaseError> {
    let topo = mesh.topology();
    for s in 0..mesh.simplex_count() {
        let host = mesh.simplex(s);
        let ring = topo.one_ring(s);
        prop_assert_eq!(&ring.vertices[..=D], host);
        let mut expected: Vec<u32> = host.to_vec();
        for &h in host {
            expected.extend_from_slice(topo.adjacent_vertices(h as usize));
        }
        expected.sort_unstable();
        expected.dedup();
        // After the hosts, the others ascending.
        prop_assert!(ring.vertices[D + 1..].windows(2).all(|w| w[0] < w[1]));
        let mut got = ring.vertices.to_vec();
        got.sort_unstable();
        prop_assert_eq!(got, expected);
        for (&v, &mask) in ring.vertices.iter().zip(ring.masks) {
            for (n, &h) in host.iter().enumerate() {
                let adjacent = v == h || topo.adjacent_vertices(h as usize).contains(&v);
                prop_assert_eq!(mask & (1 << n) != 0, adjacent);
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn interval_topology(mesh in common::interval()) {
        check_adjacency(&mesh)?;
        check_boundary(&mesh)?;
        check_one_rings(&mesh)?;
        prop_assert_eq!(mesh.entity_counts().euler_characteristic(), 1);
        prop_assert_eq!(mesh.topology().boundary_vertices().len(), 2);
        prop_assert!((mesh.total_volume() - 3.0).abs() < 1e-12);
    }

    #[test]
    fn rectangle_topology(mesh in common::rectangle()) {
        check_adjacency(&mesh)?;
        check_boundary(&mesh)?;
        check_one_rings(&mesh)?;
        prop_assert_eq!(mesh.entity_counts().euler_characteristic(), 1);
        prop_assert!((mesh.total_volume() - 2.0).abs() < 1e-12);
        let perimeter: f64 = mesh.topology().boundary_facets().iter().map(|f| f.measure).sum();
        prop_assert!((perimeter - 6.0).abs() < 1e-12);
        // Closed boundary: Σ measure · normal = 0 (divergence theorem for a constant field).
        let flux: nalgebra::Vector2<f64> = mesh.topology().boundary_facets().iter().map(|f| f.normal * f.measure).sum();
        prop_assert!(flux.norm() < 1e-12);
    }

    #[test]
    fn box_topology(mesh in common::cuboid()) {
        check_adjacency(&mesh)?;
        check_boundary(&mesh)?;
        check_one_rings(&mesh)?;
        prop_assert_eq!(mesh.entity_counts().euler_characteristic(), 1);
        prop_assert!((mesh.total_volume() - 0.75).abs() < 1e-12);
        let area: f64 = mesh.topology().boundary_facets().iter().map(|f| f.measure).sum();
        prop_assert!((area - 2.0 * (1.5 + 0.5 + 0.75)).abs() < 1e-12);
        let flux: nalgebra::Vector3<f64> = mesh.topology().boundary_facets().iter().map(|f| f.normal * f.measure).sum();
        prop_assert!(flux.norm() < 1e-12);
    }
}

#[test]
fn square_vertex_normals_and_counts() {
    use umls_mesh::generate::{Diagonal, Lattice};
    let mesh = Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4])
        .triangles(Diagonal::Right)
        .unwrap();
    let counts = mesh.entity_counts();
    assert_eq!(
        (counts.vertices, counts.edges, counts.triangles),
        (25, 56, 32)
    );
    assert_eq!(mesh.topology().boundary_vertices().len(), 16);
    // Edge midpoint vertex (0.5, 0) has normal (0, −1); corner (1, 1) has (1, 1)/√2.
    let bottom = mesh.vertex_count() - 25 + 2;
    assert!(
        (mesh.topology().vertex_normal(bottom) - nalgebra::Vector2::new(0.0, -1.0)).norm() < 1e-14
    );
    let corner = 24;
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert!((mesh.topology().vertex_normal(corner) - nalgebra::Vector2::new(s, s)).norm() < 1e-14);
    assert_eq!(
        mesh.topology().vertex_normal(12),
        nalgebra::Vector2::zeros()
    );
}
