//! Basis integrals of one linear sub-segment: the closed form and regime
//! selection of docs/math.md sections 3 and 4.
//!
//! A sub-segment of length `l` has extinction linear from `tau_f` (front) to
//! `tau_b` (back); with `a = tau_f l`, `b = tau_b l`, `x in [0, 1]` and the
//! optical depth `D(x) = a x + (b - a) x^2 / 2`, everything a renderer needs
//! is a combination of five non-negative integrals of `exp(-D)`:
//!
//! ```text
//! psi   = int exp(-D)            phi_f = int (1-x) exp(-D)    phi_b = int x exp(-D)
//! w_f   = int (1-x) D' exp(-D)   w_b   = int x D' exp(-D)     (w_f = 1 - psi, w_b = psi - T)
//! glow:      C = c_f w_f + c_b w_b          emission:  C = l (E_f phi_f + E_b phi_b)
//! ```
//!
//! Regimes (docs/math.md section 4.2):
//! * `max(a, b) <= 2`: 12-point Gauss-Legendre over positive integrands, no
//!   cancellation at any depth down to subnormals (error ~5e-16); 8 points
//!   for `max(a, b) <= 1/2`, where they are as accurate (a speed refinement of
//!   the closed form there, checked by the golden and stress tests);
//! * `a == b`: constant extinction, `expm1` forms;
//! * `b > a`: scaled complementary error function `P = sqrt(pi) erfcx` and
//!   `Q = 1 - uP`; `b < a`: `B = 2 Dawson`, `G = 1 - vB`. For arguments up to
//!   8 both are Taylor series about the nearest tabulated centre `k/16` (the
//!   516 constants in `tables_sf.rs`), above 8 scaled asymptotic series that
//!   never overflow (so `tau_f ~ tau_b` and depths of 1e6 are harmless).

use super::tables_sf::{GL12, GL8, SF_TABLE};
use crate::numeric::tolerance::{
    GAUSS_LEGENDRE_8_MAX_DEPTH, GAUSS_LEGENDRE_MAX_DEPTH, SERIES_SUM_FLOOR, SERIES_TRUNCATION_REL,
};

/// Above this argument the special functions use their asymptotic series.
const ASYM_X: f64 = 8.0;
/// Spacing of the tabulated centres.
const H_INV: f64 = 16.0;
/// Optical thicknesses are clamped here so `inf * 0` can never appear
/// (`exp(-1e300)` is already exactly zero).
const MAX_THICKNESS: f64 = 1e300;

/// Which formula evaluated a sub-segment (for tests and diagnostics).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Regime {
    /// 12-point Gauss-Legendre, `max(a, b) <= 2`.
    Small,
    /// Constant extinction `a == b`.
    Constant,
    /// Increasing extinction (`erfcx` family).
    Erfcx,
    /// Decreasing extinction (Dawson family).
    Dawson,
}

/// The basis integrals of one linear sub-segment (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    pub psi: f64,
    pub phi_f: f64,
    pub phi_b: f64,
    pub w_f: f64,
    pub w_b: f64,
    /// Opacity `1 - exp(-(a + b)/2)`.
    pub alpha: f64,
    /// Transmittance `exp(-(a + b)/2)`.
    pub t: f64,
    pub regime: Regime,
}

/// `1 / (n + 1)` for the Taylor recurrences (a multiply instead of a
/// divide in the inner loops).
const INV: [f64; 64] = {
    let mut t = [0.0; 64];
    let mut n = 0;
    while n < 64 {
        t[n] = 1.0 / (n as f64 + 1.0);
        n += 1;
    }
    t
};

/// `(P(x), Q(x))` for `0 <= x <= 8`: Taylor series about the nearest centre.
#[inline]
fn taylor_pq(x: f64) -> (f64, f64) {
    let k = ((x * H_INV + 0.5) as usize).min(SF_TABLE.len() - 1);
    let x0 = k as f64 / H_INV;
    let dl = x - x0;
    let [p0, q0, _, _] = SF_TABLE[k];
    let (mut pm1, mut p) = (p0, -2.0 * q0);
    let mut sp = p0 + p * dl;
    let mut sq = q0 + (-x0 * p - p0) * dl;
    let mut dn = dl;
    let mut n = 1;
    while n < 60 {
        let pn1 = (2.0 * x0 * p + 2.0 * pm1) * INV[n];
        dn *= dl;
        let tp = pn1 * dn;
        let tq = (-x0 * pn1 - p) * dn;
        sp += tp;
        sq += tq;
        pm1 = p;
        p = pn1;
        n += 1;
        if tp.abs() <= SERIES_TRUNCATION_REL * sp.abs()
            && tq.abs() <= SERIES_TRUNCATION_REL * sq.abs()
        {
            break;
        }
    }
    (sp, sq)
}

