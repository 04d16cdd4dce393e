//! A cursor over the bytes of an MSH file: whitespace-separated ASCII tokens with line
//! numbers, and fixed-size binary values with byte offsets.

use crate::error::{IoError, Position, Result};

/// Longest excerpt of a bad field quoted in an error message.
const QUOTE_LIMIT: usize = 40;

/// Byte order of binary data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Endian {
    Little,
    Big,
}

pub(crate) struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Line of `pos` (1-based), kept up to date by the ASCII readers only.
    line: usize,
    /// Whether the file is binary (errors then report byte offsets: line numbers mean
    /// nothing once binary data has been passed).
    pub(crate) binary: bool,
    pub(crate) endian: Endian,
    /// The section being read, for messages.
    pub(crate) section: &'static str,
}

fn quote(text: &[u8]) -> String {
    let text = String::from_utf8_lossy(text);
    if text.chars().count() > QUOTE_LIMIT {
        format!("{}…", text.chars().take(QUOTE_LIMIT).collect::<String>())
    } else {
        text.into_owned()
    }
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            pos: 0,
            line: 1,
            binary: false,
            endian: Endian::Little,
            section: "MeshFormat",
        }
    }

    /// Where the cursor is, as a line (ASCII) or byte offset (binary).
    pub(crate) fn position(&self) -> Position {
        if self.binary {
            Position::Byte(self.pos)
        } else {
            Position::Line(self.line)
        }
    }

    /// Bytes left to read (bounds pre-allocation by declared counts).
    pub(crate) fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    pub(crate) fn truncated(&self, expected: &'static str) -> IoError {
        IoError::Truncated {
            at: self.position(),
            section: self.section,
            expected,
        }
    }

    pub(crate) fn malformed(&self, message: impl Into<String>) -> IoError {
        IoError::Malformed {
            at: self.position(),
            message: message.into(),
        }
    }

    fn skip_whitespace(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if b == b'\n' {
                self.line += 1;
            } else if !b.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
    }

    /// The next whitespace-separated token and the line it starts on.
    pub(crate) fn token(&mut self, expected: &'static str) -> Result<(&'a [u8], Position)> {
        self.skip_whitespace();
        let at = self.position();
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.truncated(expected));
        }
        Ok((&self.bytes[start..self.pos], at))
    }

    fn bad_field(&self, at: Position, expected: &'static str, found: &[u8]) -> IoError {
        IoError::BadField {
            at,
            section: self.section,
            expected,
            found: quote(found),
        }
    }

    /// The next token parsed as `T`.
    pub(crate) fn parse<T: std::str::FromStr>(&mut self, expected: &'static str) -> Result<T> {
        self.parse_at(expected).map(|(value, _)| value)
    }

    /// The next token parsed as `T`, and where it starts.
    pub(crate) fn parse_at<T: std::str::FromStr>(
        &mut self,
        expected: &'static str,
    ) -> Result<(T, Position)> {
        let (token, at) = self.token(expected)?;
        std::str::from_utf8(token)
            .ok()
            .and_then(|s| s.parse().ok())
            .map(|value| (value, at))
            .ok_or_else(|| self.bad_field(at, expected, token))
    }

    /// The next token as a count, which must not exceed what the remaining bytes could
    /// hold at `min_bytes` per item (so that a corrupt count cannot trigger a huge allocation).
    pub(crate) fn count(&mut self, expected: &'static str, min_bytes: usize) -> Result<usize> {
        let (n, at) = self.parse_at::<usize>(expected)?;
        self.check_count(at, expected, n, min_bytes)
    }

    pub(crate) fn check_count(
        &self,
        at: Position,
        expected: &'static str,
        n: usize,
        min_bytes: usize,
    ) -> Result<usize> {
        if n.saturating_mul(min_bytes.max(1)) > self.remaining() {
            Err(IoError::BadField {
                at,
                section: self.section,
                expected,
                found: format!(
                    "{n} (more than the {} bytes left can hold)",
                    self.remaining()
                ),
            })
        } else {
            Ok(n)
        }
    }

    /// Skips the rest of the current line, including its newline.
    pub(crate) fn skip_line(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            self.pos += 1;
            if b == b'\n' {
                self.line += 1;
                return;
            }
        }
    }

    /// The rest of the current line (without the newline), consuming it.
    pub(crate) fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        while self.bytes.get(self.pos).is_some_and(|&b| b != b'\n') {
            self.pos += 1;
        }
        let line = &self.bytes[start..self.pos];
        self.skip_line();
        line
    }

    /// Expects the next token to be `$End<section>`.
    pub(crate) fn expect_end(&mut self, section: &'static str) -> Result<()> {
        let (token, at) = self.token("a section end")?;
        let expected = format!("$End{section}");
        if token != expected.as_bytes() {
            return Err(IoError::Malformed {
                at,
                message: format!("expected {expected}, found `{}`", quote(token)),
            });
        }
        Ok(())
    }

    /// Skips an unknown section up to and including `$End<name>`.
    pub(crate) fn skip_section(&mut self, name: &str) -> Result<()> {
        let end = format!("$End{name}");
        loop {
            self.skip_whitespace();
            if self.pos >= self.bytes.len() {
                return Err(self.malformed(format!("file ends before {end}")));
            }
            let line = self.rest_of_line();
            if line.strip_suffix(b"\r").unwrap_or(line) == end.as_bytes() {
                return Ok(());
            }
        }
    }

    /// Ends the ASCII header of a binary block: binary data starts after the next newline.
    pub(crate) fn start_binary(&mut self) {
        if !self.binary {
            return;
        }
        while let Some(&b) = self.bytes.get(self.pos) {
            if b == b'\n' {
                self.pos += 1;
                self.line += 1;
                break;
            }
            if !b.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
    }

    fn take<const N: usize>(&mut self, expected: &'static str) -> Result<[u8; N]> {
        let bytes = self
            .bytes
            .get(self.pos..self.pos + N)
            .ok_or_else(|| self.truncated(expected))?;
        self.pos += N;
        let mut out = [0; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }

    /// A binary 4-byte signed integer.
    pub(crate) fn int(&mut self, expected: &'static str) -> Result<i32> {
        let b = self.take::<4>(expected)?;
        Ok(match self.endian {
            Endian::Little => i32::from_le_bytes(b),
            Endian::Big => i32::from_be_bytes(b),
        })
    }

    /// A binary 8-byte unsigned integer (`size_t`).
    pub(crate) fn size(&mut self, expected: &'static str) -> Result<u64> {
        let b = self.take::<8>(expected)?;
        Ok(match self.endian {
            Endian::Little => u64::from_le_bytes(b),
            Endian::Big => u64::from_be_bytes(b),
        })
    }

    /// A binary `size_t` count, bounded like [`Self::count`].
    pub(crate) fn size_count(&mut self, expected: &'static str, min_bytes: usize) -> Result<usize> {
        let at = self.position();
        let n = self.size(expected)?;
        let n = usize::try_from(n).unwrap_or(usize::MAX);
        self.check_count(at, expected, n, min_bytes)
    }

    /// A binary 8-byte float.
    pub(crate) fn double(&mut self, expected: &'static str) -> Result<f64> {
        let b = self.take::<8>(expected)?;
        Ok(match self.endian {
            Endian::Little => f64::from_le_bytes(b),
            Endian::Big => f64::from_be_bytes(b),
        })
    }
}
