//! Isosurfaces, drawn without extracting triangles (Roettger, Kraus and
//! Ertl 2000, sections 7-10: a ray segment through a piece crosses the
//! isovalue `V` where its end scalars `s_f`, `s_b` bracket `V`), alone
//! (`--mode iso`) or mixed with the volume in the exact visibility order
//! (`--iso` with a segment mode, or with the reference ray caster).
//!
//! # What a surface is
//! Along a ray the scalar is continuous. A point of the ray is *below* `V`
//! when `s < V` and *at or above* otherwise; the ray crosses the surface
//! where it passes from one class to the other. A segment from `s_f` to
//! `s_b` (linear along it) crosses `V` exactly when `min < V <= max` of its
//! ends, once, at the fraction `u = (V - s_f) / (s_b - s_f)` of its length.
//! Two segments that meet at a point with `s = V` do not both count it (the
//! classes of the shared end are the same), so a surface through a face of
//! the mesh is drawn once; a segment lying in the surface (`s_f = s_b = V`)
//! crosses nothing (the crossing, if any, is where the ray enters the
//! level region). An isovalue at the field's minimum is never crossed; at
//! its maximum only where a ray touches the maximum. "At or above" allows
//! for rounding: a scalar within [`ISO_LEVEL_F64`] (relative to the
//! span, at least a few ulps of `V`; the GPU
//! stages [`crate::numeric::tolerance::ISO_LEVEL_F32`]) below `V` counts as
//! reaching it, so that a face whose points all have the value `V` is one
//! surface.
//!
//! # Colour and light
//! Each surface has a colour and opacity per side: the *front* side is the
//! one a ray meets while the scalar rises (`s_f < s_b`), facing the viewer
//! when the gradient points away from it; the *back* side the other. By
//! default both are the transfer function's colour at `V`, opaque. The light
//! is a headlight: a directional light along the view direction, as VTK's,
//! diffuse with [`AMBIENT`] and [`DIFFUSE`] (no specular term); the surface's
//! premultiplied colour is `(k c a, a)` with `k = AMBIENT + DIFFUSE |n . d|`
//! (`n` the unit gradient, `d` the view direction). [`Lighting`] chooses the
//! gradient: flat (one per piece) or smooth (interpolated from the points),
//! as [`super::gradients`] defines them; or no light (`k = 1`). A zero
//! gradient has no direction and is lit as facing the viewer.
//!
//! # Mixing
//! Inside one segment the volume is split at the crossings: the volume in
//! front of the first surface, the surface, the volume behind it up to the
//! next, and so on, composited front to back ([`IsoSet::composite`]). The
//! segment keeps its place in the exact order, so surfaces and volume are
//! composited in their true order along every ray. Only the isovalues
//! between the segment's ends are visited (a binary search in the sorted
//! values; the GPU stages search only the values within the piece's own
//! scalar range, [`crate::render::modes::iso::IsoVertex::candidates`]):
//! the cost does not grow with the
//! number of surfaces that a segment does not cross.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;
use serde::Serialize;

use crate::integrate::SegmentValue;
use crate::numeric::tolerance::{ISO_LEVEL_F64, ISO_LEVEL_ULPS};
use crate::tf::TransferFunction;

/// Ambient part of the headlight.
pub const AMBIENT: f64 = 0.25;
/// Diffuse part of the headlight (`AMBIENT + DIFFUSE = 1`: a surface facing
/// the viewer has its full colour).
pub const DIFFUSE: f64 = 0.75;
/// The most isosurfaces one render draws (each fragment loops only over the
/// values its segment crosses, but the list is bound as one buffer).
pub const MAX_SURFACES: usize = 1024;

/// How isosurfaces are lit (`--shading`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Lighting {
    /// Headlight on the gradients at the points, interpolated like the
    /// scalar (continuous across faces).
    #[default]
    Smooth,
    /// Headlight on one gradient per piece (its least-squares linear fit).
    Flat,
    /// No light: each side's colour as it is.
    None,
}

impl Lighting {
    /// The name `--shading` takes.
    pub fn name(self) -> &'static str {
        match self {
            Lighting::Smooth => "smooth",
            Lighting::Flat => "flat",
            Lighting::None => "none",
        }
    }

    /// The code the shaders use (`IsoParams::lighting`).
    pub fn code(self) -> u32 {
        match self {
            Lighting::None => 0,
            Lighting::Flat => 1,
            Lighting::Smooth => 2,
        }
    }
}

