//! A binary MSH 4.1 file built byte by byte, in both byte orders: the reader detects the
//! order from the marker and reads the same mesh.

use umls_io::gmsh::{MshVersion, ReadOptions, parse_msh};

/// Serialises fields in one byte order.
struct Writer {
    big: bool,
    bytes: Vec<u8>,
}

impl Writer {
    fn text(&mut self, s: &str) -> &mut Self {
        self.bytes.extend_from_slice(s.as_bytes());
        self
    }
    fn int(&mut self, v: i32) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.bytes.extend_from_slice(&b);
        self
    }
    fn size(&mut self, v: u64) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.bytes.extend_from_slice(&b);
        self
    }
    fn double(&mut self, v: f64) -> &mut Self {
        let b = if self.big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        };
        self.bytes.extend_from_slice(&b);
        self
    }
}

/// Two triangles on the unit square; surface entity 1 in physical group 7 ("plate").
fn square(big: bool) -> Vec<u8> {
    let mut w = Writer {
        big,
        bytes: Vec::new(),
    };
    w.text("$MeshFormat\n4.1 1 8\n")
        .int(1)
        .text("\n$EndMeshFormat\n");
    w.text("$PhysicalNames\n1\n2 7 \"plate\"\n$EndPhysicalNames\n");
    w.text("$Entities\n").size(0).size(0).size(1).size(0);
    w.int(1);
    for c in [0.0, 0.0, 0.0, 1.0, 1.0, 0.0] {
        w.double(c);
    }
    w.size(1).int(7).size(0).text("\n$EndEntities\n");
    w.text("$Nodes\n").size(1).size(4).size(10).size(13);
    w.int(2).int(1).int(0).size(4);
    for tag in 10..14 {
        w.size(tag);
    }
    for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        w.double(x).double(y).double(0.0);
    }
    w.text("\n$EndNodes\n");
    w.text("$Elements\n").size(1).size(2).size(1).size(2);
    w.int(2).int(1).int(2).size(2);
    w.size(1).size(10).size(11).size(12);
    w.size(2).size(10).size(12).size(13);
    w.text("\n$EndElements\n");
    w.bytes
}

#[test]
fn both_byte_orders_read_the_same_mesh() {
    let little = parse_msh::<2>(&square(false), ReadOptions::default()).unwrap();
    let big = parse_msh::<2>(&square(true), ReadOptions::default()).unwrap();
    for m in [&little, &big] {
        assert_eq!(m.version, MshVersion::V41Binary);
        assert_eq!(m.mesh.simplex_count(), 2);
        assert_eq!(m.vertex_tags, [10, 11, 12, 13]);
        assert!((m.mesh.total_volume() - 1.0).abs() < 1e-15);
        assert_eq!(m.group("plate").unwrap().cells, [0, 1]);
    }
    assert_eq!(little.mesh.vertices(), big.mesh.vertices());
    assert_eq!(little.mesh.connectivity(), big.mesh.connectivity());
}

#[test]
fn a_bad_marker_or_a_short_block_names_the_byte() {
    let mut bytes = square(false);
    let marker = bytes.windows(3).position(|w| w == b"8\n\x01").unwrap() + 2;
    bytes[marker] = 2;
    let err = parse_msh::<2>(&bytes, ReadOptions::default()).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!("byte {marker}: binary endianness marker is 2, expected 1")
    );
    let bytes = square(false);
    let cut = bytes.windows(9).position(|w| w == b"$Elements").unwrap() + 40;
    let err = parse_msh::<2>(&bytes[..cut], ReadOptions::default()).unwrap_err();
    assert!(err.to_string().starts_with("byte "), "{err}");
}
