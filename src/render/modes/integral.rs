//! The CPU twin of `shaders/integral.wgsl`: the exact ray integral of one
//! cell segment through a piecewise-linear transfer function, in `f32`,
//! function for function with the shader (same names, same operations in
//! the same order), and the buffers the shader reads.
//!
//! It is the `f32` port of [`crate::integrate::segment`] and
//! [`crate::integrate::weights`] (docs/math.md sections 2 and 4.2): a
//! segment is sliced at every transfer-function node strictly between its
//! end scalars; each linear piece is integrated in closed form —
//! Gauss-Legendre over positive integrands where the optical depth is at
//! most 2, else the scaled `erfcx` (increasing extinction) or Dawson
//! (decreasing) forms, as Taylor series about the 129 tabulated centres up
//! to argument 8 and asymptotic series above — and the pieces are
//! composited front to back (the opacity from the summed optical depth, the
//! transmittance in front of a piece the product of those before). Neither form
//! cancels: thin segments, near-equal extinctions and depths of 1e6 keep
//! full `f32` relative accuracy (`tests/exact_frag.rs` checks the golden
//! vectors).
//!
//! Buffers: [`closed_form_constants`] (binding 2) and [`TfBuffer`]
//! (binding 1), with scalars normalised by a
//! [`super::segment::ScalarMap`].

use crate::integrate::tables_sf::SF_TABLE;
use crate::tf::{EmissionModel, TransferFunction};

use super::segment::ScalarMap;

const SF_CENTRES: usize = 129;
pub(crate) const GL6_BASE: usize = 129;
/// Up to this optical thickness (both ends) the basis integrals are a
/// Gauss-Legendre rule ([`GaussRule`]: 6 nodes up to here, fewer where the
/// frame's segments are thinner); above it the closed form (`GAUSS_MAX`).
pub const GAUSS_MAX: f32 = 2.0;

/// The 6-point Gauss-Legendre rule on [0, 1] `(x, w)`: in `f32` as good as
/// the f64 path's 12 points up to depth 2 (error below 6e-9, tested).
pub const GL6: [(f64, f64); 6] = [
    (0.03376524289842399, 0.08566224618958518),
    (0.16939530676686773, 0.1803807865240693),
    (0.38069040695840156, 0.23395696728634552),
    (0.6193095930415985, 0.23395696728634552),
    (0.8306046932331322, 0.1803807865240693),
    (0.966234757101576, 0.08566224618958518),
];

/// The 5-point Gauss-Legendre rule on [0, 1] `(x, w)`.
pub const GL5: [(f64, f64); 5] = [
    (0.046910077030668, 0.11846344252809454),
    (0.2307653449471585, 0.23931433524968324),
    (0.5, 0.28444444444444444),
    (0.7692346550528415, 0.23931433524968324),
    (0.953089922969332, 0.11846344252809454),
];

/// The 4-point Gauss-Legendre rule on [0, 1] `(x, w)`.
pub const GL4: [(f64, f64); 4] = [
    (0.06943184420297371, 0.17392742256872692),
    (0.3300094782075719, 0.32607257743127305),
    (0.6699905217924281, 0.32607257743127305),
    (0.9305681557970262, 0.17392742256872692),
];

/// The Gauss-Legendre rule of the thin regime (`GAUSS_NODES` in the
/// shader): the fewest nodes whose error in the basis integrals, relative
/// to the segment's own optical depth, stays below `f32`'s rounding unit
/// (2^-24, 6.0e-8) for every segment up to [`GaussRule::max_depth`]
/// (measured in f64 against a 40-node rule over a 41 x 41 grid of end
/// depths: 5.4e-8 for 4 nodes up to depth 0.35, 4.3e-8 for 5 up to 1.25,
/// 5.5e-9 for 6 up to 2; the test `shorter_rules_hold_their_range` checks
/// the `f32` twin against the f64 closed form there). Chosen per frame
/// from the thickest segment the scene can hold, not per fragment: the
/// lanes of a SIMD group that straddle a threshold would run both rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GaussRule {
    Four,
    Five,
    /// Every depth up to [`GAUSS_MAX`]: the rule of a stage with thick
    /// segments.
    #[default]
    Six,
}

