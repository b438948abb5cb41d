//! The pre-integration tables of the table modes (`preint3d`, `preint2d`,
//! `preint2d-cyl`): what each texel holds, the three ways to build them,
//! local rebuilds after a transfer-function edit, and the per-device cache.
//!
//! **Texels.** Scalars are the normalised ones of the segment payload
//! ([`ScalarMap`]: the transfer function's node range is [0, 1]); lengths
//! are world lengths. With `ns` samples per scalar axis at `i / (ns - 1)`:
//! - [`TableKind::Cube`] (RKE section 3), `ns x ns x nz`: texel `(i, j, k)`
//!   is the premultiplied colour and opacity of the segment
//!   `(s_i, s_j, l_k = k / (nz - 1) l_table)`;
//! - [`TableKind::Flat`] (RKE section 4), `ns x ns`: colour and **optical
//!   depth** (not opacity) of `(s_i, s_j, l_table)`, `l_table` the mean cell
//!   thickness;
//! - [`TableKind::Cylinder`] (RE section 4), `ns x ns x nz` planes: texel
//!   `(u, v, a)` is the segment at equation 9's `(S_f, S_b, L)`
//!   ([`cyl_to_table`]), `l = L l_table`.
//!
//! **Builds** ([`TableBuild`]): `Exact` evaluates [`crate::integrate::segment`]
//! in `f64` on all cores; `Fast` uses the integral functions of
//! [`crate::integrate::fast`] (EKE 3.5: exact opacity, mean-glow colour);
//! `Gpu` runs `shaders/table_build.wgsl` through the generic compute
//! facility ([`crate::gpu::compute`], [`super::table_build`]): one
//! invocation per column of the 3D table's lengths, one per texel of the
//! others (`integrate_segment`, shaders/integral.wgsl); its CPU twins are
//! [`super::table_build::build_column`] and
//! [`super::table_build::build_main`].
//!
//! **Edits.** A segment's integral depends only on the transfer function
//! between its two scalars, so after an edit confined to the scalar
//! interval `[a, b]` ([`tf_change`]) only texels whose scalar interval meets
//! it change; every build takes that interval and leaves the other texels
//! as they are (the CPU keeps its texels, the GPU its storage buffer).
//!
//! **Cache** ([`TableCache`], one per device through
//! [`Context::resource`]): tables by (kind, size, length, build); a frame
//! with the same transfer function reuses the table, an edit updates the
//! touched texels, anything else (another scalar range, another emission
//! model) rebuilds.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;

use crate::gpu::{Context, GpuError, Table, TableDim};
use crate::integrate::cylinder::cyl_to_table;
use crate::integrate::fast::{approx_rgba, point_source, FastColour, IntegralFunctions};
use crate::integrate::segment;
use crate::mesh::quality::{cell_diagonal, cell_volume};
use crate::mesh::Mesh;
use crate::numeric::tolerance::{INTEGRAL_FUNCTION_MIN_DS_REL, TABLE_LENGTH_MARGIN};
use crate::render::TableBuild;
use crate::tf::TransferFunction;

use super::integral::{closed_form_constants, TfBuffer};
use super::segment::ScalarMap;
use super::table_build::{build_main, column_main, BuildParams};
pub use super::table_build::{gpu_build, TABLE_BUILD, TABLE_COLUMNS};

/// Largest number of texels a table may have (256 Mi: 4 GiB of RGBA f32).
pub const MAX_TEXELS: u64 = 1 << 28;

/// Which table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TableKind {
    /// The 3D `(s_f, s_b, l)` table.
    Cube,
    /// The 2D `(s_f, s_b)` table at the mean cell thickness.
    Flat,
    /// The cylindrical planes of the 3D table.
    Cylinder,
}

impl TableKind {
    /// Samples per scalar axis when `--table` is absent (measured, see
    /// the modes' registry entries).
    pub fn default_size(self) -> u32 {
        match self {
            TableKind::Cube => 128,
            TableKind::Flat => 512,
            TableKind::Cylinder => 128,
        }
    }

    /// The texture shape.
    pub fn dim(self) -> TableDim {
        match self {
            TableKind::Cube => TableDim::D3,
            TableKind::Flat => TableDim::D2,
            TableKind::Cylinder => TableDim::D2Array,
        }
    }

    /// Texels per axis for `--table n`: the 3D table has `n` lengths, the
    /// cylinder `2 n` planes (RE: `n` to `4 n`; measured in the modes'
    /// entries).
    pub fn extent(self, n: u32) -> [u32; 3] {
        match self {
            TableKind::Cube => [n, n, n],
            TableKind::Flat => [n, n, 1],
            TableKind::Cylinder => [n, n, n.saturating_mul(2)],
        }
    }

