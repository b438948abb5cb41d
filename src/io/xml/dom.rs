//! A light element tree of a VTK XML file, built with quick-xml's pull parser.
//!
//! VTK XML files are small trees of elements (`VTKFile` > `UnstructuredGrid` >
//! `Piece` > `Points` > `DataArray` ...) whose bulk data is either inline text
//! (ASCII numbers or base64) or a block of appended bytes at the end of the
//! file. The tree keeps element names, unescaped attributes, the byte offset
//! of each element and the byte *ranges* of its direct text children, so inline
//! data is decoded later straight from the file bytes without copying.
//!
//! `<AppendedData encoding="raw">` is followed by arbitrary binary bytes that
//! are not XML: parsing stops at its start tag, and the data region is located
//! by byte offset (after the `_` marker), never parsed.
//!
//! Hostile XML: quick-xml never expands entities beyond the five predefined
//! ones; an unknown `&name;` in an attribute is an error, and a `DOCTYPE` that
//! declares entities is refused outright (no billion-laughs, no external
//! entities). Element nesting is capped at [`MAX_DEPTH`].

use std::ops::Range;
use std::path::Path;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use crate::io::{IoError, Location};

/// Deepest element nesting accepted (VTK files use about 6 levels).
pub const MAX_DEPTH: usize = 64;

/// One XML element.
#[derive(Clone, Debug, Default)]
pub struct Element {
    /// Tag name.
    pub name: String,
    /// Attributes, values unescaped.
    pub attrs: Vec<(String, String)>,
    /// Child elements in document order.
    pub children: Vec<Element>,
    /// Byte ranges of the direct text children (not of descendants).
    pub text: Vec<Range<usize>>,
    /// Byte offset of the element's `<`.
    pub pos: usize,
}

impl Element {
    /// Value of attribute `key`.
    pub fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// First child named `name`.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }

    /// Children named `name`.
    pub fn children_named<'s>(&'s self, name: &'s str) -> impl Iterator<Item = &'s Element> + 's {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// A human-readable place for error messages: tag, `Name` attribute and
    /// byte offset.
    pub fn location(&self) -> Location {
        match self.attr("Name") {
            Some(n) => Location::Element(format!(
                "<{} Name=\"{}\"> at byte {}",
                self.name, n, self.pos
            )),
            None => Location::Element(format!("<{}> at byte {}", self.name, self.pos)),
        }
    }
}

/// How the appended data block is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AppendedEncoding {
    Raw,
    Base64,
}

/// The appended data block: the bytes after the `_` marker.
#[derive(Clone, Copy, Debug)]
pub struct Appended<'a> {
    pub encoding: AppendedEncoding,
    /// Data from just after `_` (raw: to the end of the file; base64: to the
    /// closing tag).
    pub data: &'a [u8],
    /// Byte offset of `data[0]` in the file.
    pub start: usize,
}

/// A parsed file: the root element and the appended block, if any.
#[derive(Debug)]
pub struct Document<'a> {
    pub root: Element,
    pub appended: Option<Appended<'a>>,
}

fn xml_err(path: &Path, pos: u64, e: impl std::fmt::Display) -> IoError {
    IoError::parse(path, Location::Byte(pos), format!("malformed XML: {e}"))
}

fn start_element(path: &Path, e: &BytesStart<'_>, pos: usize) -> Result<Element, IoError> {
    let mut el = Element {
        name: String::from_utf8_lossy(e.name().as_ref()).into_owned(),
        pos,
        ..Element::default()
    };
    for a in e.attributes() {
        let a = a.map_err(|err| xml_err(path, pos as u64, err))?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a.unescape_value().map_err(|err| {
            IoError::parse(
                path,
                Location::Element(format!("<{}> at byte {pos}, attribute {key}", el.name)),
                format!(
                    "bad attribute value: {err} (only the predefined XML entities are accepted)"
                ),
            )
        })?;
        el.attrs.push((key, value.into_owned()));
    }
    Ok(el)
}

/// Attaches `el` to the top of the stack, or makes it the root.
fn attach(stack: &mut [Element], root: &mut Option<Element>, el: Element) {
    match stack.last_mut() {
        Some(parent) => parent.children.push(el),
        None => {
            if root.is_none() {
                *root = Some(el);
            }
        }
    }
}