impl GaussRule {
    /// The nodes and weights on [0, 1].
    pub fn nodes(self) -> &'static [(f64, f64)] {
        match self {
            GaussRule::Four => &GL4,
            GaussRule::Five => &GL5,
            GaussRule::Six => &GL6,
        }
    }

    /// The largest optical depth (at either end of a segment) it holds.
    pub fn max_depth(self) -> f64 {
        match self {
            GaussRule::Four => 0.35,
            GaussRule::Five => 1.25,
            GaussRule::Six => GAUSS_MAX as f64,
        }
    }

    /// The shortest rule holding every segment up to optical depth
    /// `depth`; `None` above [`GAUSS_MAX`] (or NaN), where the closed form
    /// takes over.
    pub fn for_depth(depth: f64) -> Option<GaussRule> {
        [GaussRule::Four, GaussRule::Five, GaussRule::Six]
            .into_iter()
            .find(|r| depth <= r.max_depth())
    }
}

/// Terms of the Taylor series about the nearest centre (`|x - x0| <=
/// 1/32`); the truncation error is below 1e-9 relative (tested).
const TAYLOR_TERMS: u32 = 9;
/// Terms of the asymptotic series (argument `t <= 1/128`): below 1e-10.
const ASYM_TERMS: u32 = 9;
const ASYM_X: f32 = 8.0;
pub(crate) const MAX_THICKNESS: f32 = 1e30;
pub(crate) const MAX_SCALAR: f32 = 1e30;

/// The constants buffer of the closed form: `P, Q, B, G` at the 129 centres
/// `k/16`, then the 6-point Gauss-Legendre rule on [0, 1] as `(x, w, x, w)`
/// pairs.
pub fn closed_form_constants() -> Vec<[f32; 4]> {
    let mut c: Vec<[f32; 4]> = SF_TABLE.iter().map(|r| r.map(|v| v as f32)).collect();
    debug_assert_eq!(c.len(), SF_CENTRES);
    for p in GL6.chunks(2) {
        c.push([p[0].0 as f32, p[0].1 as f32, p[1].0 as f32, p[1].1 as f32]);
    }
    debug_assert_eq!(c.len(), GL6_BASE + 3);
    c
}

/// The transfer function as the shader reads it (`TfBuffer`): node scalars
/// normalised by a [`ScalarMap`], extinction and colour (glow colour or
/// emission) in `f32`.
#[derive(Clone, Debug, PartialEq)]
pub struct TfBuffer {
    /// 0: glow, 1: independent emission.
    pub model: u32,
    /// `(s, tau, 0, 0)` and `(colour, 0)` per node.
    pub nodes: Vec<[f32; 4]>,
}

/// Extinction and colour at a scalar (`Material` in the shader).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Material {
    pub tau: f32,
    pub col: [f32; 3],
}

/// The basis integrals of one linear sub-segment (`Weights`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Weights {
    pub psi: f32,
    pub phi_f: f32,
    pub phi_b: f32,
    pub w_f: f32,
    pub w_b: f32,
    pub alpha: f32,
    pub t: f32,
}

impl TfBuffer {
    /// The buffer of `tf` with scalars through `map`.
    pub fn new(tf: &TransferFunction, map: &ScalarMap) -> TfBuffer {
        let mut nodes = Vec::with_capacity(2 * tf.s.len());
        for i in 0..tf.s.len() {
            let c = tf.col[i];
            nodes.push([map.apply(tf.s[i]) as f32, tf.tau[i] as f32, 0.0, 0.0]);
            nodes.push([c[0] as f32, c[1] as f32, c[2] as f32, 0.0]);
        }
        TfBuffer {
            model: match tf.model() {
                EmissionModel::Glow => 0,
                EmissionModel::Independent => 1,
            },
            nodes,
        }
    }