/// `(B(x), G(x))` for `0 <= x <= 8`: Taylor series about the nearest centre.
#[inline]
fn taylor_bg(x: f64) -> (f64, f64) {
    let k = ((x * H_INV + 0.5) as usize).min(SF_TABLE.len() - 1);
    let x0 = k as f64 / H_INV;
    let dl = x - x0;
    let [_, _, b0, g0] = SF_TABLE[k];
    let (mut bm1, mut b) = (b0, 2.0 * g0);
    let mut sb = b0 + b * dl;
    let mut sg = g0 + (-x0 * b - b0) * dl;
    let mut dn = dl;
    let mut n = 1;
    while n < 60 {
        let bn1 = (-2.0 * x0 * b - 2.0 * bm1) * INV[n];
        dn *= dl;
        let tb = bn1 * dn;
        let tg = (-x0 * bn1 - b) * dn;
        sb += tb;
        sg += tg;
        bm1 = b;
        b = bn1;
        n += 1;
        if tb.abs() <= SERIES_TRUNCATION_REL * sb.abs()
            && tg.abs() <= SERIES_TRUNCATION_REL * sg.abs().max(SERIES_SUM_FLOOR)
        {
            break;
        }
    }
    (sb, sg)
}

/// Scaled asymptotic series: `S = sum sign^k (2k-1)!! t^k`,
/// `q = sum sign^k (2k+1)!! t^k`.
#[inline]
fn asym(t: f64, sign: f64) -> (f64, f64) {
    let mut s = 1.0;
    let mut q = 1.0;
    let mut term = 1.0;
    let mut qterm = 1.0;
    for k in 1..40 {
        let kf = k as f64;
        term *= sign * (2.0 * kf - 1.0) * t;
        s += term;
        if k >= 2 {
            qterm *= sign * (2.0 * kf - 1.0) * t;
            q += qterm;
        }
        if term.abs() < SERIES_TRUNCATION_REL && qterm.abs() < SERIES_TRUNCATION_REL {
            break;
        }
    }
    (s, q)
}

/// `sqrt(pi) erfcx(x)` for `x >= 0` (portable, ~5e-16 relative).
pub fn sqrtpi_erfcx(x: f64) -> f64 {
    if x <= ASYM_X {
        taylor_pq(x).0
    } else {
        asym(0.5 / (x * x), -1.0).0 / x
    }
}

/// `2 Dawson(x)` for `x >= 0` (portable, ~5e-16 relative).
pub fn two_dawson(x: f64) -> f64 {
    if x <= ASYM_X {
        taylor_bg(x).0
    } else {
        asym(0.5 / (x * x), 1.0).0 / x
    }
}

/// Endpoint helper, increasing extinction: `(X, Y) = (P(u)/r, Q(u)/d)`.
#[inline]
fn ends_increasing(c: f64, r: f64, d: f64) -> (f64, f64) {
    let u = c / r;
    if u <= ASYM_X {
        let (p, q) = taylor_pq(u);
        (p / r, q / d)
    } else {
        let (s, q) = asym(d / (c * c), -1.0);
        (s / c, q / (c * c))
    }
}

/// Endpoint helper, decreasing extinction: `(X, Y) = (B(v)/r, -G(v)/e)`.
#[inline]
fn ends_decreasing(c: f64, r: f64, e: f64) -> (f64, f64) {
    let v = c / r;
    if v <= ASYM_X {
        let (b, g) = taylor_bg(v);
        (b / r, -g / e)
    } else {
        let (s, q) = asym(e / (c * c), 1.0);
        (s / c, q / (c * c))
    }
}

