//! `zoovr animate SERIES -o DIR [...]`: numbered frames of a time series
//! (or a turntable of one dataset), then optionally a GIF or an MP4.
//!
//! How a run goes:
//! 1. The steps are listed ([`zoovr::io::sequence::list_steps`]) and the
//!    frames planned: frame `i` shows step `i` (a single dataset with
//!    `--count N` gives N frames of it) from azimuth `--azimuth + i *
//!    --orbit`; `--frames A..B` keeps frames A to B, named by their index
//!    in the whole run, so separate ranges add up to one run.
//! 2. The colour range: `--range`, else a first pass over every step's
//!    values (`--range-from all`, the default) or step 0's
//!    (`--range-from first`). Always over the whole series, whatever
//!    `--frames` keeps, so every process of a farmed run agrees.
//! 3. The camera is fitted once, to step 0's bounds, and stays fixed (or
//!    turns with `--orbit`), so a deforming mesh moves in a still frame.
//! 4. The frames are rendered by one [`Renderer`]: a loader thread reads
//!    the next step while the current one is drawn; each step is compared
//!    with the geometry drawn before ([`Geometry::next_step`]) and the
//!    renderer keeps what did not change ([`StepChange`]); under a fixed
//!    camera it keeps each part's projected regions too
//!    (`ProjectedOptions::keep_regions`), which values-only steps reuse.
//!    Every frame is
//!    written atomically (temporary file, then rename), so an interrupted
//!    run leaves only whole frames.
//! 5. `--gif` / `--mp4` assemble the frames of DIR ([`super::assemble`]).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use anyhow::{anyhow, bail, Context as _, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;

use zoovr::camera::Camera;
use zoovr::gpu::PendingContext;
use zoovr::io::{self, ReadOptions, TimeStep};
use zoovr::mesh::Mesh;
use zoovr::render::{
    Geometry, ModeStats, RenderOptions, RenderStats, Renderer, SceneSpec, Shading, StepChange,
};

use super::args::{parse_finite, parse_frames, parse_positive};
use super::assemble::{self, AssembleArgs};
use super::render::ViewArgs;
use super::UsageError;

/// Where the colour range comes from when `--range` is absent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RangeFrom {
    /// Min..max of the field over every step (a first pass over the values).
    All,
    /// Min..max of the field in step 0.
    First,
}

#[derive(Args, Debug)]
pub struct AnimateArgs {
    /// The time series: a .pvd or .series collection, a quoted glob
    /// pattern ('out/step_*.vtu'), a folder of numbered dataset files, or
    /// one dataset (a turntable with --orbit and --count).
    #[arg(required_unless_present = "assemble")]
    pub series: Option<PathBuf>,
    /// Output folder for the frames DIR/frame_NNNNN.png (made if missing).
    #[arg(short, long, value_name = "DIR", required_unless_present_any = ["assemble", "range_only"])]
    pub output: Option<PathBuf>,
    /// Render nothing: assemble the frames already in DIR (e.g. written by
    /// several `--frames` runs) into --gif and/or --mp4.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["series", "output", "frames"])]
    pub assemble: Option<PathBuf>,
    /// Also write an animated GIF of the frames (one global palette,
    /// looping forever).
    #[arg(long, value_name = "FILE")]
    pub gif: Option<PathBuf>,
    /// Also write an MP4 (H.264, Constrained Baseline) of the frames,
    /// encoded in process (OpenH264); odd sizes are padded by one pixel.
    #[arg(long, value_name = "FILE")]
    pub mp4: Option<PathBuf>,
    /// Frames per second of the GIF and MP4.
    #[arg(long, value_parser = parse_positive, default_value_t = 10.0)]
    pub fps: f64,
    /// Degrees of azimuth added per frame (a turning camera).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true, value_name = "DEG")]
    pub orbit: Option<f64>,
    /// Frames of a single dataset (a turntable with --orbit).
    #[arg(long, value_name = "N")]
    pub count: Option<usize>,
    /// Render only frames A..B (inclusive, indices in the whole run).
    #[arg(long, value_parser = parse_frames, value_name = "A..B")]
    pub frames: Option<(usize, usize)>,
    /// Colour range when --range is absent: all (every step's values, a
    /// first pass over the series) or first (step 0's).
    #[arg(long, value_enum, conflicts_with = "range")]
    pub range_from: Option<RangeFrom>,
    /// Render nothing: write the colour range the run would use (JSON
    /// `{"range": [LO, HI]}`) to FILE, for --range-file in separate
    /// processes of one run.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["output", "frames", "gif", "mp4"])]
    pub range_only: Option<PathBuf>,
    /// Read the colour range from a file written by --range-only.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["range", "range_from", "range_only"])]
    pub range_file: Option<PathBuf>,
    /// Reuse nothing across frames: a new geometry, topology, sorter, GPU
    /// context and projection per step, as separate `render` runs would
    /// (to measure what reuse saves).
    #[arg(long)]
    pub no_reuse: bool,
    #[command(flatten)]
    pub view: ViewArgs,
}

