//! The 2D exponential table `alpha(l, tau) = 1 - exp(-l tau)` and its CPU twin.
//!
//! MWS (section II) looks the opacity up in a 2D texture addressed by the
//! interpolated thickness `l` and mean extinction `tau`. Both axes here use the
//! same warp, linear near zero and logarithmic beyond, so that texel density
//! follows the optical depth over many decades:
//!
//! ```text
//! s(x) = ln(1 + x X) / ln(1 + X^2),   X = AXIS_MAX = 1e6,   s in [0, 1]
//! ```
//!
//! (`x` is `l / unit` or `tau * unit` for the frame's length unit, see
//! [`super::ExactParams`]). Texel `i` of `N` sits at
//! `s = i / (N - 1)`, i.e. at `x_i = expm1(s_i ln(1 + X^2)) / X`, and stores
//! `1 - exp(-x_i x_j)` (computed in f64, stored as f32; the table is symmetric).
//! The shader reads the four neighbours from the table's storage buffer
//! and filters them bilinearly in f32 itself, so the result does not depend on a GPU's
//! fixed-point filter weights and [`ExpTable::alpha_of`] reproduces it.
//!
//! * Range: each of `l'`, `tau'` in `[0, 1e6]`; optical depths from below
//!   1e-12 (the linear region, where `alpha ~ l tau` keeps its relative
//!   accuracy) up to opaque.
//! * Clamping: a coordinate beyond `AXIS_MAX` clamps to the last texel, so
//!   `alpha = 1 - exp(-min(l', X) min(tau', X))`; negative or NaN inputs are
//!   treated as 0 (alpha 0).
//! * Resolution and error: N = 1024 (4 MiB, R32Float). In log space a texel
//!   spans `h = ln(1 + 1e12) / 1023 = 0.027`; bilinear filtering of
//!   `1 - exp(-e^(a + b))` then errs by about `0.07 h^2`. Measured maximum
//!   absolute error against the exact f64 value (`ExpTable::max_error_in`,
//!   2000^2 log-spaced samples): 5.7e-5 for `l', tau'` in `[1e-3, 1e3]`,
//!   9.5e-5 over the whole range (worst at skewed extremes such as
//!   `l' = 2e-6, tau' = 1e6`, where one axis crosses from the linear to the
//!   logarithmic part of the warp); bound used by tests:
//!   [`crate::numeric::tolerance::EXP_TABLE_MAX_ABS_ERROR`]. (N = 512: 3.9e-4,
//!   N = 2048: 2.4e-5.) Thin layers keep their relative accuracy (< 1e-3,
//!   measured ~1e-4) while both `l'` and `tau'` are above the first texel,
//!   `x_1 = 2.7e-8`; below it the relative error grows to `h / 2 = 1.4%` of an
//!   opacity that is then below `2.7e-8 * max(l', tau')`.

/// Per-axis maximum of the normalised coordinates `l'` and `tau'`.
pub const AXIS_MAX: f64 = 1e6;

/// Texels per axis of the table the compositor uses.
pub const TABLE_N: u32 = 1024;

/// Below this argument the shader and the twin use a 3-term series for
/// `ln(1 + z)` (f32 `ln(1 + z)` loses the relative accuracy of tiny `z`).
pub const LOG1P_SERIES_BELOW: f32 = 1e-3;

/// `ln(1 + X^2)`: the log-space length of one axis.
pub fn log_range() -> f64 {
    (AXIS_MAX * AXIS_MAX).ln_1p()
}

/// The warp's scale and reciprocal range as the shader receives them:
/// `(X, 1 / ln(1 + X^2))` in f32.
pub fn shader_params() -> (f32, f32) {
    (AXIS_MAX as f32, (1.0 / log_range()) as f32)
}

/// The exponential table (row-major, `n * n` values).
#[derive(Clone, Debug, PartialEq)]
pub struct ExpTable {
    n: u32,
    data: Vec<f32>,
}

impl ExpTable {
    /// Builds an `n x n` table (`n` is raised to at least 2).
    pub fn new(n: u32) -> ExpTable {
        let n = n.max(2);
        let xs: Vec<f64> = (0..n).map(|i| axis_value(i, n)).collect();
        let mut data = Vec::with_capacity(n as usize * n as usize);
        for &y in &xs {
            for &x in &xs {
                data.push((-(-(x * y)).exp_m1()) as f32);
            }
        }
        ExpTable { n, data }
    }

    /// Texels per axis.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// The values, row-major (row = tau axis, column = l axis).
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Twin of `texel`: value `(i, j)` (`i` along the length).
    pub fn texel(&self, i: u32, j: u32) -> f32 {
        self.data
            .get(j as usize * self.n as usize + i as usize)
            .copied()
            .unwrap_or(1.0)
    }

    /// The CPU twin of `alpha_of` in `shaders/exact.wgsl`: the same f32
    /// operations (warp, clamp, four loads, bilinear `mix`).
    pub fn alpha_of(&self, l: f32, tau: f32) -> f32 {
        let (scale, inv_range) = shader_params();
        let u = coord(l, scale, inv_range, self.n);
        let v = coord(tau, scale, inv_range, self.n);
        let i0 = (u as u32).min(self.n - 2);
        let j0 = (v as u32).min(self.n - 2);
        let fu = u - i0 as f32;
        let fv = v - j0 as f32;
        let mix = |a: f32, b: f32, t: f32| a * (1.0 - t) + b * t;
        let r0 = mix(self.texel(i0, j0), self.texel(i0 + 1, j0), fu);
        let r1 = mix(self.texel(i0, j0 + 1), self.texel(i0 + 1, j0 + 1), fu);
        mix(r0, r1, fv)
    }

