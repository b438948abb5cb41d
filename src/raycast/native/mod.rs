//! The `native` field model: the iso-parametric field of hexahedra (trilinear),
//! wedges and pyramids, integrated along a ray between the ray's
//! intersections with the cells' true boundaries, to a stated accuracy.
//!
//! **Cell boundary** ([`boundary`]): the ray's intervals inside a cell
//! ([`cell_intervals`]), between its exact crossings of the cell's bilinear
//! and triangular faces; two cells sharing a face compute bit-identical
//! roots, so intervals meet with no gap and no double count.
//!
//! **Along an interval** `s(t)` is not a polynomial in `t`:
//! 1. **Evaluate** `s(t)`: invert the iso-parametric map `x(xi) = o + t d` by
//!    Newton's method (warm-started from the previous solution, then from
//!    the cell's centre; the 3x3 Jacobian solved directly), then
//!    `s = sum N_i(xi) s_i`. `ds/dt` is `grad_xi s . J^-1 d`. Evaluations
//!    that fail from both starts are counted ([`NativeStats::newton_failures`]).
//! 2. **Split** so that each piece is monotone in `s` and inside one piece of
//!    the transfer function ([`breakpoint_crossings`]): from 8 equal
//!    subintervals, each is refined adaptively until the cubic Hermite
//!    interpolant of its end values and slopes reproduces `s` and `s'` at
//!    the midpoint (to [`NATIVE_HERMITE_REL`] relative) and shows at most one extremum, which
//!    is then bisected on `s'`; then `s(t) - S_k` is bisected for every
//!    breakpoint `S_k` crossed on each monotone part. The precise guarantee
//!    and assumption are stated at [`monotone_nodes`]: exact for cubic
//!    `s(t)` (all affine cells), an accuracy assumption otherwise.
//! 3. **Integrate** each smooth piece by adaptive Gauss-Legendre collocation:
//!    on an interval, the 8-point Gauss nodes give `tau` and the source `g`;
//!    the optical depth at each node is the exact integral of the degree-7
//!    interpolant of `tau` (a precomputed integration matrix), and the
//!    colour is `sum w_i g_i exp(-D_i)`. Intervals are halved until halves
//!    and whole agree to [`NATIVE_INTEGRAL_TOL`] (absolute, colour and
//!    depth). Material is only evaluated at interior nodes, never exactly on
//!    a breakpoint.
//!
//! **Isosurfaces** ([`iso`]): the crossings of each isovalue are found as
//! the breakpoints are, on the same monotone pieces, and the volume is
//! integrated between them.
//!
//! If the map cannot be inverted inside an interval (degenerate cell,
//! Newton failure) the interval falls back to the linear integral between
//! the exact boundary scalars at its ends ([`interval_value`]), counted in
//! [`NativeStats::fallback_intervals`].

use std::sync::OnceLock;

use glam::{DMat3, DVec3};

mod boundary;
pub mod iso;

pub use boundary::{axes_of, cell_intervals, ray_bilinear, ray_triangle, Interval};

use super::{Scalars, Scene};
use crate::camera::Ray;
use crate::integrate::{RayMaterial, SegmentValue};
use crate::mesh::CellKind;
use crate::numeric::tolerance::{
    GAUSS_LEGENDRE_NODE_TOL, HERMITE_QUADRATIC_REL, NATIVE_HERMITE_ABS, NATIVE_HERMITE_REL,
    NATIVE_INTEGRAL_TOL, NATIVE_NEWTON_ACCEPT, NATIVE_NEWTON_DIVERGED, NATIVE_NEWTON_TOL,
    NATIVE_PARAM_TOL,
};

const GL_N: usize = 8;
const MAX_LEVEL: u32 = 24;

struct Quadrature {
    x: [f64; GL_N],
    w: [f64; GL_N],
    /// `s[i][j] = integral from 0 to x_i of the Lagrange basis l_j`.
    s: [[f64; GL_N]; GL_N],
}

fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, dp)
}