/// One frame of the run.
#[derive(Clone, Copy, Debug)]
struct FramePlan {
    index: usize,
    step: usize,
    azimuth: f64,
}

/// What `--stats` reports per frame.
#[derive(Debug, Serialize)]
struct FrameReport {
    frame: usize,
    step: usize,
    time: f64,
    file: String,
    /// What changed since the frame before: none, values, points, cells, or
    /// camera (an orbit on the same step).
    change: &'static str,
    /// The scalar range the transfer function maps (the same in every
    /// frame).
    range: (f64, f64),
    /// Waiting for the step's file (read by the loader thread), preparing
    /// its geometry and shading.
    load_s: f64,
    /// The visibility sort.
    sort_s: f64,
    /// Everything else in the render: projection, drawing, readback.
    draw_s: f64,
    /// Writing the PNG.
    write_s: f64,
    total_s: f64,
    render: RenderStats,
}

/// The name of frame `i` in the output folder.
pub fn frame_name(i: usize) -> String {
    format!("frame_{i:05}.png")
}

fn plan(args: &AnimateArgs, series: &Path, steps: &[TimeStep]) -> Result<Vec<FramePlan>> {
    let count = match args.count {
        Some(0) => return Err(UsageError("--count must be at least 1".into()).into()),
        Some(n) if steps.len() == 1 => n,
        Some(_) => {
            return Err(UsageError(format!(
                "--count is for a single dataset; {} has {} steps (one frame each)",
                series.display(),
                steps.len()
            ))
            .into())
        }
        None => steps.len(),
    };
    let orbit = args.orbit.unwrap_or(0.0);
    let all: Vec<FramePlan> = (0..count)
        .map(|i| FramePlan {
            index: i,
            step: if steps.len() == 1 { 0 } else { i },
            azimuth: args.view.azimuth + i as f64 * orbit,
        })
        .collect();
    match args.frames {
        None => Ok(all),
        Some((a, b)) if b < all.len() => Ok(all[a..=b].to_vec()),
        Some((a, b)) => Err(UsageError(format!(
            "--frames {a}..{b}: the run has {} frames (0..{})",
            all.len(),
            all.len() - 1
        ))
        .into()),
    }
}

/// Reads step `k` (its errors name the file).
fn read_step(steps: &[TimeStep], k: usize, opts: &ReadOptions) -> Result<Mesh> {
    let path = &steps[k].path;
    io::read(path, opts).with_context(|| format!("step {k}"))
}

/// The field's name and association in a shading, to check every step
/// renders the same field.
fn field_key(s: &Shading) -> Option<(String, zoovr::field::Association)> {
    s.field.as_ref().map(|f| (f.name.clone(), f.association))
}

fn check_field(
    want: &Option<(String, zoovr::field::Association)>,
    got: &Shading,
    step: &TimeStep,
) -> Result<()> {
    let got = field_key(got);
    if &got != want {
        let show = |k: &Option<(String, zoovr::field::Association)>| match k {
            Some((n, a)) => format!("{a:?} field '{n}'"),
            None => "no field".to_string(),
        };
        bail!(
            "{}: this step renders {}, but the first step renders {} (give --field)",
            step.path.display(),
            show(&got),
            show(want)
        );
    }
    Ok(())
}

