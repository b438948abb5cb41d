//! ParaView colour-map import and colour-space resampling.
//!
//! A ParaView colour-map file is a JSON array of objects (the first is used)
//! or one object, with `RGBPoints: [x, r, g, b, ...]`, optional opacity
//! `Points: [x, o, midpoint, sharpness, ...]` and `ColorSpace`.
//!
//! * `ColorSpace` `RGB` (or absent): used as is. `Lab`, `Diverging`, `HSV`
//!   (also `Lab/CIEDE2000`, `Step`): each interval is resampled into
//!   [`PIECES_PER_INTERVAL`] linear RGB pieces of the colour that VTK's
//!   `vtkColorTransferFunction` interpolates in that space (CIE-Lab with
//!   the sRGB curve, Moreland's Msh diverging rule, HSV the short way round;
//!   `Step` becomes jumps). The result is therefore piecewise linear, as the
//!   exact integrals need, within about 1e-3 of ParaView's colours.
//! * Opacity points with midpoint 0.5 and sharpness 0 are linear and used
//!   exactly; any other midpoint/sharpness is approximated by resampling
//!   the interval into [`PIECES_PER_INTERVAL`] linear pieces of VTK's
//!   midpoint/sharpness curve.
//! * Without `Points` the opacity is a linear ramp 0 -> 1 over the colour
//!   points' range (what ParaView shows for a fresh colour map).
//!
//! Extinction = opacity / unit distance, glow emission.

use serde::Deserialize;

use super::{EmissionModel, TfError, TransferFunction};
use crate::numeric::tolerance::PARAVIEW_MIDPOINT_CLAMP;

/// Linear pieces per interval when a non-linear interpolation is resampled.
pub const PIECES_PER_INTERVAL: usize = 32;

/// Colour interpolation spaces of ParaView.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    Rgb,
    Lab,
    Diverging,
    Hsv,
    Step,
}

impl ColorSpace {
    fn parse(s: &str) -> Result<Self, TfError> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "rgb" => Self::Rgb,
            "lab" | "lab/ciede2000" | "ciede2000" => Self::Lab,
            "diverging" => Self::Diverging,
            "hsv" => Self::Hsv,
            "step" => Self::Step,
            other => return Err(TfError::Format(format!("unknown ColorSpace {other:?}"))),
        })
    }
}

#[derive(Deserialize)]
struct PvMap {
    #[serde(rename = "RGBPoints")]
    rgb_points: Option<Vec<f64>>,
    #[serde(rename = "Points")]
    points: Option<Vec<f64>>,
    #[serde(rename = "ColorSpace")]
    color_space: Option<String>,
    #[serde(rename = "Name")]
    name: Option<String>,
}

/// Parses a ParaView colour-map JSON value (array or object).
pub(crate) fn from_value(
    v: serde_json::Value,
    unit_distance: f64,
) -> Result<TransferFunction, TfError> {
    let obj = match v {
        serde_json::Value::Array(mut a) => {
            if a.is_empty() {
                return Err(TfError::Empty);
            }
            a.swap_remove(0)
        }
        o => o,
    };
    let map: PvMap = serde_json::from_value(obj)?;
    let _ = map.name;
    let rgb = map
        .rgb_points
        .ok_or_else(|| TfError::Format("ParaView colour map without RGBPoints".into()))?;
    if rgb.is_empty() {
        return Err(TfError::Empty);
    }
    if rgb.len() % 4 != 0 {
        return Err(TfError::Format(format!(
            "RGBPoints has {} numbers, not a multiple of 4 (x, r, g, b)",
            rgb.len()
        )));
    }
    let colours: Vec<(f64, [f64; 3])> = rgb
        .chunks_exact(4)
        .map(|c| (c[0], [c[1], c[2], c[3]]))
        .collect();
    check_points("RGBPoints", colours.iter().map(|c| c.0))?;
    let space = match &map.color_space {
        Some(s) => ColorSpace::parse(s)?,
        None => ColorSpace::Rgb,
    };
    let colours = resample_colors(&colours, space, PIECES_PER_INTERVAL);
    let opacity: Vec<(f64, [f64; 1])> = match map.points {
        Some(p) if !p.is_empty() => {
            if p.len() % 4 != 0 {
                return Err(TfError::Format(format!(
                    "Points has {} numbers, not a multiple of 4 (x, opacity, midpoint, sharpness)",
                    p.len()
                )));
            }
            let pts: Vec<[f64; 4]> = p
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect();
            check_points("Points", pts.iter().map(|c| c[0]))?;
            for (i, q) in pts.iter().enumerate() {
                if !(0.0..=1.0).contains(&q[1]) {
                    return Err(TfError::OpacityRange {
                        what: "Points",
                        index: i,
                        value: q[1],
                    });
                }
            }
            resample_opacity(&pts)
        }
        _ => {
            let (lo, hi) = (colours[0].0, colours[colours.len() - 1].0);
            vec![(lo, [0.0]), (hi, [1.0])]
        }
    };
    let tau: Vec<(f64, [f64; 1])> = opacity
        .iter()
        .map(|&(s, [o])| (s, [o / unit_distance]))
        .collect();
    let mut tf = TransferFunction::from_channels(&tau, &colours, None, EmissionModel::Glow)?;
    tf.unit_distance = Some(unit_distance);
    Ok(tf)
}

