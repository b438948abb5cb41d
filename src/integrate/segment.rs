//! Exact integral of one cell segment through a piecewise-linear transfer
//! function, whole rays, and the per-vertex values of the exact GPU mode.
//!
//! A cell segment `(l, s_f, s_b)` (scalar linear from `s_f` at the front to
//! `s_b` at the back) is sliced at every breakpoint strictly between `s_f` and
//! `s_b` (docs/math.md section 2): each piece takes the transfer-function piece
//! that contains its *midpoint* scalar and evaluates it at the piece's end
//! scalars (exact node values at breakpoints). Pieces are integrated with
//! [`weights`] and composited front to back, accumulating optical depth.
//!
//! Input hygiene: `l` that is NaN or not positive gives the empty segment;
//! `l` is clamped to 1e150 and scalars to +-1e300, so no input produces NaN
//! or infinity; a NaN scalar gives the empty segment.

use super::weights::weights;
use super::{Material, RayAccumulator, RayMaterial, SegmentValue};
use crate::numeric::tolerance::GLOW_LIMIT_DEPTH;
use crate::tf::{EmissionModel, TransferFunction};

const MAX_LENGTH: f64 = 1e150;
const MAX_SCALAR: f64 = 1e300;

/// Calls `f(length, tau_f, tau_b, col_f, col_b)` for each linear piece of the
/// segment, front to back (`col` is the glow colour or the emission).
#[inline]
pub(crate) fn for_each_piece(
    tf: &TransferFunction,
    l: f64,
    s_f: f64,
    s_b: f64,
    mut f: impl FnMut(f64, f64, f64, [f64; 3], [f64; 3]),
) {
    if s_f == s_b {
        let (t, c) = tf.eval_piece(tf.piece_index(s_f), s_f);
        f(l, t, t, c, c);
        return;
    }
    let (lo, hi) = if s_f < s_b { (s_f, s_b) } else { (s_b, s_f) };
    let br = tf.breakpoints_slice();
    let i0 = br.partition_point(|&x| x <= lo);
    let i1 = br.partition_point(|&x| x < hi);
    let mut piece = |x0: f64, x1: f64, s0: f64, s1: f64| {
        if x1 <= x0 {
            return;
        }
        let idx = tf.piece_index(0.5 * (s0 + s1));
        let (t0, c0) = tf.eval_piece(idx, s0);
        let (t1, c1) = tf.eval_piece(idx, s1);
        f(l * (x1 - x0), t0, t1, c0, c1);
    };
    let cross = br.get(i0..i1).unwrap_or(&[]);
    if cross.is_empty() {
        piece(0.0, 1.0, s_f, s_b);
        return;
    }
    let inv = 1.0 / (s_b - s_f);
    let (mut x_prev, mut s_prev) = (0.0, s_f);
    let mut visit = |sk: f64| {
        let x = (sk - s_f) * inv;
        piece(x_prev, x, s_prev, sk);
        x_prev = x;
        s_prev = sk;
    };
    if s_b > s_f {
        cross.iter().for_each(|&sk| visit(sk));
    } else {
        cross.iter().rev().for_each(|&sk| visit(sk));
    }
    piece(x_prev, 1.0, s_prev, s_b);
}

/// Colour, depth and opacity of one linear piece (`alpha` is exactly
/// `-expm1(-depth)`).
#[inline]
fn piece_value(
    model: EmissionModel,
    l: f64,
    t0: f64,
    t1: f64,
    c0: [f64; 3],
    c1: [f64; 3],
) -> ([f64; 3], f64, f64) {
    let (a, b) = (t0 * l, t1 * l);
    let w = weights(a, b);
    let c = match model {
        EmissionModel::Glow => std::array::from_fn(|k| c0[k] * w.w_f + c1[k] * w.w_b),
        EmissionModel::Independent => {
            std::array::from_fn(|k| l * (c0[k] * w.phi_f + c1[k] * w.phi_b))
        }
    };
    (c, 0.5 * (a + b), w.alpha)
}

/// Cleans inputs; `None` means the empty segment.
#[inline]
fn sanitize(l: f64, s_f: f64, s_b: f64) -> Option<(f64, f64, f64)> {
    if l.is_nan() || l <= 0.0 || s_f.is_nan() || s_b.is_nan() {
        return None;
    }
    Some((
        l.min(MAX_LENGTH),
        s_f.clamp(-MAX_SCALAR, MAX_SCALAR),
        s_b.clamp(-MAX_SCALAR, MAX_SCALAR),
    ))
}

/// Exact colour, opacity and optical depth of a segment of length `l` over
/// which the scalar goes linearly from `s_f` (front) to `s_b` (back).
pub fn segment(tf: &TransferFunction, l: f64, s_f: f64, s_b: f64) -> SegmentValue {
    let Some((l, s_f, s_b)) = sanitize(l, s_f, s_b) else {
        return SegmentValue::default();
    };
    let model = tf.model();
    let mut color = [0.0; 3];
    let mut depth = 0.0f64;
    let mut alpha = 0.0;
    let mut pieces = 0u32;
    for_each_piece(tf, l, s_f, s_b, |ls, t0, t1, c0, c1| {
        let (c, d, a) = piece_value(model, ls, t0, t1, c0, c1);
        let tr = if depth == 0.0 { 1.0 } else { (-depth).exp() };
        for k in 0..3 {
            color[k] += tr * c[k];
        }
        depth += d;
        alpha = a;
        pieces += 1;
    });
    if pieces != 1 {
        alpha = -(-depth).exp_m1();
    }
    SegmentValue {
        color,
        alpha,
        depth,
    }
}

