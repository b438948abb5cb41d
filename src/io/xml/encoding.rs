//! Decoding one `<DataArray>` into a typed `Vec`: every VTK XML encoding.
//!
//! A data array is stored in one of three ways:
//! - `format="ascii"`: whitespace-separated numbers in the element's text;
//! - `format="binary"`: base64 in the element's text;
//! - `format="appended"` with `offset=`: in the `<AppendedData>` block, raw
//!   bytes or base64 (per the block's `encoding`).
//!
//! Binary payloads start with a header of `header_type` words (UInt32 or
//! UInt64, in the file's `byte_order`). Uncompressed: one word, the payload
//! size in bytes, then the bytes (in base64 both share one stream). Compressed
//! (`vtkZLibDataCompressor`, `vtkLZ4DataCompressor`, `vtkLZMADataCompressor`):
//! `[nblocks, block_size, last_block_size, compressed_size_0 ..]`, then the
//! compressed blocks (zlib streams, raw LZ4 blocks, or `.xz` streams, as
//! liblzma's `lzma_easy_buffer_encode` writes them); in base64 the header and
//! the blocks are two separately padded streams.
//!
//! Hostile input: every size read from a header is checked before anything
//! is allocated from it. Uncompressed sizes must fit in the bytes present;
//! compressed blocks must be present, and each block's uncompressed size may
//! not exceed its compressed size times the format's maximum ratio (1032:1
//! for deflate, 255:1 for LZ4, [`LZMA_MAX_RATIO`] for LZMA). When the caller
//! knows how many values the
//! array must hold (from `NumberOfPoints` and friends), the decoded size must
//! match it exactly.
//!
//! Speed: blocks are inflated in parallel (rayon), each into a per-thread
//! scratch buffer that is converted straight into its slot of the target
//! `Vec` (no whole-array intermediate copy); large base64 texts are decoded in
//! parallel chunks; raw appended data is converted straight from the file's
//! bytes.

use std::borrow::Cow;
use std::cell::Cell;
use std::path::Path;

use base64::engine::{DecodePaddingMode, Engine, GeneralPurpose, GeneralPurposeConfig};
use rayon::prelude::*;

use super::dom::{Appended, AppendedEncoding, Element};
use super::scalar::{convert_bytes, convert_par};
pub use super::scalar::{Scalar, Target};
use crate::io::IoError;

/// Deflate's maximum compression ratio (a 258-byte match per 2 bits).
const ZLIB_MAX_RATIO: u64 = 1032;
/// LZ4's maximum compression ratio (one 255-extension byte per 255 bytes).
const LZ4_MAX_RATIO: u64 = 255;
/// A bound on LZMA's compression ratio for one block. LZMA has no small
/// hard limit (a long run costs a fraction of a bit per 273-byte match);
/// `xz` makes about 7000:1 of a gigabyte of zeros, and VTK's blocks (32 KiB
/// by default) reach a few hundred to one, the stream's own framing being
/// some 60 bytes. 2^14:1 admits every real file; the memory budget
/// ([`IoError`] on exceeding it) bounds what a hostile header can claim.
pub const LZMA_MAX_RATIO: u64 = 1 << 14;
/// Slack per block on top of the ratio bound (stream headers, tiny blocks).
const BLOCK_SLACK: u64 = 64;
/// Base64 characters decoded per parallel task (a multiple of 4).
const B64_CHUNK: usize = 1 << 20;

const B64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new()
        .with_decode_padding_mode(DecodePaddingMode::Indifferent)
        .with_decode_allow_trailing_bits(true),
);

/// The file's compressor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compressor {
    None,
    Zlib,
    Lz4,
    Lzma,
}

/// File-wide encoding settings from the `<VTKFile>` attributes.
#[derive(Clone, Copy, Debug)]
pub struct Codec {
    /// `header_type="UInt64"`.
    pub header64: bool,
    /// `byte_order="BigEndian"`.
    pub big_endian: bool,
    pub compressor: Compressor,
}

impl Codec {
    fn hsize(&self) -> usize {
        if self.header64 {
            8
        } else {
            4
        }
    }

