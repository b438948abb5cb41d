//! `.vtm`: a `vtkMultiBlockDataSet`, the file ParaView writes for a dataset
//! of several blocks (the zones of a multi-block CFD grid, the element
//! blocks of an Exodus file, an OpenFOAM case's internal mesh and its
//! boundary patches).
//!
//! The file holds only the tree: `<Block>` and `<Piece>` elements (nested to
//! any depth) whose `<DataSet file="...">` leaves name the blocks' own
//! files, relative to the `.vtm`'s folder (a leaf without `file` is an empty
//! block). Every leaf is read as the dataset its file is (any format zoovr
//! reads but a collection or another `.vtm`), in parallel, and the blocks
//! that hold 3D cells are merged into one mesh as the pieces of a parallel
//! file are ([`super::arrays::merge`]: point ids offset per block, an array
//! missing from some block dropped with a note). Blocks of polygonal data
//! (`.vtp`: surfaces, such as boundary patches) and blocks whose cells are
//! all 0D-2D hold nothing to render: they are left out, and a note names
//! them. The time is the blocks' `TimeValue` where they agree.
//!
//! Refused with a clean error naming the `.vtm` and the block: a missing or
//! unreadable block file, a block that is the `.vtm` itself, another `.vtm`
//! or a collection, and a tree with no block holding 3D cells.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::dom::Element;
use crate::io::{detect_format, Format, IoError, Location, ReadOptions};
use crate::mesh::Mesh;

/// One leaf of the tree: where it is named and the file it names.
struct Leaf<'a> {
    el: &'a Element,
    /// The block names from the root (`name` attributes, else indices).
    label: String,
    file: PathBuf,
}

/// Collects the `DataSet` leaves under `el`.
fn leaves<'a>(el: &'a Element, label: &str, dir: &Path, out: &mut Vec<Leaf<'a>>) {
    for (k, c) in el.children.iter().enumerate() {
        let name = c
            .attr("name")
            .map(str::to_string)
            .or_else(|| c.attr("index").map(str::to_string))
            .unwrap_or_else(|| k.to_string());
        let label = if label.is_empty() {
            name
        } else {
            format!("{label}/{name}")
        };
        match c.name.as_str() {
            "Block" | "Piece" => leaves(c, &label, dir, out),
            "DataSet" => {
                if let Some(f) = c.attr("file").map(str::trim).filter(|f| !f.is_empty()) {
                    out.push(Leaf {
                        el: c,
                        label,
                        file: dir.join(f),
                    });
                }
            }
            _ => {}
        }
    }
}

/// Reads the `.vtm` `path` whose root's `<vtkMultiBlockDataSet>` is `tree`.
pub fn read(path: &Path, tree: &Element) -> Result<Mesh, IoError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut found = Vec::new();
    leaves(tree, "", dir, &mut found);
    if found.is_empty() {
        return Err(IoError::parse(
            path,
            tree.location(),
            "the multiblock dataset names no block files",
        ));
    }
    let me = std::fs::canonicalize(path).ok();
    let blocks = found
        .par_iter()
        .map(|leaf| read_leaf(path, me.as_deref(), leaf))
        .collect::<Result<Vec<_>, IoError>>()?;
    let mut notes = Vec::new();
    let mut kept = Vec::new();
    for (leaf, block) in found.iter().zip(blocks) {
        match block {
            Some(m) if !m.cells.is_empty() => kept.push(m),
            Some(_) => notes.push(format!(
                "block '{}' ({}) holds no 3D cells: left out",
                leaf.label,
                leaf.file.display()
            )),
            None => notes.push(format!(
                "block '{}' ({}) is polygonal data (no 3D cells): left out",
                leaf.label,
                leaf.file.display()
            )),
        }
    }
    if kept.is_empty() {
        return Err(IoError::parse(
            path,
            tree.location(),
            format!(
                "no block holds 3D cells ({} blocks: {})",
                found.len(),
                notes.join("; ")
            ),
        ));
    }
    let mut mesh = super::merge_parts(path, tree, kept, "blocks")?;
    for n in notes {
        if !mesh.source.notes.contains(&n) {
            mesh.source.notes.push(n);
        }
    }
    Ok(mesh)
}

/// One block: its mesh, or `None` for polygonal data.
fn read_leaf(path: &Path, me: Option<&Path>, leaf: &Leaf) -> Result<Option<Mesh>, IoError> {
    let at = || {
        Location::Element(format!(
            "block '{}' (file=\"{}\") at byte {}",
            leaf.label,
            leaf.el.attr("file").unwrap_or(""),
            leaf.el.pos
        ))
    };
    let fail = |msg: String| IoError::parse(path, at(), msg);
    let file = &leaf.file;
    super::referenced_file(path, me, file, "block", at)?;
    let ext = file
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if ext == "vtp" || ext == "pvtp" {
        return Ok(None);
    }
    let format = detect_format(file).map_err(|e| fail(format!("block failed: {e}")))?;
    if matches!(format, Format::Pvd | Format::Series | Format::XmlMultiBlock) {
        return Err(fail(format!(
            "block {} is itself a collection or a multiblock file",
            file.display()
        )));
    }
    crate::io::read(file, &ReadOptions::default())
        .map(Some)
        .map_err(|e| fail(format!("block failed: {e}")))
}