/// Basis integrals for optical thicknesses `a = tau_f l`, `b = tau_b l`.
///
/// Negative or NaN thicknesses are treated as 0 and infinite ones as 1e300,
/// so the result is always finite.
pub fn weights(a: f64, b: f64) -> Weights {
    let a = sanitize(a);
    let b = sanitize(b);
    let d1 = 0.5 * (a + b);
    if a.max(b) <= GAUSS_LEGENDRE_MAX_DEPTH {
        // One transcendental: T = 1 - alpha is accurate here (T >= e^-2).
        let alpha = -(-d1).exp_m1();
        let t = 1.0 - alpha;
        // Positive integrands only: no cancellation for any a, b >= 0.
        let rule: &[(f64, f64)] = if a.max(b) <= GAUSS_LEGENDRE_8_MAX_DEPTH {
            &GL8
        } else {
            &GL12
        };
        let [wf, wb, pf, pb] = gauss(a, b, rule);
        return Weights {
            psi: pf + pb,
            phi_f: pf,
            phi_b: pb,
            w_f: wf,
            w_b: wb,
            alpha,
            t,
            regime: Regime::Small,
        };
    }
    // Here d1 > 1, so alpha = 1 - T loses nothing (alpha > 0.63).
    let t = (-d1).exp();
    let alpha = 1.0 - t;
    let (psi, phi_b, regime) = if a == b {
        let em = -(-a).exp_m1();
        let psi = em / a;
        let phi_b = (em - a * (-a).exp()) / (a * a);
        (psi, phi_b, Regime::Constant)
    } else if b > a {
        let d = b - a;
        let r = (2.0 * d).sqrt();
        let (xf, yf) = ends_increasing(a, r, d);
        let (xb, yb) = ends_increasing(b, r, d);
        (xf - t * xb, yf - t * yb - t * xb, Regime::Erfcx)
    } else {
        let e = a - b;
        let r = (2.0 * e).sqrt();
        let (xf, yf) = ends_decreasing(a, r, e);
        let (xb, yb) = ends_decreasing(b, r, e);
        (xf - t * xb, yf - t * yb - t * xb, Regime::Dawson)
    };
    Weights {
        psi,
        phi_f: psi - phi_b,
        phi_b,
        w_f: 1.0 - psi,
        w_b: psi - t,
        alpha,
        t,
        regime,
    }
}

/// `[w_f, w_b, phi_f, phi_b]` by a Gauss-Legendre rule on [0, 1]:
/// positive integrands only, so no cancellation for any `a, b >= 0`.
#[inline]
fn gauss(a: f64, b: f64, rule: &[(f64, f64)]) -> [f64; 4] {
    let (mut wf, mut wb, mut pf, mut pb) = (0.0, 0.0, 0.0, 0.0);
    for &(x, w) in rule {
        let y = 1.0 - x;
        let dx = x * (a * (1.0 - 0.5 * x) + b * (0.5 * x));
        let dp = a * y + b * x;
        let e = w * (-dx).exp();
        let ed = e * dp;
        wf += y * ed;
        wb += x * ed;
        pf += y * e;
        pb += x * e;
    }
    [wf, wb, pf, pb]
}

#[inline]
fn sanitize(x: f64) -> f64 {
    if x > 0.0 {
        x.min(MAX_THICKNESS)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_functions_at_table_centres_and_limits() {
        // P(0) = sqrt(pi), B(0) = 0; asymptotics x P(x) -> 1, x B(x) -> 1.
        assert_eq!(sqrtpi_erfcx(0.0), 1.772453850905516);
        assert_eq!(two_dawson(0.0), 0.0);
        assert!((sqrtpi_erfcx(1e6) * 1e6 - 1.0).abs() < 1e-11);
        assert!((two_dawson(1e6) * 1e6 - 1.0).abs() < 1e-11);
        // Continuity across the asymptotic switch.
        let (lo, hi) = (8.0, f64::from_bits(8.0f64.to_bits() + 1));
        assert!((sqrtpi_erfcx(lo) / sqrtpi_erfcx(hi) - 1.0).abs() < 1e-14);
        assert!((two_dawson(lo) / two_dawson(hi) - 1.0).abs() < 1e-14);
        // Dawson maximum F(0.9241388730) = 0.5410442246.
        assert!((two_dawson(0.924_138_873_0) - 2.0 * 0.541_044_224_6).abs() < 1e-9);
    }

    #[test]
    fn eight_nodes_match_twelve_below_depth_one_half() {
        let mut worst = 0.0f64;
        for i in 0..=40 {
            for j in 0..=40 {
                let (a, b) = (i as f64 / 80.0, j as f64 / 80.0);
                let g8 = gauss(a, b, &GL8);
                let g12 = gauss(a, b, &GL12);
                for k in 0..4 {
                    if g12[k] > 0.0 {
                        let e = (g8[k] - g12[k]).abs() / g12[k];
                        worst = worst.max(e);
                    }
                }
            }
        }
        assert!(worst < 1e-15, "{worst:e}");
    }

    #[test]
    fn weights_identities_hold_in_every_regime() {
        for &(a, b) in &[
            (0.5, 1.5),
            (3.0, 3.0),
            (1.0, 9.0),
            (9.0, 1.0),
            (1e4, 2e4),
            (0.0, 0.0),
        ] {
            let w = weights(a, b);
            assert!((w.w_f + w.w_b - w.alpha).abs() < 1e-14, "{a} {b}");
            assert!((w.phi_f + w.phi_b - w.psi).abs() < 1e-14);
            assert!(w.t <= w.psi + 1e-15 && w.psi <= 1.0 + 1e-15);
            assert!(w.phi_b <= w.phi_f + 1e-15);
        }
        assert_eq!(weights(f64::NAN, -1.0).alpha, 0.0);
        assert!(weights(f64::INFINITY, 1.0).psi.is_finite());
    }
}