fn quadrature() -> &'static Quadrature {
    static Q: OnceLock<Quadrature> = OnceLock::new();
    Q.get_or_init(|| {
        let mut x = [0.0; GL_N];
        let mut w = [0.0; GL_N];
        for i in 0..GL_N {
            let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (GL_N as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(GL_N, z);
                let dz = p / dp;
                z -= dz;
                if dz.abs() < GAUSS_LEGENDRE_NODE_TOL {
                    break;
                }
            }
            let (_, dp) = legendre(GL_N, z);
            // Map [-1, 1] -> [0, 1], ascending.
            x[GL_N - 1 - i] = 0.5 * (z + 1.0);
            w[GL_N - 1 - i] = 1.0 / ((1.0 - z * z) * dp * dp);
        }
        let lagrange = |j: usize, t: f64| {
            let mut v = 1.0;
            for m in 0..GL_N {
                if m != j {
                    v *= (t - x[m]) / (x[j] - x[m]);
                }
            }
            v
        };
        let s = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let acc: f64 = (0..GL_N).map(|k| w[k] * lagrange(j, x[i] * x[k])).sum();
                x[i] * acc
            })
        });
        Quadrature { x, w, s }
    })
}

/// Shape functions and their parametric derivatives of a zoo cell.
fn shape(kind: CellKind, p: DVec3, n: &mut [f64; 8], dn: &mut [DVec3; 8]) -> usize {
    let (r, s, t) = (p.x, p.y, p.z);
    match kind {
        CellKind::Hexahedron => {
            const C: [[f64; 3]; 8] = [
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [0., 1., 0.],
                [0., 0., 1.],
                [1., 0., 1.],
                [1., 1., 1.],
                [0., 1., 1.],
            ];
            let f = |c: f64, x: f64| if c > 0.5 { x } else { 1.0 - x };
            let df = |c: f64| if c > 0.5 { 1.0 } else { -1.0 };
            for (i, c) in C.iter().enumerate() {
                let (a, b, cc) = (f(c[0], r), f(c[1], s), f(c[2], t));
                n[i] = a * b * cc;
                dn[i] = DVec3::new(df(c[0]) * b * cc, a * df(c[1]) * cc, a * b * df(c[2]));
            }
            8
        }
        CellKind::Wedge => {
            let u = 1.0 - r - s;
            let bot = [u, r, s];
            let dbot = [DVec3::new(-1., -1., 0.), DVec3::X, DVec3::Y];
            for k in 0..3 {
                n[k] = bot[k] * (1.0 - t);
                n[k + 3] = bot[k] * t;
                dn[k] = dbot[k] * (1.0 - t) - DVec3::Z * bot[k];
                dn[k + 3] = dbot[k] * t + DVec3::Z * bot[k];
            }
            6
        }
        CellKind::Pyramid => {
            let base = [(1.0 - r) * (1.0 - s), r * (1.0 - s), r * s, (1.0 - r) * s];
            let dbase = [
                DVec3::new(-(1.0 - s), -(1.0 - r), 0.0),
                DVec3::new(1.0 - s, -r, 0.0),
                DVec3::new(s, r, 0.0),
                DVec3::new(-s, 1.0 - r, 0.0),
            ];
            for k in 0..4 {
                n[k] = base[k] * (1.0 - t);
                dn[k] = dbase[k] * (1.0 - t) - DVec3::Z * base[k];
            }
            n[4] = t;
            dn[4] = DVec3::Z;
            5
        }
        _ => 0,
    }
}

/// Subdivision depth limit of the monotone-piece search.
const BRACKET_DEPTH: u32 = 30;
/// Initial samples of `s(t)` per interval before the adaptive refinement.
const BRACKET_START: usize = 8;

