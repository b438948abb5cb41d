//! PLOT3D reader: 3D whole-format binary grids (`.xyz`, `.bin`, `.p3d`),
//! single- or multi-grid, and their `q` solution files.
//!
//! PLOT3D files carry no magic number, so the layout is inferred from the
//! sizes. A grid file is `[nblocks]? ni nj nk`, then all x, all y, all z
//! (`f32` or `f64`), then optionally `ni*nj*nk` 32-bit IBLANK flags. A
//! multi-grid file has `nblocks > 1`, the dimensions of every grid in one
//! record, then each grid's record in turn (a q file: each grid's
//! conditions and data); its grids are merged into one mesh as the pieces
//! of a parallel file are (point ids offset per grid), and the topology
//! joins them where their faces meet point for point. Written
//! by Fortran, each record may be framed by 4-byte length markers. For both
//! byte orders and each framing we read the dimensions and keep the variant
//! whose expected size fits the file: with markers the markers must match;
//! without them the variant (precision, IBLANK) that leaves the fewest
//! trailing bytes wins, and trailing padding shorter than one extra array
//! (`4 * ni*nj*nk` bytes) is tolerated. Counts are checked against the file
//! size before anything is allocated.
//!
//! A `q` file has the same header (dimensions must match), then `fsmach,
//! alpha, re, time` and five arrays: density, momentum x/y/z and stagnation
//! energy. Like VTK's `vtkMultiBlockPLOT3DReader` the mesh gets the point
//! arrays `Density`, `Momentum` (3 components), `StagnationEnergy`, and the
//! derived `VelocityMagnitude` (|m| / rho) and `Pressure`
//! ((gamma - 1) (E - rho |v|^2 / 2), gamma = 1.4 as VTK's `f32`), computed in `f64` the
//! way VTK does and stored at the file's precision.
//!
//! The grid becomes hexahedra in VTK node order (see
//! [`crate::io::legacy`]'s structured builder). Cells touching a blanked
//! point (IBLANK = 0) are dropped and the IBLANK flags kept as the point
//! array `IBlank`.

use std::path::Path;

use glam::DVec3;

use super::{IoError, Location};
use crate::field::{ArrayData, DataArray};
use crate::mesh::Mesh;

/// Ratio of specific heats used for the derived pressure: VTK's default 1.4,
/// which VTK holds as an `f32`; using the same value (1.39999998...)
/// reproduces VTK's `Pressure` bit for bit (checked on the Blunt Fin data).
pub const GAMMA: f64 = 1.4f32 as f64;

/// How a file's header is framed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Framing {
    big_endian: bool,
    markers: bool,
    nblocks: bool,
}

impl Framing {
    const ALL: [Framing; 8] = {
        let mut a = [Framing {
            big_endian: true,
            markers: true,
            nblocks: false,
        }; 8];
        let mut i = 0;
        while i < 8 {
            a[i] = Framing {
                big_endian: i & 1 == 0,
                markers: i & 2 == 0,
                nblocks: i & 4 != 0,
            };
            i += 1;
        }
        a
    };

    fn int(self, b: &[u8], off: usize) -> Option<i64> {
        let s = b.get(off..off.checked_add(4)?)?;
        let a = [s[0], s[1], s[2], s[3]];
        Some(i64::from(if self.big_endian {
            i32::from_be_bytes(a)
        } else {
            i32::from_le_bytes(a)
        }))
    }

