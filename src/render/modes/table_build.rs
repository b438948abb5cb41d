//! The CPU twin of `shaders/table_build.wgsl`, the GPU build of the
//! pre-integration tables, and the kernel's description and buffers.
//!
//! The kernel ([`TABLE_BUILD`], behind `shaders/integral.wgsl`) runs one
//! invocation per texel of every slice in one dispatch through the generic
//! compute facility ([`crate::gpu::compute`]), each the exact `f32`
//! integral `integrate_segment` at the texel's `(s_f, s_b, l)`; the 2D
//! table holds the optical depth instead of the opacity ([`optical_depth`]).
//! [`GpuBuilt`] holds the kernel's storage buffer (rows padded for the copy
//! into the table's texture). On the CPU, [`build_main`] is the twin of one
//! invocation; `cyl_to_table` is [`crate::integrate::cylinder::cyl_to_table`]
//! (in `f64`, through [`TableSpec::texel_point`]).

use bytemuck::{Pod, Zeroable};

use crate::gpu::compute::{ComputeBinding, ComputeDesc, ComputeResource, GpuBuffer, ROW_ALIGN};
use crate::gpu::{Context, GpuError, Table};
use crate::tf::TransferFunction;

use super::integral::{closed_form_constants, TfBuffer};
use super::preint_tables::{TableKind, TableSpec};
use super::segment::ScalarMap;

/// Keep in sync with `BuildParams` in `shaders/table_build.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug)]
struct BuildParams {
    kind: u32,
    ns: u32,
    nz: u32,
    row_texels: u32,
    l_table: f32,
    lo: f32,
    hi: f32,
    _pad: f32,
}

/// The GPU build kernel.
pub static TABLE_BUILD: ComputeDesc = ComputeDesc {
    name: "table_build.wgsl",
    wgsl: concat!(
        include_str!("../../../shaders/integral.wgsl"),
        include_str!("../../../shaders/table_build.wgsl"),
    ),
    entry: "build_main",
    bindings: &[
        ComputeBinding::Uniform,
        ComputeBinding::Storage,
        ComputeBinding::Storage,
        ComputeBinding::StorageRw,
    ],
};

/// Texels per padded row of a GPU-built table of `ns` texels per row.
pub fn row_texels(ns: u32) -> u32 {
    let per_align = ROW_ALIGN / 16;
    ns.div_ceil(per_align) * per_align
}

/// A table built on the GPU: its storage buffer (rows padded) and texture.
pub struct GpuBuilt {
    pub buffer: GpuBuffer,
    pub row_texels: u32,
}

impl GpuBuilt {
    /// A zeroed buffer for `spec`.
    pub fn new(ctx: &Context, spec: &TableSpec) -> Result<GpuBuilt, GpuError> {
        let rt = row_texels(spec.size[0]);
        let len = rt as u64 * spec.size[1] as u64 * spec.size[2] as u64 * 16;
        Ok(GpuBuilt {
            buffer: GpuBuffer::new(ctx, "pre-integration table", len)?,
            row_texels: rt,
        })
    }

    /// Integrates the texels of `spec` that meet `range` into the buffer
    /// and copies the buffer into `table`.
    pub fn build(
        &self,
        ctx: &Context,
        spec: &TableSpec,
        tf: &TransferFunction,
        range: (f64, f64),
        table: &Table,
    ) -> Result<(), GpuError> {
        let clamp = |x: f64| x.clamp(-1e30, 1e30) as f32;
        let params = BuildParams {
            kind: spec.kind.code(),
            ns: spec.size[0],
            nz: spec.size[2],
            row_texels: self.row_texels,
            l_table: spec.l_table as f32,
            lo: clamp(range.0),
            hi: clamp(range.1),
            _pad: 0.0,
        };
        let buf = TfBuffer::new(tf, &ScalarMap::of(tf));
        let consts = closed_form_constants();
        ctx.dispatch(
            &TABLE_BUILD,
            &[
                ComputeResource::Uniform(bytemuck::bytes_of(&params)),
                ComputeResource::Storage(&buf.bytes()),
                ComputeResource::Storage(bytemuck::cast_slice(&consts)),
                ComputeResource::Buffer(&self.buffer),
            ],
            [
                spec.size[0].div_ceil(8),
                spec.size[1].div_ceil(8),
                spec.size[2],
            ],
        )?;
        self.buffer.copy_to_table(ctx, table, self.row_texels * 16);
        ctx.check()
    }

    /// The texels (unpadded, RGBA, x fastest), read back.
    pub fn read(&self, ctx: &Context, spec: &TableSpec) -> Result<Vec<f32>, GpuError> {
        let bytes = self.buffer.read(ctx)?;
        let all: &[f32] = bytemuck::cast_slice(&bytes);
        let (ns, rt) = (spec.size[0] as usize, self.row_texels as usize);
        let rows = spec.size[1] as usize * spec.size[2] as usize;
        let mut out = Vec::with_capacity(4 * ns * rows);
        for r in 0..rows {
            out.extend_from_slice(&all[4 * r * rt..4 * (r * rt + ns)]);
        }
        Ok(out)
    }
}

/// Twin of `build_main` for one texel of a table of `kind`: the `f32`
/// closed form at the texel's point `p` (`(s_f, s_b, l)`, from
/// [`TableSpec::texel_point`], which holds the twin of `cyl_to_table`).
pub fn build_main(tf: &TfBuffer, consts: &[[f32; 4]], kind: TableKind, p: [f32; 3]) -> [f32; 4] {
    let mut v = tf.integrate_segment(consts, p[2], p[0], p[1]);
    if kind == TableKind::Flat {
        v[3] = optical_depth(tf, p[2], p[0], p[1]);
    }
    v
}

/// Twin of `optical_depth`: `l` times the mean extinction over
/// `[s_f, s_b]`, piece by piece of the transfer function.
pub fn optical_depth(tf: &TfBuffer, l: f32, sf: f32, sb: f32) -> f32 {
    let (lo, hi) = (sf.min(sb), sf.max(sb));
    let count = (tf.nodes.len() / 2) as u32;
    let node_s = |i: u32| tf.nodes[2 * i as usize][0];
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return l * tf.eval_piece(tf.piece_index(lo), lo).tau;
    }
    let (mut sum, mut s0, mut i) = (0.0f32, lo, tf.piece_index(lo));
    loop {
        let next = if i < count { node_s(i).min(hi) } else { hi };
        if next > s0 {
            let idx = tf.piece_index(0.5 * (s0 + next));
            let t0 = tf.eval_piece(idx, s0).tau;
            let t1 = tf.eval_piece(idx, next).tau;
            sum += 0.5 * (t0 + t1) * (next - s0);
        }
        if next >= hi || i >= count {
            break;
        }
        s0 = next;
        i += 1;
    }
    l * (sum / (hi - lo))
}
