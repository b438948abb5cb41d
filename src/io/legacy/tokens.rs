//! The byte cursor under the legacy VTK reader.
//!
//! A legacy file is a stream of whitespace-separated ASCII tokens (keywords,
//! counts, names, type names) interleaved, in `BINARY` files, with raw
//! big-endian arrays that start right after the newline that ends the line
//! announcing them. [`Cursor`] walks the bytes once: it hands out tokens,
//! counts lines while it skips whitespace (so ASCII errors name a line), and
//! decodes arrays in either encoding. Binary files report byte offsets, since
//! line numbers stop meaning anything after the first raw array.
//!
//! Every array read first checks its size against the bytes left in the file
//! (for ASCII: every value needs at least one digit and one separator), so a
//! header claiming 10^12 values is refused before anything is allocated.
//! Values that fail validation later (an out-of-range point id, a NaN
//! coordinate) are located through [`Span`]: a byte offset computed from the
//! index in binary files, a re-scan of the section in ASCII files (error path
//! only).

use std::path::Path;

use crate::field::ArrayData;
use crate::io::{IoError, Location};

/// The value types a legacy file may name for an array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ValueType {
    Bit,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl ValueType {
    /// Parses a legacy type name (`float`, `unsigned_char`, `vtktypeint64`, ...).
    pub(crate) fn parse(tok: &[u8]) -> Option<ValueType> {
        let t = tok.to_ascii_lowercase();
        Some(match t.as_slice() {
            b"bit" => ValueType::Bit,
            b"char" | b"signed_char" | b"vtktypeint8" => ValueType::I8,
            b"unsigned_char" | b"vtktypeuint8" => ValueType::U8,
            b"short" | b"vtktypeint16" => ValueType::I16,
            b"unsigned_short" | b"vtktypeuint16" => ValueType::U16,
            b"int" | b"vtktypeint32" => ValueType::I32,
            b"unsigned_int" | b"vtktypeuint32" => ValueType::U32,
            // `long` is 8 bytes on the LP64 platforms that write these files.
            b"long" | b"vtktypeint64" | b"vtkidtype" => ValueType::I64,
            b"unsigned_long" | b"vtktypeuint64" => ValueType::U64,
            b"float" | b"vtktypefloat32" => ValueType::F32,
            b"double" | b"vtktypefloat64" => ValueType::F64,
            _ => return None,
        })
    }

    /// Bytes per value in a binary file (bits are packed, see [`Cursor::read_values`]).
    pub(crate) fn size(self) -> usize {
        match self {
            ValueType::Bit | ValueType::I8 | ValueType::U8 => 1,
            ValueType::I16 | ValueType::U16 => 2,
            ValueType::I32 | ValueType::U32 | ValueType::F32 => 4,
            ValueType::I64 | ValueType::U64 | ValueType::F64 => 8,
        }
    }

    /// The VTK XML type name used in [`crate::field::DataArray::vtk_type`].
    pub(crate) fn vtk_name(self) -> &'static str {
        match self {
            ValueType::Bit | ValueType::U8 => "UInt8",
            ValueType::I8 => "Int8",
            ValueType::I16 => "Int16",
            ValueType::U16 => "UInt16",
            ValueType::I32 => "Int32",
            ValueType::U32 => "UInt32",
            ValueType::I64 => "Int64",
            ValueType::U64 => "UInt64",
            ValueType::F32 => "Float32",
            ValueType::F64 => "Float64",
        }
    }
}

/// Where an array's values start, to locate a bad value after the fact.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Span {
    start: usize,
    line: usize,
    elem: usize,
    bits: bool,
}

/// A cursor over the bytes of a legacy file.
pub(crate) struct Cursor<'a> {
    path: &'a Path,
    buf: &'a [u8],
    pos: usize,
    line: usize,
    binary: bool,
    tok_pos: usize,
    tok_line: usize,
}