    /// Each grid's dimensions and the offset where the data starts (after
    /// the header records and, with markers, before the first data record's
    /// leading marker). With an `nblocks` prefix the dimensions of all
    /// grids form one record; a grid count needs that many plausible
    /// triples within the file.
    fn header(self, b: &[u8]) -> Option<(Vec<[usize; 3]>, usize)> {
        let mut off = 0;
        let mut grids = 1usize;
        if self.nblocks {
            if self.markers {
                (self.int(b, 0)? == 4).then_some(())?;
                grids = usize::try_from(self.int(b, 4)?).ok()?;
                (self.int(b, 8)? == 4).then_some(())?;
                off = 12;
            } else {
                grids = usize::try_from(self.int(b, 0)?).ok()?;
                off = 4;
            }
            // Each grid needs at least its dimensions and a point.
            if grids == 0 || grids > MAX_GRIDS || grids.saturating_mul(16) > b.len() {
                return None;
            }
        }
        if self.markers {
            (self.int(b, off)? == 12 * grids as i64).then_some(())?;
            off += 4;
        }
        let mut dims = Vec::with_capacity(grids);
        for g in 0..grids {
            let mut d = [0usize; 3];
            for (i, v) in d.iter_mut().enumerate() {
                let x = self.int(b, off + 12 * g + 4 * i)?;
                *v = usize::try_from(x)
                    .ok()
                    .filter(|&x| (1..=1 << 24).contains(&x))?;
            }
            dims.push(d);
        }
        off += 12 * grids;
        if self.markers {
            (self.int(b, off)? == 12 * grids as i64).then_some(())?;
            off += 4;
        }
        Some((dims, off))
    }
}

/// The most grids a multi-grid file may hold: far above real multi-block
/// and overset grids (thousands), low enough that a hostile count of tiny
/// grids cannot make a million meshes to merge.
const MAX_GRIDS: usize = 1 << 16;

/// A detected layout of a grid or q file.
#[derive(Clone, Debug)]
struct Layout {
    framing: Framing,
    /// Each grid's dimensions.
    dims: Vec<[usize; 3]>,
    double: bool,
    iblank: bool,
    /// Offset of the first value of each grid's main data record.
    data: Vec<usize>,
    padding: usize,
}

/// Point count of a grid, saturating (each dimension is at most 2^24, so
/// a product can exceed `usize`; a saturated count fails the size checks).
fn point_count(dims: [usize; 3]) -> usize {
    dims.iter().fold(1usize, |a, &d| a.saturating_mul(d))
}

impl Layout {
    fn real_size(&self) -> usize {
        if self.double {
            8
        } else {
            4
        }
    }

    fn real(&self, b: &[u8], off: usize) -> f64 {
        let be = self.framing.big_endian;
        if self.double {
            let mut a = [0u8; 8];
            a.copy_from_slice(&b[off..off + 8]);
            if be {
                f64::from_be_bytes(a)
            } else {
                f64::from_le_bytes(a)
            }
        } else {
            let mut a = [0u8; 4];
            a.copy_from_slice(&b[off..off + 4]);
            f64::from(if be {
                f32::from_be_bytes(a)
            } else {
                f32::from_le_bytes(a)
            })
        }
    }
}

/// Finds the layout (framing, precision, IBLANK) whose size fits the file
/// with the least trailing padding (`want`: dimensions the header must
/// give). A grid has one record after the header (coordinates and IBLANK);
/// a q file two (the four conditions, the data).
fn detect(b: &[u8], q: bool, want: Option<&[[usize; 3]]>) -> Option<Layout> {
    let mut best: Option<Layout> = None;
    for framing in Framing::ALL {
        let Some((dims, off)) = framing.header(b) else {
            continue;
        };
        if want.is_some_and(|w| w != dims.as_slice()) {
            continue;
        }
        let Some(counts) = dims
            .iter()
            .map(|d| d[0].checked_mul(d[1]).and_then(|x| x.checked_mul(d[2])))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        for double in [false, true] {
            let rs = if double { 8 } else { 4 };
            for iblank in [false, true] {
                if q && iblank {
                    continue;
                }
                let Some((data, end)) = walk_records(b, framing, off, &counts, q, rs, iblank)
                else {
                    continue;
                };
                let padding = b.len() - end;
                let last = counts.last().copied().unwrap_or(1);
                if padding >= 4 * last.max(1) {
                    continue;
                }
                let cand = Layout {
                    framing,
                    dims: dims.clone(),
                    double,
                    iblank,
                    data,
                    padding,
                };
                // A 3D reading beats one with a dimension of 1 (which could be
                // an `nblocks = 1` prefix misread), then the least padding wins.
                let key = |l: &Layout| (l.dims.iter().any(|d| d.contains(&1)), l.padding);
                if best.as_ref().is_none_or(|x| key(&cand) < key(x)) {
                    best = Some(cand);
                }
            }
        }
    }
    best
}