    /// Header word `i` of `buf`, if present.
    fn word(&self, buf: &[u8], i: usize) -> Option<u64> {
        let hs = self.hsize();
        let b = buf.get(i.checked_mul(hs)?..i.checked_mul(hs)?.checked_add(hs)?)?;
        Some(match (self.header64, self.big_endian) {
            (true, false) => u64::from_le_bytes(b.try_into().ok()?),
            (true, true) => u64::from_be_bytes(b.try_into().ok()?),
            (false, false) => u32::from_le_bytes(b.try_into().ok()?) as u64,
            (false, true) => u32::from_be_bytes(b.try_into().ok()?) as u64,
        })
    }
}

/// Base64 length of `n` bytes (padded).
fn enc_len(n: usize) -> usize {
    n.div_ceil(3) * 4
}

/// Decodes base64 (no whitespace), in parallel chunks for long inputs.
fn b64_decode(text: &[u8]) -> Result<Vec<u8>, String> {
    let bad = |e: base64::DecodeSliceError| format!("invalid base64: {e}");
    let est = base64::decoded_len_estimate(text.len());
    let mut out = vec![0u8; est];
    let nfull = text.len().saturating_sub(1) / B64_CHUNK;
    let split_t = nfull * B64_CHUNK;
    let split_o = split_t / 4 * 3;
    let (head_o, tail_o) = out.split_at_mut(split_o);
    text[..split_t]
        .par_chunks(B64_CHUNK)
        .zip(head_o.par_chunks_mut(B64_CHUNK / 4 * 3))
        .try_for_each(|(t, o)| match B64.decode_slice(t, o) {
            Ok(n) if n == o.len() => Ok(()),
            Ok(_) => Err("invalid base64: padding inside the data".to_string()),
            Err(e) => Err(bad(e)),
        })?;
    let n = B64.decode_slice(&text[split_t..], tail_o).map_err(bad)?;
    out.truncate(split_o + n);
    Ok(out)
}

/// The parsed header of a compressed payload.
struct BlockHeader {
    block_size: u64,
    /// Uncompressed size of each block.
    usizes: Vec<u64>,
    /// Compressed size of each block.
    csizes: Vec<u64>,
}

impl BlockHeader {
    fn total(&self) -> u64 {
        self.usizes.iter().sum()
    }
}

/// Where one array's bytes come from, and how to decode them.
pub struct Source<'a> {
    pub path: &'a Path,
    pub bytes: &'a [u8],
    pub codec: Codec,
    pub appended: Option<Appended<'a>>,
    /// Binary bytes decoded so far (see [`Source::charge`]).
    pub spent: Cell<u64>,
}

impl<'a> Source<'a> {
    /// A source over a whole file's bytes.
    pub fn new(
        path: &'a Path,
        bytes: &'a [u8],
        codec: Codec,
        appended: Option<Appended<'a>>,
    ) -> Self {
        Source {
            path,
            bytes,
            codec,
            appended,
            spent: Cell::new(0),
        }
    }

    /// Charges `n` decoded bytes against the file's budget: all arrays
    /// together may not decode to more than the maximum compression ratio
    /// times the file size. Without compression (or with distinct blocks per
    /// array, as every writer does) this never triggers; it stops files whose
    /// arrays share one highly compressed block through repeated offsets.
    fn charge(&self, n: u64) -> Result<(), String> {
        let total = self.spent.get().saturating_add(n);
        let budget = (self.bytes.len() as u64)
            .saturating_mul(ZLIB_MAX_RATIO)
            .saturating_add(BLOCK_SLACK << 20);
        if total > budget {
            return Err(format!(
                "the arrays decode to more than {budget} bytes from a {}-byte file (offsets reused?)",
                self.bytes.len()
            ));
        }
        self.spent.set(total);
        Ok(())
    }

