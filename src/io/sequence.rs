//! The steps of an animation from what a user types: a collection, a glob
//! pattern, a folder of numbered files, or one dataset.
//!
//! [`list_steps`] decides in this order:
//! 1. an existing folder: its dataset files (`.vtk`, `.vtu`, `.vts`, `.vtr`,
//!    `.vti`, `.pvtu`, `.pvts`, `.pvtr`, `.pvti`, `.vtm`), hidden files left
//!    out; where it holds parallel or multiblock files (`.pvt*`, `.vtm`),
//!    only those, since the serial files beside them are their pieces;
//! 2. an existing file: a `.pvd` or `.series` collection lists its steps
//!    with their times ([`super::read_series`]); any other file is one step
//!    at time 0;
//! 3. a path holding `*`, `?` or `[`: a glob pattern (quoted, so the shell
//!    leaves it alone), matched with the `glob` crate; the matches that are
//!    files.
//!
//! Files found by a folder or a pattern are put in natural order (runs of
//! digits compare as numbers, so `step_2` comes before `step_10`) and their
//! time is their index in that order (`zoovr animate` then takes the time
//! a file records itself, `TimeValue` or legacy `TIME`, where it has one). An empty folder or a pattern that
//! matches nothing is an error naming it.

use std::cmp::Ordering;
use std::path::{Path, PathBuf};

use super::{read_series, IoError, Location, TimeStep};

/// File extensions (lower case) of the datasets a folder is searched for.
const DATASET_EXTENSIONS: [&str; 10] = [
    "vtk", "vtu", "vts", "vtr", "vti", "pvtu", "pvts", "pvtr", "pvti", "vtm",
];

/// Whether `path` looks like a glob pattern.
fn is_pattern(path: &Path) -> bool {
    path.to_string_lossy().contains(['*', '?', '['])
}

/// The steps that `path` names (module docs), in time order.
pub fn list_steps(path: &Path) -> Result<Vec<TimeStep>, IoError> {
    if path.is_dir() {
        let entries = std::fs::read_dir(path).map_err(|e| IoError::open(path, e))?;
        let mut files = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| IoError::open(path, e))?;
            let p = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_lowercase())
                .unwrap_or_default();
            if !name.starts_with('.') && p.is_file() && DATASET_EXTENSIONS.contains(&ext.as_str()) {
                files.push(p);
            }
        }
        // Serial files next to parallel or multiblock ones are their
        // pieces.
        let parallel = |p: &PathBuf| {
            p.extension().is_some_and(|e| {
                let e = e.to_string_lossy().to_lowercase();
                e.starts_with("pvt") || e == "vtm"
            })
        };
        if files.iter().any(parallel) {
            files.retain(parallel);
        }
        return numbered(
            path,
            files,
            "the folder holds no dataset files (.vtk, .vtu, .vts, .vtr, .vti, .pvtu, .pvts, .pvtr, .pvti, .vtm)",
        );
    }
    if path.exists() || !is_pattern(path) {
        return read_series(path);
    }
    let pattern = path.to_string_lossy();
    let paths = glob::glob(&pattern)
        .map_err(|e| IoError::parse(path, Location::None, format!("bad glob pattern: {e}")))?;
    let mut files = Vec::new();
    for p in paths {
        let p = p.map_err(|e| {
            IoError::parse(path, Location::None, format!("cannot read a match: {e}"))
        })?;
        if p.is_file() {
            files.push(p);
        }
    }
    numbered(path, files, "the pattern matches no files")
}

/// The files in natural order, time = index.
fn numbered(what: &Path, mut files: Vec<PathBuf>, empty: &str) -> Result<Vec<TimeStep>, IoError> {
    if files.is_empty() {
        return Err(IoError::parse(what, Location::None, empty));
    }
    files.sort_by(|a, b| natural_cmp(&a.to_string_lossy(), &b.to_string_lossy()));
    Ok(files
        .into_iter()
        .enumerate()
        .map(|(i, path)| TimeStep {
            time: i as f64,
            path,
        })
        .collect())
}

/// Compares two names with runs of ASCII digits compared as numbers
/// (leading zeros ignored; equal numbers then by length), the rest byte by
/// byte.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i].is_ascii_digit() && b[j].is_ascii_digit() {
            let si = i;
            while i < a.len() && a[i].is_ascii_digit() {
                i += 1;
            }
            let sj = j;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            let da = trim_zeros(&a[si..i]);
            let db = trim_zeros(&b[sj..j]);
            let ord = da
                .len()
                .cmp(&db.len())
                .then_with(|| da.cmp(db))
                .then_with(|| (i - si).cmp(&(j - sj)));
            if ord != Ordering::Equal {
                return ord;
            }
        } else {
            if a[i] != b[j] {
                return a[i].cmp(&b[j]);
            }
            i += 1;
            j += 1;
        }
    }
    (a.len() - i).cmp(&(b.len() - j))
}

fn trim_zeros(d: &[u8]) -> &[u8] {
    let k = d.iter().position(|&c| c != b'0').unwrap_or(d.len());
    &d[k..]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order() {
        let mut v = vec!["s_10.vtu", "s_2.vtu", "s_1.vtu", "s_02.vtu", "a.vtu"];
        v.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(v, ["a.vtu", "s_1.vtu", "s_2.vtu", "s_02.vtu", "s_10.vtu"]);
    }

    #[test]
    fn folder_and_pattern() {
        let dir = tempfile::tempdir().unwrap();
        for n in ["f_10.vtu", "f_9.vtu", "notes.txt", ".hidden.vtu"] {
            std::fs::write(dir.path().join(n), "x").unwrap();
        }
        let steps = list_steps(dir.path()).unwrap();
        let names: Vec<_> = steps
            .iter()
            .map(|s| s.path.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["f_9.vtu", "f_10.vtu"]);
        assert_eq!(steps[1].time, 1.0);
        let pat = dir.path().join("f_*.vtu");
        assert_eq!(list_steps(&pat).unwrap().len(), 2);
        let none = dir.path().join("g_*.vtu");
        let err = list_steps(&none).unwrap_err().to_string();
        assert!(
            err.contains("g_*.vtu") && err.contains("matches no files"),
            "{err}"
        );
        let empty = tempfile::tempdir().unwrap();
        assert!(list_steps(empty.path()).is_err());
    }

    /// A folder of parallel steps with their pieces beside them lists the
    /// parallel files only.
    #[test]
    fn folder_of_parallel_steps_leaves_their_pieces_out() {
        let dir = tempfile::tempdir().unwrap();
        for n in [
            "s_1.pvts",
            "s_1_0.vts",
            "s_1_1.vts",
            "s_0.PVTS",
            "s_0_0.vts",
        ] {
            std::fs::write(dir.path().join(n), "x").unwrap();
        }
        let names: Vec<_> = list_steps(dir.path())
            .unwrap()
            .iter()
            .map(|s| s.path.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["s_0.PVTS", "s_1.pvts"]);
    }
}