    pub(super) fn code(self) -> u32 {
        match self {
            TableKind::Cube => 0,
            TableKind::Flat => 1,
            TableKind::Cylinder => 2,
        }
    }
}

/// A `--table` size that no device can hold.
#[derive(Debug, Error, PartialEq)]
pub enum TableSizeError {
    #[error("--table {0}: a table needs at least 2 samples per axis")]
    TooSmall(u32),
    #[error(
        "--table {size}: the table would have {texels} texels ({gib:.1} GiB), more than the {max} \
         (4 GiB) zoovr allows"
    )]
    TooLarge {
        size: u32,
        texels: u64,
        gib: f64,
        max: u64,
    },
}

/// One table: its kind, texels per axis and the length it spans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableSpec {
    pub kind: TableKind,
    pub size: [u32; 3],
    /// The longest tabulated length (cube, cylinder) or the reference
    /// length (flat), world units.
    pub l_table: f64,
}

impl TableSpec {
    /// Refuses `--table n` below 2 samples.
    pub fn check_small(kind: TableKind, n: Option<u32>) -> Result<(), TableSizeError> {
        let n = n.unwrap_or(kind.default_size());
        if n < 2 {
            return Err(TableSizeError::TooSmall(n));
        }
        Ok(())
    }

    /// The table of `kind` for `--table n` (`None`: the default size).
    pub fn new(kind: TableKind, n: Option<u32>, l_table: f64) -> Result<Self, TableSizeError> {
        Self::check_small(kind, n)?;
        let n = n.unwrap_or(kind.default_size());
        let size = kind.extent(n);
        let texels = size.iter().map(|&v| v as u64).product::<u64>();
        if texels > MAX_TEXELS {
            return Err(TableSizeError::TooLarge {
                size: n,
                texels,
                gib: texels as f64 * 16.0 / (1u64 << 30) as f64,
                max: MAX_TEXELS,
            });
        }
        Ok(TableSpec {
            kind,
            size,
            l_table,
        })
    }

    /// Number of texels.
    pub fn texels(&self) -> usize {
        self.size.iter().map(|&v| v as usize).product()
    }

    /// The normalised scalars and the length of texel `(i, j, z)`.
    pub fn texel_point(&self, i: u32, j: u32, z: u32) -> [f64; 3] {
        let ns = (self.size[0] - 1) as f64;
        let (x, y) = (i as f64 / ns, j as f64 / ns);
        let zn = self.size[2].max(2) as f64 - 1.0;
        match self.kind {
            TableKind::Cube => [x, y, z as f64 / zn * self.l_table],
            TableKind::Flat => [x, y, self.l_table],
            TableKind::Cylinder => {
                let (sf, sb, l) = cyl_to_table(z as f64 / zn, x, y);
                [sf, sb, l * self.l_table]
            }
        }
    }
}

/// How the transfer function changed between two builds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TfChange {
    /// Not at all.
    Same,
    /// Only inside this normalised scalar interval.
    Range(f64, f64),
    /// Everywhere (another scalar map or emission model).
    All,
}

/// Right (`right`) or left limit of `tf`'s extinction and colour at `s`.
fn limit(tf: &TransferFunction, s: f64, right: bool) -> (f64, [f64; 3]) {
    let n = tf.s.len();
    let i = if right {
        tf.s.partition_point(|&x| x <= s)
    } else {
        tf.s.partition_point(|&x| x < s)
    };
    if i == 0 {
        return (tf.tau[0], tf.col[0]);
    }
    if i >= n {
        return (tf.tau[n - 1], tf.col[n - 1]);
    }
    let (s0, s1) = (tf.s[i - 1], tf.s[i]);
    let u = if s1 > s0 { (s - s0) / (s1 - s0) } else { 0.0 };
    let (t0, t1) = (tf.tau[i - 1], tf.tau[i]);
    let (c0, c1) = (tf.col[i - 1], tf.col[i]);
    (
        t0 + (t1 - t0) * u,
        std::array::from_fn(|k| c0[k] + (c1[k] - c0[k]) * u),
    )
}