/// Walks the data records of grids of `counts` points from `off`: per grid
/// one record (coordinates and IBLANK), or for a q file two (the four
/// conditions, the data), each framed by matching markers when the file
/// has them. Returns each grid's main data offset and where the records
/// end, if they fit the file.
fn walk_records(
    b: &[u8],
    framing: Framing,
    off: usize,
    counts: &[usize],
    q: bool,
    rs: usize,
    iblank: bool,
) -> Option<(Vec<usize>, usize)> {
    let marker = |pos: usize, r: usize| {
        !framing.markers || framing.int(b, pos).and_then(|m| usize::try_from(m).ok()) == Some(r)
    };
    let step = if framing.markers { 4 } else { 0 };
    let mut pos = off;
    let mut data = Vec::with_capacity(counts.len());
    for &n in counts {
        let main = if q {
            n.checked_mul(5 * rs)?
        } else {
            n.checked_mul(3 * rs + if iblank { 4 } else { 0 })?
        };
        let both = [4 * rs, main];
        let records: &[usize] = if q { &both } else { &both[1..] };
        for (k, &r) in records.iter().enumerate() {
            marker(pos, r).then_some(())?;
            pos += step;
            if k + 1 == records.len() {
                data.push(pos);
            }
            pos = pos.checked_add(r).filter(|&p| p <= b.len())?;
            marker(pos, r).then_some(())?;
            pos += step;
        }
    }
    (pos <= b.len()).then_some((data, pos))
}

/// Explains why no layout fits: for the first framing whose header reads as
/// dimensions, where the data should start and how many bytes it needs.
fn diagnose(path: &Path, b: &[u8], q: bool) -> IoError {
    let kind = if q { "q solution" } else { "grid" };
    // A multi-grid header first (its count would also read as a single
    // grid's first dimension).
    let multi = Framing::ALL
        .iter()
        .filter_map(|&f| f.header(b).map(|h| (f, h)))
        .find(|(_, (dims, _))| dims.len() > 1);
    let first = multi.or_else(|| {
        Framing::ALL
            .iter()
            .find_map(|&f| f.header(b).map(|h| (f, h)))
    });
    if let Some((framing, (dims, off))) = first {
        let order = if framing.big_endian { "big" } else { "little" };
        let marks = if framing.markers { "with" } else { "without" };
        if dims.len() > 1 {
            return IoError::parse(
                path,
                Location::Byte(off as u64),
                format!(
                    "PLOT3D {kind} header says {} grids ({order}-endian, {marks} record markers), \
                     but no precision/IBLANK layout fits their data in the {} bytes that remain",
                    dims.len(),
                    b.len() - off
                ),
            );
        }
        let d = dims[0];
        let n = d[0] as u128 * d[1] as u128 * d[2] as u128;
        let min = if q { 5 * 4 * n + 16 } else { 3 * 4 * n };
        return IoError::parse(
            path,
            Location::Byte(off as u64),
            format!(
                "PLOT3D {kind} header says {}x{}x{} points ({order}-endian, {marks} record markers), \
                 but no precision/IBLANK layout fits: the data needs at least {min} bytes \
                 (with matching record markers), {} remain",
                d[0],
                d[1],
                d[2],
                b.len() - off
            ),
        );
    }
    IoError::parse(
        path,
        Location::Byte(0),
        format!(
            "not a 3D whole-format PLOT3D {kind}: the first bytes hold no plausible \
             dimensions (1..=2^24 each) in either byte order, with or without record markers \
             ({} bytes in the file)",
            b.len()
        ),
    )
}