/// The colour range (module docs, step 2), or `None` where there is no
/// field.
fn colour_range(
    args: &AnimateArgs,
    steps: &[TimeStep],
    ropts: &ReadOptions,
) -> Result<Option<(f64, f64)>> {
    if let Some(r) = args.view.scene.range {
        return Ok(Some(r));
    }
    if let Some(file) = &args.range_file {
        return read_range_file(file);
    }
    let spec = args.view.scene_spec();
    let upto = match args.range_from.unwrap_or(RangeFrom::All) {
        RangeFrom::All => steps.len(),
        RangeFrom::First => 1,
    };
    let mut range: Option<(f64, f64)> = None;
    let mut first_field = None;
    for (k, step) in steps.iter().take(upto).enumerate() {
        let mesh = read_step(steps, k, ropts)?;
        let (mesh, _, _) = Geometry::prepare(mesh, spec.show_hidden)
            .with_context(|| format!("{}", step.path.display()))?;
        let shading = Shading::build_for_mesh(&mesh, &spec)
            .with_context(|| format!("{}", step.path.display()))?;
        if k == 0 {
            first_field = field_key(&shading);
        } else {
            check_field(&first_field, &shading, step)?;
        }
        if let Some(f) = &shading.field {
            let (lo, hi) = f.range;
            if lo.is_finite() && hi.is_finite() {
                range = Some(match range {
                    Some((a, b)) => (a.min(lo), b.max(hi)),
                    None => (lo, hi),
                });
            }
        }
    }
    Ok(range)
}

/// A warning for each `--iso` value outside the range the field takes over
/// the whole series (that surface is drawn in no frame). Only where that
/// range was read from every step (not `--range`, a range file or
/// `--range-from first`).
fn iso_range_warnings(args: &AnimateArgs, range: Option<(f64, f64)>) {
    let whole_series = args.view.scene.range.is_none()
        && args.range_file.is_none()
        && args.range_from.unwrap_or(RangeFrom::All) == RangeFrom::All;
    let (Some(list), Some((lo, hi)), true) = (&args.view.iso, range, whole_series) else {
        return;
    };
    for s in &list.0 {
        if !(s.value >= lo && s.value <= hi) {
            eprintln!(
                "zoovr: warning: isovalue {} is outside the range [{lo}, {hi}] the field takes \
                 over the series: that surface is drawn in no frame",
                s.value
            );
        }
    }
}

/// The range of a `--range-only` file.
fn read_range_file(file: &Path) -> Result<Option<(f64, f64)>> {
    #[derive(serde::Deserialize)]
    struct RangeFile {
        range: Option<(f64, f64)>,
    }
    let text = std::fs::read_to_string(file)
        .with_context(|| format!("{}: cannot read the range file", file.display()))?;
    let r: RangeFile = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: not a range file (expected {{\"range\": [LO, HI]}})",
            file.display()
        )
    })?;
    if let Some((lo, hi)) = r.range {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            bail!("{}: bad range [{lo}, {hi}]", file.display());
        }
    }
    Ok(r.range)
}

/// A progress bar of frames on a terminal (hidden otherwise).
fn frame_bar(n: usize) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(n as u64);
    if std::io::stderr().is_terminal() {
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "frame {pos}/{len} [{bar:30}] {elapsed} (ETA {eta}) {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    bar
}

pub fn run(args: &AnimateArgs) -> Result<()> {
    if let Some(dir) = &args.assemble {
        if args.gif.is_none() && args.mp4.is_none() {
            return Err(UsageError("--assemble needs --gif FILE and/or --mp4 FILE".into()).into());
        }
        return assemble::run(&AssembleArgs {
            dir: dir.clone(),
            gif: args.gif.clone(),
            mp4: args.mp4.clone(),
            fps: args.fps,
            only: None,
        });
    }
    if let (Some(series), Some(file)) = (&args.series, &args.range_only) {
        return write_range(args, series, file);
    }
    let (Some(series), Some(out)) = (&args.series, &args.output) else {
        return Err(UsageError("give SERIES and -o DIR (or --assemble DIR)".into()).into());
    };
    render_series(args, series, out)
}

/// `--range-only FILE`: the colour range of the whole series, as JSON.
fn write_range(args: &AnimateArgs, series: &Path, file: &Path) -> Result<()> {
    let steps = io::sequence::list_steps(series)?;
    let ropts = args.view.scene.read_options();
    let range = colour_range(args, &steps, &ropts)?;
    let text = serde_json::to_string(&serde_json::json!({ "range": range }))?;
    std::fs::write(file, text + "\n")
        .with_context(|| format!("{}: cannot write the range", file.display()))?;
    Ok(())
}