/// The smallest normalised scalar interval outside which `old` and `new`
/// are the same function (both piecewise linear: they agree on an interval
/// between consecutive nodes of either iff they agree at its two ends).
pub fn tf_change(old: &TransferFunction, new: &TransferFunction) -> TfChange {
    if old.model() != new.model() || ScalarMap::of(old) != ScalarMap::of(new) {
        return TfChange::All;
    }
    let mut p: Vec<f64> = old.s.iter().chain(&new.s).copied().collect();
    p.sort_by(f64::total_cmp);
    p.dedup();
    let same = |s: f64, right: bool| limit(old, s, right) == limit(new, s, right);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let last = p.len() - 1;
    if !same(p[0], false) {
        lo = f64::NEG_INFINITY;
    }
    if !same(p[last], true) {
        hi = f64::INFINITY;
    }
    for w in p.windows(2) {
        if !same(w[0], true) || !same(w[1], false) {
            lo = lo.min(w[0]);
            hi = hi.max(w[1]);
        }
    }
    if lo > hi {
        return TfChange::Same;
    }
    let map = ScalarMap::of(new);
    let norm = |s: f64| {
        if s.is_finite() {
            map.apply(s)
        } else {
            s
        }
    };
    TfChange::Range(norm(lo), norm(hi))
}

/// Whether a texel of scalar interval `[min(sf, sb), max(sf, sb)]` meets
/// the touched interval `[lo, hi]`.
#[inline]
fn touched(sf: f64, sb: f64, lo: f64, hi: f64) -> bool {
    sf.max(sb) >= lo && sf.min(sb) <= hi
}

/// Fills (or, over `range`, updates) `data` (RGBA, x fastest) on the CPU
/// with `method` (`Gpu` means the CPU twin of the GPU build).
pub fn fill_cpu(
    spec: &TableSpec,
    tf: &TransferFunction,
    method: TableBuild,
    range: (f64, f64),
    data: &mut [f32],
) -> usize {
    let ns = spec.size[0] as usize;
    let map = ScalarMap::of(tf);
    let data_s = |s: f64| map.offset + s / map.scale;
    let (lo, hi) = range;
    let row = |r: usize, out: &mut [f32], f: &(dyn Fn([f64; 3]) -> [f64; 4] + Sync)| {
        let (j, z) = ((r % ns) as u32, (r / ns) as u32);
        let mut n = 0;
        for i in 0..ns {
            let p = spec.texel_point(i as u32, j, z);
            if touched(p[0], p[1], lo, hi) {
                out[4 * i..4 * i + 4].copy_from_slice(&f(p).map(|x| x as f32));
                n += 1;
            }
        }
        n
    };
    let mut run = |f: &(dyn Fn([f64; 3]) -> [f64; 4] + Sync)| -> usize {
        data.par_chunks_mut(4 * ns)
            .enumerate()
            .map(|(r, out)| row(r, out, f))
            .sum()
    };
    let flat = spec.kind == TableKind::Flat;
    match method {
        TableBuild::Exact | TableBuild::Auto => run(&|p| {
            let v = segment(tf, p[2], data_s(p[0]), data_s(p[1]));
            let a = if flat { v.depth } else { v.alpha };
            [v.color[0], v.color[1], v.color[2], a]
        }),
        TableBuild::Fast => {
            let f = IntegralFunctions::new(tf);
            let min_ds = INTEGRAL_FUNCTION_MIN_DS_REL / map.scale;
            run(&|p| {
                let (sf, sb) = (data_s(p[0]), data_s(p[1]));
                let ends = (f.eval(sf), f.eval(sb));
                let mid = || point_source(tf, 0.5 * (sf + sb));
                let ds = sb - sf;
                let mut v = approx_rgba(p[2], ds, ends, mid, min_ds, FastColour::MeanGlow);
                if flat {
                    let tau = if ds.abs() > min_ds {
                        ((ends.1 .0 - ends.0 .0) / ds).max(0.0)
                    } else {
                        mid().0
                    };
                    v[3] = p[2] * tau;
                }
                v
            })
        }
        TableBuild::Gpu if spec.kind == TableKind::Cube => {
            // The twin of the kernel's columns: one per (i, j), every length.
            let buf = TfBuffer::new(tf, &map);
            let consts = closed_form_constants();
            let params = BuildParams::new(spec, range);
            let nz = spec.size[2] as usize;
            let columns: Vec<Option<Vec<[f32; 4]>>> = (0..ns * ns)
                .into_par_iter()
                .map(|c| {
                    let mut out = vec![[0.0; 4]; nz];
                    let (ix, iy) = ((c % ns) as u32, (c / ns) as u32);
                    column_main(&buf, &consts, &params, ix, iy, &mut out).then_some(out)
                })
                .collect();
            let mut n = 0;
            for (c, col) in columns.iter().enumerate() {
                let Some(col) = col else { continue };
                for (k, v) in col.iter().enumerate() {
                    let at = 4 * (k * ns * ns + c);
                    data[at..at + 4].copy_from_slice(v);
                }
                n += nz;
            }
            n
        }
        TableBuild::Gpu => {
            let buf = TfBuffer::new(tf, &map);
            let consts = closed_form_constants();
            run(&|p| {
                let q = p.map(|x| x as f32);
                build_main(&buf, &consts, spec.kind, q).map(|x| x as f64)
            })
        }
    }
}

