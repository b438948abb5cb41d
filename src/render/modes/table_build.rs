//! The CPU twin of `shaders/table_build.wgsl`, the GPU build of the
//! pre-integration tables, and the kernel's description and buffers.
//!
//! The kernel ([`TABLE_BUILD`], behind `shaders/integral.wgsl`) fills
//! every texel in one dispatch through the generic compute facility
//! ([`crate::gpu::compute`]), each the `f32` integral at the texel's
//! `(s_f, s_b, l)`: the 3D table one invocation per column of lengths
//! ([`build_column`]: the Gauss-Legendre rule with each node's exponential
//! a power of its value at the shortest length, spans cut into sub-spans
//! thin enough for the rule, the lengths too thick for the cut texel by
//! texel), the other tables one invocation per texel (`integrate_segment`);
//! the 2D table holds the optical depth instead of the opacity
//! ([`optical_depth`]). The shader's head comment explains the column.
//! [`gpu_build`] writes the table's own storage buffer in place. On the CPU, [`build_main`] and
//! [`build_column`] are the twins of one invocation; `cyl_to_table` is
//! [`crate::integrate::cylinder::cyl_to_table`] (in `f64`, through
//! [`TableSpec::texel_point`]).

use bytemuck::{Pod, Zeroable};

use crate::gpu::compute::{ComputeBinding, ComputeDesc, ComputeResource};
use crate::gpu::{Context, GpuError, Table};
use crate::tf::TransferFunction;

use super::integral::{
    closed_form_constants, neg_expm1, GaussRule, Material, TfBuffer, GAUSS_MAX, GL6_BASE,
    MAX_THICKNESS,
};
use super::preint_tables::{TableKind, TableSpec};
use super::segment::ScalarMap;

/// The kernel's uniforms. Keep in sync with `BuildParams` in
/// `shaders/table_build.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug)]
pub struct BuildParams {
    kind: u32,
    ns: u32,
    nz: u32,
    _pad0: u32,
    l_table: f32,
    lo: f32,
    hi: f32,
    _pad: f32,
}

impl BuildParams {
    /// The uniforms that build the texels of `spec` meeting `range`.
    pub fn new(spec: &TableSpec, range: (f64, f64)) -> BuildParams {
        let clamp = |x: f64| x.clamp(-1e30, 1e30) as f32;
        BuildParams {
            kind: spec.kind.code(),
            ns: spec.size[0],
            nz: spec.size[2],
            _pad0: 0,
            l_table: spec.l_table as f32,
            lo: clamp(range.0),
            hi: clamp(range.1),
            _pad: 0.0,
        }
    }

    /// The workgroups of the dispatch: a column per invocation for the 3D
    /// table, a texel per invocation for the others.
    fn groups(&self) -> [u32; 3] {
        let z = if self.kind == TableKind::Cube.code() {
            1
        } else {
            self.nz
        };
        [self.ns.div_ceil(8), self.ns.div_ceil(8), z]
    }
}

/// Lengths per chunk of a column (`CHUNK`).
pub const CHUNK: usize = 16;
/// At most this many sub-spans per span of a column (`MAX_SUBSPANS`).
pub const MAX_SUBSPANS: u32 = 8;
/// Fewest lengths the recurrences serve in a column (`MIN_RECURRENCE`).
pub const MIN_RECURRENCE: u32 = 16;

const BUILD_BINDINGS: &[ComputeBinding] = &[
    ComputeBinding::Uniform,
    ComputeBinding::Storage,
    ComputeBinding::Storage,
    ComputeBinding::StorageRw,
];

const BUILD_WGSL: &str = concat!(
    include_str!("../../../shaders/integral.wgsl"),
    include_str!("../../../shaders/table_build.wgsl"),
);

/// The GPU build kernel, one invocation per texel (the 2D table and the
/// cylindrical planes).
pub static TABLE_BUILD: ComputeDesc = ComputeDesc {
    name: "table_build.wgsl",
    wgsl: BUILD_WGSL,
    entry: "build_main",
    bindings: BUILD_BINDINGS,
};

/// The GPU build kernel, one invocation per column of the 3D table.
pub static TABLE_COLUMNS: ComputeDesc = ComputeDesc {
    name: "table_build.wgsl columns",
    wgsl: BUILD_WGSL,
    entry: "column_main",
    bindings: BUILD_BINDINGS,
};

/// Integrates the texels of `spec` that meet `range` into `table`'s
/// storage buffer, in place (the table is what the stages then read).
pub fn gpu_build(
    ctx: &Context,
    spec: &TableSpec,
    tf: &TransferFunction,
    range: (f64, f64),
    table: &Table,
) -> Result<(), GpuError> {
    if table.size() != spec.size || !table.is_rgba() {
        return Err(GpuError::BadOption(
            "the table does not have the spec's size",
        ));
    }
    let params = BuildParams::new(spec, range);
    let buf = TfBuffer::new(tf, &ScalarMap::of(tf));
    let consts = closed_form_constants();
    let kernel = if spec.kind == TableKind::Cube {
        &TABLE_COLUMNS
    } else {
        &TABLE_BUILD
    };
    ctx.dispatch(
        kernel,
        &[
            ComputeResource::Uniform(bytemuck::bytes_of(&params)),
            ComputeResource::Storage(&buf.bytes()),
            ComputeResource::Storage(bytemuck::cast_slice(&consts)),
            ComputeResource::Buffer(table.buffer()),
        ],
        params.groups(),
    )?;
    ctx.check()
}