fn is_ws(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `buf`; `path` only names the file in errors.
    pub(crate) fn new(path: &'a Path, buf: &'a [u8]) -> Cursor<'a> {
        Cursor {
            path,
            buf,
            pos: 0,
            line: 1,
            binary: false,
            tok_pos: 0,
            tok_line: 1,
        }
    }

    /// Switches to binary mode: arrays are raw big-endian, locations are bytes.
    pub(crate) fn set_binary(&mut self, binary: bool) {
        self.binary = binary;
    }

    /// Whether the file is `BINARY`.
    pub(crate) fn is_binary(&self) -> bool {
        self.binary
    }

    /// Bytes not yet consumed.
    pub(crate) fn remaining(&self) -> usize {
        self.buf.len().saturating_sub(self.pos)
    }

    /// Total file size in bytes.
    pub(crate) fn len(&self) -> usize {
        self.buf.len()
    }

    /// Location of the last token read.
    pub(crate) fn loc(&self) -> Location {
        if self.binary {
            Location::Byte(self.tok_pos as u64)
        } else {
            Location::Line(self.tok_line)
        }
    }

    /// Location of the cursor itself (used at end of file).
    pub(crate) fn loc_here(&self) -> Location {
        if self.binary {
            Location::Byte(self.pos as u64)
        } else {
            Location::Line(self.line)
        }
    }

    /// An error at the last token.
    pub(crate) fn err(&self, msg: impl Into<String>) -> IoError {
        IoError::parse(self.path, self.loc(), msg)
    }

    /// An error at a given location.
    pub(crate) fn err_at(&self, loc: Location, msg: impl Into<String>) -> IoError {
        IoError::parse(self.path, loc, msg)
    }

    fn skip_ws(&mut self) {
        while let Some(&b) = self.buf.get(self.pos) {
            if !is_ws(b) {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// The next whitespace-delimited token, `None` at end of file.
    pub(crate) fn next_token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        if self.pos >= self.buf.len() {
            self.tok_pos = self.pos;
            self.tok_line = self.line;
            return None;
        }
        let start = self.pos;
        while self.pos < self.buf.len() && !is_ws(self.buf[self.pos]) {
            self.pos += 1;
        }
        self.tok_pos = start;
        self.tok_line = self.line;
        Some(&self.buf[start..self.pos])
    }

    /// The next token, or an error naming what was expected.
    pub(crate) fn token(&mut self, what: &str) -> Result<&'a [u8], IoError> {
        match self.next_token() {
            Some(t) => Ok(t),
            None => Err(self.err_at(
                self.loc_here(),
                format!("unexpected end of file, expected {what}"),
            )),
        }
    }

    /// The next token if it is on the current line (spaces and tabs skipped).
    pub(crate) fn token_on_line(&mut self) -> Option<&'a [u8]> {
        while let Some(&b) = self.buf.get(self.pos) {
            if b == b' ' || b == b'\t' || b == b'\r' {
                self.pos += 1;
            } else {
                break;
            }
        }
        match self.buf.get(self.pos) {
            None | Some(b'\n') => None,
            Some(_) => self.next_token(),
        }
    }

    /// A non-negative count.
    pub(crate) fn count(&mut self, what: &str) -> Result<usize, IoError> {
        let t = self.token(what)?;
        let s = std::str::from_utf8(t).unwrap_or("");
        match s.parse::<i64>() {
            Ok(v) if v >= 0 => {
                usize::try_from(v).map_err(|_| self.err(format!("{what} {v} is too large")))
            }
            Ok(v) => Err(self.err(format!("{what} must not be negative, got {v}"))),
            Err(_) => Err(self.err(format!("expected {what} (an integer), got '{}'", show(t)))),
        }
    }

    /// A floating-point header value (ORIGIN, SPACING).
    pub(crate) fn real(&mut self, what: &str) -> Result<f64, IoError> {
        let t = self.token(what)?;
        let v = std::str::from_utf8(t)
            .ok()
            .and_then(|s| s.parse::<f64>().ok());
        match v {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(self.err(format!(
                "expected {what} (a finite number), got '{}'",
                show(t)
            ))),
        }
    }

    /// A value type name.
    pub(crate) fn value_type(&mut self) -> Result<ValueType, IoError> {
        let t = self.token("a data type")?;
        ValueType::parse(t).ok_or_else(|| self.err(format!("unsupported data type '{}'", show(t))))
    }

    /// Consumes the next token if it equals `kw` (ignoring case).
    pub(crate) fn accept_keyword(&mut self, kw: &str) -> bool {
        let saved = (self.pos, self.line, self.tok_pos, self.tok_line);
        if let Some(t) = self.next_token() {
            if t.eq_ignore_ascii_case(kw.as_bytes()) {
                return true;
            }
        }
        (self.pos, self.line, self.tok_pos, self.tok_line) = saved;
        false
    }

    /// The rest of the current line (without the newline), consuming it.
    pub(crate) fn line_rest(&mut self) -> &'a [u8] {
        let start = self.pos;
        let rest = &self.buf[start.min(self.buf.len())..];
        match rest.iter().position(|&b| b == b'\n') {
            Some(i) => {
                self.pos = start + i + 1;
                self.line += 1;
                &rest[..i]
            }
            None => {
                self.pos = self.buf.len();
                rest
            }
        }
    }

    /// Skips a `METADATA` block (the keyword already read): every line up to
    /// and including the first empty one.
    pub(crate) fn skip_metadata(&mut self) {
        self.line_rest();
        while self.pos < self.buf.len() {
            if self.line_rest().iter().all(|&b| is_ws(b)) {
                break;
            }
        }
    }

    /// Reads `n` values of type `ty` (ASCII tokens or raw big-endian bytes).
    pub(crate) fn read_values(
        &mut self,
        n: usize,
        ty: ValueType,
        what: &str,
    ) -> Result<(ArrayData, Span), IoError> {
        if self.binary {
            self.read_binary(n, ty, what)
        } else {
            self.read_ascii(n, ty, what)
        }
    }

    fn read_binary(
        &mut self,
        n: usize,
        ty: ValueType,
        what: &str,
    ) -> Result<(ArrayData, Span), IoError> {
        // The data starts after the newline that ends the announcing line.
        self.line_rest();
        let start = self.pos;
        let nbytes = if ty == ValueType::Bit {
            Some(n.div_ceil(8))
        } else {
            n.checked_mul(ty.size())
        };
        let rem = self.remaining();
        let nbytes = match nbytes {
            Some(b) if b <= rem => b,
            _ => {
                return Err(self.err_at(
                    Location::Byte(start as u64),
                    format!(
                        "{what}: {n} binary values of {} bytes do not fit in the {rem} bytes left (truncated or corrupt count)",
                        ty.size()
                    ),
                ))
            }
        };
        let raw = &self.buf[start..start + nbytes];
        self.pos = start + nbytes;
        self.tok_pos = start;
        let span = Span {
            start,
            line: self.line,
            elem: ty.size(),
            bits: ty == ValueType::Bit,
        };
        let data = decode_be(raw, n, ty).map_err(|i| {
            self.err_at(
                Location::Byte((start + i * ty.size()) as u64),
                format!("{what}: value {i} does not fit in a 64-bit signed integer"),
            )
        })?;
        Ok((data, span))
    }

    fn read_ascii(
        &mut self,
        n: usize,
        ty: ValueType,
        what: &str,
    ) -> Result<(ArrayData, Span), IoError> {
        let rem = self.remaining();
        if n > rem / 2 + 1 {
            return Err(self.err(format!(
                "{what}: {n} values cannot fit in the {rem} bytes left (truncated or corrupt count)"
            )));
        }
        self.skip_ws();
        let span = Span {
            start: self.pos,
            line: self.line,
            elem: 0,
            bits: false,
        };
        let data = match ty {
            ValueType::F32 => {
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push(self.ascii_num::<f32>(what)?);
                }
                ArrayData::F32(v)
            }
            ValueType::F64 => {
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push(self.ascii_num::<f64>(what)?);
                }
                ArrayData::F64(v)
            }
            ValueType::U64 => {
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    let x = self.ascii_num::<u64>(what)?;
                    let x = i64::try_from(x).map_err(|_| {
                        self.err(format!(
                            "{what}: value {x} does not fit in a 64-bit signed integer"
                        ))
                    })?;
                    v.push(x);
                }
                ArrayData::Int(v)
            }
            _ => {
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push(self.ascii_num::<i64>(what)?);
                }
                ArrayData::Int(v)
            }
        };
        Ok((data, span))
    }

    fn ascii_num<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, IoError> {
        let t = self.token(what)?;
        std::str::from_utf8(t)
            .ok()
            .and_then(|s| s.parse::<T>().ok())
            .ok_or_else(|| self.err(format!("{what}: invalid number '{}'", show(t))))
    }

    /// The location of value `idx` of an array read with [`Cursor::read_values`].
    pub(crate) fn value_location(&self, span: Span, idx: usize) -> Location {
        if self.binary {
            let off = if span.bits {
                span.start + idx / 8
            } else {
                span.start.saturating_add(idx.saturating_mul(span.elem))
            };
            return Location::Byte(off as u64);
        }
        let mut c = Cursor::new(self.path, self.buf);
        c.pos = span.start;
        c.line = span.line;
        for _ in 0..=idx {
            if c.next_token().is_none() {
                break;
            }
        }
        Location::Line(c.tok_line)
    }
}

