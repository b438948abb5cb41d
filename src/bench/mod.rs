//! `zoovr bench`: run time against error, for every mode, on one scene.
//!
//! How it works:
//! 1. **Plan.** The modes asked for expand into [`Entry`]s, one per setting
//!    that trades time for error: the exact mode's colour refinement
//!    tolerance, the table modes' resolutions, the ray caster's three field
//!    models ([`entries_for`]). Views turn the camera about the view-up by
//!    equal steps, every other one raised by 30 degrees ([`views`]).
//! 2. **Estimate.** Every entry and both references render once at a small
//!    probe size ([`PROBE_SIDE`] square); the probes scale to the sizes
//!    asked for (ray caster: by pixels; projected modes: by the square root
//!    of the pixels, since their cost is mostly per cell on the software
//!    rasterisers and per pixel on a real GPU) and are multiplied by the
//!    runs. Above the cap ([`BenchConfig::max_seconds`]) the bench stops
//!    before the long part, with its estimate ([`BenchError::TooLong`]).
//!    The probes also warm the caches a first render builds (the sorter's
//!    geometry, the GPU device).
//! 3. **Run.** For each size and view: the references first (the ray
//!    caster on the mode's field and on `native`, surfaces included),
//!    then each entry: `warmup` untimed renders and `repeats` timed ones;
//!    a row keeps the (lower) median run's stage times and the spread of the
//!    totals, the triangles and pieces, the process's peak resident memory
//!    over the row ([`memory`]) and the errors of the median run's image.
//! 4. **Error.** Display values (PNG values in [0, 1] over the background,
//!    before 8-bit rounding), max absolute and RMS over pixels and
//!    channels, and PSNR, against two references: the ray caster on the
//!    same field as the mode (`faces`, or `tets` for `--split all`:
//!    algorithm error) and on the `native` field (algorithm plus model
//!    error). A ray caster row against itself is 0 by definition; its
//!    native columns are the model error of its field.
//!
//! The rows print as a table ([`report`]), and are written as CSV, JSON
//! and a log-log plot of time against error ([`plot`]). VTK's mappers can
//! join as external points ([`vtk`]).

pub mod memory;
pub mod plot;
pub mod report;
pub mod vtk;

use std::time::Instant;

use serde::Serialize;
use thiserror::Error;

use crate::camera::CameraParams;
use crate::image::{compare_display, Image, ImageDiff};
use crate::raycast::FieldModel;
use crate::render::{Mode, PieceDraw, RenderError, RenderOptions, RenderStats, Renderer, Shading};

/// Side of the square probe images the estimate renders.
pub const PROBE_SIDE: u32 = 64;

/// Errors of a bench.
#[derive(Debug, Error)]
pub enum BenchError {
    /// The estimate is over the cap.
    #[error(
        "the bench would take about {estimate_s:.0} s (estimated from {side}x{side} probe \
         renders; longest part: {longest}), over --max-seconds {cap_s:.0}; ask for fewer \
         --sizes, --views or --modes, or raise --max-seconds"
    )]
    TooLong {
        estimate_s: f64,
        cap_s: f64,
        side: u32,
        longest: String,
    },
    /// A reference render failed (nothing can be measured without it).
    #[error("the reference ray caster ({model}) failed: {source}")]
    Reference {
        model: &'static str,
        #[source]
        source: RenderError,
    },
    /// Writing or running the VTK comparison.
    #[error("{0}")]
    Vtk(String),
    /// Writing a report.
    #[error("{path}: {msg}")]
    Write { path: String, msg: String },
}

/// A setting that trades time for error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// The mode as `render` draws it.
    Default,
    /// The exact mode's colour refinement tolerance (`--refine-tol`).
    RefineTol(f64),
    /// A table mode's samples per axis (`--table`).
    Table(u32),
    /// The ray caster's field (`--model`).
    Model(FieldModel),
    /// How exact-frag draws its pieces (`--piece-draw`: regions or quads).
    PieceDraw(PieceDraw),
}

impl Setting {
    /// The label in reports, written as the `render` flag that gives it.
    pub fn label(self) -> String {
        match self {
            Setting::Default => "default".into(),
            Setting::RefineTol(t) => format!("refine-tol={t}"),
            Setting::Table(n) => format!("table={n}"),
            Setting::Model(m) => format!("model={}", m.name()),
            Setting::PieceDraw(d) => format!("piece-draw={}", d.name()),
        }
    }

