//! Named colour maps, opacity shapes and the default transfer function.
//!
//! Presets are normalised onto a scalar range: colour nodes at fixed
//! fractions of the range, an opacity shape ([`Opacity`]), and extinction =
//! opacity / unit distance (VTK's scalar opacity unit distance). The glow
//! emission model is used.
//!
//! Colour data: `viridis`, `inferno`, `magma`, `plasma` are the degree-6
//! polynomial fits of matplotlib's maps (M. Zucker, CC0; within ~1/255 of the
//! originals) sampled at 9 equally spaced nodes (few nodes keep the number of
//! breakpoints, hence of split cells, small); `cool-warm` is ParaView's
//! "Cool to Warm" (Moreland's diverging map, interpolated in Msh space and
//! resampled into 16 RGB pieces); `jet`, `rainbow`, `grayscale`, `hot` and
//! `blue-white-red` are piecewise linear in RGB by definition.

use super::paraview::{resample_colors, ColorSpace};
use super::{EmissionModel, TfError, TransferFunction};

/// Opacity as a function of the normalised scalar `x in [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Opacity {
    /// Linear from 0 at the range minimum to 1 at the maximum.
    Ramp,
    /// 0 below `at` (a fraction of the range), `opacity` from there on.
    Step { at: f64, opacity: f64 },
    /// The same opacity everywhere.
    Constant(f64),
}

/// Names accepted by [`preset`], for `--help` and error messages.
pub fn preset_names() -> &'static [&'static str] {
    &[
        "viridis",
        "inferno",
        "magma",
        "plasma",
        "cool-warm",
        "grayscale",
        "jet",
        "rainbow",
        "hot",
        "blue-white-red",
    ]
}

type Poly = [[f64; 3]; 7];

const VIRIDIS: Poly = [
    [0.2777273272234177, 0.005407344544966578, 0.3340998053353061],
    [0.1050930431085774, 1.404613529898575, 1.384590162594685],
    [-0.3308618287255563, 0.214847559468213, 0.09509516302823659],
    [-4.634230498983486, -5.799100973351585, -19.33244095627987],
    [6.228269936347081, 14.17993336680509, 56.69055260068105],
    [4.776384997670288, -13.74514537774601, -65.35303263337234],
    [-5.435455855934631, 4.645852612178535, 26.3124352495832],
];
const INFERNO: Poly = [
    [
        0.0002189403691192265,
        0.001651004631001012,
        -0.01948089843709184,
    ],
    [0.1065134194856116, 0.5639564367884091, 3.932712388889277],
    [11.60249308247187, -3.972853965665698, -15.9423941062914],
    [-41.70399613139459, 17.43639888205313, 44.35414519872813],
    [77.162935699427, -33.40235894210092, -81.80730925738993],
    [-71.31942824499214, 32.62606426397723, 73.20951985803202],
    [25.13112622477341, -12.24266895238567, -23.07032500287172],
];
const MAGMA: Poly = [
    [
        -0.002136485053939582,
        -0.000749655052795221,
        -0.005386127855323933,
    ],
    [0.2516605407371642, 0.6775232436837668, 2.494026599312351],
    [8.353717279216625, -3.577719514958484, 0.3144679030132573],
    [-27.66873308576866, 14.26473078096533, -13.64921318813922],
    [52.17613981234068, -27.94360607168351, 12.94416944238394],
    [-50.76852536473588, 29.04658282127291, 4.23415299384598],
    [18.65570506591883, -11.48977351997711, -5.601961508734096],
];
#[allow(clippy::excessive_precision)] // published coefficients, verbatim
const PLASMA: Poly = [
    [0.05873234392399702, 0.02333670892565664, 0.5433401826748754],
    [2.176514634195958, 0.2383834171260182, 0.7539604599784036],
    [-2.689460476458034, -7.455851135738909, 3.110799939717086],
    [6.130348345893603, 42.3461881477227, -28.51885465332158],
    [-11.10743619062271, -82.66631109428045, 60.13984767418263],
    [10.02306557647065, 71.41361770095349, -54.07218655560067],
    [-3.658713842777788, -22.93153465461149, 18.19190778539828],
];

