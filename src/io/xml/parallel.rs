//! The parallel files: `.pvtu` (`PUnstructuredGrid`), `.pvts`
//! (`PStructuredGrid`), `.pvtr` (`PRectilinearGrid`) and `.pvti`
//! (`PImageData`), whose `<Piece Source="...">` elements name the serial
//! files of one kind (`.vtu`, `.vts`, `.vtr`, `.vti`; relative to the
//! parallel file's folder). The pieces are read in parallel and merged
//! (point ids offset per piece). Structured pieces carry their own `Extent`
//! (and `.vti` pieces their `Origin` and `Spacing`), so each becomes its
//! hexahedra as a serial file would; neighbouring pieces repeat the points
//! of their shared layer, which the topology merges as it merges any
//! coincident points, so the cells meet face to face. The `PPointData` /
//! `PCellData` `Scalars` attribute marks the active scalars. The step's time
//! is the pieces' `TimeValue` (ParaView writes it into every piece); pieces
//! that disagree leave it unset, with a note.
//!
//! Refused with a clean error naming the parallel file and the piece: a
//! missing or unreadable piece, a piece that is the parallel file itself,
//! and a piece that is itself a parallel file (which could otherwise recurse
//! forever).

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::dom::Element;
use crate::io::{Format, IoError, Location};
use crate::mesh::Mesh;

/// Deepest nesting of parallel files (a piece may not be one).
const MAX_DEPTH: usize = 1;

/// Reads the parallel file `path` whose pieces are files of `piece_format`
/// (what a piece that does not name its own type is read as).
pub fn read(
    path: &Path,
    grid: &Element,
    depth: usize,
    piece_format: Format,
) -> Result<Mesh, IoError> {
    if depth >= MAX_DEPTH {
        return Err(IoError::parse(
            path,
            grid.location(),
            "a piece of a parallel file is itself a parallel file",
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
            super::referenced_file(path, me.as_deref(), file, "piece", at)?;
            let bytes = std::fs::read(file).map_err(|e| {
                IoError::parse(
                    path,
                    at(),
                    format!("piece file {} cannot be read: {e}", file.display()),
                )
            })?;
            super::read_nested(file, &bytes, piece_format, depth + 1)
                .map_err(|e| IoError::parse(path, at(), format!("piece failed: {e}")))
        })
        .collect::<Result<Vec<Mesh>, IoError>>()?;
    let mut mesh = super::merge_parts(path, grid, meshes, "pieces")?;
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