/// Counters of one ray's (or a whole render's) native work: what had to
/// fall back from the exact method, so that a reference image says how
/// reference it is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct NativeStats {
    /// Cell intervals integrated through the iso-parametric field.
    pub intervals: u64,
    /// Cells whose bilinear boundary the ray crosses although the walk over
    /// the triangulated faces did not visit them (found through shared
    /// bilinear faces).
    pub extra_cells: u64,
    /// Point evaluations where Newton did not converge from the warm start
    /// and then also not from the cell's centre.
    pub newton_failures: u64,
    /// Intervals integrated with the linear (`faces`-style) fallback
    /// `segment(l, s_a, s_b)` between the exact boundary scalars because
    /// the map could not be inverted somewhere inside.
    pub fallback_intervals: u64,
    /// Intervals between two boundary roots whose midpoint could not be
    /// located (Newton failure): classified by root parity instead.
    pub parity_classified: u64,
    /// Pieces taken as monotone only because the subdivision reached its
    /// depth limit (the cubic-Hermite test had not yet accepted them).
    pub bracket_depth_limited: u64,
}

impl NativeStats {
    /// Adds `o` to `self`.
    pub fn add(&mut self, o: &NativeStats) {
        self.intervals += o.intervals;
        self.extra_cells += o.extra_cells;
        self.newton_failures += o.newton_failures;
        self.fallback_intervals += o.fallback_intervals;
        self.parity_classified += o.parity_classified;
        self.bracket_depth_limited += o.bracket_depth_limited;
    }

    /// The counts added since `earlier` (a snapshot of the same counters).
    pub fn since(&self, earlier: &NativeStats) -> NativeStats {
        NativeStats {
            intervals: self.intervals - earlier.intervals,
            extra_cells: self.extra_cells - earlier.extra_cells,
            newton_failures: self.newton_failures - earlier.newton_failures,
            fallback_intervals: self.fallback_intervals - earlier.fallback_intervals,
            parity_classified: self.parity_classified - earlier.parity_classified,
            bracket_depth_limited: self.bracket_depth_limited - earlier.bracket_depth_limited,
        }
    }

    /// Whether anything fell back from the exact method.
    pub fn any_fallback(&self) -> bool {
        self.newton_failures + self.fallback_intervals + self.parity_classified > 0
            || self.bracket_depth_limited > 0
    }
}

/// Whether `kind` has an iso-parametric field here.
pub fn is_native_kind(kind: CellKind) -> bool {
    matches!(
        kind,
        CellKind::Hexahedron | CellKind::Wedge | CellKind::Pyramid
    )
}

fn centre_of(kind: CellKind) -> DVec3 {
    match kind {
        CellKind::Hexahedron => DVec3::splat(0.5),
        CellKind::Wedge => DVec3::new(1.0 / 3.0, 1.0 / 3.0, 0.5),
        _ => DVec3::new(0.5, 0.5, 0.25),
    }
}

/// Whether parametric point `xi` is in the (closed, `NATIVE_PARAM_TOL`-widened)
/// reference element of `kind`.
pub fn in_reference(kind: CellKind, xi: DVec3) -> bool {
    let lo = -NATIVE_PARAM_TOL;
    let hi = 1.0 + NATIVE_PARAM_TOL;
    let box01 = |v: f64| v >= lo && v <= hi;
    match kind {
        CellKind::Wedge => xi.x >= lo && xi.y >= lo && xi.x + xi.y <= hi && box01(xi.z),
        _ => box01(xi.x) && box01(xi.y) && box01(xi.z),
    }
}

/// One cell's iso-parametric map and field along one ray.
pub struct IsoRay {
    kind: CellKind,
    x: [DVec3; 8],
    s: [f64; 8],
    o: DVec3,
    d: DVec3,
    xi: DVec3,
    /// Evaluations that failed from both starts.
    pub failures: u64,
}

impl IsoRay {
    /// The field of cell `nodes` (positions `x`, scalars `s`) along `ray`;
    /// `None` for kinds without an iso-parametric field here.
    pub fn new(kind: CellKind, x: &[DVec3], s: &[f64], ray: &Ray) -> Option<IsoRay> {
        let n = match kind {
            CellKind::Hexahedron => 8,
            CellKind::Wedge => 6,
            CellKind::Pyramid => 5,
            _ => return None,
        };
        if x.len() != n || s.len() != n {
            return None;
        }
        let mut xs = [DVec3::ZERO; 8];
        let mut ss = [0.0; 8];
        xs[..n].copy_from_slice(x);
        ss[..n].copy_from_slice(s);
        Some(IsoRay {
            kind,
            x: xs,
            s: ss,
            o: ray.origin,
            d: ray.dir,
            xi: centre_of(kind),
            failures: 0,
        })
    }