    /// Decodes `el` (a `<DataArray>` of type `ty`). `expected`: the number of
    /// values (tuples x components) the array must hold, when known.
    pub fn decode<T: Target>(
        &self,
        el: &Element,
        ty: Scalar,
        expected: Option<usize>,
    ) -> Result<Vec<T>, IoError> {
        let err = |msg: String| IoError::parse(self.path, el.location(), msg);
        match el.attr("format").unwrap_or("ascii") {
            "ascii" => ascii(&self.text(el), ty, expected).map_err(err),
            "binary" => {
                let text = self.text(el);
                let compact: Cow<[u8]> = if text.iter().any(u8::is_ascii_whitespace) {
                    Cow::Owned(
                        text.iter()
                            .copied()
                            .filter(|b| !b.is_ascii_whitespace())
                            .collect(),
                    )
                } else {
                    text
                };
                self.base64(&compact, ty, expected).map_err(err)
            }
            "appended" => {
                let off: usize = el
                    .attr("offset")
                    .and_then(|o| o.trim().parse().ok())
                    .ok_or_else(|| err("appended DataArray without a valid offset".into()))?;
                let ap = self.appended.ok_or_else(|| {
                    err("format=\"appended\" but the file has no <AppendedData>".into())
                })?;
                let data = ap.data.get(off..).ok_or_else(|| {
                    err(format!(
                        "appended offset {off} is beyond the appended data ({} bytes from byte {})",
                        ap.data.len(),
                        ap.start
                    ))
                })?;
                let at = |m: String| err(format!("appended data at byte {}: {m}", ap.start + off));
                match ap.encoding {
                    AppendedEncoding::Raw => self.raw(data, ty, expected).map_err(at),
                    AppendedEncoding::Base64 => self.base64(data, ty, expected).map_err(at),
                }
            }
            other => Err(err(format!(
                "unknown format '{other}' (expected ascii, binary or appended)"
            ))),
        }
    }