    /// A number to order the settings of one mode along a line in the plot
    /// (finer last).
    fn rank(self) -> f64 {
        match self {
            Setting::Default => 0.0,
            Setting::RefineTol(t) => -t,
            Setting::Table(n) => n as f64,
            Setting::Model(m) => m as u8 as f64,
            Setting::PieceDraw(d) => d as u8 as f64,
        }
    }

    fn apply(self, opts: &mut RenderOptions) {
        match self {
            Setting::Default => {}
            Setting::RefineTol(t) => opts.projected.refine_tol = t,
            Setting::Table(n) => opts.tables.size = Some(n),
            Setting::Model(m) => opts.reference.model = m,
            Setting::PieceDraw(d) => opts.projected.piece_draw = d,
        }
    }
}

/// One (mode, setting) of the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    pub mode: Mode,
    pub setting: Setting,
}

impl Entry {
    /// The render options of this entry on top of `base`.
    pub fn options(self, base: &RenderOptions) -> RenderOptions {
        let mut o = base.clone();
        o.mode = self.mode;
        self.setting.apply(&mut o);
        o
    }

    /// The field of the reference this entry is measured against for
    /// algorithm error.
    fn same_field(self, base: &RenderOptions) -> FieldModel {
        match self.setting {
            Setting::Model(m) => m,
            _ if base.projected.split_all => FieldModel::Tets,
            _ => FieldModel::Faces,
        }
    }
}

/// The entries of `modes` (in the order given): the settings each mode
/// trades time for error with.
pub fn entries_for(modes: &[Mode]) -> Vec<Entry> {
    let mut out = Vec::new();
    for &mode in modes {
        let settings: Vec<Setting> = match mode {
            Mode::Exact => [0.016, crate::numeric::tolerance::COLOR_REFINE_TOL, 0.001]
                .into_iter()
                .map(Setting::RefineTol)
                .collect(),
            Mode::Preint3d | Mode::Preint2dCyl => {
                [32, 64, 128].into_iter().map(Setting::Table).collect()
            }
            Mode::Preint2d => [128, 256, 512].into_iter().map(Setting::Table).collect(),
            Mode::ExactFrag => [PieceDraw::Regions, PieceDraw::Quads]
                .into_iter()
                .map(Setting::PieceDraw)
                .collect(),
            Mode::Iso => vec![Setting::Default],
            Mode::Raycast => [FieldModel::Faces, FieldModel::Tets, FieldModel::Native]
                .into_iter()
                .map(Setting::Model)
                .collect(),
        };
        out.extend(settings.into_iter().map(|setting| Entry { mode, setting }));
    }
    out
}

/// The modes `--modes all` means: every mode that can draw the scene
/// (`iso` only with surfaces).
pub fn all_modes(surfaces: bool) -> Vec<Mode> {
    Mode::ALL
        .iter()
        .copied()
        .filter(|m| match m {
            Mode::Iso => surfaces,
            _ => true,
        })
        .collect()
}

/// A view: degrees added to the base camera's azimuth and elevation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct View {
    pub azimuth: f64,
    pub elevation: f64,
}

/// `n` views about the base camera: azimuth steps of 360/n degrees, every
/// odd one also raised by 30 degrees of elevation.
pub fn views(n: usize) -> Vec<View> {
    (0..n)
        .map(|k| View {
            azimuth: 360.0 * k as f64 / n as f64,
            elevation: if k % 2 == 1 { 30.0 } else { 0.0 },
        })
        .collect()
}

/// What to bench.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    pub entries: Vec<Entry>,
    pub sizes: Vec<(u32, u32)>,
    pub views: Vec<View>,
    /// Options every render starts from (camera flags, GPU, surfaces).
    pub base: RenderOptions,
    pub warmup: usize,
    pub repeats: usize,
    pub background: [f32; 3],
    /// Seconds the file took to read (reported in every row).
    pub load_s: f64,
    /// Cap on the estimated time of the whole bench.
    pub max_seconds: f64,
    /// Keep every frame's reference images in [`BenchOutput::frames`]
    /// (for external points; they cost 16 bytes per pixel each).
    pub keep_references: bool,
}

