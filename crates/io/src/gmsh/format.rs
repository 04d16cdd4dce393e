//! The `$MeshFormat` header and the section loop shared by both format versions.

use super::cursor::{Cursor, Endian};
use super::raw::RawMsh;
use super::{v2, v4};
use crate::error::{IoError, Result};

/// The format versions this reader handles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MshVersion {
    /// MSH 2.2, ASCII.
    V22,
    /// MSH 4.1, ASCII.
    V41Ascii,
    /// MSH 4.1, binary.
    V41Binary,
}

fn read_header(c: &mut Cursor<'_>) -> Result<MshVersion> {
    let (first, at) = c.token("$MeshFormat")?;
    if first != b"$MeshFormat" {
        return Err(IoError::Malformed {
            at,
            message: "not a Gmsh MSH file: it does not start with $MeshFormat".into(),
        });
    }
    let (version, at) = c.token("the format version")?;
    let version = String::from_utf8_lossy(version).into_owned();
    let file_type: i32 = c.parse("the file type (0 ASCII, 1 binary)")?;
    let data_size: i32 = c.parse("the data size")?;
    let format = match (version.as_str(), file_type) {
        ("2.2", 0) => MshVersion::V22,
        ("4.1", 0) => MshVersion::V41Ascii,
        ("4.1", 1) if data_size == 8 => MshVersion::V41Binary,
        _ => {
            let mode = if file_type == 0 { "ASCII" } else { "binary" };
            return Err(IoError::UnsupportedVersion {
                at,
                version: format!("{version} {mode} (data size {data_size})"),
            });
        }
    };
    if format == MshVersion::V41Binary {
        c.binary = true;
        c.start_binary();
        let at = c.position();
        let one = c.int("the endianness marker")?;
        c.endian = match one {
            1 => Endian::Little,
            0x0100_0000 => Endian::Big,
            _ => {
                return Err(IoError::Malformed {
                    at,
                    message: format!("binary endianness marker is {one}, expected 1"),
                });
            }
        };
    }
    c.expect_end("MeshFormat")?;
    Ok(format)
}

fn read_physical_names(c: &mut Cursor<'_>, raw: &mut RawMsh) -> Result<()> {
    let n = c.count("the number of physical names", 6)?;
    for _ in 0..n {
        let (dim, at) = c.parse_at::<usize>("a physical group dimension")?;
        if dim > 3 {
            return Err(IoError::BadField {
                at,
                section: c.section,
                expected: "a physical group dimension 0..=3",
                found: dim.to_string(),
            });
        }
        let tag: i32 = c.parse("a physical tag")?;
        let rest = String::from_utf8_lossy(c.rest_of_line()).into_owned();
        let name = match (rest.find('"'), rest.rfind('"')) {
            (Some(a), Some(b)) if b > a => rest[a + 1..b].to_string(),
            _ => {
                return Err(IoError::BadField {
                    at,
                    section: c.section,
                    expected: "a quoted physical name",
                    found: rest.trim().to_string(),
                });
            }
        };
        raw.names.insert((dim, tag), name);
    }
    Ok(())
}

/// Parses a whole file into its raw contents.
pub(crate) fn parse_raw(bytes: &[u8]) -> Result<(MshVersion, RawMsh)> {
    let mut c = Cursor::new(bytes);
    let version = read_header(&mut c)?;
    let mut raw = RawMsh::default();
    let mut physicals = v4::EntityPhysicals::new();
    let (mut has_nodes, mut has_elements) = (false, false);
    loop {
        let (token, at) = match c.token("a section") {
            Ok(t) => t,
            Err(IoError::Truncated { .. }) => break,
            Err(e) => return Err(e),
        };
        let Some(name) = token.strip_prefix(b"$") else {
            return Err(IoError::Malformed {
                at,
                message: format!(
                    "expected a $Section, found `{}`",
                    String::from_utf8_lossy(&token[..token.len().min(40)])
                ),
            });
        };
        let name = String::from_utf8_lossy(name).into_owned();
        let section: &'static str = match name.as_str() {
            "PhysicalNames" => "PhysicalNames",
            "Entities" if version != MshVersion::V22 => "Entities",
            "PartitionedEntities" if version != MshVersion::V22 => "PartitionedEntities",
            "Nodes" => "Nodes",
            "Elements" => "Elements",
            _ => {
                c.skip_section(&name)?;
                continue;
            }
        };
        c.section = section;
        match section {
            "PhysicalNames" => read_physical_names(&mut c, &mut raw)?,
            // Model and partitioned entities have distinct tags; elements of a partitioned
            // file refer to the latter.
            "Entities" => physicals.extend(v4::read_entities(&mut c)?),
            "PartitionedEntities" => physicals.extend(v4::read_partitioned_entities(&mut c)?),
            "Nodes" if has_nodes => return Err(c.malformed("a second $Nodes section")),
            "Elements" if has_elements => return Err(c.malformed("a second $Elements section")),
            "Nodes" if version == MshVersion::V22 => v2::read_nodes(&mut c, &mut raw)?,
            "Nodes" => v4::read_nodes(&mut c, &mut raw)?,
            "Elements" if version == MshVersion::V22 => v2::read_elements(&mut c, &mut raw)?,
            _ => v4::read_elements(&mut c, &mut raw, &physicals)?,
        }
        has_nodes |= section == "Nodes";
        has_elements |= section == "Elements";
        c.expect_end(section)?;
    }
    if !has_nodes {
        return Err(IoError::MissingSection { section: "Nodes" });
    }
    if !has_elements {
        return Err(IoError::MissingSection {
            section: "Elements",
        });
    }
    Ok((version, raw))
}