    /// The element's direct text, trimmed (borrowed when in one piece).
    fn text(&self, el: &Element) -> Cow<'a, [u8]> {
        let bytes = self.bytes;
        let seg = |r: &std::ops::Range<usize>| bytes.get(r.clone()).unwrap_or_default();
        let t: Cow<'a, [u8]> = match el.text.as_slice() {
            [] => Cow::Borrowed(&[]),
            [one] => Cow::Borrowed(seg(one)),
            many => Cow::Owned(many.iter().flat_map(|r| seg(r).iter().copied()).collect()),
        };
        let start = t.iter().position(|b| !b.is_ascii_whitespace());
        let end = t.iter().rposition(|b| !b.is_ascii_whitespace());
        match (start, end, t) {
            (Some(s), Some(e), Cow::Borrowed(b)) => Cow::Borrowed(&b[s..=e]),
            (Some(s), Some(e), Cow::Owned(v)) => Cow::Owned(v[s..=e].to_vec()),
            _ => Cow::Borrowed(&[]),
        }
    }

    /// A raw (appended) payload starting at `data[0]`.
    fn raw<T: Target>(
        &self,
        data: &[u8],
        ty: Scalar,
        expected: Option<usize>,
    ) -> Result<Vec<T>, String> {
        let c = self.codec;
        if c.compressor == Compressor::None {
            let size = c.word(data, 0).ok_or("truncated: no size header")?;
            let body = &data[c.hsize()..];
            if size > body.len() as u64 {
                return Err(format!(
                    "header claims {size} bytes but only {} remain in the file",
                    body.len()
                ));
            }
            self.charge(size)?;
            return uncompressed(&body[..size as usize], ty, c.big_endian, expected);
        }
        let n0 = c.word(data, 0).ok_or("truncated compression header")?;
        let hdr_len = header_len(n0, c.hsize(), data.len())?;
        let hdr = self.block_header(&data[..hdr_len])?;
        self.inflate(&hdr, &data[hdr_len..], ty, expected)
    }

    /// A base64 payload (inline text, or appended text from the offset on).
    fn base64<T: Target>(
        &self,
        text: &[u8],
        ty: Scalar,
        expected: Option<usize>,
    ) -> Result<Vec<T>, String> {
        let c = self.codec;
        let hs = c.hsize();
        let hc = enc_len(hs);
        if c.compressor == Compressor::None {
            let first = text.get(..hc).ok_or("truncated base64: no size header")?;
            if text.len() > hc && first.ends_with(b"=") {
                // Header encoded as its own padded stream.
                let h = b64_decode(first)?;
                let size = c.word(&h, 0).ok_or("bad size header")?;
                let need = enc_len(usize::try_from(size).map_err(|_| "size overflows")?);
                let t = text.get(hc..hc + need).ok_or_else(|| {
                    format!("header claims {size} bytes but the base64 text is shorter")
                })?;
                let body = b64_decode(t)?;
                self.charge(size)?;
                return uncompressed(
                    body.get(..size as usize).ok_or("base64 text too short")?,
                    ty,
                    c.big_endian,
                    expected,
                );
            }
            let h = b64_decode(&text[..hc.min(text.len())])?;
            let size = c.word(&h, 0).ok_or("bad size header")?;
            let total = (size as usize).checked_add(hs).ok_or("size overflows")?;
            if enc_len(total) > text.len() {
                return Err(format!(
                    "header claims {size} bytes but the base64 text holds at most {}",
                    text.len() / 4 * 3
                ));
            }
            let all = b64_decode(&text[..enc_len(total)])?;
            let body = all.get(hs..total).ok_or("base64 text too short")?;
            self.charge(body.len() as u64)?;
            return uncompressed(body, ty, c.big_endian, expected);
        }
        // Compressed: [nblocks, bs, last] tells the header length.
        let first = text
            .get(..enc_len(3 * hs))
            .ok_or("truncated compression header")?;
        let h3 = b64_decode(first)?;
        let nb = c.word(&h3, 0).ok_or("bad compression header")?;
        let hdr_len = header_len(nb, hs, text.len() / 4 * 3)?;
        let hchars = enc_len(hdr_len);
        let htext = text.get(..hchars).ok_or("truncated compression header")?;
        let hdr = self.block_header(&b64_decode(htext)?)?;
        let csum = hdr
            .csizes
            .iter()
            .try_fold(0u64, |a, &c| a.checked_add(c))
            .ok_or("compressed sizes overflow")?;
        if hdr_len % 3 != 0 && !htext.ends_with(b"=") {
            // Header and blocks encoded as one base64 stream (not VTK's way,
            // but seen in other writers).
            let total = usize::try_from(csum)
                .ok()
                .and_then(|c| c.checked_add(hdr_len))
                .ok_or("sizes overflow")?;
            let t = text.get(..enc_len(total)).ok_or_else(|| {
                format!("compressed blocks need {csum} bytes but the base64 text is shorter")
            })?;
            let all = b64_decode(t)?;
            return self.inflate(&hdr, &all[hdr_len.min(all.len())..], ty, expected);
        }
        let rest = &text[hchars..];
        let need = enc_len(usize::try_from(csum).map_err(|_| "sizes overflow")?);
        let dtext = rest.get(..need).ok_or_else(|| {
            format!(
                "compressed blocks need {csum} bytes but the base64 text holds at most {}",
                rest.len() / 4 * 3
            )
        })?;
        let data = b64_decode(dtext)?;
        self.inflate(&hdr, &data, ty, expected)
    }

    fn block_header(&self, h: &[u8]) -> Result<BlockHeader, String> {
        let c = self.codec;
        let w = |i: usize| c.word(h, i).ok_or("truncated compression header");
        let nb = w(0)? as usize;
        let bs = w(1)?;
        let last = w(2)?;
        if nb > 0 && bs == 0 {
            return Err("compression header: block size 0".into());
        }
        if last > bs {
            return Err(format!(
                "compression header: last block size {last} > block size {bs}"
            ));
        }
        let mut usizes = vec![bs; nb];
        if let Some(l) = usizes.last_mut() {
            if last > 0 {
                *l = last;
            }
        }
        let csizes = (0..nb).map(|i| w(3 + i)).collect::<Result<Vec<_>, _>>()?;
        Ok(BlockHeader {
            block_size: bs,
            usizes,
            csizes,
        })
    }

    /// Inflates the blocks in `data` (compressed blocks back to back).
    fn inflate<T: Target>(
        &self,
        hdr: &BlockHeader,
        data: &[u8],
        ty: Scalar,
        expected: Option<usize>,
    ) -> Result<Vec<T>, String> {
        let c = self.codec;
        let ratio = match c.compressor {
            Compressor::Lz4 => LZ4_MAX_RATIO,
            Compressor::Lzma => LZMA_MAX_RATIO,
            _ => ZLIB_MAX_RATIO,
        };
        let mut blocks = Vec::with_capacity(hdr.csizes.len());
        let mut at = 0u64;
        for (i, (&cs, &us)) in hdr.csizes.iter().zip(&hdr.usizes).enumerate() {
            let end = at.checked_add(cs).ok_or("block sizes overflow")?;
            if end > data.len() as u64 {
                return Err(format!(
                    "compressed block {i} ends at {end} but only {} bytes of data are present (truncated?)",
                    data.len()
                ));
            }
            if us > cs.saturating_mul(ratio).saturating_add(BLOCK_SLACK) {
                return Err(format!(
                    "compression header: block {i} claims {us} bytes from {cs} compressed bytes (impossible ratio)"
                ));
            }
            blocks.push((&data[at as usize..end as usize], us as usize));
            at = end;
        }
        let total = hdr.total();
        let es = ty.size() as u64;
        if total % es != 0 {
            return Err(format!(
                "{total} decompressed bytes is not a whole number of {} values",
                ty.name()
            ));
        }
        let n = (total / es) as usize;
        if let Some(want) = expected {
            if want != n {
                return Err(format!(
                    "compression header gives {n} values, expected {want}"
                ));
            }
        }
        let comp = c.compressor;
        let be = c.big_endian;
        self.charge(total)?;
        let mut out = vec![T::default(); n];
        if n == 0 {
            return Ok(out);
        }
        if hdr.block_size % es == 0 {
            let per = (hdr.block_size / es) as usize;
            out.par_chunks_mut(per)
                .zip(blocks.par_iter())
                .enumerate()
                .try_for_each_init(
                    || (Vec::new(), None),
                    |(scratch, dec), (i, (o, &(src, us)))| {
                        if us != o.len() * es as usize {
                            return Err(format!("compressed block {i}: inconsistent block sizes"));
                        }
                        scratch.resize(us, 0u8);
                        inflate_block(comp, src, scratch, dec)
                            .map_err(|m| format!("compressed block {i}: {m}"))?;
                        convert_bytes(scratch, ty, be, o);
                        Ok(())
                    },
                )?;
        } else {
            let mut raw = vec![0u8; total as usize];
            raw.par_chunks_mut(hdr.block_size as usize)
                .zip(blocks.par_iter())
                .enumerate()
                .try_for_each_init(
                    || None,
                    |dec, (i, (o, &(src, us)))| {
                        if us != o.len() {
                            return Err(format!("compressed block {i}: inconsistent block sizes"));
                        }
                        inflate_block(comp, src, o, dec)
                            .map_err(|m| format!("compressed block {i}: {m}"))
                    },
                )?;
            out = convert_par(&raw, ty, be);
        }
        Ok(out)
    }
}