/// How a segment's volume and its surfaces are combined (`--iso-mix`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum IsoMix {
    /// The volume split at the crossings, composited in their order along
    /// the ray (exact).
    #[default]
    Exact,
    /// Roettger, Kraus and Ertl's smooth approximation (section 10): the
    /// whole segment's volume between the surfaces' front-face layer
    /// (opacity weighted by `1 - u`, the crossing's distance from the back)
    /// and back-face layer (weighted by `u`), for comparison.
    Blend,
}

impl IsoMix {
    /// The name `--iso-mix` takes.
    pub fn name(self) -> &'static str {
        match self {
            IsoMix::Exact => "exact",
            IsoMix::Blend => "blend",
        }
    }
}

/// The colour (linear RGB in `[0, 1]`) and opacity of one side.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SideStyle {
    /// `None`: the transfer function's colour at the isovalue.
    pub color: Option<[f64; 3]>,
    pub opacity: f64,
}

impl Default for SideStyle {
    fn default() -> Self {
        SideStyle {
            color: None,
            opacity: 1.0,
        }
    }
}

/// One isosurface as asked for: `V[:COLOUR[:OPACITY[:BACKCOLOUR[:BACKOPACITY]]]]`.
///
/// `COLOUR` is `#rrggbb` (sRGB, converted to linear like every colour of
/// zoovr) or `tf` (the transfer function's colour at `V`); `OPACITY` is in
/// `[0, 1]`. The back side takes the front's style unless given.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct IsoSpec {
    pub value: f64,
    pub front: SideStyle,
    pub back: SideStyle,
}

/// A bad `--iso` item.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IsoError {
    #[error("isovalue '{0}' is not a finite number")]
    Value(String),
    #[error("isosurface '{item}': colour '{got}' is neither #rrggbb nor 'tf'")]
    Color { item: String, got: String },
    #[error("isosurface '{item}': opacity '{got}' is not a number in [0, 1]")]
    Opacity { item: String, got: String },
    #[error("isosurface '{0}': more than five ':'-separated parts (V:COLOUR:OPACITY:BACKCOLOUR:BACKOPACITY)")]
    Parts(String),
    #[error("{0} isosurfaces asked for; at most {MAX_SURFACES} are drawn in one render")]
    TooMany(usize),
    #[error("isosurfaces need a point field (the field is per cell, constant inside each cell); --cell-to-point makes one")]
    CellData,
}

fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn parse_color(item: &str, s: &str) -> Result<Option<[f64; 3]>, IsoError> {
    let bad = || IsoError::Color {
        item: item.to_string(),
        got: s.to_string(),
    };
    if s.eq_ignore_ascii_case("tf") {
        return Ok(None);
    }
    let hex = s.strip_prefix('#').ok_or_else(bad)?;
    if hex.len() != 6 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
        return Err(bad());
    }
    let byte = |k: usize| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).map_err(|_| bad());
    Ok(Some([
        srgb_to_linear(byte(0)? as f64 / 255.0),
        srgb_to_linear(byte(1)? as f64 / 255.0),
        srgb_to_linear(byte(2)? as f64 / 255.0),
    ]))
}

fn parse_opacity(item: &str, s: &str) -> Result<f64, IsoError> {
    match s.trim().parse::<f64>() {
        Ok(a) if (0.0..=1.0).contains(&a) => Ok(a),
        _ => Err(IsoError::Opacity {
            item: item.to_string(),
            got: s.to_string(),
        }),
    }
}

impl FromStr for IsoSpec {
    type Err = IsoError;

    fn from_str(item: &str) -> Result<IsoSpec, IsoError> {
        let parts: Vec<&str> = item.split(':').collect();
        if parts.len() > 5 {
            return Err(IsoError::Parts(item.to_string()));
        }
        let value = match parts[0].trim().parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            _ => return Err(IsoError::Value(parts[0].to_string())),
        };
        let mut front = SideStyle::default();
        if let Some(c) = parts.get(1) {
            front.color = parse_color(item, c.trim())?;
        }
        if let Some(a) = parts.get(2) {
            front.opacity = parse_opacity(item, a)?;
        }
        let mut back = front;
        if let Some(c) = parts.get(3) {
            back.color = parse_color(item, c.trim())?;
        }
        if let Some(a) = parts.get(4) {
            back.opacity = parse_opacity(item, a)?;
        }
        Ok(IsoSpec { value, front, back })
    }
}