fn check_points(what: &'static str, xs: impl Iterator<Item = f64>) -> Result<(), TfError> {
    let mut prev = f64::NEG_INFINITY;
    for (index, x) in xs.enumerate() {
        if !x.is_finite() {
            return Err(TfError::NonFiniteScalar { what, index });
        }
        if x < prev {
            return Err(TfError::Unsorted {
                what,
                index,
                value: x,
                previous: prev,
            });
        }
        prev = x;
    }
    Ok(())
}

/// Resamples colour points interpolated in `space` into linear RGB pieces
/// (`pieces` per interval; RGB input is returned unchanged).
pub(crate) fn resample_colors(
    p: &[(f64, [f64; 3])],
    space: ColorSpace,
    pieces: usize,
) -> Vec<(f64, [f64; 3])> {
    if space == ColorSpace::Rgb || p.len() < 2 {
        return p.to_vec();
    }
    let mut out = Vec::with_capacity(p.len() * (pieces + 1));
    out.push(p[0]);
    for w in p.windows(2) {
        let ((x0, c0), (x1, c1)) = (w[0], w[1]);
        if x1 == x0 {
            out.push(w[1]);
            continue;
        }
        if space == ColorSpace::Step {
            out.push((x1, c0));
            out.push((x1, c1));
            continue;
        }
        for k in 1..=pieces {
            let t = k as f64 / pieces as f64;
            let x = if k == pieces { x1 } else { x0 + (x1 - x0) * t };
            let c = if k == pieces {
                c1
            } else {
                interpolate(c0, c1, t, space)
            };
            out.push((x, c.map(|v| v.clamp(0.0, 1.0))));
        }
    }
    // A Step map can produce three points at one scalar; keep the outer two.
    out.dedup_by(|b, a| a.0 == b.0 && a.1 == b.1);
    let mut merged: Vec<(f64, [f64; 3])> = Vec::with_capacity(out.len());
    for q in out {
        let n = merged.len();
        if n >= 2 && merged[n - 1].0 == q.0 && merged[n - 2].0 == q.0 {
            merged[n - 1] = q;
        } else {
            merged.push(q);
        }
    }
    merged
}

fn interpolate(c0: [f64; 3], c1: [f64; 3], t: f64, space: ColorSpace) -> [f64; 3] {
    match space {
        ColorSpace::Rgb | ColorSpace::Step => std::array::from_fn(|k| c0[k] + (c1[k] - c0[k]) * t),
        ColorSpace::Lab => {
            let (a, b) = (rgb_to_lab(c0), rgb_to_lab(c1));
            lab_to_rgb(std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t))
        }
        ColorSpace::Hsv => {
            let (a, b) = (rgb_to_hsv(c0), rgb_to_hsv(c1));
            let mut dh = b[0] - a[0];
            if dh > 0.5 {
                dh -= 1.0;
            } else if dh < -0.5 {
                dh += 1.0;
            }
            let h = (a[0] + dh * t).rem_euclid(1.0);
            hsv_to_rgb([h, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t])
        }
        ColorSpace::Diverging => diverging(c0, c1, t),
    }
}

