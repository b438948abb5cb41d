//! Transfer-function files: the project's JSON format, VTK-style files such
//! as `bench_tf.json`, and ParaView colour maps.
//!
//! # The zoovr transfer-function format (version 1)
//!
//! ```json
//! {
//!   "zoovr_tf": 1,
//!   "scalar": "Density",
//!   "emission": "glow",
//!   "unit_distance": 0.5,
//!   "points": [
//!     { "s": 0.0, "opacity": 0.0, "rgb": [0.0, 0.0, 1.0] },
//!     { "s": 0.4, "opacity": 0.5, "rgb": [0.0, 0.6, 1.0] },
//!     { "s": 0.4, "tau": 3.0,     "rgb": [1.0, 0.2, 0.0] },
//!     { "s": 1.0, "tau": 0.5,     "rgb": [0.8, 0.0, 0.3] }
//!   ]
//! }
//! ```
//!
//! * `zoovr_tf`: format version, 1. May be omitted (files such as
//!   the benchmark's `bench_tf.json` load as they are); any other
//!   value is an error.
//! * `scalar` (optional): the field to colour by when `--field` is absent.
//! * `emission` (optional): `"glow"` (default; source = extinction x colour)
//!   or `"independent"` (source = the `emission` RGB per unit length).
//! * `unit_distance` (optional): VTK/ParaView's scalar opacity unit
//!   distance; an `opacity` o means extinction `o / unit_distance` (per unit
//!   length). Without it the caller's fallback is used (the CLI passes the
//!   default, bounds diagonal / 10).
//! * Scalars `s` are absolute values of the field, non-decreasing; two
//!   points at the same `s` are a jump (left value first); outside the points
//!   every channel is constant.
//! * Either one list `points`, each with `s`, `rgb`, exactly one of `tau`
//!   (extinction per unit length) or `opacity` (in [0, 1]), and `emission`
//!   (RGB, required for independent emission); or separate lists, merged
//!   onto the union of their scalars: `opacity_points` (`s`, `opacity`) or
//!   `extinction_points` (`s`, `tau`), `color_points` (`s`, `rgb`) and, for
//!   independent emission, `emission_points` (`s`, `rgb`).
//! * `description`, `name`, `comment`: free text, ignored. Other keys are
//!   errors (so that typos do not pass silently).
//!
//! A JSON array, or an object with `RGBPoints`, is read as a ParaView colour
//! map (see the `paraview` module: colour spaces resampled into RGB pieces,
//! opacity `Points` with midpoint/sharpness).
//!
//! Errors are [`TfError`]s: JSON syntax and type errors carry line and
//! column; unsorted points, negative or non-finite values, empty lists and
//! opacities outside [0, 1] name the list and the point index.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{paraview, EmissionModel, TfError, TransferFunction};

/// The format version this build writes and reads.
pub const FORMAT_VERSION: u64 = 1;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProjectFile {
    zoovr_tf: Option<u64>,
    scalar: Option<String>,
    emission: Option<String>,
    unit_distance: Option<f64>,
    points: Option<Vec<PointIn>>,
    opacity_points: Option<Vec<PointIn>>,
    extinction_points: Option<Vec<PointIn>>,
    color_points: Option<Vec<PointIn>>,
    emission_points: Option<Vec<PointIn>>,
    #[allow(dead_code)]
    description: Option<String>,
    #[allow(dead_code)]
    name: Option<String>,
    #[allow(dead_code)]
    comment: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointIn {
    s: f64,
    tau: Option<f64>,
    opacity: Option<f64>,
    rgb: Option<[f64; 3]>,
    emission: Option<[f64; 3]>,
}

#[derive(Serialize)]
struct ProjectOut<'a> {
    zoovr_tf: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    scalar: Option<&'a str>,
    emission: &'static str,
    points: Vec<PointOut>,
}

#[derive(Serialize)]
struct PointOut {
    s: f64,
    tau: f64,
    rgb: [f64; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    emission: Option<[f64; 3]>,
}

impl TransferFunction {
    /// Reads a transfer function from JSON text (project format, VTK-style
    /// or ParaView; see the module docs). `fallback_unit_distance` applies to
    /// opacities when the file gives no `unit_distance` (ParaView files never
    /// do).
    pub fn from_json_str(text: &str, fallback_unit_distance: f64) -> Result<Self, TfError> {
        let value: serde_json::Value = serde_json::from_str(text)?;
        let paraview = match &value {
            serde_json::Value::Array(_) => true,
            serde_json::Value::Object(o) => o.contains_key("RGBPoints"),
            _ => false,
        };
        if paraview {
            check_unit(fallback_unit_distance)?;
            return paraview::from_value(value, fallback_unit_distance);
        }
        // Re-parse from the text so type errors carry line and column.
        let file: ProjectFile = serde_json::from_str(text)?;
        from_project(file, fallback_unit_distance)
    }

