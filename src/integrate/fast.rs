//! Integral functions of a transfer function (Engel, Kraus, Ertl 2001,
//! section 3.5) for fast approximate table fills.
//!
//! `T(s) = int_{s_0}^{s} tau` and `K(s) = int_{s_0}^{s} g` with the source
//! `g = tau c` (glow) or `E` (independent emission) are exact for a
//! piecewise-linear transfer function (piecewise quadratic and cubic; each
//! piece integrated with Simpson's rule, which is exact for them). A segment
//! `(l, s_f, s_b)` is then approximated by
//!
//! ```text
//! tau_mean = (T(s_b) - T(s_f)) / (s_b - s_f)        alpha = 1 - exp(-l tau_mean)   (exact)
//! g_mean   = (K(s_b) - K(s_f)) / (s_b - s_f)
//! NoAttenuation:  C = l g_mean                      (EKE: ignores self-attenuation)
//! MeanGlow:       C = g_mean l (1 - exp(-l tau_mean)) / (l tau_mean)
//! ```
//!
//! `MeanGlow` is the extinction-weighted mean glow times the exact opacity
//! (docs/math.md 8.4): exact for a constant glow colour, bounded by the colour
//! range. Where `|s_b - s_f|` is below
//! [`INTEGRAL_FUNCTION_MIN_DS_REL`](crate::numeric::tolerance::INTEGRAL_FUNCTION_MIN_DS_REL)
//! times the table's scalar range, the difference quotients lose their digits
//! and the values at the midpoint scalar are used instead.

use crate::numeric::tolerance::ONE_MINUS_EXP_SERIES_X;
use crate::tf::{EmissionModel, TransferFunction};

/// Colour rule of the integral-function approximation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FastColour {
    /// `C = l (K_b - K_f)/(s_b - s_f)`: no attenuation inside the segment.
    NoAttenuation,
    /// Mean glow times exact opacity (bounded; the default).
    #[default]
    MeanGlow,
}

/// Exact integral functions `T` and `K` of a transfer function.
#[derive(Clone, Debug)]
pub struct IntegralFunctions {
    s: Vec<f64>,
    tau: Vec<f64>,
    src: Vec<[f64; 3]>,
    t_cum: Vec<f64>,
    k_cum: Vec<[f64; 3]>,
    glow: bool,
}

impl IntegralFunctions {
    /// Tabulates the cumulative integrals at the nodes.
    pub fn new(tf: &TransferFunction) -> Self {
        let s = tf.s.clone();
        let tau = tf.tau.clone();
        // Glow colour or emission; `glow` says whether tau multiplies it.
        let src = tf.col.clone();
        let glow = tf.model() == EmissionModel::Glow;
        let n = s.len();
        let mut t_cum = vec![0.0; n];
        let mut k_cum = vec![[0.0; 3]; n];
        for j in 1..n {
            let h = s[j] - s[j - 1];
            let (dt, dk) = piece_integral(h, tau[j - 1], tau[j], src[j - 1], src[j], glow);
            t_cum[j] = t_cum[j - 1] + dt;
            k_cum[j] = std::array::from_fn(|k| k_cum[j - 1][k] + dk[k]);
        }
        Self {
            s,
            tau,
            src,
            t_cum,
            k_cum,
            glow,
        }
    }

    /// `(T(s), K(s))`, exact.
    pub fn eval(&self, s: f64) -> (f64, [f64; 3]) {
        let glow = self.glow;
        let n = self.s.len();
        let idx = self.s.partition_point(|&x| x <= s);
        if idx == 0 {
            let h = s - self.s[0];
            let g = source(self.tau[0], self.src[0], glow);
            return (self.tau[0] * h, std::array::from_fn(|k| g[k] * h));
        }
        let j = idx - 1;
        if idx >= n {
            let h = s - self.s[n - 1];
            let g = source(self.tau[n - 1], self.src[n - 1], glow);
            return (
                self.t_cum[n - 1] + self.tau[n - 1] * h,
                std::array::from_fn(|k| self.k_cum[n - 1][k] + g[k] * h),
            );
        }
        let (s0, s1) = (self.s[j], self.s[j + 1]);
        let u = (s - s0) / (s1 - s0);
        let t1 = self.tau[j] + (self.tau[j + 1] - self.tau[j]) * u;
        let c0 = self.src[j];
        let c1: [f64; 3] = std::array::from_fn(|k| c0[k] + (self.src[j + 1][k] - c0[k]) * u);
        let (dt, dk) = piece_integral(s - s0, self.tau[j], t1, c0, c1, glow);
        (
            self.t_cum[j] + dt,
            std::array::from_fn(|k| self.k_cum[j][k] + dk[k]),
        )
    }
}