/// VTK's midpoint/sharpness curve between opacities `v1` and `v2`
/// (`vtkPiecewiseFunction`), `x in [0, 1]`.
fn midpoint_sharpness(v1: f64, v2: f64, x: f64, mid: f64, sharp: f64) -> f64 {
    let mid = mid.clamp(PARAVIEW_MIDPOINT_CLAMP, 1.0 - PARAVIEW_MIDPOINT_CLAMP);
    let x = if x < mid {
        0.5 * x / mid
    } else {
        0.5 + 0.5 * (x - mid) / (1.0 - mid)
    };
    if sharp > 0.99 {
        return if x < 0.5 { v1 } else { v2 };
    }
    if sharp < 0.01 {
        return (1.0 - x) * v1 + x * v2;
    }
    let x = if x < 0.5 {
        0.5 * (x * 2.0).powf(1.0 + 10.0 * sharp)
    } else if x > 0.5 {
        1.0 - 0.5 * ((1.0 - x) * 2.0).powf(1.0 + 10.0 * sharp)
    } else {
        x
    };
    let (x2, x3) = (x * x, x * x * x);
    let h1 = 2.0 * x3 - 3.0 * x2 + 1.0;
    let h2 = -2.0 * x3 + 3.0 * x2;
    let h3 = x3 - 2.0 * x2 + x;
    let h4 = x3 - x2;
    let t = (1.0 - sharp) * (v2 - v1);
    let v = h1 * v1 + h2 * v2 + h3 * t + h4 * t;
    v.clamp(v1.min(v2), v1.max(v2))
}

fn resample_opacity(p: &[[f64; 4]]) -> Vec<(f64, [f64; 1])> {
    let mut out = vec![(p[0][0], [p[0][1]])];
    for w in p.windows(2) {
        let ([x0, o0, mid, sharp], [x1, o1, _, _]) = (w[0], w[1]);
        if x1 == x0 || (mid == 0.5 && sharp == 0.0) {
            out.push((x1, [o1]));
            continue;
        }
        for k in 1..=PIECES_PER_INTERVAL {
            let t = k as f64 / PIECES_PER_INTERVAL as f64;
            let x = if k == PIECES_PER_INTERVAL {
                x1
            } else {
                x0 + (x1 - x0) * t
            };
            out.push((x, [midpoint_sharpness(o0, o1, t, mid, sharp)]));
        }
    }
    out
}

// ---- colour spaces (as in vtkMath, D65 white) ----

fn srgb_to_linear(c: f64) -> f64 {
    if c > 0.04045 {
        ((c + 0.055) / 1.055).powf(2.4)
    } else {
        c / 12.92
    }
}

fn linear_to_srgb(c: f64) -> f64 {
    if c > 0.0031308 {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    } else {
        12.92 * c
    }
}

const WHITE: [f64; 3] = [0.9505, 1.0, 1.089];