fn poly_points(p: &Poly, n: usize) -> Vec<(f64, [f64; 3])> {
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64;
            let c = std::array::from_fn(|k| {
                let mut v = p[6][k];
                for d in (0..6).rev() {
                    v = v * t + p[d][k];
                }
                v.clamp(0.0, 1.0)
            });
            (t, c)
        })
        .collect()
}

fn linear(points: &[(f64, [f64; 3])]) -> Vec<(f64, [f64; 3])> {
    points.to_vec()
}

/// Normalised colour points of a named map (`x in [0, 1]`).
pub(crate) fn colour_points(name: &str) -> Option<Vec<(f64, [f64; 3])>> {
    let lower = name.to_ascii_lowercase();
    Some(match lower.as_str() {
        "viridis" => poly_points(&VIRIDIS, 9),
        "inferno" => poly_points(&INFERNO, 9),
        "magma" => poly_points(&MAGMA, 9),
        "plasma" => poly_points(&PLASMA, 9),
        "cool-warm" | "coolwarm" | "cool to warm" => resample_colors(
            &[
                (0.0, [0.23137254902, 0.298039215686, 0.752941176471]),
                (0.5, [0.865, 0.865, 0.865]),
                (1.0, [0.705882352941, 0.0156862745098, 0.149019607843]),
            ],
            ColorSpace::Diverging,
            8,
        ),
        "grayscale" | "greyscale" | "gray" | "grey" => linear(&[(0.0, [0.0; 3]), (1.0, [1.0; 3])]),
        "jet" => linear(&[
            (0.0, [0.0, 0.0, 0.5]),
            (0.125, [0.0, 0.0, 1.0]),
            (0.375, [0.0, 1.0, 1.0]),
            (0.625, [1.0, 1.0, 0.0]),
            (0.875, [1.0, 0.0, 0.0]),
            (1.0, [0.5, 0.0, 0.0]),
        ]),
        "rainbow" => linear(&[
            (0.0, [0.0, 0.0, 1.0]),
            (0.25, [0.0, 1.0, 1.0]),
            (0.5, [0.0, 1.0, 0.0]),
            (0.75, [1.0, 1.0, 0.0]),
            (1.0, [1.0, 0.0, 0.0]),
        ]),
        "hot" => linear(&[
            (0.0, [0.0, 0.0, 0.0]),
            (0.375, [1.0, 0.0, 0.0]),
            (0.75, [1.0, 1.0, 0.0]),
            (1.0, [1.0, 1.0, 1.0]),
        ]),
        "blue-white-red" | "bwr" => linear(&[
            (0.0, [0.0, 0.0, 1.0]),
            (0.5, [1.0, 1.0, 1.0]),
            (1.0, [1.0, 0.0, 0.0]),
        ]),
        _ => return None,
    })
}

/// A usable `[lo, hi]`: swapped if reversed, widened if empty (by half of
/// `max(1, |lo|)` on each side, so a constant field gets the middle of the
/// map), `(0, 1)` if not finite.
pub fn usable_range(range: (f64, f64)) -> (f64, f64) {
    let (lo, hi) = range;
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    if hi > lo {
        return (lo, hi);
    }
    let h = 0.5 * lo.abs().max(1.0);
    (lo - h, hi + h)
}

/// A named preset normalised onto `range`, with extinction = opacity /
/// `unit_distance` and glow emission.
pub fn preset(
    name: &str,
    range: (f64, f64),
    unit_distance: f64,
    opacity: Opacity,
) -> Result<TransferFunction, TfError> {
    if !(unit_distance.is_finite() && unit_distance > 0.0) {
        return Err(TfError::UnitDistance(unit_distance));
    }
    let colours = colour_points(name).ok_or_else(|| TfError::UnknownPreset {
        name: name.to_string(),
        available: preset_names().join(", "),
    })?;
    let (lo, hi) = usable_range(range);
    let at = |x: f64| lo + (hi - lo) * x;
    let col: Vec<(f64, [f64; 3])> = colours.iter().map(|&(x, c)| (at(x), c)).collect();
    let op: Vec<(f64, f64)> = match opacity {
        Opacity::Ramp => vec![(0.0, 0.0), (1.0, 1.0)],
        Opacity::Constant(o) => vec![(0.0, o)],
        Opacity::Step { at, opacity } => {
            let x = at.clamp(0.0, 1.0);
            vec![(x, 0.0), (x, opacity)]
        }
    };
    for &(_, o) in &op {
        if !(0.0..=1.0).contains(&o) {
            return Err(TfError::OpacityRange {
                what: "preset opacity",
                index: 0,
                value: o,
            });
        }
    }
    let tau: Vec<(f64, [f64; 1])> = op
        .iter()
        .map(|&(x, o)| (at(x), [o / unit_distance]))
        .collect();
    let mut tf = TransferFunction::from_channels(&tau, &col, None, EmissionModel::Glow)?;
    tf.unit_distance = Some(unit_distance);
    Ok(tf)
}