    /// Reads a transfer-function file (see [`TransferFunction::from_json_str`]).
    pub fn from_json_file(path: &Path, fallback_unit_distance: f64) -> Result<Self, TfError> {
        let text = std::fs::read_to_string(path).map_err(|source| TfError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_json_str(&text, fallback_unit_distance)
    }

    /// Writes the project format (extinction per point, explicit jumps).
    pub fn to_json(&self) -> String {
        let independent = self.model == EmissionModel::Independent;
        let out = ProjectOut {
            zoovr_tf: FORMAT_VERSION,
            scalar: self.scalar.as_deref(),
            emission: if independent { "independent" } else { "glow" },
            points: (0..self.s.len())
                .map(|i| PointOut {
                    s: self.s[i],
                    tau: self.tau[i],
                    rgb: self.color[i],
                    emission: independent.then_some(self.col[i]),
                })
                .collect(),
        };
        serde_json::to_string_pretty(&out).unwrap_or_default()
    }
}

fn check_unit(u: f64) -> Result<(), TfError> {
    if u.is_finite() && u > 0.0 {
        Ok(())
    } else {
        Err(TfError::UnitDistance(u))
    }
}

/// Extinction of a point: `tau`, or `opacity / unit distance`.
fn extinction(
    what: &'static str,
    index: usize,
    p: &PointIn,
    unit: Option<f64>,
) -> Result<f64, TfError> {
    match (p.tau, p.opacity) {
        (Some(t), None) => Ok(t),
        (None, Some(o)) => {
            if !(0.0..=1.0).contains(&o) {
                return Err(TfError::OpacityRange {
                    what,
                    index,
                    value: o,
                });
            }
            match unit {
                Some(u) => Ok(o / u),
                None => Err(TfError::Format(format!(
                    "{what}: point {index}: opacity needs a unit distance"
                ))),
            }
        }
        (Some(_), Some(_)) => Err(TfError::Format(format!(
            "{what}: point {index}: give either tau or opacity, not both"
        ))),
        (None, None) => Err(TfError::Format(format!(
            "{what}: point {index}: tau or opacity missing"
        ))),
    }
}

fn rgb(
    what: &'static str,
    index: usize,
    v: Option<[f64; 3]>,
    key: &str,
) -> Result<[f64; 3], TfError> {
    v.ok_or_else(|| TfError::Format(format!("{what}: point {index}: {key} missing")))
}

fn from_project(f: ProjectFile, fallback_unit: f64) -> Result<TransferFunction, TfError> {
    if let Some(v) = f.zoovr_tf {
        if v != FORMAT_VERSION {
            return Err(TfError::Version(v));
        }
    }
    let model = match f.emission.as_deref() {
        None | Some("glow") => EmissionModel::Glow,
        Some("independent") => EmissionModel::Independent,
        Some(other) => {
            return Err(TfError::Format(format!(
                "emission must be \"glow\" or \"independent\", not {other:?}"
            )))
        }
    };
    let unit = match f.unit_distance {
        Some(u) => {
            check_unit(u)?;
            Some(u)
        }
        None => check_unit(fallback_unit).ok().map(|_| fallback_unit),
    };
    let independent = model == EmissionModel::Independent;
    let mut tf = if let Some(points) = f.points {
        if f.opacity_points.is_some() || f.extinction_points.is_some() || f.color_points.is_some() {
            return Err(TfError::Format(
                "give either points or separate opacity/colour lists, not both".into(),
            ));
        }
        const W: &str = "points";
        let mut tau = Vec::with_capacity(points.len());
        let mut col = Vec::with_capacity(points.len());
        let mut em = Vec::new();
        for (i, p) in points.iter().enumerate() {
            tau.push((p.s, [extinction(W, i, p, unit)?]));
            col.push((p.s, rgb(W, i, p.rgb, "rgb")?));
            if independent {
                em.push((p.s, rgb(W, i, p.emission, "emission")?));
            }
        }
        TransferFunction::from_channels(&tau, &col, independent.then_some(&em[..]), model)?
    } else {
        let tau: Vec<(f64, [f64; 1])> = match (f.opacity_points, f.extinction_points) {
            (Some(p), None) => p
                .iter()
                .enumerate()
                .map(|(i, q)| Ok((q.s, [extinction("opacity_points", i, q, unit)?])))
                .collect::<Result<_, TfError>>()?,
            (None, Some(p)) => p
                .iter()
                .enumerate()
                .map(|(i, q)| Ok((q.s, [extinction("extinction_points", i, q, unit)?])))
                .collect::<Result<_, TfError>>()?,
            (Some(_), Some(_)) => {
                return Err(TfError::Format(
                    "give opacity_points or extinction_points, not both".into(),
                ))
            }
            (None, None) => {
                return Err(TfError::Format(
                    "no points, opacity_points or extinction_points".into(),
                ))
            }
        };
        let col: Vec<(f64, [f64; 3])> = f
            .color_points
            .ok_or_else(|| TfError::Format("color_points missing".into()))?
            .iter()
            .enumerate()
            .map(|(i, q)| Ok((q.s, rgb("color_points", i, q.rgb, "rgb")?)))
            .collect::<Result<_, TfError>>()?;
        let em: Option<Vec<(f64, [f64; 3])>> = match f.emission_points {
            Some(p) => Some(
                p.iter()
                    .enumerate()
                    .map(|(i, q)| Ok((q.s, rgb("emission_points", i, q.rgb, "rgb")?)))
                    .collect::<Result<_, TfError>>()?,
            ),
            None => None,
        };
        TransferFunction::from_channels(&tau, &col, em.as_deref(), model)?
    };
    tf.scalar = f.scalar;
    tf.unit_distance = f.unit_distance;
    Ok(tf)
}