/// Header length in bytes for `nb` blocks, checked against `avail` bytes.
fn header_len(nb: u64, hs: usize, avail: usize) -> Result<usize, String> {
    let len = nb
        .checked_add(3)
        .and_then(|w| w.checked_mul(hs as u64))
        .filter(|&l| l <= avail as u64)
        .ok_or_else(|| {
            format!("compression header claims {nb} blocks but only {avail} bytes remain")
        })?;
    Ok(len as usize)
}

/// Inflates one block into exactly `dst.len()` bytes.
fn inflate_block(
    comp: Compressor,
    src: &[u8],
    dst: &mut [u8],
    dec: &mut Option<flate2::Decompress>,
) -> Result<(), String> {
    match comp {
        Compressor::Zlib => {
            let d = dec.get_or_insert_with(|| flate2::Decompress::new(true));
            d.reset(true);
            let status = d
                .decompress(src, dst, flate2::FlushDecompress::Finish)
                .map_err(|e| format!("corrupt zlib stream: {e}"))?;
            if status != flate2::Status::StreamEnd || d.total_out() != dst.len() as u64 {
                return Err(format!(
                    "zlib stream gives {} bytes (stream end: {}), header says {}",
                    d.total_out(),
                    status == flate2::Status::StreamEnd,
                    dst.len()
                ));
            }
            Ok(())
        }
        Compressor::Lz4 => {
            let n = lz4_flex::block::decompress_into(src, dst)
                .map_err(|e| format!("corrupt LZ4 block: {e}"))?;
            if n != dst.len() {
                return Err(format!(
                    "LZ4 block gives {n} bytes, header says {}",
                    dst.len()
                ));
            }
            Ok(())
        }
        Compressor::Lzma => {
            // One `.xz` stream per block; its check (CRC32 or CRC64, as
            // the writer chose) is verified by the decoder.
            let mut d = xz2::stream::Stream::new_stream_decoder(u64::MAX, 0)
                .map_err(|e| format!("cannot start the LZMA decoder: {e}"))?;
            // The decoder may stop with the output full before it has
            // read the stream's index and footer: go on while it moves.
            let status = loop {
                let (i, o) = (d.total_in() as usize, d.total_out() as usize);
                let status = d
                    .process(&src[i..], &mut dst[o..], xz2::stream::Action::Finish)
                    .map_err(|e| format!("corrupt LZMA stream: {e}"))?;
                let moved = d.total_in() as usize != i || d.total_out() as usize != o;
                if status != xz2::stream::Status::Ok || !moved {
                    break status;
                }
            };
            if status != xz2::stream::Status::StreamEnd
                || d.total_out() != dst.len() as u64
                || d.total_in() != src.len() as u64
            {
                return Err(format!(
                    "LZMA stream gives {} bytes from {} of {} compressed bytes (stream end: {}), header says {}",
                    d.total_out(),
                    d.total_in(),
                    src.len(),
                    status == xz2::stream::Status::StreamEnd,
                    dst.len()
                ));
            }
            Ok(())
        }
        Compressor::None => Err("internal: no compressor".into()),
    }
}