    /// Newton on `x(xi) = target` from `start`: the parametric point and the
    /// inverse Jacobian there.
    fn newton(&self, target: DVec3, start: DVec3) -> Option<(DVec3, DMat3)> {
        let mut n = [0.0; 8];
        let mut dn = [DVec3::ZERO; 8];
        let mut xi = start;
        for it in 0..40 {
            let cnt = shape(self.kind, xi, &mut n, &mut dn);
            let mut pos = DVec3::ZERO;
            let mut jac = DMat3::ZERO;
            for i in 0..cnt {
                pos += self.x[i] * n[i];
                jac.x_axis += self.x[i] * dn[i].x;
                jac.y_axis += self.x[i] * dn[i].y;
                jac.z_axis += self.x[i] * dn[i].z;
            }
            let det = jac.determinant();
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let inv = jac.inverse();
            let step = inv * (target - pos);
            xi += step;
            if !xi.is_finite() || xi.abs().max_element() > NATIVE_NEWTON_DIVERGED {
                return None;
            }
            if step.length() < NATIVE_NEWTON_TOL || it == 39 {
                if step.length() > NATIVE_NEWTON_ACCEPT {
                    return None;
                }
                return Some((xi, inv));
            }
        }
        None
    }

    /// Newton from the warm start, then from the cell's centre.
    fn invert(&mut self, t: f64) -> Option<(DVec3, DMat3)> {
        let target = self.o + self.d * t;
        let r = self
            .newton(target, self.xi)
            .or_else(|| self.newton(target, centre_of(self.kind)));
        match r {
            Some((xi, inv)) => {
                self.xi = xi;
                Some((xi, inv))
            }
            None => {
                self.failures += 1;
                None
            }
        }
    }

    /// The parametric coordinates of the ray's point at depth `t`.
    pub fn locate(&mut self, t: f64) -> Option<DVec3> {
        self.invert(t).map(|(xi, _)| xi)
    }

    /// Scalar and its derivative along the ray at depth `t`.
    pub fn eval(&mut self, t: f64) -> Option<(f64, f64)> {
        let (xi, inv) = self.invert(t)?;
        let mut n = [0.0; 8];
        let mut dn = [DVec3::ZERO; 8];
        let cnt = shape(self.kind, xi, &mut n, &mut dn);
        let mut sv = 0.0;
        let mut grad = DVec3::ZERO;
        for i in 0..cnt {
            sv += self.s[i] * n[i];
            grad += dn[i] * self.s[i];
        }
        Some((sv, grad.dot(inv * self.d)))
    }
}