/// Renders the planned frames of `series` into `out` (module docs, steps 1
/// to 4), then assembles them (step 5).
fn render_series(args: &AnimateArgs, series: &Path, out: &Path) -> Result<()> {
    super::interrupt::install();
    let steps = io::sequence::list_steps(series)?;
    // A collection's times win; steps found by a folder or a pattern take
    // the file's own TimeValue where it has one, else their index.
    let collection = series.is_file()
        && matches!(
            io::detect_format(series),
            Ok(io::Format::Pvd | io::Format::Series)
        );
    let frames = plan(args, series, &steps)?;
    if args.mp4.is_some() {
        assemble::check_mp4_size(args.view.size)?;
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot make the output folder", out.display()))?;
    let ropts = args.view.scene.read_options();
    let opts = args.view.render_options();
    // A fixed camera over several steps: each part's regions are kept and
    // take the next step's values where only values change.
    let keep_regions =
        !args.no_reuse && frames.len() > 1 && frames.iter().all(|f| f.azimuth == frames[0].azimuth);
    let pending = opts
        .mode
        .info()
        .gpu
        .then(|| zoovr::gpu::Context::spawn(&opts.gpu));
    let range = colour_range(args, &steps, &ropts)?;
    iso_range_warnings(args, range);
    let mut spec = args.view.scene_spec();
    if range.is_some() {
        spec.range = range;
    }

    // The steps in the order the frames need them, read ahead by a loader
    // thread (one step in flight) while the frame before is drawn.
    let mut needed: Vec<usize> = Vec::new();
    for f in &frames {
        if needed.last() != Some(&f.step) {
            needed.push(f.step);
        }
    }
    let bar = frame_bar(frames.len());
    let mut reports = Vec::new();
    let mut drawer = Drawer {
        args,
        spec: &spec,
        steps: &steps,
        ropts: &ropts,
        out,
        collection,
        first_step: frames.first().map_or(0, |f| f.step),
        opts,
        keep_regions,
        renderer: None,
        pending,
        current: None,
        first_field: None,
        camera_bounds: None,
    };
    let result = std::thread::scope(|scope| -> Result<()> {
        let (tx, rx) = mpsc::sync_channel::<(usize, Result<Mesh>)>(1);
        let (steps_ref, ropts_ref, needed_ref) = (&steps, &ropts, &needed);
        scope.spawn(move || {
            for &k in needed_ref {
                let mesh = read_step(steps_ref, k, ropts_ref);
                let failed = mesh.is_err();
                if tx.send((k, mesh)).is_err() || failed {
                    break;
                }
            }
        });
        for f in &frames {
            if super::interrupt::requested() {
                break;
            }
            let t0 = Instant::now();
            let on_screen = matches!(&drawer.current, Some((k, _, _)) if *k == f.step);
            let change = if !on_screen {
                let (k, mesh) = rx
                    .recv()
                    .map_err(|_| anyhow!("the loader thread stopped"))?;
                debug_assert_eq!(k, f.step);
                drawer.load(k, mesh?)?
            } else if drawer.opts.camera.azimuth == f.azimuth {
                "none"
            } else {
                "camera"
            };
            let report = drawer.draw(f, change, t0)?;
            bar.set_message(format!(
                "load {:.0} ms, sort {:.0} ms, draw {:.0} ms",
                report.load_s * 1e3,
                report.sort_s * 1e3,
                report.draw_s * 1e3
            ));
            bar.inc(1);
            emit(args, &report)?;
            reports.push(report);
        }
        Ok(())
    });
    bar.finish_and_clear();
    finish(args, out, &frames, &reports, result)
}

/// What the frame loop keeps from frame to frame: the one renderer (made
/// at the first step, then told what each step changed), the GPU device
/// opening meanwhile, the step on screen with its shading and time, and
/// the camera's bounds (step 0's).
struct Drawer<'a> {
    args: &'a AnimateArgs,
    spec: &'a SceneSpec,
    steps: &'a [TimeStep],
    ropts: &'a ReadOptions,
    out: &'a Path,
    /// Whether the series is a collection, whose times win over the files'.
    collection: bool,
    /// The step of the first frame, whose field every step must render.
    first_step: usize,
    opts: RenderOptions,
    /// Keep the parts' regions for the next frame (a fixed camera), from
    /// frames whose step changed no points ([`Drawer::draw`]).
    keep_regions: bool,
    renderer: Option<Renderer>,
    pending: Option<PendingContext>,
    current: Option<(usize, Shading, f64)>,
    first_field: Option<(String, zoovr::field::Association)>,
    camera_bounds: Option<[f64; 6]>,
}