/// Parses a comma-separated `--iso` list (at most [`MAX_SURFACES`]).
pub fn parse_list(s: &str) -> Result<Vec<IsoSpec>, IsoError> {
    let specs = s
        .split(',')
        .map(|item| item.trim().parse::<IsoSpec>())
        .collect::<Result<Vec<_>, _>>()?;
    if specs.len() > MAX_SURFACES {
        return Err(IsoError::TooMany(specs.len()));
    }
    Ok(specs)
}

/// What a render is asked to draw of isosurfaces (`--iso`, `--shading`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct IsoOptions {
    pub surfaces: Vec<IsoSpec>,
    pub lighting: Lighting,
    /// The surfaces without the volume, whatever the mode (`--iso-only`;
    /// what `--mode iso` always draws, so with `--mode raycast` its
    /// reference).
    pub alone: bool,
    /// How volume and surfaces combine within a segment (`--iso-mix`).
    pub mix: IsoMix,
}

impl IsoOptions {
    /// Whether any surface is asked for.
    pub fn any(&self) -> bool {
        !self.surfaces.is_empty()
    }
}

impl fmt::Display for IsoOptions {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} isosurface(s), {} shading",
            self.surfaces.len(),
            self.lighting.name()
        )
    }
}

/// The isosurfaces of one render, resolved against its transfer function:
/// sorted by value (a value given twice keeps its first style), each side's
/// linear colour and opacity.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IsoSet {
    /// The isovalues as asked for.
    pub values: Vec<f64>,
    /// The levels a scalar must reach to be at or above each value: the
    /// value less [`ISO_LEVEL_F64`] of the span or [`ISO_LEVEL_ULPS`] ulps
    /// of the value, whichever is more (a face whose points all
    /// have the value is one surface, not two or none).
    pub levels: Vec<f64>,
    /// Front and back side of each: `[r, g, b, opacity]`, not premultiplied.
    pub sides: Vec<[[f64; 4]; 2]>,
    pub lighting: Lighting,
    pub mix: IsoMix,
}