fn bisect(lo: f64, hi: f64, f_lo: f64, mut f: impl FnMut(f64) -> Option<f64>) -> Option<f64> {
    let (mut a, mut b, mut fa) = (lo, hi, f_lo);
    for _ in 0..64 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = f(m)?;
        if (fm > 0.0) == (fa > 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    Some(0.5 * (a + b))
}

/// A sample of `s(t)`: depth, value, slope.
type Sample = (f64, f64, f64);

/// Whether the cubic Hermite interpolant of `a`, `b` has a critical point
/// strictly inside `(a.0, b.0)`.
fn hermite_has_critical(a: Sample, b: Sample) -> bool {
    let h = b.0 - a.0;
    // On x in [0, 1]: H'(x) / h = d0 p0' + ... ; in slope units:
    // H'(x) = c0 + c1 x + c2 x^2 with
    let m = (b.1 - a.1) / h;
    let c0 = a.2;
    let c1 = 6.0 * m - 4.0 * a.2 - 2.0 * b.2;
    let c2 = 3.0 * (a.2 + b.2) - 6.0 * m;
    let has_root = |x: f64| x > 0.0 && x < 1.0;
    if c2.abs() <= HERMITE_QUADRATIC_REL * (c0.abs() + c1.abs()) {
        return c1 != 0.0 && has_root(-c0 / c1);
    }
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc < 0.0 {
        return false;
    }
    let q = -0.5 * (c1 + c1.signum() * disc.sqrt());
    let r1 = q / c2;
    let r2 = if q != 0.0 { c0 / q } else { r1 };
    has_root(r1) || has_root(r2)
}

/// Slope of the cubic Hermite interpolant of `a`, `b` at the midpoint.
fn hermite_mid_slope(a: Sample, b: Sample) -> f64 {
    1.5 * (b.1 - a.1) / (b.0 - a.0) - 0.25 * (a.2 + b.2)
}

/// Value of the cubic Hermite interpolant of `a`, `b` at the midpoint.
fn hermite_mid(a: Sample, b: Sample) -> f64 {
    0.5 * (a.1 + b.1) + 0.125 * (b.0 - a.0) * (a.2 - b.2)
}

/// Splits `[t_in, t_out]` into pieces on which `s` is monotone, returning
/// the piece ends with their values (`nodes`), front to back.
///
/// An interval `[a, b]` (with midpoint `m` evaluated) is accepted as
/// monotone when the slopes at `a`, `m`, `b` are non-zero with one sign,
/// the cubic Hermite interpolant of the end values and slopes has no
/// critical point inside, and it predicts `s(m)` to within [`NATIVE_HERMITE_REL`] of
/// `|s(b) - s(a)|` (plus [`NATIVE_HERMITE_ABS`] absolute). An interval with opposite end
/// slopes whose Hermite interpolant has exactly one critical point and
/// predicts `s(m)` so is taken to hold exactly one extremum, found by
/// bisection on the slope. Anything else is halved (depth limit
/// `BRACKET_DEPTH`, counted). Where `s(t)` is a cubic polynomial (every
/// affine cell: parallelepipeds, affine wedges and pyramids) the Hermite
/// interpolant is exact, so every extremum, and hence every breakpoint
/// crossing, is bracketed; for curved cells the stated assumption is that
/// an accepted interval, on which a cubic reproduces `s` and `s'` at three
/// points to that accuracy, hides no pair of extrema.
fn monotone_nodes(
    field: &mut IsoRay,
    t_in: f64,
    t_out: f64,
    stats: &mut NativeStats,
) -> Option<Vec<(f64, f64)>> {
    let mut nodes = Vec::new();
    let sample = |field: &mut IsoRay, t: f64| field.eval(t).map(|(s, d)| (t, s, d));
    let h = (t_out - t_in) / BRACKET_START as f64;
    let mut prev = sample(field, t_in)?;
    nodes.push((prev.0, prev.1));
    for k in 1..=BRACKET_START {
        let t = if k == BRACKET_START {
            t_out
        } else {
            t_in + h * k as f64
        };
        let next = sample(field, t)?;
        split_monotone(field, prev, next, 0, &mut nodes, stats)?;
        prev = next;
    }
    Some(nodes)
}

fn split_monotone(
    field: &mut IsoRay,
    a: Sample,
    b: Sample,
    depth: u32,
    nodes: &mut Vec<(f64, f64)>,
    stats: &mut NativeStats,
) -> Option<()> {
    let tm = 0.5 * (a.0 + b.0);
    if !(tm > a.0 && tm < b.0) {
        nodes.push((b.0, b.1));
        return Some(());
    }
    let m = field.eval(tm).map(|(s, d)| (tm, s, d))?;
    let scale = 1.0 + a.1.abs().max(b.1.abs());
    let tol = NATIVE_HERMITE_REL * (b.1 - a.1).abs() + NATIVE_HERMITE_ABS * scale;
    let h = b.0 - a.0;
    let secant = (b.1 - a.1) / h;
    let dtol = NATIVE_HERMITE_REL * (a.2.abs() + b.2.abs() + secant.abs())
        + NATIVE_HERMITE_ABS * scale / h;
    let cubic_ok =
        (hermite_mid(a, b) - m.1).abs() <= tol && (hermite_mid_slope(a, b) - m.2).abs() <= dtol;
    let pos = a.2 > 0.0 || m.2 > 0.0 || b.2 > 0.0;
    let neg = a.2 < 0.0 || m.2 < 0.0 || b.2 < 0.0;
    if cubic_ok && !(pos && neg) && !hermite_has_critical(a, b) {
        nodes.push((b.0, b.1));
        return Some(());
    }
    // Opposite end slopes: the interpolant's slope (a quadratic) has an odd
    // number of roots inside, i.e. exactly one.
    let opposite = (a.2 > 0.0 && b.2 < 0.0) || (a.2 < 0.0 && b.2 > 0.0);
    let one_extremum = cubic_ok && opposite;
    if one_extremum || depth >= BRACKET_DEPTH {
        if !one_extremum {
            stats.bracket_depth_limited += 1;
        }
        if opposite {
            let te = bisect(a.0, b.0, a.2, |t| field.eval(t).map(|v| v.1))?;
            let se = field.eval(te)?.0;
            nodes.push((te, se));
        }
        nodes.push((b.0, b.1));
        return Some(());
    }
    split_monotone(field, a, m, depth + 1, nodes, stats)?;
    split_monotone(field, m, b, depth + 1, nodes, stats)
}

/// The depths in `(t_in, t_out)` where `s(t)` crosses one of the sorted
/// `breakpoints`, in order (see [`monotone_nodes`] for the bracketing
/// guarantee); `None` when the map cannot be inverted somewhere.
pub fn breakpoint_crossings(
    field: &mut IsoRay,
    breakpoints: &[f64],
    t_in: f64,
    t_out: f64,
    stats: &mut NativeStats,
) -> Option<Vec<f64>> {
    let nodes = monotone_nodes(field, t_in, t_out, stats)?;
    node_crossings(field, &nodes, breakpoints)
}

/// [`breakpoint_crossings`] on the monotone pieces `nodes` (from
/// [`monotone_nodes`]): each breakpoint strictly inside a piece's scalar
/// range is bracketed there and found by bisection ([`piece_root`]).
fn node_crossings(
    field: &mut IsoRay,
    nodes: &[(f64, f64)],
    breakpoints: &[f64],
) -> Option<Vec<f64>> {
    let mut cuts = Vec::new();
    for w in nodes.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (lo, hi) = (a.1.min(b.1), a.1.max(b.1));
        let mut here = Vec::new();
        for &v in breakpoints {
            if v > lo && v < hi {
                here.push(piece_root(field, a, b, v)?);
            }
        }
        here.sort_by(f64::total_cmp);
        cuts.extend(here);
    }
    cuts.sort_by(f64::total_cmp);
    Some(cuts)
}