/// Whether the first bytes look like a PLOT3D grid header (used by format
/// sniffing when the extension says nothing).
pub fn looks_like_grid(head: &[u8]) -> bool {
    Framing::ALL.iter().any(|f| {
        let Some((grids, off)) = f.header(head) else {
            return false;
        };
        let dims = grids[0];
        let Some(n) = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d)) else {
            return false;
        };
        if n < 8 || dims.iter().any(|&d| d < 2) {
            return false;
        }
        if f.markers {
            // The data record marker must announce a plausible grid size.
            return f.int(head, off).is_some_and(|m| {
                [12usize, 16, 24, 28]
                    .iter()
                    .any(|&per| per.checked_mul(n).is_some_and(|b| m == b as i64))
            });
        }
        // Without markers, the first coordinates must be sane numbers.
        let sane32 = (0..2).all(|i| {
            head.get(off + 4 * i..off + 4 * i + 4).is_some_and(|s| {
                let a = [s[0], s[1], s[2], s[3]];
                let v = if f.big_endian {
                    f32::from_be_bytes(a)
                } else {
                    f32::from_le_bytes(a)
                };
                v.is_finite() && v.abs() < 1e30
            })
        });
        let sane64 = head.get(off..off + 8).is_some_and(|s| {
            let mut a = [0u8; 8];
            a.copy_from_slice(s);
            let v = if f.big_endian {
                f64::from_be_bytes(a)
            } else {
                f64::from_le_bytes(a)
            };
            v.is_finite() && v.abs() < 1e30
        });
        sane32 || sane64
    })
}

/// Reads a PLOT3D grid (and optional q solution) from files.
pub fn read(path: &Path, q: Option<&Path>) -> Result<Mesh, IoError> {
    let grid = std::fs::read(path).map_err(|e| IoError::open(path, e))?;
    let qdata = match q {
        Some(qp) => Some((qp, std::fs::read(qp).map_err(|e| IoError::open(qp, e))?)),
        None => None,
    };
    read_bytes(path, &grid, qdata.as_ref().map(|(p, b)| (*p, b.as_slice())))
}

/// Reads a PLOT3D grid (and optional q solution: its path and bytes) from
/// memory; paths only name the files in errors.
pub fn read_bytes(path: &Path, grid: &[u8], q: Option<(&Path, &[u8])>) -> Result<Mesh, IoError> {
    let lay = detect(grid, false, None).ok_or_else(|| diagnose(path, grid, false))?;
    let qlay = match q {
        Some((qp, qb)) => Some((qp, qb, q_layout(&lay.dims, qp, qb)?)),
        None => None,
    };
    let mut grids = Vec::with_capacity(lay.dims.len());
    for g in 0..lay.dims.len() {
        let mut mesh = read_grid(path, grid, &lay, g)?;
        if let Some((qp, qb, ql)) = &qlay {
            attach_q(&mut mesh, qp, qb, ql, g);
        }
        grids.push(mesh);
    }
    let count = grids.len();
    let mut mesh = super::xml::merge_pieces(grids);
    if count > 1 {
        mesh.source.notes.push(format!("{count} grids merged"));
    }
    if lay.padding > 0 {
        mesh.source
            .notes
            .push(format!("{} trailing padding bytes ignored", lay.padding));
    }
    Ok(mesh)
}

/// Grid `g` of the file as hexahedra (cells touching a blanked point left
/// out).
fn read_grid(path: &Path, grid: &[u8], lay: &Layout, g: usize) -> Result<Mesh, IoError> {
    let dims = lay.dims[g];
    let n = point_count(dims);
    let rs = lay.real_size();
    let data = lay.data[g];
    let mut points = Vec::with_capacity(n);
    for p in 0..n {
        let mut v = [0.0; 3];
        for (c, x) in v.iter_mut().enumerate() {
            let off = data + (c * n + p) * rs;
            *x = lay.real(grid, off);
            if !x.is_finite() {
                let which = if lay.dims.len() > 1 {
                    format!("grid {g}, ")
                } else {
                    String::new()
                };
                return Err(IoError::parse(
                    path,
                    Location::Byte(off as u64),
                    format!("{which}point {p} has a non-finite coordinate"),
                ));
            }
        }
        points.push(DVec3::from(v));
    }
    let mut mesh = Mesh {
        points,
        cells: super::legacy::hexahedra(dims),
        ..Mesh::default()
    };
    if lay.iblank {
        let base = data + 3 * n * rs;
        let flags: Vec<i64> = (0..n)
            .map(|p| lay.framing.int(grid, base + 4 * p).unwrap_or(1))
            .collect();
        drop_blanked(&mut mesh, &flags);
        mesh.point_data.push(DataArray {
            name: "IBlank".into(),
            components: 1,
            data: ArrayData::Int(flags),
            vtk_type: "Int32".into(),
        });
    }
    let total = super::legacy::vtk_cell_count(dims);
    if mesh.cells.is_empty() {
        mesh.source.ignored_cells = total;
    } else {
        mesh.source
            .cells_by_type
            .insert("hexahedron".into(), mesh.cells.len());
    }
    Ok(mesh)
}