#[inline]
fn source(tau: f64, c: [f64; 3], glow: bool) -> [f64; 3] {
    if glow {
        [tau * c[0], tau * c[1], tau * c[2]]
    } else {
        c
    }
}

/// Integral of `tau` and of the source over one linear piece of width `h`
/// (Simpson: exact for the quadratic `tau c`).
#[inline]
fn piece_integral(
    h: f64,
    t0: f64,
    t1: f64,
    c0: [f64; 3],
    c1: [f64; 3],
    glow: bool,
) -> (f64, [f64; 3]) {
    let dt = 0.5 * h * (t0 + t1);
    let dk = if glow {
        let tm = 0.5 * (t0 + t1);
        std::array::from_fn(|k| {
            let cm = 0.5 * (c0[k] + c1[k]);
            h / 6.0 * (t0 * c0[k] + 4.0 * tm * cm + t1 * c1[k])
        })
    } else {
        std::array::from_fn(|k| 0.5 * h * (c0[k] + c1[k]))
    };
    (dt, dk)
}

/// `(1 - exp(-x)) / x`, stable at 0.
#[inline]
pub(crate) fn one_minus_exp_over(x: f64) -> f64 {
    if x < ONE_MINUS_EXP_SERIES_X {
        1.0 - 0.5 * x
    } else {
        -(-x).exp_m1() / x
    }
}

/// Approximate RGBA (premultiplied colour, opacity) from integral-function
/// values at the two ends: `(T_f, K_f)`, `(T_b, K_b)`; `mid` gives the point
/// values `(tau, g)` used when `|s_b - s_f| <= min_ds`.
#[inline]
pub(crate) fn approx_rgba(
    l: f64,
    ds: f64,
    ends: ((f64, [f64; 3]), (f64, [f64; 3])),
    mid: impl FnOnce() -> (f64, [f64; 3]),
    min_ds: f64,
    rule: FastColour,
) -> [f64; 4] {
    let (tau_mean, g_mean) = if ds.abs() > min_ds {
        let ((tf, kf), (tb, kb)) = ends;
        let inv = 1.0 / ds;
        (
            ((tb - tf) * inv).max(0.0),
            std::array::from_fn(|k| ((kb[k] - kf[k]) * inv).max(0.0)),
        )
    } else {
        mid()
    };
    let x = l * tau_mean;
    let alpha = -(-x).exp_m1();
    let f = match rule {
        FastColour::NoAttenuation => l,
        FastColour::MeanGlow => l * one_minus_exp_over(x),
    };
    [g_mean[0] * f, g_mean[1] * f, g_mean[2] * f, alpha]
}

/// Point values `(tau, source)` of the transfer function at `s`.
pub(crate) fn point_source(tf: &TransferFunction, s: f64) -> (f64, [f64; 3]) {
    let (tau, c) = tf.eval_piece(tf.piece_index(s), s);
    (tau, source(tau, c, tf.model() == EmissionModel::Glow))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tf::Node;

    #[test]
    fn integral_functions_match_quadrature() {
        let nodes = [
            Node {
                s: 0.0,
                tau: 1.0,
                color: [0.0, 1.0, 0.5],
                emission: [0.0; 3],
            },
            Node {
                s: 1.0,
                tau: 3.0,
                color: [1.0, 0.0, 0.5],
                emission: [0.0; 3],
            },
            Node {
                s: 1.0,
                tau: 0.5,
                color: [0.2, 0.2, 0.2],
                emission: [0.0; 3],
            },
            Node {
                s: 2.5,
                tau: 2.0,
                color: [0.9, 0.1, 0.4],
                emission: [0.0; 3],
            },
        ];
        let tf = TransferFunction::from_nodes(&nodes, EmissionModel::Glow).unwrap();
        let f = IntegralFunctions::new(&tf);
        // Midpoint-rule reference with many steps.
        let (a, b) = (-0.5, 3.0);
        let m = 350_000; // cell edges on the jump at s = 1
        let (mut t, mut k) = (0.0, [0.0; 3]);
        for i in 0..m {
            let s = a + (b - a) * (i as f64 + 0.5) / m as f64;
            let (tau, g) = point_source(&tf, s);
            t += tau * (b - a) / m as f64;
            for c in 0..3 {
                k[c] += g[c] * (b - a) / m as f64;
            }
        }
        let (ta, ka) = f.eval(a);
        let (tb, kb) = f.eval(b);
        assert!(((tb - ta) - t).abs() < 1e-6, "{} {}", tb - ta, t);
        for c in 0..3 {
            assert!(((kb[c] - ka[c]) - k[c]).abs() < 1e-6);
        }
    }
}
