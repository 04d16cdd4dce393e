//! The `.vtu` XML writer: ASCII, or inline base64 binary with a `UInt64` byte-count header
//! (VTK's uncompressed "binary" format, which ParaView reads as is).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

use super::grid::{Field, FieldValues, UnstructuredGrid};
use crate::error::{IoError, Result};

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
    const SIZE: usize;
    fn extend(self, out: &mut Vec<u8>);
}

macro_rules! impl_bytes {
    ($($t:ty => $name:literal),*) => {$(
        impl Bytes for $t {
            const VTK_TYPE: &'static str = $name;
            const SIZE: usize = std::mem::size_of::<$t>();
            fn extend(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}

impl_bytes!(f64 => "Float64", i32 => "Int32", u64 => "UInt64", u8 => "UInt8");

/// Bytes base64-encoded per chunk, a multiple of 3 long so that the chunks' encodings
/// concatenate to the encoding of the whole (no padding before the end): a frame is
/// written without ever holding its encoded document, or even one whole encoded array.
const BASE64_CHUNK: usize = 3 * 4096;

/// Base64 of a byte stream, written to `out` as it comes.
struct Base64Stream<'a, W: Write> {
    out: &'a mut W,
    pending: Vec<u8>,
    encoded: String,
}

impl<'a, W: Write> Base64Stream<'a, W> {
    fn new(out: &'a mut W) -> Self {
        Self {
            out,
            pending: Vec::with_capacity(BASE64_CHUNK + 8),
            encoded: String::with_capacity(BASE64_CHUNK / 3 * 4 + 4),
        }
    }

    /// Encodes and writes the whole chunks gathered so far.
    fn drain(&mut self) -> std::io::Result<()> {
        let whole = self.pending.len() / 3 * 3;
        if whole >= BASE64_CHUNK {
            self.encoded.clear();
            STANDARD.encode_string(&self.pending[..whole], &mut self.encoded);
            self.out.write_all(self.encoded.as_bytes())?;
            self.pending.drain(..whole);
        }
        Ok(())
    }

    fn push<T: Bytes>(&mut self, value: T) -> std::io::Result<()> {
        value.extend(&mut self.pending);
        self.drain()
    }

    /// Encodes the rest, with its padding.
    fn finish(self) -> std::io::Result<()> {
        let mut encoded = self.encoded;
        encoded.clear();
        STANDARD.encode_string(&self.pending, &mut encoded);
        self.out.write_all(encoded.as_bytes())
    }
}

/// One `<DataArray>`: the values come from an iterator, so a caller can write a derived
/// array (padded coordinates, cell types) without collecting it first.
fn data_array<T: Bytes, W: Write>(
    out: &mut W,
    name: Option<&str>,
    components: usize,
    values: impl ExactSizeIterator<Item = T>,
    encoding: Encoding,
) -> std::io::Result<()> {
    write!(out, "        <DataArray type=\"{}\"", T::VTK_TYPE)?;
    if let Some(name) = name {
        write!(out, " Name=\"{}\"", escape(name))?;
    }
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Binary => "binary",
    };
    write!(
        out,
        " NumberOfComponents=\"{components}\" format=\"{format}\">\n          "
    )?;
    match encoding {
        Encoding::Ascii => {
            for (i, v) in values.enumerate() {
                if i > 0 {
                    out.write_all(b" ")?;
                }
                write!(out, "{v}")?;
            }
        }
        Encoding::Binary => {
            let payload = (values.len() * T::SIZE) as u64;
            let mut stream = Base64Stream::new(out);
            stream.push(payload)?;
            for v in values {
                stream.push(v)?;
            }
            stream.finish()?;
        }
    }
    out.write_all(b"\n        </DataArray>\n")
}

fn fields<W: Write>(
    out: &mut W,
    tag: &str,
    fields: &[Field],
    encoding: Encoding,
) -> std::io::Result<()> {
    if fields.is_empty() {
        return Ok(());
    }
    writeln!(out, "      <{tag}>")?;
    for f in fields {
        let name = Some(f.name.as_str());
        match &f.values {
            FieldValues::Float64(v) => {
                data_array(out, name, f.components, v.iter().copied(), encoding)?
            }
            FieldValues::Int32(v) => {
                data_array(out, name, f.components, v.iter().copied(), encoding)?
            }
        }
    }
    writeln!(out, "      </{tag}>")
}

impl UnstructuredGrid {
    /// The `.vtu` document.
    pub fn to_vtu(&self, encoding: Encoding) -> String {
        let mut out = Vec::new();
        self.write_document(&mut out, encoding)
            .expect("writing to memory does not fail");
        String::from_utf8(out).expect("the document is ASCII")
    }

    /// Writes the `.vtu` file, streaming: memory beyond the grid itself stays a few
    /// buffers, whatever the size of the frame.
    pub fn write_vtu(&self, path: impl AsRef<Path>, encoding: Encoding) -> Result<()> {
        let path = path.as_ref();
        let error = |source| IoError::File {
            path: path.to_path_buf(),
            source,
        };
        let mut file = BufWriter::new(File::create(path).map_err(error)?);
        self.write_document(&mut file, encoding).map_err(error)?;
        file.flush().map_err(error)
    }

    /// The document, streamed into `out`.
    fn write_document<W: Write>(&self, out: &mut W, encoding: Encoding) -> std::io::Result<()> {
        out.write_all(b"<?xml version=\"1.0\"?>\n")?;
        out.write_all(
            b"<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        )?;
        out.write_all(b"  <UnstructuredGrid>\n")?;
        writeln!(
            out,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len(),
            self.cell_count()
        )?;
        fields(out, "PointData", &self.point_data, encoding)?;
        fields(out, "CellData", &self.cell_data, encoding)?;
        out.write_all(b"      <Points>\n")?;
        let coordinates = self.points.iter().flatten().copied();
        data_array(
            out,
            Some("Points"),
            3,
            ExactLen(coordinates, 3 * self.points.len()),
            encoding,
        )?;
        out.write_all(b"      </Points>\n      <Cells>\n")?;
        data_array(
            out,
            Some("connectivity"),
            1,
            self.connectivity.iter().copied(),
            encoding,
        )?;
        data_array(
            out,
            Some("offsets"),
            1,
            self.offsets.iter().copied(),
            encoding,
        )?;
        let types = self.types.iter().map(|t| t.vtk_id());
        data_array(out, Some("types"), 1, types, encoding)?;
        out.write_all(b"      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    }
}

/// An iterator with its length known in advance (a flattened one does not say).
struct ExactLen<I>(I, usize);

impl<I: Iterator> Iterator for ExactLen<I> {
    type Item = I::Item;
    fn next(&mut self) -> Option<I::Item> {
        let item = self.0.next()?;
        self.1 -= 1;
        Some(item)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.1, Some(self.1))
    }
}

impl<I: Iterator> ExactSizeIterator for ExactLen<I> {}
