//! Mutated and truncated real MSH files: the reader returns a valid mesh or an error,
//! never panics, and never allocates for a count the file cannot hold.

use std::path::PathBuf;

use proptest::prelude::*;
use umls_io::gmsh::{AnyGmshMesh, ReadOptions, parse_msh_any};

const FIXTURES: [&str; 8] = [
    "square-v41.msh",
    "square-v41-binary.msh",
    "square-v22.msh",
    "cube-v41-binary.msh",
    "cube-v22.msh",
    "bar-v41.msh",
    "quads-v41.msh",
    "square-partitioned-v41-binary.msh",
];

fn fixture(index: usize) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(FIXTURES[index % FIXTURES.len()]);
    std::fs::read(path).expect("fixture exists")
}

/// One edit of a file.
#[derive(Debug, Clone)]
enum Mutation {
    /// Overwrite the byte at a relative position.
    Byte(f64, u8),
    /// Replace a byte with a character that often changes meaning (digit, sign, space…).
    Char(f64, char),
    /// Delete a range.
    Delete(f64, usize),
    /// Duplicate a range.
    Repeat(f64, usize),
    /// Cut the file.
    Truncate(f64),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0, any::<u8>()).prop_map(|(p, b)| Mutation::Byte(p, b)),
        (
            0.0..1.0,
            prop::sample::select(vec!['0', '9', '-', '.', 'e', ' ', '\n', '$', '"', 'x'])
        )
            .prop_map(|(p, c)| Mutation::Char(p, c)),
        (0.0..1.0, 1usize..40).prop_map(|(p, n)| Mutation::Delete(p, n)),
        (0.0..1.0, 1usize..40).prop_map(|(p, n)| Mutation::Repeat(p, n)),
        (0.0..1.0).prop_map(Mutation::Truncate),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let at = |p: f64, len: usize| ((p * len as f64) as usize).min(len.saturating_sub(1));
    match *m {
        Mutation::Byte(p, b) if !bytes.is_empty() => {
            let i = at(p, bytes.len());
            bytes[i] = b;
        }
        Mutation::Char(p, c) if !bytes.is_empty() => {
            let i = at(p, bytes.len());
            bytes[i] = c as u8;
        }
        Mutation::Delete(p, n) if !bytes.is_empty() => {
            let i = at(p, bytes.len());
            let end = (i + n).min(bytes.len());
            bytes.drain(i..end);
        }
        Mutation::Repeat(p, n) if !bytes.is_empty() => {
            let i = at(p, bytes.len());
            let end = (i + n).min(bytes.len());
            let copy = bytes[i..end].to_vec();
            bytes.splice(end..end, copy);
        }
        Mutation::Truncate(p) => bytes.truncate((p * bytes.len() as f64) as usize),
        _ => {}
    }
}

/// A mesh that came out of a mutated file must still be a valid one.
fn check(mesh: &AnyGmshMesh) {
    fn volume_positive<const D: usize>(m: &umls_io::gmsh::GmshMesh<D>) {
        assert!((0..m.mesh.simplex_count()).all(|s| m.mesh.volume(s) > 0.0));
        assert_eq!(m.vertex_tags.len(), m.mesh.vertex_count());
        assert_eq!(m.cell_tags.len(), m.mesh.simplex_count());
        for g in &m.groups {
            assert!(
                g.vertices
                    .iter()
                    .all(|&v| (v as usize) < m.mesh.vertex_count())
            );
            assert!(
                g.cells
                    .iter()
                    .all(|&c| (c as usize) < m.mesh.simplex_count())
            );
        }
    }
    match mesh {
        AnyGmshMesh::Segments(m) => volume_positive(m),
        AnyGmshMesh::Triangles(m) => volume_positive(m),
        AnyGmshMesh::Tetrahedra(m) => volume_positive(m),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn mutated_files_never_panic(
        file in 0usize..FIXTURES.len(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let mut bytes = fixture(file);
        for m in &mutations {
            apply(&mut bytes, m);
        }
        if let Ok(mesh) = parse_msh_any(&bytes, ReadOptions::default()) {
            check(&mesh);
        }
    }
}

#[test]
fn every_truncation_of_every_fixture_is_an_error() {
    for (index, name) in FIXTURES.iter().enumerate() {
        let bytes = fixture(index);
        // Cutting anywhere before the final "$EndElements" loses data.
        let end = bytes
            .windows(12)
            .rposition(|w| w == b"$EndElements")
            .unwrap();
        for cut in 0..end {
            assert!(
                parse_msh_any(&bytes[..cut], ReadOptions::default()).is_err(),
                "{name} cut at {cut} was accepted"
            );
        }
    }
}