impl Drawer<'_> {
    /// Puts step `k` (its mesh read) on screen: builds the renderer at the
    /// first step, else tells it what changed, and the step's shading;
    /// returns the change's name.
    fn load(&mut self, k: usize, mesh: Mesh) -> Result<&'static str> {
        let step = &self.steps[k];
        let time = match mesh.source.time_value {
            Some(t) if !self.collection => t,
            _ => step.time,
        };
        let at = || format!("{}", step.path.display());
        let (no_reuse, hidden) = (self.args.no_reuse, self.spec.show_hidden);
        if no_reuse {
            self.renderer = None;
        }
        let change = match self.renderer.as_mut() {
            None if no_reuse && self.current.is_some() => {
                let g = Geometry::build(mesh, hidden).with_context(at)?;
                self.renderer = Some(Renderer::new(g));
                StepChange::Cells
            }
            None => {
                let g = Geometry::build(mesh, hidden).with_context(at)?;
                let mut r = Renderer::new(g);
                if let Some(p) = self.pending.take() {
                    r.set_pending_gpu(p);
                }
                self.renderer = Some(r);
                StepChange::None
            }
            Some(r) => {
                let (g, change) = r.geometry().next_step(mesh, hidden).with_context(at)?;
                r.set_geometry(g, change);
                if change == StepChange::Cells && !no_reuse {
                    eprintln!(
                        "zoovr: note: {}: its cells differ from the step before; \
                         rendered with a new topology (nothing reused)",
                        step.path.display()
                    );
                }
                change
            }
        };
        let r = self
            .renderer
            .as_ref()
            .ok_or_else(|| anyhow!("no renderer"))?;
        let shading = Shading::build(r.geometry(), self.spec).with_context(at)?;
        self.args.view.non_finite_warning(&shading, &step.path);
        if self.current.is_none() && k == self.first_step {
            self.first_field = field_key(&shading);
        } else {
            check_field(&self.first_field, &shading, step)?;
        }
        self.current = Some((k, shading, time));
        Ok(change.name())
    }

    /// Renders frame `f` of the step on screen and writes it; `t0` is when
    /// the frame began, `change` what its step changed.
    fn draw(&mut self, f: &FramePlan, change: &'static str, t0: Instant) -> Result<FrameReport> {
        let step = &self.steps[f.step];
        let renderer = self
            .renderer
            .as_mut()
            .ok_or_else(|| anyhow!("no renderer"))?;
        let Some((_, shading, time)) = &self.current else {
            bail!("no shading");
        };
        let bounds = match self.camera_bounds {
            Some(b) => b,
            None => {
                let b = step0_bounds(
                    self.steps,
                    f.step,
                    renderer,
                    self.ropts,
                    self.spec.show_hidden,
                )?;
                self.camera_bounds = Some(b);
                b
            }
        };
        let load_s = t0.elapsed().as_secs_f64();
        self.opts.camera.azimuth = f.azimuth;
        // Regions are kept from the first frame and from values-only steps:
        // a deforming mesh (new points every step) would only pay for
        // keeping them.
        self.opts.projected.keep_regions = self.keep_regions && matches!(change, "none" | "values");
        let camera = Camera::fit(bounds, &self.opts.camera);
        let (image, stats) = renderer
            .render_with_camera(shading, &self.opts, &camera, |_, _| {})
            .with_context(|| format!("{}", step.path.display()))?;
        let t_write = Instant::now();
        let path = self.out.join(frame_name(f.index));
        super::legend::write_frame(&image, &path, &self.args.view, shading, Some(*time))?;
        let write_s = t_write.elapsed().as_secs_f64();
        let sort_s = match &stats.detail {
            ModeStats::Projected(p) => p.sort_s,
            _ => 0.0,
        };
        Ok(FrameReport {
            frame: f.index,
            step: f.step,
            time: *time,
            file: step.path.display().to_string(),
            change,
            range: shading.range,
            load_s,
            sort_s,
            draw_s: (stats.total_s - sort_s).max(0.0),
            write_s,
            total_s: t0.elapsed().as_secs_f64(),
            render: stats,
        })
    }
}