/// The depth where `s(t) = v` on the monotone piece from node `a` to node
/// `b` (`v` between their values): an end that has the value exactly, else
/// bisection of `s(t) - v`.
fn piece_root(field: &mut IsoRay, a: (f64, f64), b: (f64, f64), v: f64) -> Option<f64> {
    if a.1 == v {
        return Some(a.0);
    }
    if b.1 == v {
        return Some(b.0);
    }
    bisect(a.0, b.0, a.1 - v, |t| field.eval(t).map(|e| e.0 - v))
}

/// Integrates `[t_in, t_out]` through the iso-parametric field; `None` when
/// the map cannot be inverted.
pub fn integrate<M: RayMaterial>(
    field: &mut IsoRay,
    material: &M,
    t_in: f64,
    t_out: f64,
    stats: &mut NativeStats,
) -> Option<SegmentValue> {
    let mut cuts = vec![t_in];
    cuts.extend(breakpoint_crossings(
        field,
        material.breakpoints(),
        t_in,
        t_out,
        stats,
    )?);
    cuts.push(t_out);
    cuts.sort_by(f64::total_cmp);
    integrate_cuts(field, material, &cuts)
}

/// Integrates between consecutive depths of the sorted `cuts` (each part
/// smooth: inside one piece of the transfer function) and composites the
/// parts front to back.
fn integrate_cuts<M: RayMaterial>(
    field: &mut IsoRay,
    material: &M,
    cuts: &[f64],
) -> Option<SegmentValue> {
    let mut acc = SegmentValue::default();
    for w in cuts.windows(2) {
        if w[1] > w[0] {
            let (d, c) = piece(field, material, w[0], w[1])?;
            let tr = (-acc.depth).exp();
            for (a, ck) in acc.color.iter_mut().zip(c) {
                *a += tr * ck;
            }
            acc.depth += d;
        }
    }
    acc.alpha = -(-acc.depth).exp_m1();
    Some(acc)
}

