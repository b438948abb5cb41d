//! `.pvtu`: a `PUnstructuredGrid` whose `<Piece Source="...">` elements name
//! `.vtu` files (relative to the `.pvtu`'s folder). The pieces are read in
//! parallel and merged (point ids offset per piece). The `PPointData` /
//! `PCellData` `Scalars` attribute marks the active scalars. The step's time
//! is the pieces' `TimeValue` (ParaView writes it into every piece); pieces
//! that disagree leave it unset, with a note.
//!
//! Refused with a clean error naming the `.pvtu` and the piece: a missing or
//! unreadable piece, a piece that is the `.pvtu` itself, and a piece that is
//! itself a parallel file (which could otherwise recurse forever).

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::dom::Element;
use crate::io::{Format, IoError, Location};
use crate::mesh::Mesh;

/// Deepest nesting of parallel files (a piece may not be a `.pvtu`).
const MAX_DEPTH: usize = 1;

pub fn read(path: &Path, grid: &Element, depth: usize) -> Result<Mesh, IoError> {
    if depth >= MAX_DEPTH {
        return Err(IoError::parse(
            path,
            grid.location(),
            "a piece of a .pvtu is itself a parallel file",
        ));
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let me = std::fs::canonicalize(path).ok();
    let pieces: Vec<(usize, &Element, PathBuf)> = grid
        .children_named("Piece")
        .enumerate()
        .map(|(i, p)| {
            let s = p.attr("Source").unwrap_or("");
            if s.trim().is_empty() {
                return Err(IoError::parse(
                    path,
                    p.location(),
                    format!("piece {i} has no Source"),
                ));
            }
            Ok((i, p, dir.join(s.trim())))
        })
        .collect::<Result<_, _>>()?;
    if pieces.is_empty() {
        return Err(IoError::parse(path, grid.location(), "no <Piece> element"));
    }
    let meshes = pieces
        .par_iter()
        .map(|(i, p, file)| {
            let at = || {
                Location::Element(format!(
                    "piece {i} (Source=\"{}\") at byte {}",
                    p.attr("Source").unwrap_or(""),
                    p.pos
                ))
            };
            let canon = std::fs::canonicalize(file).map_err(|e| {
                IoError::parse(
                    path,
                    at(),
                    format!("piece file {} cannot be opened: {e}", file.display()),
                )
            })?;
            if Some(&canon) == me.as_ref() {
                return Err(IoError::parse(
                    path,
                    at(),
                    "the piece is the .pvtu file itself",
                ));
            }
            if !canon.is_file() {
                return Err(IoError::parse(
                    path,
                    at(),
                    format!("piece {} is not a regular file", file.display()),
                ));
            }
            let bytes = std::fs::read(file).map_err(|e| {
                IoError::parse(
                    path,
                    at(),
                    format!("piece file {} cannot be read: {e}", file.display()),
                )
            })?;
            super::read_nested(file, &bytes, Format::XmlUnstructured, depth + 1)
                .map_err(|e| IoError::parse(path, at(), format!("piece failed: {e}")))
        })
        .collect::<Result<Vec<Mesh>, IoError>>()?;
    let times: Vec<Option<f64>> = meshes.iter().map(|m| m.source.time_value).collect();
    let mut mesh = super::merge_checked(path, grid, meshes)?;
    let first = times.iter().flatten().next().copied();
    if times.iter().flatten().all(|t| Some(*t) == first) {
        mesh.source.time_value = first;
    } else {
        mesh.source
            .notes
            .push("the pieces' TimeValues differ: no time value".into());
    }
    let active = |el: Option<&Element>| el.and_then(|e| e.attr("Scalars")).map(str::to_string);
    if let Some(s) =
        active(grid.child("PPointData")).filter(|s| mesh.point_data.iter().any(|a| &a.name == s))
    {
        mesh.active_point_scalars = Some(s);
    }
    if let Some(s) =
        active(grid.child("PCellData")).filter(|s| mesh.cell_data.iter().any(|a| &a.name == s))
    {
        mesh.active_cell_scalars = Some(s);
    }
    Ok(mesh)
}