impl IsoSet {
    /// Resolves `opts` against `tf`.
    pub fn new(opts: &IsoOptions, tf: &TransferFunction) -> IsoSet {
        let mut specs = opts.surfaces.clone();
        specs.sort_by(|a, b| a.value.total_cmp(&b.value));
        specs.dedup_by(|b, a| a.value == b.value);
        let side = |v: f64, s: &SideStyle| {
            let c = s.color.unwrap_or_else(|| tf.color_at(v));
            [c[0], c[1], c[2], s.opacity]
        };
        let (lo, hi) = tf.scalar_range();
        let span = if (hi - lo).is_finite() { hi - lo } else { 0.0 };
        IsoSet {
            values: specs.iter().map(|s| s.value).collect(),
            levels: specs
                .iter()
                .map(|s| {
                    let ulps = ISO_LEVEL_ULPS * f64::EPSILON * s.value.abs();
                    s.value - (ISO_LEVEL_F64 * span).max(ulps)
                })
                .collect(),
            sides: specs
                .iter()
                .map(|s| [side(s.value, &s.front), side(s.value, &s.back)])
                .collect(),
            lighting: opts.lighting,
            mix: opts.mix,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The indices of the values a segment from `s_f` to `s_b` crosses
    /// (`min < V <= max`), in increasing value.
    pub fn crossed(&self, s_f: f64, s_b: f64) -> std::ops::Range<usize> {
        let (lo, hi) = if s_f <= s_b { (s_f, s_b) } else { (s_b, s_f) };
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return 0..0;
        }
        let a = self.levels.partition_point(|&v| v <= lo);
        let b = self.levels.partition_point(|&v| v <= hi);
        a..b
    }

    /// Whether some value lies in `[lo, hi]` (a piece with that scalar
    /// range may hold a surface).
    pub fn any_in(&self, lo: f64, hi: f64) -> bool {
        let a = self.levels.partition_point(|&v| v < lo);
        a < self.levels.len() && self.levels[a] <= hi
    }

    /// The light factor of a surface point with gradient `g` seen along the
    /// unit view direction `d`.
    pub fn light(&self, g: DVec3, d: DVec3) -> f64 {
        if self.lighting == Lighting::None {
            return 1.0;
        }
        let n = g.length();
        if !(n > 0.0 && n.is_finite()) {
            return 1.0;
        }
        AMBIENT + DIFFUSE * (g.dot(d).abs() / n).min(1.0)
    }

    /// Surface `k` crossed rising or falling, with gradient `g`, as a
    /// segment value (its opacity as an optical depth).
    pub fn surface(&self, k: usize, rising: bool, g: DVec3, d: DVec3) -> SegmentValue {
        self.surface_weighted(k, rising, g, d, 1.0)
    }

    /// [`Self::surface`] with its opacity times `w` (RKE's blend).
    pub fn surface_weighted(
        &self,
        k: usize,
        rising: bool,
        g: DVec3,
        d: DVec3,
        w: f64,
    ) -> SegmentValue {
        let c = self.sides[k][if rising { 0 } else { 1 }];
        let i = self.light(g, d);
        let a = (c[3] * w).clamp(0.0, 1.0);
        SegmentValue {
            color: [c[0] * i * a, c[1] * i * a, c[2] * i * a],
            alpha: a,
            depth: -(-a).ln_1p(),
        }
    }

    /// The segment of length `l` from `s_f` to `s_b` (gradients `g_f`,
    /// `g_b` at its ends, linear between), its volume given by `volume(l,
    /// s0, s1)`, split at the surfaces it crosses and composited front to
    /// back (see the module docs). `d` is the unit view direction in the
    /// gradients' coordinates.
    pub fn composite(
        &self,
        l: f64,
        s_f: f64,
        s_b: f64,
        g: [DVec3; 2],
        d: DVec3,
        volume: impl Fn(f64, f64, f64) -> SegmentValue,
    ) -> SegmentValue {
        let range = self.crossed(s_f, s_b);
        if range.is_empty() {
            return volume(l, s_f, s_b);
        }
        let rising = s_f < s_b;
        let mut acc = SegmentValue::default();
        let (mut u0, mut s0) = (0.0, s_f);
        let n = range.len();
        if self.mix == IsoMix::Blend {
            let mut back = SegmentValue::default();
            for i in 0..n {
                let k = if rising {
                    range.start + i
                } else {
                    range.end - 1 - i
                };
                let u = ((self.levels[k] - s_f) / (s_b - s_f)).clamp(0.0, 1.0);
                let g = g[0].lerp(g[1], u);
                acc = over(acc, self.surface_weighted(k, rising, g, d, 1.0 - u));
                back = over(back, self.surface_weighted(k, rising, g, d, u));
            }
            return over(over(acc, volume(l, s_f, s_b)), back);
        }
        for i in 0..n {
            let k = if rising {
                range.start + i
            } else {
                range.end - 1 - i
            };
            let v = self.levels[k];
            let u = ((v - s_f) / (s_b - s_f)).clamp(0.0, 1.0);
            acc = over(acc, volume((u - u0) * l, s0, v));
            acc = over(acc, self.surface(k, rising, g[0].lerp(g[1], u), d));
            (u0, s0) = (u, v);
        }
        over(acc, volume((1.0 - u0) * l, s0, s_b))
    }
}

/// `back` behind `front`, both as segment values.
pub fn over(front: SegmentValue, back: SegmentValue) -> SegmentValue {
    let t = (-front.depth).exp();
    let depth = front.depth + back.depth;
    SegmentValue {
        color: std::array::from_fn(|k| front.color[k] + t * back.color[k]),
        alpha: -(-depth).exp_m1(),
        depth,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(values: &[f64]) -> IsoSet {
        IsoSet {
            values: values.to_vec(),
            levels: values.to_vec(),
            sides: values
                .iter()
                .map(|_| [[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.5]])
                .collect(),
            lighting: Lighting::None,
            mix: IsoMix::Exact,
        }
    }

    #[test]
    fn parses_styles_and_refuses_bad_items() {
        let s: IsoSpec = "0.5".parse().unwrap();
        assert_eq!(s.value, 0.5);
        assert_eq!(s.front, SideStyle::default());
        let s: IsoSpec = "2:#ff0000:0.25:#000000".parse().unwrap();
        assert_eq!(s.front.color, Some([1.0, 0.0, 0.0]));
        assert_eq!(s.front.opacity, 0.25);
        assert_eq!(s.back.color, Some([0.0, 0.0, 0.0]));
        assert_eq!(s.back.opacity, 0.25);
        assert!(matches!("nan".parse::<IsoSpec>(), Err(IsoError::Value(_))));
        assert!(matches!("x".parse::<IsoSpec>(), Err(IsoError::Value(_))));
        assert!(matches!(
            "1:#ff00".parse::<IsoSpec>(),
            Err(IsoError::Color { .. })
        ));
        assert!(matches!(
            "1:tf:2".parse::<IsoSpec>(),
            Err(IsoError::Opacity { .. })
        ));
        assert!(matches!(
            "1:tf:1:tf:1:x".parse::<IsoSpec>(),
            Err(IsoError::Parts(_))
        ));
        let many = vec!["1"; MAX_SURFACES + 1].join(",");
        assert_eq!(parse_list(&many), Err(IsoError::TooMany(MAX_SURFACES + 1)));
        assert_eq!(parse_list("1, 2,3").unwrap().len(), 3);
    }

    #[test]
    fn a_segment_crosses_the_values_strictly_above_its_low_end() {
        let s = set(&[1.0, 2.0, 3.0]);
        assert_eq!(s.crossed(0.0, 2.0), 0..2);
        assert_eq!(s.crossed(2.0, 0.0), 0..2);
        // Meeting at V = 2: the segment ending there crosses it, the one
        // leaving it does not.
        assert_eq!(s.crossed(1.5, 2.0), 1..2);
        assert_eq!(s.crossed(2.0, 2.5), 2..2);
        // Flat at V: nothing.
        assert_eq!(s.crossed(2.0, 2.0), 0..0);
        assert!(s.any_in(2.0, 2.0) && !s.any_in(3.5, 9.0));
    }

    #[test]
    fn an_opaque_surface_hides_what_lies_behind_it() {
        let s = set(&[1.0]);
        let vol = |l: f64, _: f64, _: f64| SegmentValue {
            color: [0.0, l, 0.0],
            alpha: -(-l).exp_m1(),
            depth: l,
        };
        let d = DVec3::Z;
        let g = [DVec3::Z; 2];
        // Rising from 0 to 2 over length 2: volume 1, then the red surface.
        let v = s.composite(2.0, 0.0, 2.0, g, d, vol);
        let t = (-1.0f64).exp();
        assert!((v.color[0] - t).abs() < 1e-12);
        assert!((v.color[1] - 1.0).abs() < 1e-12);
        assert_eq!(v.alpha, 1.0);
        // Falling: the back side, half transparent.
        let v = s.composite(2.0, 2.0, 0.0, g, d, vol);
        assert!((v.color[2] - 0.5 * t).abs() < 1e-12);
        assert!((v.color[1] - (1.0 + 0.5 * t)).abs() < 1e-12);
        assert!((v.alpha - (1.0 - 0.5 * t * t)).abs() < 1e-12);
    }

    /// The level's margin is relative to the span (with a floor of a few
    /// ulps of the value): in a field spanning 1e-12 around 1, a margin of
    /// 1e-12 of the value would put the level below the whole field, and
    /// no segment would cross it.
    #[test]
    fn levels_resolve_a_field_spanning_1e_minus_12() {
        let (lo, span) = (1.0, 1e-12);
        let tf = TransferFunction::from_channels(
            &[(lo, [0.0]), (lo + span, [1.0])],
            &[(lo, [1.0, 1.0, 1.0])],
            None,
            crate::tf::EmissionModel::Glow,
        )
        .unwrap();
        let v = lo + 0.37 * span;
        let opts = IsoOptions {
            surfaces: vec![IsoSpec {
                value: v,
                front: SideStyle::default(),
                back: SideStyle::default(),
            }],
            ..Default::default()
        };
        let set = IsoSet::new(&opts, &tf);
        let margin = v - set.levels[0];
        assert!(margin > 0.0 && margin <= 1e-3 * span, "margin {margin:e}");
        assert_eq!(set.crossed(lo + 0.3 * span, lo + 0.4 * span), 0..1);
        assert_eq!(set.crossed(lo, lo + 0.36 * span), 0..0);
        // A value of order 1 over a span of 1: the span's margin.
        let tf = TransferFunction::from_channels(
            &[(0.0, [0.0]), (1.0, [1.0])],
            &[(0.0, [1.0, 1.0, 1.0])],
            None,
            crate::tf::EmissionModel::Glow,
        )
        .unwrap();
        let opts = IsoOptions {
            surfaces: vec![IsoSpec {
                value: 0.5,
                front: SideStyle::default(),
                back: SideStyle::default(),
            }],
            ..Default::default()
        };
        assert_eq!(IsoSet::new(&opts, &tf).levels[0], 0.5 - ISO_LEVEL_F64);
    }
}