/// Converts an uncompressed payload, checking its size.
fn uncompressed<T: Target>(
    body: &[u8],
    ty: Scalar,
    be: bool,
    expected: Option<usize>,
) -> Result<Vec<T>, String> {
    if body.len() % ty.size() != 0 {
        return Err(format!(
            "{} bytes is not a whole number of {} values",
            body.len(),
            ty.name()
        ));
    }
    let n = body.len() / ty.size();
    if let Some(want) = expected {
        if want != n {
            return Err(format!("holds {n} values, expected {want}"));
        }
    }
    Ok(convert_par(body, ty, be))
}

/// Parses ASCII numbers.
fn ascii<T: Target>(text: &[u8], ty: Scalar, expected: Option<usize>) -> Result<Vec<T>, String> {
    let s = std::str::from_utf8(text).map_err(|_| "ASCII data is not valid UTF-8".to_string())?;
    if let Some(want) = expected {
        // Each value needs at least one character and one separator.
        if want > s.len() / 2 + 1 {
            return Err(format!(
                "expected {want} values but the text has only {} characters",
                s.len()
            ));
        }
    }
    let mut out = Vec::with_capacity(expected.unwrap_or(0));
    for (i, tok) in s.split_ascii_whitespace().enumerate() {
        let bad = || {
            format!(
                "bad {} value '{}' at index {i}",
                ty.name(),
                tok.chars().take(32).collect::<String>()
            )
        };
        let v = match ty {
            Scalar::F32 => T::from_f32(tok.parse::<f32>().map_err(|_| bad())?),
            Scalar::F64 => T::from_f64(tok.parse::<f64>().map_err(|_| bad())?),
            Scalar::U8 | Scalar::U16 | Scalar::U32 | Scalar::U64 => {
                T::from_u64(tok.parse::<u64>().map_err(|_| bad())?)
            }
            _ => T::from_i64(tok.parse::<i64>().map_err(|_| bad())?),
        };
        out.push(v);
    }
    if let Some(want) = expected {
        if out.len() != want {
            return Err(format!("holds {} values, expected {want}", out.len()));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_parallel_matches_serial() {
        use base64::engine::general_purpose::STANDARD;
        let data: Vec<u8> = (0..3_000_001u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        let text = STANDARD.encode(&data);
        assert_eq!(b64_decode(text.as_bytes()).unwrap(), data);
        assert!(b64_decode(b"ab!d").is_err());
    }
}
