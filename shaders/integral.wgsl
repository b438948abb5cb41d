// Exact ray integral of one cell segment through a piecewise-linear transfer
// function, in f32 (Williams and Max, "A Volume Density Optical Model", the
// closed form ported from src/integrate/weights.rs; docs/math.md sections 2
// and 4.2). Used by the fragment stage of the exact-frag mode and by the GPU
// build of pre-integration tables.
//
// Twin: render::modes::integral, function for function, same names.
//
// Bindings it declares (a stage that includes this file keeps them free):
// 1: the transfer function (`TfBuffer`, nodes normalised as
//    src/render/modes/segment.rs `ScalarMap` says);
// 2: the constants of the closed form (`consts`): the Taylor centres of the
//    special functions (129 entries: P, Q, B, G at x = k/16) followed by the
//    6-node Gauss-Legendre rule on [0, 1] ((x, w) pairs, two per entry),
//    which the table build's recurrences read.
//
// Up to optical depth 2 the basis integrals are a Gauss-Legendre rule whose
// nodes are literals here (`gauss`): loaded from a buffer they cost a
// gather per node on a software rasteriser. The 6-node rule is as good in
// f32 as the f64 path's 12 nodes (error below 6e-9 up to depth 2, tested)
// at half the cost; a stage whose every segment is thinner takes a shorter
// rule (`GAUSS_NODES`, chosen on the CPU per frame from the scene's
// thickest possible segment, never per fragment: the lanes of a SIMD group
// that straddle a threshold would run both rules).

struct TfBuffer {
    // Number of nodes (>= 1).
    count: u32,
    // 0: glow (source tau * colour), 1: independent emission.
    model: u32,
    _pad0: u32,
    _pad1: u32,
    // Two entries per node: (s, tau, 0, 0) and (colour or emission, 0).
    nodes: array<vec4<f32>>,
}

@group(0) @binding(1) var<storage, read> tf: TfBuffer;
@group(0) @binding(2) var<storage, read> consts: array<vec4<f32>>;

const SF_CENTRES: u32 = 129u;
const GL6_BASE: u32 = 129u;
// Terms of the Taylor series about the nearest centre (|x - x0| <= 1/32):
// the truncation error is below 1e-9 relative (twin test).
const TAYLOR_TERMS: u32 = 9u;
// Terms of the asymptotic series (argument t <= 1/128): below 1e-10.
const ASYM_TERMS: u32 = 9u;
// Up to this optical thickness (both ends) the basis integrals are a
// Gauss-Legendre rule (`GAUSS_NODES`: 6 nodes are accurate to 6e-9 up to
// here); above it the closed form of the special functions.
const GAUSS_MAX: f32 = 2.0;
// Whether a segment can be thicker than GAUSS_MAX. A stage whose every
// segment is thinner (the transfer function's largest extinction times the
// mesh's largest cell diameter, checked on the CPU) sets it to false: the
// compiler then drops the closed form, whose mere presence slowed every
// fragment on llvmpipe by about 12 %.
override THICK_SEGMENTS: bool = true;
// The Gauss-Legendre rule of the thin regime: 6 nodes (error below 6e-9
// relative up to depth 2), 5 (below 4.4e-8 up to depth 1.25) or 4 (below
// 5.4e-8 up to depth 0.35), all under f32's rounding unit (6.0e-8), chosen
// on the CPU (render::modes::integral::GaussRule) from the thickest
// segment the frame can hold.
override GAUSS_NODES: u32 = 6u;
// Above this argument the special functions use their asymptotic series.
const ASYM_X: f32 = 8.0;
// Optical thicknesses and lengths are clamped here (f32 range, and so that
// inf * 0 never appears); scalars likewise.
const MAX_THICKNESS: f32 = 1e30;
const MAX_SCALAR: f32 = 1e30;

struct Material {
    tau: f32,
    col: vec3<f32>,
}

// The basis integrals of one linear sub-segment (src/integrate/weights.rs).
struct Weights {
    psi: f32,
    phi_f: f32,
    phi_b: f32,
    w_f: f32,
    w_b: f32,
    alpha: f32,
    t: f32,
}

fn node_s(i: u32) -> f32 {
    return tf.nodes[2u * i].x;
}

fn node(i: u32) -> Material {
    return Material(tf.nodes[2u * i].y, tf.nodes[2u * i + 1u].xyz);
}

