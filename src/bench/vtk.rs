//! VTK's unstructured volume mappers as external points of a bench
//! (`--with-vtk PYTHON`).
//!
//! How it works: the scene goes to VTK as files, so both programs render
//! the same thing.
//! - The mesh as zoovr holds it (after hidden cells are left out and
//!   quadratic cells reduced to corners), written as `.vtu` with one array,
//!   `zoovr_scalar`: the selected field's values (point or cell).
//! - The transfer function as VTK's colour and opacity points with a unit
//!   distance: opacity = extinction x unit distance, the unit chosen so the
//!   largest opacity is 1 (VTK's unstructured mappers take opacity / unit
//!   distance as extinction and emit the colour times it, zoovr's glow
//!   model). Nodes at the same scalar (a jump) are nudged apart by 1e-9 of
//!   the range, as VTK's functions keep one value per scalar.
//! - Each frame's fitted camera (position, focal point, view-up, view
//!   angle, parallel scale), so no camera rule is re-implemented in Python.
//!
//! The script (`scripts/vtk_bench.py`, embedded in the binary and written
//! next to the scene) renders each mapper in its own child process (a crash
//! of one is a failed row, not a failed bench), tetrahedralising first where
//! VTK needs it, and prints one `RESULT {json}` line per mapper and frame.
//! Its PNG images are compared here with the same references as zoovr's
//! rows. VTK's mappers integrate their own tetrahedralisation's linear
//! field, so their error against `faces` mixes a field difference into the
//! algorithm error on cells that are not tetrahedra.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde::Deserialize;
use serde_json::json;

use crate::camera::Camera;
use crate::image::Image;
use crate::io::writer::{write_vtu, Compression};
use crate::mesh::data::{ArrayData, Association, DataArray};
use crate::raycast::FieldModel;
use crate::render::{Geometry, Shading};
use crate::tf::EmissionModel;

use super::{BenchError, FrameRefs, Row};

/// The script, as shipped in `scripts/vtk_bench.py`.
pub const SCRIPT: &str = include_str!("../../scripts/vtk_bench.py");

/// VTK's mappers the bench runs by default, in order.
pub const MAPPERS: &[&str] = &[
    "pt",
    "raycast-linear",
    "raycast-partial",
    "raycast-preint",
    "raycast-homog",
    "zsweep",
];

/// Exit code of the script when its Python has no `vtk` module.
const NO_VTK: i32 = 3;

/// One line the script prints.
#[derive(Debug, Deserialize)]
struct Result_ {
    mapper: String,
    tag: String,
    error: Option<String>,
    #[serde(default)]
    first_s: f64,
    #[serde(default)]
    median_s: f64,
    #[serde(default)]
    min_s: f64,
    #[serde(default)]
    max_s: f64,
    #[serde(default)]
    times_s: Vec<f64>,
    #[serde(default)]
    tetra_s: f64,
    #[serde(default)]
    read_s: f64,
    #[serde(default)]
    cells: usize,
    #[serde(default)]
    peak_rss_mb: Option<f64>,
    image: Option<PathBuf>,
}

fn vtk_err(msg: impl Into<String>) -> BenchError {
    BenchError::Vtk(msg.into())
}

/// A transfer function as VTK's points: colours `[s, r, g, b]`,
/// opacities `[s, a]` and the unit distance.
type VtkTf = (Vec<[f64; 4]>, Vec<[f64; 2]>, f64);

/// The transfer function as VTK's points.
fn tf_points(shading: &Shading) -> Result<VtkTf, BenchError> {
    let tf = &shading.tf;
    if tf.model() == EmissionModel::Independent {
        return Err(vtk_err(
            "--with-vtk: VTK's unstructured mappers have no independent emission; use a glow \
             transfer function",
        ));
    }
    let nodes = tf.nodes();
    let max_tau = nodes.iter().map(|n| n.tau).fold(0.0, f64::max);
    let unit = if max_tau > 0.0 { 1.0 / max_tau } else { 1.0 };
    let (lo, hi) = tf.scalar_range();
    let nudge = (hi - lo).abs().max(f64::MIN_POSITIVE) * 1e-9;
    let mut colours: Vec<[f64; 4]> = Vec::new();
    let mut opacity: Vec<[f64; 2]> = Vec::new();
    let mut last = f64::NEG_INFINITY;
    for n in &nodes {
        let s = if n.s <= last { last + nudge } else { n.s };
        last = s;
        colours.push([s, n.color[0], n.color[1], n.color[2]]);
        opacity.push([s, (n.tau * unit).clamp(0.0, 1.0)]);
    }
    Ok((colours, opacity, unit))
}

/// Writes the mesh with the field as `zoovr_scalar`.
fn write_mesh(path: &Path, geometry: &Geometry, shading: &Shading) -> Result<(), BenchError> {
    let mut mesh = (*geometry.mesh).clone();
    mesh.point_data.clear();
    mesh.cell_data.clear();
    mesh.active_point_scalars = None;
    mesh.active_cell_scalars = None;
    let (assoc, values) = match &shading.field {
        Some(f) => (f.association, f.values.clone()),
        None => (Association::Point, vec![0.0; mesh.points.len()]),
    };
    let array = DataArray {
        name: "zoovr_scalar".into(),
        components: 1,
        data: ArrayData::F64(values),
        vtk_type: "Float64".into(),
    };
    match assoc {
        Association::Point => mesh.point_data.push(array),
        Association::Cell => mesh.cell_data.push(array),
    }
    write_vtu(path, &mesh, Compression::None).map_err(|e| vtk_err(e.to_string()))
}