fn rgb_to_lab(c: [f64; 3]) -> [f64; 3] {
    let [r, g, b] = c.map(srgb_to_linear);
    let x = 0.4124 * r + 0.3576 * g + 0.1805 * b;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = 0.0193 * r + 0.1192 * g + 0.9505 * b;
    let f = |t: f64| {
        if t > 0.008856 {
            t.cbrt()
        } else {
            7.787 * t + 16.0 / 116.0
        }
    };
    let (fx, fy, fz) = (f(x / WHITE[0]), f(y / WHITE[1]), f(z / WHITE[2]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

fn lab_to_rgb(lab: [f64; 3]) -> [f64; 3] {
    let fy = (lab[0] + 16.0) / 116.0;
    let fx = lab[1] / 500.0 + fy;
    let fz = fy - lab[2] / 200.0;
    let g = |t: f64| {
        let t3 = t * t * t;
        if t3 > 0.008856 {
            t3
        } else {
            (t - 16.0 / 116.0) / 7.787
        }
    };
    let (x, y, z) = (g(fx) * WHITE[0], g(fy) * WHITE[1], g(fz) * WHITE[2]);
    let r = 3.2406 * x - 1.5372 * y - 0.4986 * z;
    let gg = -0.9689 * x + 1.8758 * y + 0.0415 * z;
    let b = 0.0557 * x - 0.2040 * y + 1.0570 * z;
    [r, gg, b].map(|v| linear_to_srgb(v.max(0.0)).clamp(0.0, 1.0))
}

fn rgb_to_hsv(c: [f64; 3]) -> [f64; 3] {
    let max = c[0].max(c[1]).max(c[2]);
    let min = c[0].min(c[1]).min(c[2]);
    let d = max - min;
    let s = if max > 0.0 { d / max } else { 0.0 };
    let h = if d == 0.0 {
        0.0
    } else if max == c[0] {
        ((c[1] - c[2]) / d / 6.0).rem_euclid(1.0)
    } else if max == c[1] {
        ((c[2] - c[0]) / d + 2.0) / 6.0
    } else {
        ((c[0] - c[1]) / d + 4.0) / 6.0
    };
    [h, s, max]
}

fn hsv_to_rgb(hsv: [f64; 3]) -> [f64; 3] {
    let [h, s, v] = hsv;
    let h6 = (h * 6.0).rem_euclid(6.0);
    let i = h6.floor();
    let f = h6 - i;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match i as u32 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

fn lab_to_msh(lab: [f64; 3]) -> [f64; 3] {
    let m = (lab[0] * lab[0] + lab[1] * lab[1] + lab[2] * lab[2]).sqrt();
    let s = if m > 0.001 {
        (lab[0] / m).clamp(-1.0, 1.0).acos()
    } else {
        0.0
    };
    let h = if s > 0.001 { lab[2].atan2(lab[1]) } else { 0.0 };
    [m, s, h]
}

fn msh_to_lab(msh: [f64; 3]) -> [f64; 3] {
    let [m, s, h] = msh;
    [m * s.cos(), m * s.sin() * h.cos(), m * s.sin() * h.sin()]
}

fn adjust_hue(msh: [f64; 3], unsat_m: f64) -> f64 {
    if msh[0] >= unsat_m - 0.1 {
        return msh[2];
    }
    let spin = msh[1] * (unsat_m * unsat_m - msh[0] * msh[0]).sqrt() / (msh[0] * msh[1].sin());
    if msh[2] > -0.3 * std::f64::consts::PI {
        msh[2] + spin
    } else {
        msh[2] - spin
    }
}

/// Moreland's diverging interpolation in Msh space (as in VTK).
fn diverging(c0: [f64; 3], c1: [f64; 3], t: f64) -> [f64; 3] {
    let mut m1 = lab_to_msh(rgb_to_lab(c0));
    let mut m2 = lab_to_msh(rgb_to_lab(c1));
    let mut t = t;
    let pi = std::f64::consts::PI;
    let mut dh = (m1[2] - m2[2]).abs();
    if dh > pi {
        dh = 2.0 * pi - dh;
    }
    if m1[1] > 0.05 && m2[1] > 0.05 && dh > pi / 3.0 {
        let mid = m1[0].max(m2[0]).max(88.0);
        if t < 0.5 {
            m2 = [mid, 0.0, 0.0];
            t *= 2.0;
        } else {
            m1 = [mid, 0.0, 0.0];
            t = 2.0 * t - 1.0;
        }
    }
    if m1[1] < 0.05 && m2[1] > 0.05 {
        m1[2] = adjust_hue(m2, m1[0]);
    } else if m2[1] < 0.05 && m1[1] > 0.05 {
        m2[2] = adjust_hue(m1, m2[0]);
    }
    let m = std::array::from_fn(|k| (1.0 - t) * m1[k] + t * m2[k]);
    lab_to_rgb(msh_to_lab(m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_space_round_trips() {
        for c in [[0.2, 0.5, 0.9], [1.0, 0.0, 0.0], [0.3, 0.3, 0.3]] {
            let back = lab_to_rgb(rgb_to_lab(c));
            let hsv = hsv_to_rgb(rgb_to_hsv(c));
            for k in 0..3 {
                assert!((back[k] - c[k]).abs() < 2e-3, "{c:?} {back:?}");
                assert!((hsv[k] - c[k]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn midpoint_sharpness_defaults_are_linear_and_curves_bounded() {
        for x in [0.0, 0.3, 0.5, 0.9, 1.0] {
            assert!((midpoint_sharpness(0.2, 0.8, x, 0.5, 0.0) - (0.2 + 0.6 * x)).abs() < 1e-15);
            let v = midpoint_sharpness(0.2, 0.8, x, 0.3, 0.6);
            assert!((0.2..=0.8).contains(&v));
        }
        assert_eq!(midpoint_sharpness(0.0, 1.0, 0.4, 0.5, 1.0), 0.0);
    }

    #[test]
    fn cool_to_warm_midpoint_is_neutral_grey() {
        let p = [
            (0.0, [0.23137254902, 0.298039215686, 0.752941176471]),
            (1.0, [0.705882352941, 0.0156862745098, 0.149019607843]),
        ];
        let r = resample_colors(&p, ColorSpace::Diverging, 32);
        assert_eq!(r.len(), 33);
        let mid = r[16].1;
        // Moreland: the midpoint of the cool-warm map is a light grey.
        assert!(
            (mid[0] - mid[1]).abs() < 0.05 && (mid[1] - mid[2]).abs() < 0.05,
            "{mid:?}"
        );
        assert!(mid[0] > 0.8, "{mid:?}");
    }
}