/// Decodes big-endian values; `Err(i)` names a value that overflows `i64`.
fn decode_be(raw: &[u8], n: usize, ty: ValueType) -> Result<ArrayData, usize> {
    fn ints<const N: usize>(raw: &[u8], f: impl Fn([u8; N]) -> i64) -> ArrayData {
        ArrayData::Int(
            raw.chunks_exact(N)
                .map(|c| {
                    let mut a = [0u8; N];
                    a.copy_from_slice(c);
                    f(a)
                })
                .collect(),
        )
    }
    Ok(match ty {
        ValueType::Bit => ArrayData::Int(
            (0..n)
                .map(|i| i64::from((raw.get(i / 8).copied().unwrap_or(0) >> (7 - i % 8)) & 1))
                .collect(),
        ),
        ValueType::I8 => ints::<1>(raw, |a| i64::from(a[0] as i8)),
        ValueType::U8 => ints::<1>(raw, |a| i64::from(a[0])),
        ValueType::I16 => ints::<2>(raw, |a| i64::from(i16::from_be_bytes(a))),
        ValueType::U16 => ints::<2>(raw, |a| i64::from(u16::from_be_bytes(a))),
        ValueType::I32 => ints::<4>(raw, |a| i64::from(i32::from_be_bytes(a))),
        ValueType::U32 => ints::<4>(raw, |a| i64::from(u32::from_be_bytes(a))),
        ValueType::I64 => ints::<8>(raw, i64::from_be_bytes),
        ValueType::U64 => {
            let mut v = Vec::with_capacity(n);
            for (i, c) in raw.chunks_exact(8).enumerate() {
                let mut a = [0u8; 8];
                a.copy_from_slice(c);
                v.push(i64::try_from(u64::from_be_bytes(a)).map_err(|_| i)?);
            }
            ArrayData::Int(v)
        }
        ValueType::F32 => ArrayData::F32(
            raw.chunks_exact(4)
                .map(|c| f32::from_be_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        ValueType::F64 => ArrayData::F64(
            raw.chunks_exact(8)
                .map(|c| f64::from_be_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
                .collect(),
        ),
    })
}

/// A token shown in a message: lossy UTF-8, cut to 40 characters.
pub(crate) fn show(t: &[u8]) -> String {
    let s = String::from_utf8_lossy(&t[..t.len().min(40)]).into_owned();
    if t.len() > 40 {
        format!("{s}...")
    } else {
        s
    }
}