type Piece = (f64, [f64; 3]);

fn colloc<M: RayMaterial>(field: &mut IsoRay, m: &M, a: f64, b: f64) -> Option<Piece> {
    let q = quadrature();
    let h = b - a;
    let mut tau = [0.0; GL_N];
    let mut g = [[0.0; 3]; GL_N];
    for i in 0..GL_N {
        let (s, _) = field.eval(a + h * q.x[i])?;
        let mat = m.material(s);
        tau[i] = mat.tau;
        g[i] = mat.source;
    }
    let mut depth = 0.0;
    let mut color = [0.0; 3];
    for i in 0..GL_N {
        depth += q.w[i] * tau[i];
        let di: f64 = h * (0..GL_N).map(|j| q.s[i][j] * tau[j]).sum::<f64>();
        let e = (-di).exp();
        for k in 0..3 {
            color[k] += q.w[i] * g[i][k] * e;
        }
    }
    Some((h * depth, color.map(|c| c * h)))
}

fn combine(l: Piece, r: Piece) -> Piece {
    let t = (-l.0).exp();
    (l.0 + r.0, std::array::from_fn(|k| l.1[k] + t * r.1[k]))
}

fn piece<M: RayMaterial>(field: &mut IsoRay, m: &M, a: f64, b: f64) -> Option<Piece> {
    let whole = colloc(field, m, a, b)?;
    refine(field, m, a, b, whole, 0)
}

fn refine<M: RayMaterial>(
    field: &mut IsoRay,
    m: &M,
    a: f64,
    b: f64,
    whole: Piece,
    level: u32,
) -> Option<Piece> {
    let mid = 0.5 * (a + b);
    let l = colloc(field, m, a, mid)?;
    let r = colloc(field, m, mid, b)?;
    let both = combine(l, r);
    let err = (both.0 - whole.0).abs().max(
        (0..3)
            .map(|k| (both.1[k] - whole.1[k]).abs())
            .fold(0.0, f64::max),
    );
    if err <= NATIVE_INTEGRAL_TOL || level >= MAX_LEVEL || !(mid > a && mid < b) {
        return Some(both);
    }
    let l = refine(field, m, a, mid, l, level + 1)?;
    let r = refine(field, m, mid, b, r, level + 1)?;
    Some(combine(l, r))
}

/// Integrates one native interval (clipped to `t >= t_near`): the
/// iso-parametric integral, or, when the map cannot be inverted inside, the
/// linear integral between the exact boundary scalars (counted).
pub fn interval_value<M: RayMaterial>(
    scene: &Scene,
    vals: &[f64],
    material: &M,
    ray: &Ray,
    iv: &Interval,
    t_near: f64,
    stats: &mut NativeStats,
) -> SegmentValue {
    let Some(cut) = ClippedInterval::new(scene, vals, iv, t_near, stats) else {
        return SegmentValue::default();
    };
    let (ta, tb) = (cut.ta, iv.t_b);
    let value = IsoRay::new(cut.kind, &cut.x, &cut.s, ray).and_then(|mut f| {
        let r = integrate(&mut f, material, ta, tb, stats);
        stats.newton_failures += f.failures;
        r
    });
    value.unwrap_or_else(|| {
        stats.fallback_intervals += 1;
        material.segment(tb - ta, cut.sa, iv.s_b)
    })
}