impl BenchConfig {
    /// The camera of `size` and `view`.
    pub fn camera(&self, (w, h): (u32, u32), view: View) -> CameraParams {
        let b = &self.base.camera;
        CameraParams {
            width: w,
            height: h,
            azimuth: b.azimuth + view.azimuth,
            elevation: (b.elevation + view.elevation).clamp(-89.0, 89.0),
            ..*b
        }
    }
}

/// One row: a (mode, setting, size, view), its times (seconds) and errors.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Row {
    pub mode: String,
    pub setting: String,
    /// `WxH`.
    pub size: String,
    pub width: u32,
    pub height: u32,
    pub view: usize,
    pub azimuth: f64,
    pub elevation: f64,
    pub load_s: f64,
    pub setup_s: f64,
    pub sort_s: f64,
    pub project_s: f64,
    pub tables_s: f64,
    pub gpu_s: f64,
    pub readback_s: f64,
    /// Median of the timed runs.
    pub total_s: f64,
    pub total_min_s: f64,
    pub total_max_s: f64,
    /// The first render at this size and view (with what it builds).
    pub first_s: f64,
    pub repeats: usize,
    pub triangles: usize,
    pub pieces: usize,
    /// Peak resident memory of the process during the row (MiB; `None`
    /// where the system does not tell).
    pub peak_rss_mb: Option<f64>,
    /// The field of the reference for `max_err`, `rms_err`, `psnr`.
    pub reference: String,
    pub max_err: Option<f64>,
    pub rms_err: Option<f64>,
    pub psnr: Option<f64>,
    /// Against the ray caster on the `native` field.
    pub native_max_err: Option<f64>,
    pub native_rms_err: Option<f64>,
    pub native_psnr: Option<f64>,
    /// Who drew it: `zoovr`, or `vtk` for an external point.
    pub source: String,
    /// Why the row has no figures (a mode that could not render).
    pub error: Option<String>,
    /// For ordering the settings of one mode in the plot.
    #[serde(skip)]
    pub rank: f64,
}

impl Row {
    /// Fills the error columns from the two references' images.
    pub fn set_errors(
        &mut self,
        image: &Image,
        same: Option<&Image>,
        native: Option<&Image>,
        background: [f32; 3],
    ) {
        let diff = |r: &Image| -> Option<ImageDiff> {
            compare_display(image, r, background).ok().map(|d| d.0)
        };
        if let Some(d) = same.and_then(diff) {
            self.max_err = Some(d.max_abs);
            self.rms_err = Some(d.rms);
            self.psnr = Some(d.psnr);
        }
        if let Some(d) = native.and_then(diff) {
            self.native_max_err = Some(d.max_abs);
            self.native_rms_err = Some(d.rms);
            self.native_psnr = Some(d.psnr);
        }
    }
}

/// The references of one frame (size and view), kept for external points
/// ([`vtk`]).
pub struct FrameRefs {
    pub size: (u32, u32),
    pub view: usize,
    pub camera: CameraParams,
    /// The ray caster's images by field.
    pub images: Vec<(FieldModel, Image)>,
}

impl FrameRefs {
    /// The reference image on `model`, if it was rendered.
    pub fn get(&self, model: FieldModel) -> Option<&Image> {
        self.images
            .iter()
            .find(|(m, _)| *m == model)
            .map(|(_, i)| i)
    }
}

/// What a bench produced.
pub struct BenchOutput {
    pub rows: Vec<Row>,
    pub frames: Vec<FrameRefs>,
    /// The estimate made before the runs (seconds).
    pub estimate_s: f64,
}

/// The progress callback: what runs now, runs done, runs in all.
pub type Progress<'a> = &'a mut dyn FnMut(&str, usize, usize);