    /// Maximum absolute error of [`Self::alpha_of`] against the exact
    /// `1 - exp(-l tau)` over the whole range: [`Self::max_error_in`] over
    /// `[1e-8, 1e6]` for both axes.
    pub fn max_error(&self, k: u32) -> (f64, f32, f32) {
        self.max_error_in(k, 1e-8, 1e6)
    }

    /// Maximum absolute error over a grid of `k x k` values of `l` and `tau`
    /// (zero, then log-spaced over `[lo, hi]`, offset so that samples fall
    /// between texels). Returns `(error, l, tau)` at the worst point.
    pub fn max_error_in(&self, k: u32, lo: f64, hi: f64) -> (f64, f32, f32) {
        let k = k.max(2);
        let vals: Vec<f32> = std::iter::once(0.0)
            .chain((0..k - 1).map(|i| {
                let t = (i as f64 + 0.37) / (k - 1) as f64;
                (lo * (hi / lo).powf(t)) as f32
            }))
            .collect();
        let mut worst = (0.0, 0.0, 0.0);
        for &l in &vals {
            for &tau in &vals {
                let exact = exact_alpha(l as f64, tau as f64);
                let e = (self.alpha_of(l, tau) as f64 - exact).abs();
                if e > worst.0 {
                    worst = (e, l, tau);
                }
            }
        }
        worst
    }
}

/// Axis value `x_i` of texel `i` in an `n`-texel table.
pub fn axis_value(i: u32, n: u32) -> f64 {
    let s = i as f64 / (n.max(2) - 1) as f64;
    (s * log_range()).exp_m1() / AXIS_MAX
}

/// Twin of `log1p_` in `shaders/exact.wgsl`: `ln(1 + z)` as the shader
/// computes it (f32).
pub fn log1p_(z: f32) -> f32 {
    if z < LOG1P_SERIES_BELOW {
        z * (1.0 - z * (0.5 - z * (1.0 / 3.0)))
    } else {
        (1.0 + z).ln()
    }
}

/// Twin of `coord` in `shaders/exact.wgsl`: the continuous texel
/// coordinate in `[0, n - 1]` of a normalised value
/// (negative and NaN map to 0, beyond `AXIS_MAX` clamps to `n - 1`).
pub fn coord(x: f32, scale: f32, inv_range: f32, n: u32) -> f32 {
    let xs = if x > 0.0 { x } else { 0.0 };
    let s = log1p_(xs * scale) * inv_range;
    s.min(1.0) * (n - 1) as f32
}

/// Exact opacity `1 - exp(-l tau)` in f64.
pub fn exact_alpha(l: f64, tau: f64) -> f64 {
    -(-(l * tau)).exp_m1()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[ignore]
    fn print_error_by_size() {
        for n in [256, 512, 1024, 2048] {
            let t = ExpTable::new(n);
            let (e, l, tau) = t.max_error(2000);
            println!("n {n}: max abs error {e:.3e} at l {l:.3e} tau {tau:.3e}");
            let (e, l, tau) = t.max_error_in(2000, 1e-3, 1e3);
            println!("  in [1e-3, 1e3]^2: {e:.3e} at l {l:.3e} tau {tau:.3e}");
        }
    }

    #[test]
    fn exptable_error_is_bounded() {
        let (e, l, tau) = ExpTable::new(TABLE_N).max_error(300);
        assert!(
            e <= crate::numeric::tolerance::EXP_TABLE_MAX_ABS_ERROR,
            "{e:.3e} at l {l:.3e} tau {tau:.3e}"
        );
        // Not a loose bound: the error is measurably there.
        assert!(e > 1e-6);
    }

    #[test]
    fn texel_centres_are_exact() {
        let t = ExpTable::new(64);
        for (i, j) in [(0, 0), (5, 40), (63, 63), (20, 31)] {
            let x = axis_value(i, 64) as f32;
            let y = axis_value(j, 64) as f32;
            let want = exact_alpha(x as f64, y as f64);
            assert!((t.alpha_of(x, y) as f64 - want).abs() < 2e-6 * want.max(1e-3));
        }
    }

    #[test]
    fn clamps_and_sanitises() {
        let t = ExpTable::new(TABLE_N);
        assert_eq!(t.alpha_of(0.0, 5.0), 0.0);
        assert_eq!(t.alpha_of(f32::NAN, 5.0), 0.0);
        assert_eq!(t.alpha_of(-1.0, 5.0), 0.0);
        assert!((t.alpha_of(1e9, 1.0) - 1.0).abs() < 1e-6);
        assert!((t.alpha_of(f32::INFINITY, f32::INFINITY) - 1.0).abs() < 1e-6);
        // Beyond AXIS_MAX the coordinate clamps: 1 - exp(-1e6 * 1e-7).
        let want = exact_alpha(1e6, 1e-7);
        assert!((t.alpha_of(1e8, 1e-7) as f64 - want).abs() < 1e-4);
    }

    #[test]
    fn thin_layers_keep_relative_accuracy() {
        let t = ExpTable::new(TABLE_N);
        for d in [1e-9f64, 1e-7, 1e-5, 1e-4, 1e-3] {
            for l in [1e-3f64, 1e-2, 1.0, 1e3] {
                let tau = d / l;
                if tau < 1e-6 {
                    continue;
                }
                let got = t.alpha_of(l as f32, tau as f32) as f64;
                let rel = (got - exact_alpha(l, tau)).abs() / exact_alpha(l, tau);
                assert!(rel < 1e-3, "depth {d} l {l}: rel {rel:.2e}");
            }
        }
    }
}