impl TransferFunction {
    /// The default transfer function (docs/conventions.md, Conventions): viridis over
    /// `range`, opacity ramp 0 -> 1, unit distance = `diagonal / 10`
    /// (1 if the diagonal is not positive), glow emission. An empty or
    /// reversed range is handled by [`usable_range`].
    pub fn default_for(range: (f64, f64), diagonal: f64) -> Self {
        let unit = if diagonal.is_finite() && diagonal > 0.0 {
            diagonal / 10.0
        } else {
            1.0
        };
        // Cannot fail: known name, valid unit distance and opacity.
        match preset("viridis", range, unit, Opacity::Ramp) {
            Ok(tf) => tf,
            Err(_) => Self::fallback(),
        }
    }

    /// A plain grey ramp over [0, 1] (only reached if a built-in preset were
    /// broken).
    fn fallback() -> Self {
        Self {
            s: vec![0.0, 1.0],
            tau: vec![0.0, 1.0],
            col: vec![[1.0; 3]; 2],
            color: vec![[1.0; 3]; 2],
            model: EmissionModel::Glow,
            breaks: vec![0.0, 1.0],
            scalar: None,
            unit_distance: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::RayMaterial;

    #[test]
    fn every_preset_builds_and_matches_its_ends() {
        for name in preset_names() {
            let tf = preset(name, (10.0, 20.0), 2.0, Opacity::Ramp).unwrap();
            assert_eq!(tf.scalar_range(), (10.0, 20.0), "{name}");
            assert!((tf.tau_at(20.0) - 0.5).abs() < 1e-15);
            assert_eq!(tf.tau_at(10.0), 0.0);
        }
        let v = preset("viridis", (0.0, 1.0), 1.0, Opacity::Ramp).unwrap();
        let c0 = v.color_at(0.0);
        let c1 = v.color_at(1.0);
        // matplotlib viridis ends: (0.267, 0.005, 0.329) and (0.993, 0.906, 0.144).
        assert!(
            (c0[0] - 0.267).abs() < 0.02 && (c0[2] - 0.329).abs() < 0.02,
            "{c0:?}"
        );
        assert!(
            (c1[0] - 0.993).abs() < 0.02 && (c1[1] - 0.906).abs() < 0.02,
            "{c1:?}"
        );
        let cw = preset("cool-warm", (0.0, 1.0), 1.0, Opacity::Ramp).unwrap();
        let mid = cw.color_at(0.5);
        assert!((mid[0] - 0.865).abs() < 1e-9, "{mid:?}");
        assert!(matches!(
            preset("nope", (0.0, 1.0), 1.0, Opacity::Ramp),
            Err(TfError::UnknownPreset { .. })
        ));
    }

    #[test]
    fn step_opacity_is_a_jump_and_default_handles_empty_range() {
        let tf = preset(
            "grayscale",
            (0.0, 4.0),
            0.5,
            Opacity::Step {
                at: 0.5,
                opacity: 0.8,
            },
        )
        .unwrap();
        assert_eq!(tf.tau_at(1.999), 0.0);
        assert!((tf.tau_at(2.0) - 1.6).abs() < 1e-15);
        let d = TransferFunction::default_for((3.0, 3.0), 20.0);
        let (lo, hi) = d.scalar_range();
        assert!(lo < 3.0 && hi > 3.0);
        assert!((d.tau_at(3.0) - 0.5 / 2.0).abs() < 1e-12);
        assert!(!d.breakpoints().is_empty());
    }
}