/// Runs the bench (see the module docs). `images`: where each row's
/// median image is written as PNG, if anywhere.
pub fn run(
    renderer: &mut Renderer,
    shading: &Shading,
    config: &BenchConfig,
    images: Option<&std::path::Path>,
    progress: Progress,
) -> Result<BenchOutput, BenchError> {
    let estimate_s = estimate(renderer, shading, config)?;
    let mut frames = Vec::new();
    let runs_per_entry = config.warmup + config.repeats;
    // The mode's field and `native`.
    let refs_per_frame = 2;
    let total = config.sizes.len()
        * config.views.len()
        * (config.entries.len() * runs_per_entry + refs_per_frame);
    let mut done = 0;
    progress(&format!("estimated about {estimate_s:.0} s"), done, total);
    let mut rows = Vec::new();
    for &size in &config.sizes {
        for (vi, &view) in config.views.iter().enumerate() {
            let camera = config.camera(size, view);
            let mut base = config.base.clone();
            base.camera = camera;
            let what = |name: &str| format!("{name} {}x{} view {vi}", size.0, size.1);
            let same_models: Vec<FieldModel> = {
                let mut m: Vec<FieldModel> = config
                    .entries
                    .iter()
                    .map(|e| e.same_field(&config.base))
                    .collect();
                m.sort_by_key(|m| *m as u8);
                m.dedup();
                m
            };
            // The ray caster's own rows first: their median images are
            // the references they stand for.
            let mut refs: Vec<(FieldModel, Image)> = Vec::new();
            let mut order: Vec<Entry> = config.entries.clone();
            order.sort_by_key(|e| e.mode != Mode::Raycast);
            let mut frame_rows = Vec::new();
            for entry in order {
                if entry.mode != Mode::Raycast {
                    for m in same_models.iter().copied().chain(Some(FieldModel::Native)) {
                        if !refs.iter().any(|(r, _)| *r == m) {
                            progress(&what(&format!("reference {}", m.name())), done, total);
                            done += 1;
                            refs.push((m, reference_image(renderer, shading, &base, m)?));
                        }
                    }
                }
                progress(
                    &what(&format!("{} {}", entry.mode.name(), entry.setting.label())),
                    done,
                    total,
                );
                let opts = entry.options(&base);
                let (mut row, image) = run_entry(renderer, shading, config, &opts);
                done += runs_per_entry;
                row.mode = entry.mode.name().into();
                row.setting = entry.setting.label();
                row.rank = entry.setting.rank();
                row.size = format!("{}x{}", size.0, size.1);
                (row.width, row.height) = size;
                row.view = vi;
                row.azimuth = camera.azimuth;
                row.elevation = camera.elevation;
                row.load_s = config.load_s;
                row.source = "zoovr".into();
                let same = entry.same_field(&config.base);
                row.reference = same.name().into();
                if let Some(img) = image {
                    if let Some(dir) = images {
                        let path = dir.join(image_name(&row));
                        img.write_png(&path, config.background, false)
                            .map_err(|e| BenchError::Write {
                                path: path.display().to_string(),
                                msg: e.to_string(),
                            })?;
                    }
                    if let Setting::Model(m) = entry.setting {
                        refs.push((m, img.clone()));
                    }
                    frame_rows.push((row, Some(img), same));
                } else {
                    frame_rows.push((row, None, same));
                }
            }
            // Any reference no entry needed before (a bench of the ray
            // caster alone still reports its model error).
            if !refs.iter().any(|(r, _)| *r == FieldModel::Native) {
                let m = FieldModel::Native;
                progress(&what(&format!("reference {}", m.name())), done, total);
                done += 1;
                refs.push((m, reference_image(renderer, shading, &base, m)?));
            }
            let find = |m: FieldModel| refs.iter().find(|(r, _)| *r == m).map(|(_, i)| i);
            for (mut row, image, same) in frame_rows {
                if let Some(img) = &image {
                    row.set_errors(img, find(same), find(FieldModel::Native), config.background);
                }
                rows.push(row);
            }
            frames.push(FrameRefs {
                size,
                view: vi,
                camera,
                images: if config.keep_references {
                    refs
                } else {
                    Vec::new()
                },
            });
        }
    }
    progress("done", total, total);
    Ok(BenchOutput {
        rows,
        frames,
        estimate_s,
    })
}

/// The ray caster's image on `model`.
fn reference_image(
    renderer: &mut Renderer,
    shading: &Shading,
    base: &RenderOptions,
    model: FieldModel,
) -> Result<Image, BenchError> {
    let mut o = base.clone();
    o.mode = Mode::Raycast;
    o.reference.model = model;
    renderer
        .render(shading, &o, |_, _| {})
        .map(|(img, _)| img)
        .map_err(|source| BenchError::Reference {
            model: model.name(),
            source,
        })
}

/// The file name of a row's image.
pub fn image_name(row: &Row) -> String {
    let setting = row.setting.replace(['=', '.'], "_");
    format!(
        "{}_{}_{}_{}_v{}.png",
        row.source, row.mode, setting, row.size, row.view
    )
}