/// Locates the appended block after the `<AppendedData ...>` start tag that
/// ends at `after_tag`.
fn appended_block<'a>(
    path: &Path,
    bytes: &'a [u8],
    el: &Element,
    after_tag: usize,
) -> Result<Appended<'a>, IoError> {
    let encoding = match el.attr("encoding").unwrap_or("raw") {
        "raw" => AppendedEncoding::Raw,
        "base64" => AppendedEncoding::Base64,
        other => {
            return Err(IoError::parse(
                path,
                el.location(),
                format!("unknown AppendedData encoding '{other}' (expected raw or base64)"),
            ))
        }
    };
    let rest = bytes.get(after_tag..).unwrap_or_default();
    let skip = rest.iter().position(|b| !b.is_ascii_whitespace());
    let marker = match skip {
        Some(i) if rest[i] == b'_' => i,
        _ => {
            return Err(IoError::parse(
                path,
                Location::Byte(after_tag as u64),
                "AppendedData: expected the '_' marker before the data",
            ))
        }
    };
    let start = after_tag + marker + 1;
    let mut data = &bytes[start..];
    if encoding == AppendedEncoding::Base64 {
        if let Some(end) = find(data, b"</AppendedData") {
            data = &data[..end];
        }
        let trimmed = data
            .iter()
            .rposition(|b| !b.is_ascii_whitespace())
            .map_or(0, |p| p + 1);
        data = &data[..trimmed];
    }
    Ok(Appended {
        encoding,
        data,
        start,
    })
}

/// First occurrence of `needle` in `hay`.
pub fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    if needle.is_empty() || hay.len() < needle.len() {
        return None;
    }
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Parses the element tree of `bytes` (stopping at `<AppendedData>`).
pub fn parse<'a>(path: &Path, bytes: &'a [u8]) -> Result<Document<'a>, IoError> {
    let mut reader = Reader::from_reader(bytes);
    reader.config_mut().check_end_names = true;
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    let mut appended = None;
    loop {
        let before = reader.buffer_position() as usize;
        let ev = reader
            .read_event()
            .map_err(|e| xml_err(path, reader.error_position(), e))?;
        let after = reader.buffer_position() as usize;
        match ev {
            Event::Start(e) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(IoError::parse(
                        path,
                        Location::Byte(before as u64),
                        format!("elements nested deeper than {MAX_DEPTH} levels"),
                    ));
                }
                let el = start_element(path, &e, before)?;
                if el.name == "AppendedData" {
                    appended = Some(appended_block(path, bytes, &el, after)?);
                    attach(&mut stack, &mut root, el);
                    break;
                }
                stack.push(el);
            }
            Event::Empty(e) => {
                let el = start_element(path, &e, before)?;
                attach(&mut stack, &mut root, el);
            }
            Event::End(_) => {
                if let Some(el) = stack.pop() {
                    attach(&mut stack, &mut root, el);
                }
            }
            Event::Text(_) => {
                if let Some(top) = stack.last_mut() {
                    top.text.push(before..after);
                }
            }
            Event::DocType(d) => {
                let upper = String::from_utf8_lossy(d.as_ref()).to_ascii_uppercase();
                if upper.contains("ENTITY") {
                    return Err(IoError::parse(
                        path,
                        Location::Byte(before as u64),
                        "DOCTYPE declares entities: refused (entity expansion is never performed)",
                    ));
                }
            }
            Event::Eof => break,
            Event::CData(_) | Event::Comment(_) | Event::Decl(_) | Event::PI(_) => {}
        }
    }
    // Unclosed elements (the appended block ends the parse early): attach them.
    while let Some(el) = stack.pop() {
        attach(&mut stack, &mut root, el);
    }
    let root =
        root.ok_or_else(|| IoError::parse(path, Location::Byte(0), "no XML element found"))?;
    if root.name != "VTKFile" {
        return Err(IoError::parse(
            path,
            root.location(),
            format!("root element is <{}>, expected <VTKFile>", root.name),
        ));
    }
    Ok(Document { root, appended })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_ranges_and_appended_raw() {
        let src = b"<VTKFile type=\"X\"><A Name=\"a&amp;b\">1 2 3</A><AppendedData encoding=\"raw\">\n _\x00<\xff>";
        let doc = parse(Path::new("t.vtu"), src).unwrap();
        let a = doc.root.child("A").unwrap();
        assert_eq!(a.attr("Name"), Some("a&b"));
        let r = a.text[0].clone();
        assert_eq!(&src[r], b"1 2 3");
        let ap = doc.appended.unwrap();
        assert_eq!(ap.data, b"\x00<\xff>");
        assert_eq!(ap.encoding, AppendedEncoding::Raw);
    }

    #[test]
    fn entities_are_refused() {
        let src =
            b"<?xml version=\"1.0\"?><!DOCTYPE lolz [<!ENTITY lol \"lol\">]><VTKFile a=\"&lol;\"/>";
        let e = parse(Path::new("evil.vtu"), src).unwrap_err().to_string();
        assert!(e.contains("evil.vtu") && e.contains("entit"), "{e}");
        let src = b"<VTKFile a=\"&lol;\"/>";
        assert!(parse(Path::new("evil.vtu"), src).is_err());
    }
}