/// What building (or finding) the frame's table did.
#[derive(Clone, Debug, Serialize)]
pub struct TableStats {
    pub kind: TableKind,
    /// Texels per axis.
    pub size: [u32; 3],
    /// The build method used (`auto` resolved).
    pub build: TableBuild,
    /// The longest tabulated length (cube, cylinder) or the reference
    /// length (flat), world units.
    pub l_table: f64,
    /// Texels integrated for this frame (0: the cached table was reused).
    pub texels_built: usize,
    /// Seconds spent building and uploading.
    pub build_s: f64,
}

/// Lengths of a mesh the tables are scaled to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneLengths {
    /// The largest bounding-box diagonal of a cell, which bounds every
    /// segment through a piece (pieces lie inside their cell).
    pub max_diameter: f64,
    /// The mean cell thickness: the cube root of the mean |volume|.
    pub mean_thickness: f64,
}

impl SceneLengths {
    /// The lengths of `mesh` (all cores).
    pub fn of(mesh: &Mesh) -> SceneLengths {
        let n = mesh.cells.len();
        let (dmax, vsum) = (0..n)
            .into_par_iter()
            .map(|c| {
                let d = cell_diagonal(&mesh.cells, &mesh.points, c);
                let v = cell_volume(&mesh.cells, &mesh.points, c).abs();
                (
                    if d.is_finite() { d } else { 0.0 },
                    if v.is_finite() { v } else { 0.0 },
                )
            })
            .reduce(|| (0.0, 0.0), |a, b| (a.0.max(b.0), a.1 + b.1));
        let max_diameter = if dmax > 0.0 { dmax } else { 1.0 };
        let mean = (vsum / n.max(1) as f64).cbrt();
        SceneLengths {
            max_diameter: max_diameter * (1.0 + TABLE_LENGTH_MARGIN),
            mean_thickness: if mean > 0.0 && mean.is_finite() {
                mean
            } else {
                max_diameter
            },
        }
    }
}

/// Whole tables built on the CPU, kept for the process: by spec, build and
/// transfer function (the least recently used of [`CPU_TABLES_KEPT`] goes
/// first). A CPU twin and a device's first CPU build of the same table
/// share them instead of integrating every texel again.
static CPU_TABLES: Mutex<Vec<CpuTexels>> = Mutex::new(Vec::new());

/// Whole CPU-built tables the process keeps.
const CPU_TABLES_KEPT: usize = 6;

/// One table of [`CPU_TABLES`].
struct CpuTexels {
    spec: TableSpec,
    build: TableBuild,
    tf: TransferFunction,
    data: Arc<Vec<f32>>,
}

/// Every texel of `spec` for `tf`, built on the CPU with `build`
/// ([`fill_cpu`]) or found in the process's cache of whole tables; with
/// whether it was built now.
pub fn cpu_texels(
    spec: &TableSpec,
    tf: &TransferFunction,
    build: TableBuild,
) -> (Arc<Vec<f32>>, bool) {
    let same = |e: &CpuTexels| e.spec == *spec && e.build == build && e.tf == *tf;
    {
        let mut kept = CPU_TABLES.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = kept.iter().position(same) {
            let e = kept.remove(i);
            let data = e.data.clone();
            kept.push(e);
            return (data, false);
        }
    }
    let mut data = vec![0.0; 4 * spec.texels()];
    fill_cpu(
        spec,
        tf,
        build,
        (f64::NEG_INFINITY, f64::INFINITY),
        &mut data,
    );
    let data = Arc::new(data);
    let mut kept = CPU_TABLES.lock().unwrap_or_else(|e| e.into_inner());
    if !kept.iter().any(same) {
        kept.push(CpuTexels {
            spec: *spec,
            build,
            tf: tf.clone(),
            data: data.clone(),
        });
        if kept.len() > CPU_TABLES_KEPT {
            kept.remove(0);
        }
    }
    (data, true)
}