/// One native interval clipped to `t >= t_near`, with its cell's corners:
/// what [`interval_value`] and [`iso::interval_iso`] start from.
pub(super) struct ClippedInterval<'a> {
    /// The entry, moved to `t_near` when the interval starts before it.
    pub ta: f64,
    /// The scalar at `ta` (interpolated linearly when moved).
    pub sa: f64,
    /// Whether the entry was moved.
    pub clipped: bool,
    /// The cell's kind, nodes, corner points and corner scalars.
    pub kind: CellKind,
    pub nodes: &'a [u32],
    pub x: Vec<DVec3>,
    pub s: Vec<f64>,
}

impl<'a> ClippedInterval<'a> {
    /// `None` when nothing of positive length is left; otherwise counted
    /// in [`NativeStats::intervals`].
    pub(super) fn new(
        scene: &Scene<'a>,
        vals: &[f64],
        iv: &Interval,
        t_near: f64,
        stats: &mut NativeStats,
    ) -> Option<ClippedInterval<'a>> {
        let c = iv.cell as usize;
        let (mut ta, tb) = (iv.t_a, iv.t_b);
        let mut sa = iv.s_a;
        let clipped = ta < t_near;
        if clipped {
            let x = (t_near - ta) / (tb - ta);
            sa += x * (iv.s_b - sa);
            ta = t_near;
        }
        if (tb - ta).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        stats.intervals += 1;
        let cells = &scene.mesh.cells;
        let nodes = cells.nodes(c);
        Some(ClippedInterval {
            ta,
            sa,
            clipped,
            kind: cells.kinds[c],
            nodes,
            x: nodes
                .iter()
                .map(|&n| scene.mesh.points[n as usize])
                .collect(),
            s: nodes.iter().map(|&n| vals[n as usize]).collect(),
        })
    }
}

/// Point scalars of a scene (the native model's field), if any.
pub fn point_values<'a>(scene: &Scene<'a>) -> Option<&'a [f64]> {
    match scene.scalars {
        Scalars::Point(v) => Some(v),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_integrates_polynomials() {
        let q = quadrature();
        let sum: f64 = q.w.iter().sum();
        assert!((sum - 1.0).abs() < 1e-14);
        // integral_0^{x_i} of t^3 = x_i^4 / 4 through the Lagrange matrix.
        for i in 0..GL_N {
            let v: f64 = (0..GL_N).map(|j| q.s[i][j] * q.x[j].powi(3)).sum();
            assert!((v - q.x[i].powi(4) / 4.0).abs() < 1e-14);
        }
    }

    #[test]
    fn trilinear_inversion_recovers_a_point() {
        let x: Vec<DVec3> = [
            [0., 0., 0.],
            [1.2, 0., 0.1],
            [1., 1., 0.],
            [0., 0.9, 0.],
            [0., 0., 1.],
            [1., 0.1, 1.],
            [1.1, 1., 1.2],
            [0., 1., 1.],
        ]
        .iter()
        .map(|p| DVec3::from_array(*p))
        .collect();
        let s: Vec<f64> = x.iter().map(|p| p.x + 2.0 * p.y - p.z).collect();
        let ray = Ray::new(DVec3::new(0.3, 0.4, -1.0), DVec3::Z);
        let mut f = IsoRay::new(CellKind::Hexahedron, &x, &s, &ray).unwrap();
        let (v, dv) = f.eval(1.5).unwrap();
        // s is not exactly linear in x for a general hex, but the point maps
        // back: check via the forward map.
        let mut n = [0.0; 8];
        let mut dn = [DVec3::ZERO; 8];
        shape(CellKind::Hexahedron, f.xi, &mut n, &mut dn);
        let p: DVec3 = (0..8).map(|i| x[i] * n[i]).sum();
        assert!((p - DVec3::new(0.3, 0.4, 0.5)).length() < 1e-12);
        let sv: f64 = (0..8).map(|i| s[i] * n[i]).sum();
        assert!((sv - v).abs() < 1e-14 && dv.is_finite());
    }
}