/// Renders one entry `warmup + repeats` times; the row's times and counts,
/// and the median run's image (`None` with the row's error set when the
/// mode could not render).
fn run_entry(
    renderer: &mut Renderer,
    shading: &Shading,
    config: &BenchConfig,
    opts: &RenderOptions,
) -> (Row, Option<Image>) {
    let mut row = Row::default();
    memory::reset_peak();
    let mut runs: Vec<(f64, RenderStats, Option<Image>)> = Vec::new();
    for k in 0..config.warmup + config.repeats {
        let t0 = Instant::now();
        match renderer.render(shading, opts, |_, _| {}) {
            Ok((img, stats)) => {
                let t = t0.elapsed().as_secs_f64();
                if k == 0 {
                    row.first_s = t;
                }
                if k >= config.warmup {
                    runs.push((t, stats, Some(img)));
                }
            }
            Err(e) => {
                row.error = Some(e.to_string());
                return (row, None);
            }
        }
    }
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    row.repeats = runs.len();
    row.total_min_s = runs.first().map_or(f64::NAN, |r| r.0);
    row.total_max_s = runs.last().map_or(f64::NAN, |r| r.0);
    // The lower median: a run's own stage times, never an average.
    let mid = (runs.len() - 1) / 2;
    let (t, stats, image) = &mut runs[mid];
    row.total_s = *t;
    fill_stages(&mut row, stats);
    row.peak_rss_mb = memory::peak_mb();
    (row, image.take())
}

fn fill_stages(row: &mut Row, stats: &RenderStats) {
    row.setup_s = stats.setup_s;
    if let Some(p) = stats.projected() {
        row.sort_s = p.sort_s;
        row.project_s = p.project_s;
        row.tables_s = p.table.as_ref().map_or(0.0, |t| t.build_s);
        row.gpu_s = p.gpu_total_s;
        row.readback_s = p.gpu.readback_s;
        row.triangles = p.triangles;
        row.pieces = p.pieces;
    }
}

/// Probes every entry and the references at [`PROBE_SIDE`] and fails with
/// [`BenchError::TooLong`] when the scaled estimate passes the cap.
fn estimate(
    renderer: &mut Renderer,
    shading: &Shading,
    config: &BenchConfig,
) -> Result<f64, BenchError> {
    let side = PROBE_SIDE;
    let view = config.views.first().copied().unwrap_or(View {
        azimuth: 0.0,
        elevation: 0.0,
    });
    let mut base = config.base.clone();
    base.camera = config.camera((side, side), view);
    let probe_px = (side * side) as f64;
    let time = |renderer: &mut Renderer, opts: &RenderOptions| -> f64 {
        let t0 = Instant::now();
        // A failing entry shows its error in its row; here it costs nothing.
        match renderer.render(shading, opts, |_, _| {}) {
            Ok(_) => t0.elapsed().as_secs_f64(),
            Err(_) => 0.0,
        }
    };
    let scale = |mode: Mode, px: f64| -> f64 {
        let r = (px / probe_px).max(1.0);
        if mode == Mode::Raycast {
            r
        } else {
            r.sqrt()
        }
    };
    let frames = config.views.len() as f64;
    let runs = (config.warmup + config.repeats) as f64;
    let mut total = 0.0;
    let mut longest = (0.0, String::new());
    let mut parts: Vec<(String, Mode, f64, f64)> = Vec::new();
    for m in [FieldModel::Faces, FieldModel::Native] {
        let mut o = base.clone();
        o.mode = Mode::Raycast;
        o.reference.model = m;
        let t = time(renderer, &o);
        parts.push((format!("reference {}", m.name()), Mode::Raycast, t, 1.0));
    }
    for e in &config.entries {
        let t = time(renderer, &e.options(&base));
        let label = format!("{} {}", e.mode.name(), e.setting.label());
        parts.push((label, e.mode, t, runs));
    }
    for &(w, h) in &config.sizes {
        let px = w as f64 * h as f64;
        for (label, mode, t, n) in &parts {
            let part = t * scale(*mode, px) * n * frames;
            total += part;
            if part > longest.0 {
                longest = (part, format!("{label} at {w}x{h}, about {part:.0} s"));
            }
        }
    }
    if total > config.max_seconds {
        return Err(BenchError::TooLong {
            estimate_s: total,
            cap_s: config.max_seconds,
            side,
            longest: longest.1,
        });
    }
    Ok(total)
}