/// Whole ray: cells `(l, s_f, s_b)` front to back, over a black background.
/// Returns the premultiplied colour and the opacity.
pub fn ray(tf: &TransferFunction, cells: &[(f64, f64, f64)]) -> ([f64; 3], f64) {
    let mut acc = RayAccumulator::default();
    for &(l, s_f, s_b) in cells {
        acc.add(&segment(tf, l, s_f, s_b));
    }
    (acc.color, acc.alpha())
}

/// What the exact GPU mode needs at one region vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexValues {
    /// Exact premultiplied segment colour `C`.
    pub color: [f64; 3],
    /// Exact opacity.
    pub alpha: f64,
    /// Exact optical depth.
    pub depth: f64,
    /// `C / alpha`, with its `l -> 0` limit where `alpha` vanishes (see
    /// [`vertex_values`]).
    pub glow: [f64; 3],
    /// Mean extinction over the segment, `depth / l`; exactly the mean of
    /// `tau` over the scalar interval, so it is also defined at `l = 0`.
    pub tau_mean: f64,
}

/// Exact per-vertex values (segment colour, opacity, depth), the glow colour
/// `g = C / alpha` and the mean extinction.
///
/// The `l -> 0` limit of `g` (used when the depth is below [`GLOW_LIMIT_DEPTH`], e.g. at
/// silhouette vertices with `l = 0`):
/// * glow model: the extinction-weighted mean colour over the scalar interval,
///   per piece `(c_f (2 tau_f + tau_b) + c_b (tau_f + 2 tau_b)) / 3` weighted
///   by the piece's share of the interval and divided by `2 tau_mean`; where
///   `tau_mean = 0` (fully transparent material) the plain mean colour;
/// * independent emission: mean emission / `tau_mean`; where `tau_mean = 0`
///   the emission-only material has no finite glow and `glow` is set to 0
///   (a mode that needs `g` cannot represent it and must fall back).
pub fn vertex_values(tf: &TransferFunction, l: f64, s_f: f64, s_b: f64) -> VertexValues {
    let seg = segment(tf, l, s_f, s_b);
    let direct = seg.depth > GLOW_LIMIT_DEPTH;
    let by_length = l > 0.0 && seg.depth > 0.0 && l.is_finite();
    // Interval averages (length 1 slicing; shares sum to 1), needed only
    // for the limits (most vertices skip this second pass).
    let mut tau_avg = 0.0;
    let mut weighted = [0.0; 3];
    let mut plain = [0.0; 3];
    if !(direct && by_length) {
        let (sf, sb) = (
            if s_f.is_nan() {
                0.0
            } else {
                s_f.clamp(-MAX_SCALAR, MAX_SCALAR)
            },
            if s_b.is_nan() {
                0.0
            } else {
                s_b.clamp(-MAX_SCALAR, MAX_SCALAR)
            },
        );
        for_each_piece(tf, 1.0, sf, sb, |share, t0, t1, c0, c1| {
            tau_avg += share * 0.5 * (t0 + t1);
            for k in 0..3 {
                weighted[k] += share * (c0[k] * (2.0 * t0 + t1) + c1[k] * (t0 + 2.0 * t1)) / 6.0;
                plain[k] += share * 0.5 * (c0[k] + c1[k]);
            }
        });
    }
    let glow = if direct {
        std::array::from_fn(|k| seg.color[k] / seg.alpha)
    } else {
        match tf.model() {
            EmissionModel::Glow if tau_avg > 0.0 => std::array::from_fn(|k| weighted[k] / tau_avg),
            EmissionModel::Glow => plain,
            EmissionModel::Independent if tau_avg > 0.0 => {
                std::array::from_fn(|k| plain[k] / tau_avg)
            }
            EmissionModel::Independent => [0.0; 3],
        }
    };
    let tau_mean = if by_length { seg.depth / l } else { tau_avg };
    VertexValues {
        color: seg.color,
        alpha: seg.alpha,
        depth: seg.depth,
        glow,
        tau_mean,
    }
}

/// A transfer function as the renderers see it: exact segment integrals
/// ([`segment`]), its breakpoints, and point evaluation (right-continuous
/// at jumps; the source is `tau * colour` for glow, `E` for independent
/// emission).
impl RayMaterial for TransferFunction {
    fn segment(&self, l: f64, s_f: f64, s_b: f64) -> SegmentValue {
        segment(self, l, s_f, s_b)
    }

    fn breakpoints(&self) -> &[f64] {
        &self.breaks
    }

    fn material(&self, s: f64) -> Material {
        let (tau, c) = self.eval_piece(self.piece_index(s), s);
        let source = match self.model {
            EmissionModel::Glow => [tau * c[0], tau * c[1], tau * c[2]],
            EmissionModel::Independent => c,
        };
        Material { tau, source }
    }
}