/// After the frame loop: says which frames are complete when it failed or
/// was interrupted, prints the `--stats` summary, and assembles the GIF
/// or MP4 of the frames done.
fn finish(
    args: &AnimateArgs,
    out: &Path,
    frames: &[FramePlan],
    reports: &[FrameReport],
    result: Result<()>,
) -> Result<()> {
    let done: Vec<usize> = reports.iter().map(|r| r.frame).collect();
    if let Err(e) = result {
        if !done.is_empty() {
            eprintln!(
                "zoovr: frames {} are complete in {}",
                ranges(&done),
                out.display()
            );
        }
        return Err(e);
    }
    if super::interrupt::requested() && done.len() < frames.len() {
        bail!(
            "interrupted: frames {} are complete in {} (no partial frame is left)",
            if done.is_empty() {
                "none".to_string()
            } else {
                ranges(&done)
            },
            out.display()
        );
    }
    if args.view.stats && !args.view.json {
        summary(reports);
    }
    if args.gif.is_some() || args.mp4.is_some() {
        assemble::run(&AssembleArgs {
            dir: out.to_path_buf(),
            gif: args.gif.clone(),
            mp4: args.mp4.clone(),
            fps: args.fps,
            only: Some(done),
        })?;
    }
    Ok(())
}

/// The bounds the camera is fitted to: step 0's (already loaded when the
/// run starts at step 0, else read once).
fn step0_bounds(
    steps: &[TimeStep],
    current: usize,
    renderer: &Renderer,
    ropts: &ReadOptions,
    show_hidden: bool,
) -> Result<[f64; 6]> {
    if current == 0 {
        return Ok(renderer.geometry().mesh.bounds());
    }
    let mesh = read_step(steps, 0, ropts)?;
    let (mesh, _, _) = Geometry::prepare(mesh, show_hidden)
        .with_context(|| format!("{}", steps[0].path.display()))?;
    Ok(mesh.bounds())
}

/// Prints one frame's report (`--stats`: a line on stderr; `--stats
/// --json`: one JSON object on stdout).
fn emit(args: &AnimateArgs, r: &FrameReport) -> Result<()> {
    if args.view.json {
        println!("{}", serde_json::to_string(r)?);
    } else if args.view.stats {
        eprintln!(
            "frame {:5}  step {:4}  t={:<10} change {:<6}  load {:8.1} ms  sort {:8.1} ms  draw {:8.1} ms  write {:6.1} ms  total {:8.1} ms",
            r.frame,
            r.step,
            r.time,
            r.change,
            r.load_s * 1e3,
            r.sort_s * 1e3,
            r.draw_s * 1e3,
            r.write_s * 1e3,
            r.total_s * 1e3
        );
    }
    Ok(())
}

/// The human summary of `--stats`: frames by change, mean times.
fn summary(reports: &[FrameReport]) {
    if reports.is_empty() {
        return;
    }
    let n = reports.len() as f64;
    let mean = |f: &dyn Fn(&FrameReport) -> f64| reports.iter().map(f).sum::<f64>() / n * 1e3;
    let count = |c: &str| reports.iter().filter(|r| r.change == c).count();
    eprintln!(
        "frames       {}  (changes: {} values only, {} points, {} cells, {} camera only)",
        reports.len(),
        count("values"),
        count("points"),
        count("cells"),
        count("camera")
    );
    eprintln!(
        "mean         load {:.1} ms, sort {:.1} ms, draw {:.1} ms, write {:.1} ms, total {:.1} ms per frame",
        mean(&|r| r.load_s),
        mean(&|r| r.sort_s),
        mean(&|r| r.draw_s),
        mean(&|r| r.write_s),
        mean(&|r| r.total_s)
    );
}

/// `0..3, 7` for `[0, 1, 2, 3, 7]`.
fn ranges(v: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            v[i].to_string()
        } else {
            format!("{}..{}", v[i], v[j])
        });
        i = j + 1;
    }
    out.join(", ")
}

#[cfg(test)]
mod tests {
    use super::ranges;

    #[test]
    fn ranges_of_frames() {
        assert_eq!(ranges(&[0, 1, 2, 3, 7]), "0..3, 7");
        assert_eq!(ranges(&[5]), "5");
    }
}