    /// The bytes of the storage buffer: header `(count, model, 0, 0)`, then
    /// the nodes.
    pub fn bytes(&self) -> Vec<u8> {
        let count = (self.nodes.len() / 2) as u32;
        let mut b = Vec::with_capacity(16 + 16 * self.nodes.len());
        for h in [count, self.model, 0, 0] {
            b.extend_from_slice(&h.to_le_bytes());
        }
        b.extend_from_slice(bytemuck::cast_slice(&self.nodes));
        b
    }

    pub(crate) fn count(&self) -> u32 {
        (self.nodes.len() / 2) as u32
    }

    /// The largest extinction of the nodes (the transfer function's, linear
    /// between them and constant beyond); NaN where one is NaN.
    pub fn max_tau(&self) -> f32 {
        let taus = || self.nodes.iter().step_by(2).map(|n| n[1]);
        if taus().any(f32::is_nan) {
            return f32::NAN;
        }
        taus().fold(0.0, f32::max)
    }

    pub(crate) fn node_s(&self, i: u32) -> f32 {
        self.nodes[2 * i as usize][0]
    }

    pub(crate) fn node(&self, i: u32) -> Material {
        let (a, b) = (self.nodes[2 * i as usize], self.nodes[2 * i as usize + 1]);
        Material {
            tau: a[1],
            col: [b[0], b[1], b[2]],
        }
    }

