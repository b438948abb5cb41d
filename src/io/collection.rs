//! Time collections: ParaView `.pvd` and `.series` JSON files.
//!
//! A `.pvd` is a VTK XML `Collection` of `<DataSet timestep="t" part="p"
//! file="f"/>` entries; a `.series` file is `{"file-series-version": "1.0",
//! "files": [{"name": f, "time": t}, ...]}`. Both list one dataset file per
//! time step. Files are resolved relative to the collection's folder and the
//! steps are sorted by time (stably, so equal times keep the file's order).
//! For multi-part `.pvd`s only the entries of the first part listed are kept
//! (one file per step).
//!
//! Refused with an error naming the collection and the entry: a missing file,
//! an entry that is the collection itself or another collection (which could
//! recurse), a non-finite time, an empty list.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::xml::dom;
use super::{IoError, Location, TimeStep};

/// Largest collection file read (they list file names, nothing more).
const MAX_COLLECTION_BYTES: u64 = 64 << 20;

fn read_small(path: &Path) -> Result<Vec<u8>, IoError> {
    let meta = std::fs::metadata(path).map_err(|e| IoError::open(path, e))?;
    if meta.len() > MAX_COLLECTION_BYTES {
        return Err(IoError::parse(
            path,
            Location::None,
            format!("{} bytes is too large for a collection file", meta.len()),
        ));
    }
    std::fs::read(path).map_err(|e| IoError::open(path, e))
}

/// Resolves and checks one entry.
fn resolve(coll: &Path, name: &str, at: Location) -> Result<PathBuf, IoError> {
    let name = name.trim();
    if name.is_empty() {
        return Err(IoError::parse(coll, at, "entry without a file name"));
    }
    let file = coll.parent().unwrap_or(Path::new(".")).join(name);
    let canon = std::fs::canonicalize(&file).map_err(|e| {
        IoError::parse(
            coll,
            at.clone(),
            format!("time step file {} cannot be opened: {e}", file.display()),
        )
    })?;
    if std::fs::canonicalize(coll).ok().as_ref() == Some(&canon) {
        return Err(IoError::parse(
            coll,
            at,
            format!("entry '{name}' refers to the collection itself"),
        ));
    }
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".pvd") || lower.ends_with(".series") {
        return Err(IoError::parse(
            coll,
            at,
            format!("entry '{name}' is itself a collection (nested collections are not supported)"),
        ));
    }
    Ok(file)
}

fn finish(coll: &Path, mut steps: Vec<TimeStep>) -> Result<Vec<TimeStep>, IoError> {
    if steps.is_empty() {
        return Err(IoError::parse(
            coll,
            Location::None,
            "the collection lists no time steps",
        ));
    }
    steps.sort_by(|a, b| a.time.total_cmp(&b.time));
    Ok(steps)
}

/// Reads a `.pvd` collection.
pub fn read_pvd(path: &Path) -> Result<Vec<TimeStep>, IoError> {
    let bytes = read_small(path)?;
    parse_pvd(path, &bytes)
}

/// Parses the bytes of a `.pvd` collection found at `path` (entries resolve
/// relative to it and must exist).
pub fn parse_pvd(path: &Path, bytes: &[u8]) -> Result<Vec<TimeStep>, IoError> {
    let doc = dom::parse(path, bytes)?;
    let coll = doc
        .root
        .child("Collection")
        .ok_or_else(|| IoError::parse(path, doc.root.location(), "no <Collection> element"))?;
    let mut first_part: Option<String> = None;
    let mut steps = Vec::new();
    for (i, ds) in coll.children_named("DataSet").enumerate() {
        let part = ds.attr("part").unwrap_or("").trim().to_string();
        match &first_part {
            None => first_part = Some(part),
            Some(p) if *p != part => continue,
            Some(_) => {}
        }
        let at = Location::Element(format!("DataSet {i} at byte {}", ds.pos));
        let t = ds.attr("timestep").unwrap_or("0").trim();
        let time: f64 = match t.parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            _ => return Err(IoError::parse(path, at, format!("bad timestep '{t}'"))),
        };
        let file = resolve(path, ds.attr("file").unwrap_or(""), at)?;
        steps.push(TimeStep { time, path: file });
    }
    finish(path, steps)
}

#[derive(Deserialize)]
struct SeriesFile {
    #[serde(rename = "file-series-version")]
    version: Option<String>,
    files: Vec<SeriesEntry>,
}

#[derive(Deserialize)]
struct SeriesEntry {
    name: String,
    time: f64,
}

/// Reads a `.series` JSON collection.
pub fn read_series_json(path: &Path) -> Result<Vec<TimeStep>, IoError> {
    let bytes = read_small(path)?;
    parse_series_json(path, &bytes)
}

/// Parses the bytes of a `.series` JSON collection found at `path` (entries
/// resolve relative to it and must exist).
pub fn parse_series_json(path: &Path, bytes: &[u8]) -> Result<Vec<TimeStep>, IoError> {
    let s: SeriesFile = serde_json::from_slice(bytes).map_err(|e| {
        IoError::parse(
            path,
            Location::Line(e.line()),
            format!("bad .series JSON: {e}"),
        )
    })?;
    if let Some(v) = &s.version {
        if !v.starts_with("1.") {
            return Err(IoError::parse(
                path,
                Location::None,
                format!("unsupported file-series-version '{v}'"),
            ));
        }
    }
    let mut steps = Vec::with_capacity(s.files.len());
    for (i, f) in s.files.iter().enumerate() {
        let at = Location::Element(format!("files[{i}]"));
        if !f.time.is_finite() {
            return Err(IoError::parse(path, at, "non-finite time"));
        }
        steps.push(TimeStep {
            time: f.time,
            path: resolve(path, &f.name, at)?,
        });
    }
    finish(path, steps)
}