/// One cached table.
struct Entry {
    spec: TableSpec,
    build: TableBuild,
    tf: TransferFunction,
    table: Arc<Table>,
    /// The texels, for a local update (CPU builds).
    cpu: Option<Vec<f32>>,
    /// Whether the GPU built it (a local update then rewrites the touched
    /// texels in place).
    gpu: bool,
}

/// A mesh by its address, cell count and point count.
type MeshKey = (usize, usize, usize);

/// Tables kept on one device (see the module docs).
#[derive(Default)]
pub struct TableCache {
    entries: Mutex<Vec<Entry>>,
    /// The lengths of the last mesh, by its address and counts.
    lengths: Mutex<Option<(MeshKey, SceneLengths)>>,
}

/// Tables kept per device (the least recently used goes first).
const CACHED_TABLES: usize = 4;

impl TableCache {
    /// The cache of `ctx`.
    pub fn of(ctx: &Context) -> Result<Arc<TableCache>, GpuError> {
        ctx.resource("preint: tables", |_| Ok(TableCache::default()))
    }

    /// The lengths of `mesh`, computed once per mesh.
    pub fn lengths(&self, mesh: &Mesh) -> SceneLengths {
        let key = (
            mesh as *const Mesh as usize,
            mesh.cells.len(),
            mesh.points.len(),
        );
        let mut l = self.lengths.lock().unwrap_or_else(|e| e.into_inner());
        match *l {
            Some((k, v)) if k == key => v,
            _ => {
                let v = SceneLengths::of(mesh);
                *l = Some((key, v));
                v
            }
        }
    }

    /// The table `spec` of `tf` built with `build` (not `Auto`): the
    /// cached one, updated where `tf` changed, or a new one.
    pub fn table(
        &self,
        ctx: &Context,
        spec: &TableSpec,
        build: TableBuild,
        tf: &TransferFunction,
    ) -> Result<(Arc<Table>, TableStats), GpuError> {
        let t0 = Instant::now();
        Table::check_size(ctx.limits(), spec.kind.dim(), spec.size)?;
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        let found = entries
            .iter()
            .position(|e| e.spec == *spec && e.build == build);
        let mut entry = match found {
            Some(i) => entries.remove(i),
            None => {
                let table =
                    Table::empty_rgba(ctx, "pre-integration table", spec.kind.dim(), spec.size)?;
                Entry {
                    spec: *spec,
                    build,
                    tf: tf.clone(),
                    table: Arc::new(table),
                    cpu: None,
                    gpu: false,
                }
            }
        };
        let change = match (found, entry.cpu.is_some() || entry.gpu) {
            (Some(_), true) => tf_change(&entry.tf, tf),
            _ => TfChange::All,
        };
        let range = match change {
            TfChange::Same => None,
            TfChange::Range(a, b) => Some((a, b)),
            TfChange::All => Some((f64::NEG_INFINITY, f64::INFINITY)),
        };
        let mut built = 0;
        if let Some(range) = range {
            if build == TableBuild::Gpu {
                gpu_build(ctx, spec, tf, range, &entry.table)?;
                entry.gpu = true;
                built = count_touched(spec, range);
            } else if change == TfChange::All {
                // A whole table: every texel written, from the process's
                // cache where another render built it.
                let data = cpu_texels(spec, tf, build).0.to_vec();
                built = spec.texels();
                entry.table.write_rgba(ctx, &data)?;
                entry.cpu = Some(data);
            } else {
                let data = entry
                    .cpu
                    .get_or_insert_with(|| vec![0.0; 4 * spec.texels()]);
                built = fill_cpu(spec, tf, build, range, data);
                entry.table.write_rgba(ctx, data)?;
            }
            entry.tf = tf.clone();
        }
        let table = entry.table.clone();
        entries.push(entry);
        if entries.len() > CACHED_TABLES {
            entries.remove(0);
        }
        Ok((
            table,
            TableStats {
                kind: spec.kind,
                size: spec.size,
                build,
                l_table: spec.l_table,
                texels_built: built,
                build_s: t0.elapsed().as_secs_f64(),
            },
        ))
    }
}

/// Texels of `spec` whose scalar interval meets `range`.
fn count_touched(spec: &TableSpec, range: (f64, f64)) -> usize {
    if range.0 == f64::NEG_INFINITY && range.1 == f64::INFINITY {
        return spec.texels();
    }
    let [ns, nh, nz] = spec.size;
    (0..nz)
        .flat_map(|z| (0..nh).flat_map(move |j| (0..ns).map(move |i| (i, j, z))))
        .filter(|&(i, j, z)| {
            let p = spec.texel_point(i, j, z);
            touched(p[0], p[1], range.0, range.1)
        })
        .count()
}