/// Twin of `build_main` for one texel of a table of `kind`: the `f32`
/// closed form at the texel's point `p` (`(s_f, s_b, l)`, from
/// [`TableSpec::texel_point`], which holds the twin of `cyl_to_table`).
pub fn build_main(tf: &TfBuffer, consts: &[[f32; 4]], kind: TableKind, p: [f32; 3]) -> [f32; 4] {
    let mut v = tf.integrate_segment(consts, GaussRule::Six, p[2], p[0], p[1]);
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

/// Twin of `subspans`: the sub-spans a span of `len` at the longest length
/// is cut into.
pub fn subspans(t0: f32, t1: f32, len: f32) -> u32 {
    let d = t0.max(t1) * len;
    (d / GAUSS_MAX).ceil().clamp(1.0, MAX_SUBSPANS as f32) as u32
}

fn mix(a: f32, b: f32, u: f32) -> f32 {
    a * (1.0 - u) + b * u
}

fn mix_material(m0: Material, m1: Material, u: f32) -> Material {
    Material {
        tau: mix(m0.tau, m1.tau, u),
        col: std::array::from_fn(|c| mix(m0.col[c], m1.col[c], u)),
    }
}

/// The exponentials of one sub-span at one length (`Powers`): the six
/// Gauss-Legendre nodes' (`a`: nodes 0, 2, 4; `b`: nodes 1, 3, 5) and the
/// whole sub-span's (`t`).
#[derive(Clone, Copy, Debug)]
pub struct Powers {
    pub a: [f32; 3],
    pub b: [f32; 3],
    pub t: f32,
}

/// Twin of `column_step`: the sub-span (colour weights per node, one
/// column per node) at length `k` behind composite `v`.
pub fn column_step(
    v: [f32; 4],
    k: f32,
    ga: &[[f32; 3]; 3],
    gb: &[[f32; 3]; 3],
    q: Powers,
) -> [f32; 4] {
    let c: [f32; 3] = std::array::from_fn(|ch| {
        let s: f32 = (0..3)
            .map(|i| ga[i][ch] * q.a[i] + gb[i][ch] * q.b[i])
            .sum();
        k * s
    });
    [
        v[0] + v[3] * c[0],
        v[1] + v[3] * c[1],
        v[2] + v[3] * c[2],
        v[3] * q.t,
    ]
}

/// Twin of `exp_small`: `exp(-c)` for `0 <= c <= 1/8` by seven terms of
/// its series.
pub fn exp_small(c: [f32; 3]) -> [f32; 3] {
    c.map(|c| {
        1.0 - c
            * (1.0
                - c * (1.0 / 2.0)
                    * (1.0
                        - c * (1.0 / 3.0)
                            * (1.0
                                - c * (1.0 / 4.0)
                                    * (1.0 - c * (1.0 / 5.0) * (1.0 - c * (1.0 / 6.0))))))
    })
}

/// Twin of `next_powers`: the exponentials at the next length.
pub fn next_powers(q: Powers, r: Powers) -> Powers {
    Powers {
        a: std::array::from_fn(|i| q.a[i] * r.a[i]),
        b: std::array::from_fn(|i| q.b[i] * r.b[i]),
        t: q.t * r.t,
    }
}

/// Twin of `column_subspan`: adds the linear piece from `m0` to `m1` of
/// length `k ls` behind the chunk's composites `acc[t]` (colour,
/// transmittance in front), `k = k0 + t`.
pub fn column_subspan(
    tf: &TfBuffer,
    consts: &[[f32; 4]],
    acc: &mut [[f32; 4]; CHUNK],
    k0: u32,
    ls: f32,
    m0: Material,
    m1: Material,
) {
    let (a, b) = (m0.tau * ls, m1.tau * ls);
    let e = &consts[GL6_BASE..GL6_BASE + 3];
    // Nodes 0, 2, 4 (`xa`) and 1, 3, 5 (`xb`) with their weights.
    let xa = [e[0][0], e[1][0], e[2][0]];
    let xb = [e[0][2], e[1][2], e[2][2]];
    let wa = [e[0][1], e[1][1], e[2][1]];
    let wb = [e[0][3], e[1][3], e[2][3]];
    let expo = |x: f32| x * (a * (1.0 - 0.5 * x) + b * (0.5 * x));
    let weight = |x: f32, w: f32| {
        if tf.model == 0 {
            w * (a * (1.0 - x) + b * x)
        } else {
            w * ls
        }
    };
    let colours = |x: [f32; 3], w: [f32; 3]| -> [[f32; 3]; 3] {
        std::array::from_fn(|i| {
            let f = weight(x[i], w[i]);
            std::array::from_fn(|ch| (m0.col[ch] * (1.0 - x[i]) + m1.col[ch] * x[i]) * f)
        })
    };
    let (ga, gb) = (colours(xa, wa), colours(xb, wb));
    let (ca, cb) = (xa.map(expo), xb.map(expo));
    let d = 0.5 * (a + b);
    let r = Powers {
        a: exp_small(ca),
        b: exp_small(cb),
        t: exp_small([d; 3])[0],
    };
    let k = k0 as f32;
    let mut q = Powers {
        a: ca.map(|c| (-k * c).exp()),
        b: cb.map(|c| (-k * c).exp()),
        t: (-k * d).exp(),
    };
    for (t, v) in acc.iter_mut().enumerate() {
        if t > 0 {
            q = next_powers(q, r);
        }
        *v = column_step(*v, k + t as f32, &ga, &gb, q);
    }
}

/// Twin of `store_texel`: texel `k` of a column from its composite `v`,
/// if the recurrences serve it (`k <= kmax`).
pub fn store_texel(k: u32, kmax: u32, depth: f32, v: [f32; 4], out: &mut [[f32; 4]]) {
    if k > kmax {
        return;
    }
    out[k as usize] = if k > 0 {
        let c = [v[0], v[1], v[2]].map(|x| x.min(MAX_THICKNESS));
        [c[0], c[1], c[2], neg_expm1(k as f32 * depth)]
    } else {
        [0.0; 4]
    };
}

/// Twin of `column_main` for column `(ix, iy)`: [`build_column`] where
/// the column lies in the table.
pub fn column_main(
    tf: &TfBuffer,
    consts: &[[f32; 4]],
    p: &BuildParams,
    ix: u32,
    iy: u32,
    out: &mut [[f32; 4]],
) -> bool {
    ix < p.ns && iy < p.ns && build_column(tf, consts, p, ix, iy, out)
}

/// Twin of `build_column`: writes column `(ix, iy)` of the 3D table
/// (`out[k]`, every length) unless its scalar interval misses the
/// parameters' range (then `false`, `out` untouched).
pub fn build_column(
    tf: &TfBuffer,
    consts: &[[f32; 4]],
    p: &BuildParams,
    ix: u32,
    iy: u32,
    out: &mut [[f32; 4]],
) -> bool {
    let n1 = (p.ns - 1) as f32;
    let (sf, sb) = (ix as f32 / n1, iy as f32 / n1);
    if sf.max(sb) < p.lo || sf.min(sb) > p.hi {
        return false;
    }
    let dl = if p.nz > 1 {
        p.l_table / (p.nz - 1) as f32
    } else {
        0.0
    };
    let sp = tf.segment_spans(sf, sb);
    let end = |n: u32| tf.span_end(&sp, n, sf);
    let (mut dmax, mut depth) = (0.0f32, 0.0f32);
    let (mut m_prev, mut x_prev) = (sp.m_first, 0.0f32);
    for n in 0..=sp.count {
        let (m, x) = end(n);
        if x > x_prev {
            let f = x - x_prev;
            let q = subspans(m_prev.tau, m.tau, p.l_table * f) as f32;
            dmax = dmax.max(m_prev.tau.max(m.tau) * dl * f / q);
            depth += 0.5 * (m_prev.tau + m.tau) * dl * f;
        }
        (m_prev, x_prev) = (m, x);
    }
    let mut kmax = p.nz - 1;
    if dmax * kmax as f32 > GAUSS_MAX {
        kmax = (GAUSS_MAX / dmax) as u32;
        if kmax < MIN_RECURRENCE {
            kmax = 0;
        }
    }
    let mut k0 = 0;
    while k0 <= kmax {
        let mut acc = [[0.0, 0.0, 0.0, 1.0f32]; CHUNK];
        (m_prev, x_prev) = (sp.m_first, 0.0);
        for n in 0..=sp.count {
            let (m, x) = end(n);
            if x > x_prev {
                let f = x - x_prev;
                let q = subspans(m_prev.tau, m.tau, p.l_table * f);
                let qf = q as f32;
                for j in 0..q {
                    let s0 = if j > 0 {
                        mix_material(m_prev, m, j as f32 / qf)
                    } else {
                        m_prev
                    };
                    let s1 = if j + 1 < q {
                        mix_material(m_prev, m, (j + 1) as f32 / qf)
                    } else {
                        m
                    };
                    column_subspan(tf, consts, &mut acc, k0, dl * f / qf, s0, s1);
                }
            }
            (m_prev, x_prev) = (m, x);
        }
        for (t, v) in acc.iter().enumerate() {
            store_texel(k0 + t as u32, kmax, depth, *v, out);
        }
        k0 += CHUNK as u32;
    }
    for k in kmax + 1..p.nz {
        out[k as usize] = tf.integrate_segment(consts, GaussRule::Six, k as f32 * dl, sf, sb);
    }
    true
}
