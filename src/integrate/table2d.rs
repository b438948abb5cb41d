//! 2D pre-integration tables over `(s_f, s_b)` at a reference length
//! (Röttger, Kraus, Ertl 2000, section 4; docs/math.md 8.2).
//!
//! Two variants, both filled from the exact integrals at `l_ref`:
//! * [`Table2dKind::LinearInL`] (RKE): texel `(C, alpha)` at `l_ref`; a
//!   segment of length `l` uses `C l / l_ref` and `min(1, alpha l / l_ref)`.
//!   First order in the depth: acceptable only for thin cells.
//! * [`Table2dKind::DepthGlow`] (better): texel `(g, tau_mean)` with the glow
//!   `g = C / alpha` at `l_ref` (its `l -> 0` limit where alpha vanishes, see
//!   [`super::vertex_values`]) and the exact mean extinction of the interval;
//!   a lookup returns `alpha = 1 - exp(-l tau_mean)` (exact up to
//!   interpolation) and `C = g alpha` (exact for constant glow colour).
//!
//! Layout: RGBA `f32`, `s_f` fastest (a `ns x ns` 2D texture). Lookups are
//! bilinear as in [`super::grid`]; the `l` arithmetic happens after
//! filtering, as a fragment shader would do it.

use rayon::prelude::*;

use super::grid::{bilinear, check_total, Axis, TableError};
use super::segment::{segment, vertex_values};
use crate::tf::TransferFunction;

/// Which 2D table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table2dKind {
    /// `(C, alpha)` at `l_ref`, scaled linearly in `l`.
    LinearInL,
    /// `(glow, mean extinction)`: exact opacity, glow times opacity.
    DepthGlow,
}

/// A 2D pre-integration table (see the module docs).
#[derive(Clone, Debug)]
pub struct Table2d {
    pub s_axis: Axis,
    pub l_ref: f64,
    pub kind: Table2dKind,
    /// RGBA f32, index `(j * ns + i) * 4` for `(s_f = s_i, s_b = s_j)`.
    pub data: Vec<f32>,
}

impl Table2d {
    /// Exact fill at the reference length `l_ref` (> 0; e.g. the mean
    /// segment length of the mesh).
    pub fn new(
        tf: &TransferFunction,
        ns: usize,
        s_range: (f64, f64),
        l_ref: f64,
        kind: Table2dKind,
    ) -> Result<Self, TableError> {
        let s_axis = Axis::new("scalar", s_range.0, s_range.1, ns)?;
        if !(l_ref.is_finite() && l_ref > 0.0) {
            return Err(TableError::Range {
                name: "reference length",
                lo: 0.0,
                hi: l_ref,
            });
        }
        let total = check_total("2D table", &[ns, ns])?;
        let mut t = Self {
            s_axis,
            l_ref,
            kind,
            data: vec![0.0; 4 * total],
        };
        t.update(tf, f64::NEG_INFINITY, f64::INFINITY);
        Ok(t)
    }

    /// Recomputes the texels whose scalar interval meets `[a, b]`.
    pub fn update(&mut self, tf: &TransferFunction, a: f64, b: f64) {
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        let ns = self.s_axis.n;
        let s = self.s_axis.samples();
        let (l, kind) = (self.l_ref, self.kind);
        self.data
            .par_chunks_mut(4 * ns)
            .enumerate()
            .for_each(|(j, row)| {
                for i in 0..ns {
                    if s[i].min(s[j]) > b || s[i].max(s[j]) < a {
                        continue;
                    }
                    let v = match kind {
                        Table2dKind::LinearInL => {
                            let v = segment(tf, l, s[i], s[j]);
                            [v.color[0], v.color[1], v.color[2], v.alpha]
                        }
                        Table2dKind::DepthGlow => {
                            let v = vertex_values(tf, l, s[i], s[j]);
                            [v.glow[0], v.glow[1], v.glow[2], v.tau_mean]
                        }
                    };
                    row[4 * i..4 * i + 4].copy_from_slice(&v.map(|x| x as f32));
                }
            });
    }

    /// Lookup for a segment of length `l`: `[r, g, b, alpha]`, premultiplied.
    pub fn lookup(&self, s_f: f64, s_b: f64, l: f64) -> [f64; 4] {
        let t = bilinear(
            &self.data,
            0,
            self.s_axis.n,
            self.s_axis.locate(s_f),
            self.s_axis.locate(s_b),
        );
        let l = if l > 0.0 { l } else { 0.0 };
        match self.kind {
            Table2dKind::LinearInL => {
                let r = l / self.l_ref;
                [t[0] * r, t[1] * r, t[2] * r, (t[3] * r).min(1.0)]
            }
            Table2dKind::DepthGlow => {
                let alpha = -(-l * t[3]).exp_m1();
                [t[0] * alpha, t[1] * alpha, t[2] * alpha, alpha]
            }
        }
    }

    /// The texel data as bytes, for a texture upload.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.data)
    }
}