/// Removes cells that touch a point with IBLANK = 0.
fn drop_blanked(mesh: &mut Mesh, flags: &[i64]) {
    let old = std::mem::take(&mut mesh.cells);
    let mut dropped = 0;
    for c in 0..old.len() {
        let nodes = old.nodes(c);
        if nodes.iter().all(|&p| flags[p as usize] != 0) {
            mesh.cells.push(old.kinds[c], nodes);
        } else {
            dropped += 1;
        }
    }
    if dropped > 0 {
        mesh.source.notes.push(format!(
            "{dropped} cells touching blanked points (IBLANK = 0) dropped"
        ));
    }
}

/// The layout of a q file for grids of `dims`.
fn q_layout(dims: &[[usize; 3]], path: &Path, b: &[u8]) -> Result<Layout, IoError> {
    let lay = match detect(b, true, Some(dims)) {
        Some(l) => l,
        None => match detect(b, true, None) {
            Some(other) => other,
            None => return Err(diagnose(path, b, true)),
        },
    };
    if lay.dims != dims {
        return Err(IoError::parse(
            path,
            Location::Byte(0),
            format!(
                "q dimensions {:?} differ from the grid's {:?}",
                lay.dims, dims
            ),
        ));
    }
    Ok(lay)
}

/// Attaches grid `g`'s solution (of the q file `b` with layout `lay`).
fn attach_q(mesh: &mut Mesh, _path: &Path, b: &[u8], lay: &Layout, g: usize) {
    let n = point_count(lay.dims[g]);
    let rs = lay.real_size();
    let data = lay.data[g];
    // The four reals fsmach, alpha, re, time precede the data record.
    let conds = data - 4 * rs - if lay.framing.markers { 8 } else { 0 };
    let c: Vec<f64> = (0..4).map(|i| lay.real(b, conds + i * rs)).collect();
    mesh.source.notes.push(format!(
        "q: fsmach {} alpha {} re {} time {}",
        c[0], c[1], c[2], c[3]
    ));
    let var = |v: usize, p: usize| lay.real(b, data + (v * n + p) * rs);
    let mut rho = Vec::with_capacity(n);
    let mut mom = Vec::with_capacity(3 * n);
    let mut energy = Vec::with_capacity(n);
    let mut vmag = Vec::with_capacity(n);
    let mut pres = Vec::with_capacity(n);
    for p in 0..n {
        let d0 = var(0, p);
        let m = [var(1, p), var(2, p), var(3, p)];
        let e = var(4, p);
        // VTK's formulas, including its guard against zero density.
        let d = if d0 != 0.0 { d0 } else { 1.0 };
        let rr = 1.0 / d;
        let (u, v, w) = (m[0] * rr, m[1] * rr, m[2] * rr);
        let v2 = u * u + v * v + w * w;
        rho.push(d0);
        mom.extend_from_slice(&m);
        energy.push(e);
        vmag.push(v2.sqrt());
        pres.push((GAMMA - 1.0) * (e - 0.5 * d * v2));
    }
    let arr = |name: &str, comps: usize, v: Vec<f64>| DataArray {
        name: name.into(),
        components: comps,
        data: if lay.double {
            ArrayData::F64(v)
        } else {
            ArrayData::F32(v.into_iter().map(|x| x as f32).collect())
        },
        vtk_type: if lay.double { "Float64" } else { "Float32" }.into(),
    };
    mesh.point_data.push(arr("Density", 1, rho));
    mesh.point_data.push(arr("Momentum", 3, mom));
    mesh.point_data.push(arr("StagnationEnergy", 1, energy));
    mesh.point_data.push(arr("VelocityMagnitude", 1, vmag));
    mesh.point_data.push(arr("Pressure", 1, pres));
    mesh.active_point_scalars = Some("Density".into());
}