// Number of nodes with s_node <= s (the transfer-function piece holding s):
// a binary search.
fn piece_index(s: f32) -> u32 {
    var lo = 0u;
    var hi = tf.count;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if node_s(mid) <= s {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Extinction and colour of piece `idx` at `s`: exact node values at its
// nodes, constant beyond the first and last node. Without branches (a
// software rasteriser runs every side of a branch its lanes take, with
// every side's loads): the piece's two nodes are loaded once and the
// result selected.
fn eval_piece(idx: u32, s: f32) -> Material {
    let n = tf.count;
    let j = min(max(idx, 1u), n) - 1u;
    let k = min(j + 1u, n - 1u);
    let a0 = tf.nodes[2u * j];
    let a1 = tf.nodes[2u * k];
    let c0 = tf.nodes[2u * j + 1u].xyz;
    let c1 = tf.nodes[2u * k + 1u].xyz;
    let u = (s - a0.x) / (a1.x - a0.x);
    var tau = a0.y + (a1.y - a0.y) * u;
    var col = c0 + (c1 - c0) * u;
    let at_back = s == a1.x;
    tau = select(tau, a1.y, at_back);
    col = select(col, c1, at_back);
    let at_front = idx == 0u || idx >= n || s == a0.x;
    return Material(select(tau, a0.y, at_front), select(col, c0, at_front));
}

// 1 - exp(-d) for d >= 0 without cancellation at small d.
fn neg_expm1(d: f32) -> f32 {
    if d < 0.0625 {
        return d * (1.0 - d * (0.5 - d * (1.0 / 6.0 - d * (1.0 / 24.0 - d * (1.0 / 120.0)))));
    }
    return 1.0 - exp(-d);
}

// (P(x), Q(x)) for sigma = -1 (increasing extinction), (B(x), G(x)) for
// sigma = 1 (decreasing), 0 <= x <= 8: Taylor series about the nearest
// centre. The two pairs obey one recurrence up to the sign sigma (each
// multiplication by sigma is exact), so one loop serves both: lanes of a
// SIMD group with rising and with falling extinction run it once.
fn taylor_sf(x: f32, sigma: f32) -> vec2<f32> {
    let k = min(u32(x * 16.0 + 0.5), SF_CENTRES - 1u);
    let x0 = f32(k) / 16.0;
    let dl = x - x0;
    let c = consts[k];
    let f0 = select(c.x, c.z, sigma > 0.0);
    let f1 = select(c.y, c.w, sigma > 0.0);
    var pm1 = f0;
    var p = 2.0 * sigma * f1;
    var s1 = f0 + p * dl;
    var s2 = f1 + (-x0 * p - f0) * dl;
    var dn = dl;
    for (var n = 1u; n < TAYLOR_TERMS; n++) {
        let pn1 = -sigma * (2.0 * x0 * p + 2.0 * pm1) / f32(n + 1u);
        dn *= dl;
        s1 += pn1 * dn;
        s2 += (-x0 * pn1 - p) * dn;
        pm1 = p;
        p = pn1;
    }
    return vec2<f32>(s1, s2);
}

// Scaled asymptotic series: S = sum sign^k (2k-1)!! t^k,
// q = sum sign^k (2k+1)!! t^k.
fn asym(t: f32, sign: f32) -> vec2<f32> {
    var s = 1.0;
    var q = 1.0;
    var term = 1.0;
    var qterm = 1.0;
    for (var k = 1u; k < ASYM_TERMS; k++) {
        let kf = f32(k);
        term *= sign * (2.0 * kf - 1.0) * t;
        s += term;
        if k >= 2u {
            qterm *= sign * (2.0 * kf - 1.0) * t;
            q += qterm;
        }
    }
    return vec2<f32>(s, q);
}

// One end of a segment with extinction slope d = |b - a| > 0 or, with
// r = sqrt(2 d) = 0, equal ends: (P(u)/r, Q(u)/d) for rising extinction
// (sigma = -1), (B(u)/r, -G(u)/d) for falling (sigma = 1), u = c/r; the
// scaled asymptotic series where u > ASYM_X (always where r = 0, which
// gives the equal-ends closed form). Compared as c <= ASYM_X r, without
// dividing by r.
fn ends_sf(c: f32, r: f32, d: f32, sigma: f32) -> vec2<f32> {
    if c <= ASYM_X * r {
        let t = taylor_sf(c / r, sigma);
        return vec2<f32>(t.x / r, -sigma * t.y / d);
    }
    let cc = c * c;
    let sq = asym(d / cc, sigma);
    return vec2<f32>(sq.x / c, sq.y / cc);
}

fn sanitize_thickness(x: f32) -> f32 {
    if x > 0.0 {
        return min(x, MAX_THICKNESS);
    }
    return 0.0;
}

// Adds node x with weight w of a Gauss-Legendre rule on [0, 1] to
// [w_f, w_b, phi_f, phi_b] (positive integrands: no cancellation).
fn gauss_node(acc: ptr<function, vec4<f32>>, a: f32, b: f32, x: f32, w: f32) {
    let y = 1.0 - x;
    let dx = x * (a * (1.0 - 0.5 * x) + b * (0.5 * x));
    let dp = a * y + b * x;
    let e = w * exp(-dx);
    let ed = e * dp;
    *acc += vec4<f32>(y * ed, x * ed, y * e, x * e);
}

// [w_f, w_b, phi_f, phi_b] by the GAUSS_NODES rule (twin:
// integral::GaussRule's nodes, the same f32 values).
fn gauss(a: f32, b: f32) -> vec4<f32> {
    var acc = vec4<f32>(0.0);
    if GAUSS_NODES == 4u {
        gauss_node(&acc, a, b, 0.06943184420297371, 0.17392742256872692);
        gauss_node(&acc, a, b, 0.3300094782075719, 0.32607257743127305);
        gauss_node(&acc, a, b, 0.6699905217924281, 0.32607257743127305);
        gauss_node(&acc, a, b, 0.9305681557970262, 0.17392742256872692);
    } else if GAUSS_NODES == 5u {
        gauss_node(&acc, a, b, 0.046910077030668, 0.11846344252809454);
        gauss_node(&acc, a, b, 0.2307653449471585, 0.23931433524968324);
        gauss_node(&acc, a, b, 0.5, 0.28444444444444444);
        gauss_node(&acc, a, b, 0.7692346550528415, 0.23931433524968324);
        gauss_node(&acc, a, b, 0.953089922969332, 0.11846344252809454);
    } else {
        gauss_node(&acc, a, b, 0.03376524289842399, 0.08566224618958518);
        gauss_node(&acc, a, b, 0.16939530676686773, 0.1803807865240693);
        gauss_node(&acc, a, b, 0.38069040695840156, 0.23395696728634552);
        gauss_node(&acc, a, b, 0.6193095930415985, 0.23395696728634552);
        gauss_node(&acc, a, b, 0.8306046932331322, 0.1803807865240693);
        gauss_node(&acc, a, b, 0.966234757101576, 0.08566224618958518);
    }
    return acc;
}

// Basis integrals for optical thicknesses a = tau_f l and b = tau_b l.
fn weights(a_in: f32, b_in: f32) -> Weights {
    let a = sanitize_thickness(a_in);
    let b = sanitize_thickness(b_in);
    let d1 = 0.5 * (a + b);
    let m = max(a, b);
    if m <= GAUSS_MAX || !THICK_SEGMENTS {
        let alpha = neg_expm1(d1);
        let t = 1.0 - alpha;
        let g = gauss(a, b);
        return Weights(g.z + g.w, g.z, g.w, g.x, g.y, alpha, t);
    }
    let t = exp(-d1);
    let alpha = 1.0 - t;
    // Rising or falling extinction, one path (equal ends included, as
    // the limit d = 0 of the asymptotic series).
    let sigma = select(1.0, -1.0, b > a);
    let d = abs(b - a);
    let r = sqrt(2.0 * d);
    let f = ends_sf(a, r, d, sigma);
    let k = ends_sf(b, r, d, sigma);
    let psi = f.x - t * k.x;
    let phi_b = f.y - t * k.y - t * k.x;
    return Weights(psi, psi - phi_b, phi_b, 1.0 - psi, psi - t, alpha, t);
}

// The running front-to-back composite of the pieces of one segment.
struct Composite {
    color: vec3<f32>,
    depth: f32,
    alpha: f32,
    pieces: u32,
    // Transmittance in front of the next piece: the product of the
    // pieces' own (each exp(-depth) already), so no exponential of the
    // running depth per piece.
    tr: f32,
}

// Adds one linear piece of length `l` (extinction and colour linear from
// m0 at its front to m1 at its back) behind `acc`.
fn add_piece(acc: ptr<function, Composite>, l: f32, m0: Material, m1: Material) {
    let a = m0.tau * l;
    let b = m1.tau * l;
    let w = weights(a, b);
    var c: vec3<f32>;
    if tf.model == 0u {
        c = m0.col * w.w_f + m1.col * w.w_b;
    } else {
        c = l * (m0.col * w.phi_f + m1.col * w.phi_b);
    }
    (*acc).color += (*acc).tr * c;
    (*acc).tr *= w.t;
    (*acc).depth += 0.5 * (sanitize_thickness(a) + sanitize_thickness(b));
    (*acc).alpha = w.alpha;
    (*acc).pieces += 1u;
}

// The spans of the segment from s_f to s_b through the transfer function:
// piece i0 holds the lower end, the nodes i0 .. i1 - 1 lie strictly between
// the ends (a short scan: segments cross few nodes), `count` of them; the
// spans run front to back, ascending where the scalar grows (`up`),
// descending where it falls; `inv` is 1 / (s_b - s_f) where a node lies
// between, the materials at the two ends are `m_first` and `m_last`.
struct Spans {
    i0: u32,
    i1: u32,
    count: u32,
    up: bool,
    inv: f32,
    m_first: Material,
    m_last: Material,
}

fn segment_spans(s_f: f32, s_b: f32) -> Spans {
    let lo = min(s_f, s_b);
    let hi = max(s_f, s_b);
    let i0 = piece_index(lo);
    var i1 = i0;
    while i1 < tf.count && node_s(i1) < hi {
        i1++;
    }
    let up = s_b > s_f;
    let count = i1 - i0;
    var inv = 0.0;
    if count > 0u {
        inv = 1.0 / (s_b - s_f);
    }
    let m_first = eval_piece(select(i1, i0, up), s_f);
    let m_last = eval_piece(select(i0, i1, up), s_b);
    return Spans(i0, i1, count, up, inv, m_first, m_last);
}

// The back end of span n (0 ..= count) of a segment starting at s_f: the
// material there and its fraction of the segment. At each crossed node k
// the span in front ends and the next begins with node k's own material,
// so a jump (two nodes at one scalar) is an empty span between its two
// materials.
struct SpanEnd {
    m: Material,
    x: f32,
}

fn span_end(sp: Spans, n: u32, s_f: f32) -> SpanEnd {
    if n < sp.count {
        let k = select(sp.i1 - 1u - n, sp.i0 + n, sp.up);
        return SpanEnd(node(k), (node_s(k) - s_f) * sp.inv);
    }
    return SpanEnd(sp.m_last, 1.0);
}

// Premultiplied colour and opacity of a segment of length `l` over which the
// scalar goes linearly from `s_f` (front) to `s_b` (back), sliced at every
// node strictly between them (twin: integral::integrate_segment; the f64
// original is integrate::segment).
fn integrate_segment(l_in: f32, sf_in: f32, sb_in: f32) -> vec4<f32> {
    if !(l_in > 0.0) || !(sf_in == sf_in) || !(sb_in == sb_in) {
        return vec4<f32>(0.0);
    }
    let l = min(l_in, MAX_THICKNESS);
    let s_f = clamp(sf_in, -MAX_SCALAR, MAX_SCALAR);
    let s_b = clamp(sb_in, -MAX_SCALAR, MAX_SCALAR);
    var acc = Composite(vec3<f32>(0.0), 0.0, 0.0, 0u, 1.0);
    // Front to back, count + 1 spans (`segment_spans`, `span_end`). One
    // loop with one call of add_piece keeps the shader small (every lane of
    // a SIMD group runs the loop as often as its longest segment).
    let sp = segment_spans(s_f, s_b);
    var m_prev = sp.m_first;
    var x_prev = 0.0;
    for (var n = 0u; n <= sp.count; n++) {
        let e = span_end(sp, n, s_f);
        if e.x > x_prev {
            add_piece(&acc, l * (e.x - x_prev), m_prev, e.m);
        }
        m_prev = e.m;
        x_prev = e.x;
    }
    var alpha = acc.alpha;
    if acc.pieces != 1u {
        alpha = neg_expm1(acc.depth);
    }
    // Independent emission over a huge length with no extinction can
    // exceed f32: saturate rather than return infinity.
    return vec4<f32>(min(acc.color, vec3<f32>(MAX_THICKNESS)), alpha);
}
