//! The `.vtu` XML writer: ASCII, or inline base64 binary with a `UInt64` byte-count header
//! (VTK's uncompressed "binary" format, which ParaView reads as is).

use std::fmt::Write as _;
use std::path::Path;

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

use super::grid::{Field, FieldValues, UnstructuredGrid};
use crate::error::Result;
use crate::write_file;

/// How data arrays are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Encoding {
    /// Decimal text, shortest representation that reads back to the same f64.
    Ascii,
    /// Base64 of the raw little-endian bytes, about half the size of ASCII and faster to load.
    #[default]
    Binary,
}

/// Escapes a string for an XML attribute value.
pub(crate) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

/// Raw little-endian bytes of a data array.
trait Bytes: Copy + std::fmt::Display {
    const VTK_TYPE: &'static str;
    fn extend(self, out: &mut Vec<u8>);
}

impl Bytes for f64 {
    const VTK_TYPE: &'static str = "Float64";
    fn extend(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl Bytes for i32 {
    const VTK_TYPE: &'static str = "Int32";
    fn extend(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl Bytes for u64 {
    const VTK_TYPE: &'static str = "UInt64";
    fn extend(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl Bytes for u8 {
    const VTK_TYPE: &'static str = "UInt8";
    fn extend(self, out: &mut Vec<u8>) {
        out.push(self);
    }
}

fn data_array<T: Bytes>(
    out: &mut String,
    name: Option<&str>,
    components: usize,
    values: &[T],
    encoding: Encoding,
) {
    let _ = write!(out, "        <DataArray type=\"{}\"", T::VTK_TYPE);
    if let Some(name) = name {
        let _ = write!(out, " Name=\"{}\"", escape(name));
    }
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Binary => "binary",
    };
    let _ = write!(
        out,
        " NumberOfComponents=\"{components}\" format=\"{format}\">\n          "
    );
    match encoding {
        Encoding::Ascii => {
            for (i, v) in values.iter().enumerate() {
                if i > 0 {
                    out.push(' ');
                }
                let _ = write!(out, "{v}");
            }
        }
        Encoding::Binary => {
            let mut bytes = Vec::with_capacity(8 + values.len() * 8);
            let payload = std::mem::size_of_val(values) as u64;
            bytes.extend_from_slice(&payload.to_le_bytes());
            for v in values {
                v.extend(&mut bytes);
            }
            out.push_str(&STANDARD.encode(&bytes));
        }
    }
    out.push_str("\n        </DataArray>\n");
}

fn fields(out: &mut String, tag: &str, fields: &[Field], encoding: Encoding) {
    if fields.is_empty() {
        return;
    }
    let _ = writeln!(out, "      <{tag}>");
    for f in fields {
        match &f.values {
            FieldValues::Float64(v) => data_array(out, Some(&f.name), f.components, v, encoding),
            FieldValues::Int32(v) => data_array(out, Some(&f.name), f.components, v, encoding),
        }
    }
    let _ = writeln!(out, "      </{tag}>");
}

impl UnstructuredGrid {
    /// The `.vtu` document.
    pub fn to_vtu(&self, encoding: Encoding) -> String {
        let mut out = String::new();
        out.push_str("<?xml version=\"1.0\"?>\n");
        out.push_str(
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        );
        out.push_str("  <UnstructuredGrid>\n");
        let _ = writeln!(
            out,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len(),
            self.cell_count()
        );
        fields(&mut out, "PointData", &self.point_data, encoding);
        fields(&mut out, "CellData", &self.cell_data, encoding);
        out.push_str("      <Points>\n");
        let coordinates: Vec<f64> = self.points.iter().flatten().copied().collect();
        data_array(&mut out, Some("Points"), 3, &coordinates, encoding);
        out.push_str("      </Points>\n      <Cells>\n");
        data_array(
            &mut out,
            Some("connectivity"),
            1,
            &self.connectivity,
            encoding,
        );
        data_array(&mut out, Some("offsets"), 1, &self.offsets, encoding);
        let types: Vec<u8> = self.types.iter().map(|t| t.vtk_id()).collect();
        data_array(&mut out, Some("types"), 1, &types, encoding);
        out.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
        out
    }

    /// Writes the `.vtu` file.
    pub fn write_vtu(&self, path: impl AsRef<Path>, encoding: Encoding) -> Result<()> {
        write_file(path.as_ref(), self.to_vtu(encoding).as_bytes())
    }
}
