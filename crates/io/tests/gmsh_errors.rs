//! Hand-made MSH files with one defect each: the error must say what and where.

use umls_io::gmsh::{AnyGmshMesh, ReadOptions, parse_msh, parse_msh_any};
use umls_io::{IoError, Position};
use umls_mesh::{MeshError, Orientation};

const HEADER_22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";

/// Two triangles on the unit square, plus an unused node 5, a boundary segment in
/// physical group 1 ("left") and both triangles in group 2, with `elements` appended.
fn square_22(nodes_extra: &str, elements: &[&str]) -> String {
    let mut base = vec!["1 1 2 1 1 4 1", "2 2 2 2 1 1 2 3", "3 2 2 2 1 1 3 4"];
    base.extend_from_slice(elements);
    format!(
        "{HEADER_22}$PhysicalNames\n2\n1 1 \"left\"\n2 2 \"plate\"\n$EndPhysicalNames\n\
         $Nodes\n5\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 7 7 {nodes_extra}\n$EndNodes\n\
         $Elements\n{}\n{}\n$EndElements\n",
        base.len(),
        base.join("\n")
    )
}

fn read(text: &str) -> Result<umls_io::gmsh::GmshMesh<2>, IoError> {
    parse_msh::<2>(text.as_bytes(), ReadOptions::default())
}

#[test]
fn a_valid_file_drops_unused_nodes_and_keeps_groups() {
    let m = read(&square_22("0", &[])).unwrap();
    assert_eq!(m.mesh.vertex_count(), 4, "node 5 is used by no cell");
    assert_eq!(m.vertex_tags, [1, 2, 3, 4]);
    let left = m.group("left").unwrap();
    assert_eq!((left.dimension, left.tag), (1, 1));
    assert_eq!(left.elements, [3, 0], "segment 4-1 as mesh vertices");
    assert_eq!(m.group("plate").unwrap().cells, [0, 1]);
}

#[test]
fn an_element_listed_for_two_groups_is_one_cell_in_both() {
    // MSH 2.2 repeats an element once per physical group.
    let text = square_22("0", &["2 2 2 5 1 1 2 3"]);
    let m = read(&text).unwrap();
    assert_eq!(m.mesh.simplex_count(), 2);
    let unnamed = m.groups.iter().find(|g| g.tag == 5).unwrap();
    assert_eq!(unnamed.name, "physical 2D 5");
    assert_eq!(unnamed.cells, [0]);
}

#[test]
fn the_same_tag_for_different_elements_is_an_error() {
    let err = read(&square_22("0", &["2 2 2 5 1 1 3 4"])).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::DuplicateTag {
                entity: "element",
                tag: 2,
                at: Position::Line(22)
            }
        ),
        "{err}"
    );
}

#[test]
fn unknown_node_names_element_node_and_line() {
    let err = read(&square_22("0", &["4 2 2 2 1 1 3 9"])).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::UnknownNode {
                element: 4,
                node: 9,
                at: Position::Line(22)
            }
        ),
        "{err}"
    );
    assert_eq!(
        err.to_string(),
        "line 22: element 4 refers to node 9, which $Nodes does not define"
    );
}

#[test]
fn non_numeric_field_names_line_and_section() {
    let text = square_22("0", &[]).replace("3 1 1 0", "3 1 one 0");
    let err = read(&text).unwrap_err();
    assert_eq!(
        err.to_string(),
        "line 13: in $Nodes, a y coordinate expected, found `one`"
    );
}

#[test]
fn truncated_file_says_what_was_expected() {
    let text = square_22("0", &[]);
    let cut = &text[..text.find("3 2 2 2 1 1 3 4").unwrap() + 13];
    let err = read(cut).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::Truncated {
                section: "Elements",
                expected: "a node tag of the element",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn huge_counts_do_not_allocate() {
    let text = square_22("0", &[]).replace("$Nodes\n5", "$Nodes\n99999999999999");
    let err = read(&text).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::BadField {
                section: "Nodes",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn off_plane_node_of_a_2d_mesh() {
    let text = square_22("0", &[]).replace("3 1 1 0", "3 1 1 0.5");
    let err = read(&text).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::NotFlat {
                node: 3,
                axis: 2,
                ..
            }
        ),
        "{err}"
    );
    // An unused node may lie anywhere.
    assert!(read(&square_22("3", &[])).is_ok());
}

#[test]
fn clockwise_triangles_are_fixed_or_rejected() {
    let text = square_22("0", &[]).replace("3 2 2 2 1 1 3 4", "3 2 2 2 1 1 4 3");
    let fixed = read(&text).unwrap();
    assert!((fixed.mesh.total_volume() - 1.0).abs() < 1e-15);
    let options = ReadOptions {
        orientation: Orientation::Reject,
    };
    let err = parse_msh::<2>(text.as_bytes(), options).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::InvalidMesh {
                element: 3,
                at: Position::Line(21),
                source: MeshError::InvertedSimplex { simplex: 1, .. }
            }
        ),
        "{err}"
    );
}