    /// Number of nodes with `s_node <= s`: a binary search
    /// (`piece_index`).
    pub fn piece_index(&self, s: f32) -> u32 {
        let (mut lo, mut hi) = (0, self.count());
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.node_s(mid) <= s {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Extinction and colour of piece `idx` at `s`, selected without
    /// branches as the shader does (`eval_piece`).
    pub fn eval_piece(&self, idx: u32, s: f32) -> Material {
        let n = self.count();
        let j = idx.clamp(1, n) - 1;
        let k = (j + 1).min(n - 1);
        let (s0, s1) = (self.node_s(j), self.node_s(k));
        let (m0, m1) = (self.node(j), self.node(k));
        let at_front = idx == 0 || idx >= n || s == s0;
        if at_front {
            return m0;
        }
        if s == s1 {
            return m1;
        }
        let u = (s - s0) / (s1 - s0);
        Material {
            tau: m0.tau + (m1.tau - m0.tau) * u,
            col: std::array::from_fn(|k| m0.col[k] + (m1.col[k] - m0.col[k]) * u),
        }
    }

    /// Adds one linear piece behind `acc` (`add_piece`).
    pub(crate) fn add_piece(
        &self,
        consts: &[[f32; 4]],
        rule: GaussRule,
        acc: &mut Composite,
        l: f32,
        m0: Material,
        m1: Material,
    ) {
        let (a, b) = (m0.tau * l, m1.tau * l);
        let w = weights(consts, rule, a, b);
        let c: [f32; 3] = if self.model == 0 {
            std::array::from_fn(|k| m0.col[k] * w.w_f + m1.col[k] * w.w_b)
        } else {
            std::array::from_fn(|k| l * (m0.col[k] * w.phi_f + m1.col[k] * w.phi_b))
        };
        for (a, c) in acc.color.iter_mut().zip(c) {
            *a += acc.tr * c;
        }
        acc.tr *= w.t;
        acc.depth += 0.5 * (sanitize_thickness(a) + sanitize_thickness(b));
        acc.alpha = w.alpha;
        acc.pieces += 1;
    }

    /// The spans of the segment from `s_f` to `s_b` (`segment_spans`).
    pub fn segment_spans(&self, s_f: f32, s_b: f32) -> Spans {
        let (lo, hi) = (s_f.min(s_b), s_f.max(s_b));
        let i0 = self.piece_index(lo);
        let mut i1 = i0;
        while i1 < self.count() && self.node_s(i1) < hi {
            i1 += 1;
        }
        let up = s_b > s_f;
        let count = i1 - i0;
        Spans {
            i0,
            i1,
            count,
            up,
            inv: if count > 0 { 1.0 / (s_b - s_f) } else { 0.0 },
            m_first: self.eval_piece(if up { i0 } else { i1 }, s_f),
            m_last: self.eval_piece(if up { i1 } else { i0 }, s_b),
        }
    }

    /// The material at the back end of span `n` (`0..=count`) of a segment
    /// starting at `s_f`, and its fraction of the segment (`span_end`).
    pub fn span_end(&self, sp: &Spans, n: u32, s_f: f32) -> (Material, f32) {
        if n < sp.count {
            let k = if sp.up { sp.i0 + n } else { sp.i1 - 1 - n };
            return (self.node(k), (self.node_s(k) - s_f) * sp.inv);
        }
        (sp.m_last, 1.0)
    }

    /// Premultiplied colour and opacity of a segment of length `l` over
    /// which the (normalised) scalar goes linearly from `s_f` to `s_b`
    /// (`integrate_segment`), thin pieces by `rule`.
    pub fn integrate_segment(
        &self,
        consts: &[[f32; 4]],
        rule: GaussRule,
        l_in: f32,
        sf_in: f32,
        sb_in: f32,
    ) -> [f32; 4] {
        if l_in.is_nan() || l_in <= 0.0 || sf_in.is_nan() || sb_in.is_nan() || self.nodes.is_empty()
        {
            return [0.0; 4];
        }
        let l = l_in.min(MAX_THICKNESS);
        let s_f = sf_in.clamp(-MAX_SCALAR, MAX_SCALAR);
        let s_b = sb_in.clamp(-MAX_SCALAR, MAX_SCALAR);
        let mut acc = Composite {
            tr: 1.0,
            ..Composite::default()
        };
        let sp = self.segment_spans(s_f, s_b);
        let (mut m_prev, mut x_prev) = (sp.m_first, 0.0f32);
        for n in 0..=sp.count {
            let (m, x) = self.span_end(&sp, n, s_f);
            if x > x_prev {
                self.add_piece(consts, rule, &mut acc, l * (x - x_prev), m_prev, m);
            }
            (m_prev, x_prev) = (m, x);
        }
        let alpha = if acc.pieces != 1 {
            neg_expm1(acc.depth)
        } else {
            acc.alpha
        };
        let c = acc.color.map(|v| v.min(MAX_THICKNESS));
        [c[0], c[1], c[2], alpha]
    }
}

/// The spans of a segment through the transfer function (`Spans`): nodes
/// `i0..i1` lie strictly between its ends, `count` of them, walked
/// ascending where the scalar grows (`up`); `inv` is `1 / (s_b - s_f)`
/// where a node lies between; the materials at its two ends.
#[derive(Clone, Copy, Debug)]
pub struct Spans {
    pub i0: u32,
    pub i1: u32,
    pub count: u32,
    pub up: bool,
    pub inv: f32,
    pub m_first: Material,
    pub m_last: Material,
}

/// The running composite of one segment's pieces (`Composite`).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Composite {
    pub(crate) color: [f32; 3],
    pub(crate) depth: f32,
    pub(crate) alpha: f32,
    pub(crate) pieces: u32,
    /// Transmittance in front of the next piece (the product of the
    /// pieces' own).
    pub(crate) tr: f32,
}

/// `1 - exp(-d)` for `d >= 0` without cancellation at small `d`.
pub fn neg_expm1(d: f32) -> f32 {
    if d < 0.0625 {
        return d * (1.0 - d * (0.5 - d * (1.0 / 6.0 - d * (1.0 / 24.0 - d * (1.0 / 120.0)))));
    }
    1.0 - (-d).exp()
}

/// `(P(x), Q(x))` for `sigma = -1`, `(B(x), G(x))` for `sigma = 1`,
/// `0 <= x <= 8`: one recurrence up to the sign (`taylor_sf`).
pub fn taylor_sf(consts: &[[f32; 4]], x: f32, sigma: f32) -> [f32; 2] {
    let k = ((x * 16.0 + 0.5) as u32).min(SF_CENTRES as u32 - 1);
    let x0 = k as f32 / 16.0;
    let dl = x - x0;
    let c = consts[k as usize];
    let (f0, f1) = if sigma > 0.0 {
        (c[2], c[3])
    } else {
        (c[0], c[1])
    };
    let (mut pm1, mut p) = (f0, 2.0 * sigma * f1);
    let mut s1 = f0 + p * dl;
    let mut s2 = f1 + (-x0 * p - f0) * dl;
    let mut dn = dl;
    for n in 1..TAYLOR_TERMS {
        let pn1 = -sigma * (2.0 * x0 * p + 2.0 * pm1) / (n + 1) as f32;
        dn *= dl;
        s1 += pn1 * dn;
        s2 += (-x0 * pn1 - p) * dn;
        pm1 = p;
        p = pn1;
    }
    [s1, s2]
}

/// Scaled asymptotic series (`asym`).
pub fn asym(t: f32, sign: f32) -> [f32; 2] {
    let (mut s, mut q, mut term, mut qterm) = (1.0f32, 1.0f32, 1.0f32, 1.0f32);
    for k in 1..ASYM_TERMS {
        let kf = k as f32;
        term *= sign * (2.0 * kf - 1.0) * t;
        s += term;
        if k >= 2 {
            qterm *= sign * (2.0 * kf - 1.0) * t;
            q += qterm;
        }
    }
    [s, q]
}

/// One end of a segment with extinction slope `d = |b - a|`: the Taylor
/// or the asymptotic form, rising (`sigma = -1`) or falling (`ends_sf`).
pub(crate) fn ends_sf(consts: &[[f32; 4]], c: f32, r: f32, d: f32, sigma: f32) -> [f32; 2] {
    if c <= ASYM_X * r {
        let t = taylor_sf(consts, c / r, sigma);
        return [t[0] / r, -sigma * t[1] / d];
    }
    let cc = c * c;
    let sq = asym(d / cc, sigma);
    [sq[0] / c, sq[1] / cc]
}

pub(crate) fn sanitize_thickness(x: f32) -> f32 {
    if x > 0.0 {
        x.min(MAX_THICKNESS)
    } else {
        0.0
    }
}

/// Adds node `x` with weight `w` of a rule on [0, 1] to `[w_f, w_b,
/// phi_f, phi_b]` (`gauss_node`).
pub(crate) fn gauss_node(acc: &mut [f32; 4], a: f32, b: f32, x: f32, w: f32) {
    let y = 1.0 - x;
    let dx = x * (a * (1.0 - 0.5 * x) + b * (0.5 * x));
    let dp = a * y + b * x;
    let e = w * (-dx).exp();
    let ed = e * dp;
    acc[0] += y * ed;
    acc[1] += x * ed;
    acc[2] += y * e;
    acc[3] += x * e;
}

/// `[w_f, w_b, phi_f, phi_b]` by `rule` (`gauss`, whose literals are
/// these nodes in `f32`).
pub(crate) fn gauss(rule: GaussRule, a: f32, b: f32) -> [f32; 4] {
    let mut acc = [0.0f32; 4];
    for &(x, w) in rule.nodes() {
        gauss_node(&mut acc, a, b, x as f32, w as f32);
    }
    acc
}

/// Basis integrals for optical thicknesses `a` and `b` (`weights`).
pub fn weights(consts: &[[f32; 4]], rule: GaussRule, a_in: f32, b_in: f32) -> Weights {
    let a = sanitize_thickness(a_in);
    let b = sanitize_thickness(b_in);
    let d1 = 0.5 * (a + b);
    let m = a.max(b);
    if m <= GAUSS_MAX {
        let alpha = neg_expm1(d1);
        let t = 1.0 - alpha;
        let g = gauss(rule, a, b);
        return Weights {
            psi: g[2] + g[3],
            phi_f: g[2],
            phi_b: g[3],
            w_f: g[0],
            w_b: g[1],
            alpha,
            t,
        };
    }
    let t = (-d1).exp();
    let alpha = 1.0 - t;
    let sigma = if b > a { -1.0 } else { 1.0 };
    let d = (b - a).abs();
    let r = (2.0 * d).sqrt();
    let f = ends_sf(consts, a, r, d, sigma);
    let k = ends_sf(consts, b, r, d, sigma);
    let psi = f[0] - t * k[0];
    let phi_b = f[1] - t * k[1] - t * k[0];
    Weights {
        psi,
        phi_f: psi - phi_b,
        phi_b,
        w_f: 1.0 - psi,
        w_b: psi - t,
        alpha,
        t,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::weights::{sqrtpi_erfcx, two_dawson};

    /// The fixed term counts reach f32 accuracy over the whole range.
    #[test]
    fn special_functions_match_f64() {
        let c = closed_form_constants();
        let mut worst = 0.0f64;
        for i in 0..=8000 {
            let x = i as f64 / 1000.0;
            let [p, _] = taylor_sf(&c, x as f32, -1.0);
            let [b, _] = taylor_sf(&c, x as f32, 1.0);
            // Compare at the f32 argument.
            let xf = x as f32 as f64;
            worst = worst.max((p as f64 / sqrtpi_erfcx(xf) - 1.0).abs());
            if xf > 0.05 {
                worst = worst.max((b as f64 / two_dawson(xf) - 1.0).abs());
            }
        }
        assert!(worst < 2e-6, "{worst:e}");
    }

    /// Thickness and extinction of 0, 1e-12 and 1e12 (and far beyond), any
    /// scalars: finite colour, opacity in [0, 1].
    #[test]
    fn extreme_inputs_stay_finite() {
        use crate::tf::Node;
        let c = closed_form_constants();
        for model in [EmissionModel::Glow, EmissionModel::Independent] {
            for tau in [0.0, 1e-12, 1.0, 1e12, 1e30] {
                let node = |s: f64, t: f64| Node {
                    s,
                    tau: t,
                    color: [0.5, 1.0, 0.2],
                    emission: [1e3, 0.0, 2.0],
                };
                let tf = TransferFunction::from_nodes(
                    &[
                        node(0.0, 0.0),
                        node(0.5, tau),
                        node(0.5, 0.1 * tau),
                        node(1.0, tau),
                    ],
                    model,
                )
                .unwrap();
                let buf = TfBuffer::new(&tf, &ScalarMap::of(&tf));
                for l in [
                    0.0f32,
                    1e-12,
                    1e-3,
                    1.0,
                    1e12,
                    1e38,
                    f32::INFINITY,
                    f32::NAN,
                ] {
                    for (sf, sb) in [
                        (0.0f32, 1.0f32),
                        (1.0, 0.0),
                        (0.5, 0.5),
                        (-1e30, 1e30),
                        (0.2, f32::NAN),
                    ] {
                        let v = buf.integrate_segment(&c, GaussRule::Six, l, sf, sb);
                        assert!(
                            v.iter().all(|x| x.is_finite()) && (0.0..=1.0).contains(&v[3]),
                            "{model:?} tau {tau} l {l} s {sf}..{sb}: {v:?}"
                        );
                    }
                }
            }
        }
    }

    /// Each Gauss rule holds its range: in `f32`, every basis integral
    /// against the f64 closed form, relative to the segment's depth for the
    /// colour weights (as in `GaussRule`'s error bound), within the 6-node
    /// rule's own `f32` error plus the rule's bound; and a rule is not
    /// enough beyond its range (so the thresholds are not loose).
    #[test]
    fn shorter_rules_hold_their_range() {
        let c = closed_form_constants();
        let worst = |rule: GaussRule, depth: f64| {
            let mut worst = 0.0f64;
            let n = 40;
            for i in 0..=n {
                for j in 0..=n {
                    let (a, b) = (
                        (depth * i as f64 / n as f64) as f32,
                        (depth * j as f64 / n as f64) as f32,
                    );
                    if a + b == 0.0 {
                        continue;
                    }
                    let w = weights(&c, rule, a, b);
                    let e = crate::integrate::weights(a as f64, b as f64);
                    let d1 = 0.5 * (a as f64 + b as f64);
                    for (g, x, scale) in [
                        (w.w_f, e.w_f, d1),
                        (w.w_b, e.w_b, d1),
                        (w.phi_f, e.phi_f, 1.0),
                        (w.phi_b, e.phi_b, 1.0),
                        (w.psi, e.psi, 1.0),
                    ] {
                        worst = worst.max((g as f64 - x).abs() / scale);
                    }
                }
            }
            worst
        };
        for rule in [GaussRule::Four, GaussRule::Five, GaussRule::Six] {
            let d = rule.max_depth();
            let six = worst(GaussRule::Six, d);
            let got = worst(rule, d);
            eprintln!("{rule:?} up to {d}: {got:.2e} (6 nodes {six:.2e})");
            assert!(got <= six + 6e-8, "{rule:?}: {got:e} against {six:e}");
            if rule != GaussRule::Six {
                let beyond = worst(rule, 2.0 * d);
                assert!(beyond > six + 6e-8, "{rule:?} beyond: {beyond:e}");
            }
        }
        assert_eq!(GaussRule::for_depth(0.35), Some(GaussRule::Four));
        assert_eq!(GaussRule::for_depth(0.36), Some(GaussRule::Five));
        assert_eq!(GaussRule::for_depth(2.0), Some(GaussRule::Six));
        assert_eq!(GaussRule::for_depth(2.01), None);
        assert_eq!(GaussRule::for_depth(f64::NAN), None);
    }

    /// The rules integrate polynomials up to their degree exactly.
    #[test]
    fn every_rule_is_exact_to_its_degree() {
        for rule in [GaussRule::Four, GaussRule::Five, GaussRule::Six] {
            let n = rule.nodes().len() as i32;
            for k in 0..2 * n {
                let got: f64 = rule.nodes().iter().map(|&(x, w)| w * x.powi(k)).sum();
                assert!((got - 1.0 / (k + 1) as f64).abs() < 1e-15, "{rule:?} {k}");
            }
        }
    }

    #[test]
    fn weights_match_f64_in_every_regime() {
        let c = closed_form_constants();
        let mut worst = 0.0f64;
        for &a in &[0.0, 1e-6, 0.3, 1.0, 1.9, 2.5, 7.0, 30.0, 1e3, 1e6] {
            for &b in &[
                0.0, 1e-6, 0.3, 1.0, 1.9, 2.5, 7.0, 30.0, 1e3, 1e6, 30.000_03,
            ] {
                let w = weights(&c, GaussRule::Six, a as f32, b as f32);
                let e = crate::integrate::weights(a as f32 as f64, b as f32 as f64);
                for (g, x) in [
                    (w.psi, e.psi),
                    (w.phi_f, e.phi_f),
                    (w.phi_b, e.phi_b),
                    (w.w_f, e.w_f),
                    (w.w_b, e.w_b),
                    (w.alpha, e.alpha),
                ] {
                    assert!(g.is_finite(), "{a} {b}");
                    worst = worst.max((g as f64 - x).abs() / x.abs().max(1e-3));
                }
            }
        }
        assert!(worst < 1e-5, "{worst:e}");
    }
}