/// The tag of a frame in file names and the script's lines.
fn tag(f: &FrameRefs) -> String {
    format!("{}x{}_v{}", f.size.0, f.size.1, f.view)
}

/// What a VTK run needs besides the frames.
pub struct VtkOptions<'a> {
    pub python: &'a Path,
    /// A directory of its own (scene, script, images).
    pub dir: &'a Path,
    pub mappers: Vec<String>,
    pub warmup: usize,
    pub repeats: usize,
    pub background: [f32; 3],
    pub load_s: f64,
}

/// Runs VTK's mappers on every frame and returns their rows, with errors
/// against the frames' references.
pub fn run(
    opts: &VtkOptions,
    geometry: &Geometry,
    shading: &Shading,
    frames: &[FrameRefs],
) -> Result<Vec<Row>, BenchError> {
    let (colours, opacity, unit) = tf_points(shading)?;
    let mesh_path = opts.dir.join("scene.vtu");
    write_mesh(&mesh_path, geometry, shading)?;
    let bounds = geometry.mesh.bounds();
    let frame_json: Vec<_> = frames
        .iter()
        .map(|f| {
            let c = Camera::fit(bounds, &f.camera);
            json!({
                "tag": tag(f),
                "width": f.size.0,
                "height": f.size.1,
                "camera": {
                    "position": c.position.to_array(),
                    "focal_point": c.focal_point.to_array(),
                    "view_up": c.up.to_array(),
                    "view_angle": c.view_angle,
                    "ortho": c.ortho,
                    "parallel_scale": c.parallel_scale,
                },
            })
        })
        .collect();
    let association = match shading.field.as_ref().map(|f| f.association) {
        Some(Association::Cell) => "cell",
        _ => "point",
    };
    let scene = json!({
        "mesh": mesh_path,
        "array": "zoovr_scalar",
        "association": association,
        "background": opts.background,
        "tf": { "colors": colours, "opacity": opacity, "unit_distance": unit },
        "mappers": opts.mappers,
        "warmup": opts.warmup,
        "repeats": opts.repeats,
        "out": opts.dir,
        "frames": frame_json,
    });
    let scene_path = opts.dir.join("scene.json");
    let script_path = opts.dir.join("vtk_bench.py");
    let write = |p: &Path, text: &str| {
        std::fs::write(p, text).map_err(|e| BenchError::Write {
            path: p.display().to_string(),
            msg: e.to_string(),
        })
    };
    write(
        &scene_path,
        &serde_json::to_string_pretty(&scene).unwrap_or_default(),
    )?;
    write(&script_path, SCRIPT)?;
    let out = Command::new(opts.python)
        .arg(&script_path)
        .arg(&scene_path)
        .output()
        .map_err(|e| {
            vtk_err(format!(
                "--with-vtk: cannot run '{}': {e}",
                opts.python.display()
            ))
        })?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        Some(0) => {}
        Some(NO_VTK) => {
            return Err(vtk_err(format!(
                "--with-vtk: {}",
                stderr
                    .lines()
                    .last()
                    .unwrap_or("this Python has no vtk module")
                    .trim()
            )))
        }
        code => {
            let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
            return Err(vtk_err(format!(
                "--with-vtk: '{}' failed ({}): {}",
                opts.python.display(),
                code.map_or("killed by a signal".into(), |c| format!("exit code {c}")),
                tail.into_iter().rev().collect::<Vec<_>>().join(" / ")
            )));
        }
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut rows = Vec::new();
    for line in stdout.lines() {
        let Some(text) = line.strip_prefix("RESULT ") else {
            continue;
        };
        let r: Result_ = serde_json::from_str(text)
            .map_err(|e| vtk_err(format!("--with-vtk: unreadable result line ({e}): {text}")))?;
        let Some(frame) = frames.iter().find(|f| tag(f) == r.tag) else {
            continue;
        };
        rows.push(row_of(&r, frame, opts));
    }
    if rows.is_empty() {
        return Err(vtk_err(format!(
            "--with-vtk: the script printed no results (stderr: {})",
            stderr.trim()
        )));
    }
    Ok(rows)
}

fn row_of(r: &Result_, frame: &FrameRefs, opts: &VtkOptions) -> Row {
    let mut row = Row {
        source: "vtk".into(),
        mode: r.mapper.clone(),
        setting: "default".into(),
        size: format!("{}x{}", frame.size.0, frame.size.1),
        width: frame.size.0,
        height: frame.size.1,
        view: frame.view,
        azimuth: frame.camera.azimuth,
        elevation: frame.camera.elevation,
        load_s: opts.load_s + r.read_s,
        setup_s: r.tetra_s,
        total_s: r.median_s,
        total_min_s: r.min_s,
        total_max_s: r.max_s,
        first_s: r.first_s,
        repeats: r.times_s.len(),
        triangles: 0,
        pieces: r.cells,
        peak_rss_mb: r.peak_rss_mb,
        reference: FieldModel::Faces.name().into(),
        ..Default::default()
    };
    if let Some(e) = &r.error {
        row.error = Some(e.clone());
        return row;
    }
    let image = match r.image.as_deref().map(Image::read) {
        Some(Ok(img)) => img,
        Some(Err(e)) => {
            row.error = Some(e.to_string());
            return row;
        }
        None => {
            row.error = Some("no image".into());
            return row;
        }
    };
    row.set_errors(
        &image,
        frame.get(FieldModel::Faces),
        frame.get(FieldModel::Native),
        opts.background,
    );
    row
}