#[test]
fn degenerate_triangle_names_its_element() {
    let text = square_22("0", &["4 2 2 2 1 1 2 5"]).replace("5 7 7 0", "5 2 0 0");
    let err = read(&text).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::InvalidMesh {
                element: 4,
                at: Position::Line(22),
                source: MeshError::DegenerateSimplex { simplex: 2, .. }
            }
        ),
        "{err}"
    );
}

#[test]
fn boundary_element_off_the_mesh() {
    let err = read(&square_22("0", &["4 1 2 1 1 4 5"])).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::DetachedElement {
                element: 4,
                node: 5,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("physical group left"), "{err}");
}

#[test]
fn unsupported_versions_and_headers() {
    for (text, expected) in [
        (
            "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n",
            "MSH format 3.0 ASCII",
        ),
        (
            "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n",
            "MSH format 2.2 binary",
        ),
        ("solid cube\n", "not a Gmsh MSH file"),
        ("", "file ends inside $MeshFormat"),
    ] {
        let err = read(text).unwrap_err();
        assert!(err.to_string().contains(expected), "{err}");
    }
    let err = read(&format!("{HEADER_22}$Nodes\n0\n$EndNodes\n")).unwrap_err();
    assert!(
        matches!(
            err,
            IoError::MissingSection {
                section: "Elements"
            }
        ),
        "{err}"
    );
}

#[test]
fn unknown_sections_are_skipped() {
    let text =
        square_22("0", &[]).replace("$Nodes", "$Comments\nwritten by hand\n$EndComments\n$Nodes");
    assert_eq!(read(&text).unwrap().mesh.simplex_count(), 2);
}

#[test]
fn wrong_section_end() {
    let text = square_22("0", &[]).replace("$EndNodes", "$EndNode");
    let err = read(&text).unwrap_err();
    assert_eq!(
        err.to_string(),
        "line 16: expected $EndNodes, found `$EndNode`"
    );
}

#[test]
fn dimension_is_taken_from_the_elements() {
    let m = parse_msh_any(square_22("0", &[]).as_bytes(), ReadOptions::default()).unwrap();
    assert!(matches!(m, AnyGmshMesh::Triangles(ref m) if m.mesh.simplex_count() == 2));
    let points_only = format!(
        "{HEADER_22}$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 15 2 0 1 1\n$EndElements\n"
    );
    let err = parse_msh_any(points_only.as_bytes(), ReadOptions::default()).unwrap_err();
    assert!(matches!(err, IoError::NoCells { .. }), "{err}");
}

#[test]
fn coincident_nodes_are_refused_naming_both_tags_and_the_line() {
    // The square's second triangle uses node 6, a second node at (1, 1): without the
    // check the two triangles would meet along a crack from (0, 0) to (1, 1).
    let text = format!(
        "{HEADER_22}$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n6 1 1 0\n$EndNodes\n\
         $Elements\n2\n1 2 2 2 1 1 2 3\n2 2 2 2 1 1 6 4\n$EndElements\n"
    );
    let line = text.lines().position(|l| l == "6 1 1 0").unwrap() + 1;
    let err = read(&text).unwrap_err();
    assert!(
        matches!(
            &err,
            IoError::CoincidentNodes { first: 3, second: 6, at, .. } if *at == Position::Line(line)
        ),
        "{err}"
    );
    assert!(
        err.to_string()
            .starts_with(&format!("line {line}: nodes 3 and 6 both lie at (1, 1)")),
        "{err}"
    );
    // The same square with node 3 used twice is one mesh without a crack.
    let joined = text.replace("1 1 6 4", "1 1 3 4");
    let mesh = read(&joined).unwrap().mesh;
    assert_eq!(mesh.topology().boundary_facets().len(), 4);
}
