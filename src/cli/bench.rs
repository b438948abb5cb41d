//! `zoovr bench FILE`: run time against error for every mode
//! ([`zoovr::bench`] does the work; this file parses flags, loads the
//! scene, shows progress and writes the reports).

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use clap::Args;

use zoovr::bench::{self, report, vtk, BenchConfig};
use zoovr::camera::CameraParams;
use zoovr::gpu::{AccumFormat, Backend, GpuOptions};
use zoovr::render::iso::{IsoOptions, Lighting};
use zoovr::render::{Geometry, Mode, ProjectedOptions, RenderOptions, Renderer, Shading};

use super::args::{parse_positive, parse_rgb, parse_size};
use super::render::IsoList;
use super::scene::SceneArgs;

/// `--modes`: `all` or a comma-separated list of mode names.
#[derive(Clone, Debug)]
pub struct ModeList(Option<Vec<Mode>>);

fn parse_modes(s: &str) -> Result<ModeList, String> {
    if s.trim() == "all" {
        return Ok(ModeList(None));
    }
    let mut out = Vec::new();
    for name in s.split(',') {
        let m: Mode = name.trim().parse().map_err(|_| {
            format!(
                "unknown mode '{}' (modes: all, {})",
                name.trim(),
                Mode::names().join(", ")
            )
        })?;
        if !out.contains(&m) {
            out.push(m);
        }
    }
    Ok(ModeList(Some(out)))
}

/// `--sizes`: image sizes.
#[derive(Clone, Debug)]
pub struct SizeList(Vec<(u32, u32)>);

fn parse_sizes(s: &str) -> Result<SizeList, String> {
    let v: Result<Vec<(u32, u32)>, String> = s
        .split(',')
        .map(|t| {
            let t = t.trim();
            if t.contains(['x', 'X']) {
                parse_size(t)
            } else {
                parse_size(&format!("{t}x{t}"))
            }
        })
        .collect();
    v.map(SizeList)
}

fn parse_count(s: &str) -> Result<usize, String> {
    let n: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("expected a whole number, got '{s}'"))?;
    if n > 1000 {
        return Err(format!("{n} is more than 1000"));
    }
    Ok(n)
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Dataset (VTK legacy or XML, .pvd/.series first step, PLOT3D grid).
    pub file: PathBuf,
    /// Modes to run: `all` (every mode that can draw the scene: iso only
    /// with --iso, exact only without) or a list, e.g. exact,preint3d,raycast.
    /// Each runs at the settings it trades time for error with: exact at
    /// --refine-tol 0.016, 0.004 and 0.001; preint3d and preint2d-cyl at
    /// --table 32, 64, 128; preint2d at --table 128, 256, 512; raycast with
    /// --model faces, tets and native.
    #[arg(long, value_parser = parse_modes, default_value = "all")]
    pub modes: ModeList,
    /// Image sizes, comma-separated: N (square) or WxH.
    #[arg(long, value_parser = parse_sizes, default_value = "512")]
    pub sizes: SizeList,
    /// Views: N turns of 360/N degrees about the view-up from the camera
    /// flags, every other one raised by 30 degrees.
    #[arg(long, value_parser = parse_count, default_value = "1")]
    pub views: usize,
    /// Untimed renders before the timed ones, per row.
    #[arg(long, value_parser = parse_count, default_value = "1")]
    pub warmup: usize,
    /// Timed renders per row (the row reports their median and spread).
    #[arg(long, value_parser = parse_count, default_value = "3")]
    pub repeats: usize,
    /// Write one CSV line per (mode, setting, size, view).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write the rows and the run's description as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write a log-log plot of time against error (PNG).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Write every row's image (PNG) into this directory.
    #[arg(long, value_name = "DIR")]
    pub images: Option<PathBuf>,
    /// Also time VTK's unstructured volume mappers on the same mesh,
    /// field, transfer function, cameras and sizes with this Python (it
    /// needs the `vtk` module: PYTHON -m pip install vtk).
    #[arg(long, value_name = "PYTHON")]
    pub with_vtk: Option<PathBuf>,
    /// VTK mappers for --with-vtk: pt, raycast-linear, raycast-partial,
    /// raycast-preint, raycast-homog, zsweep (default: all of them).
    #[arg(
        long,
        value_name = "M,M..",
        value_delimiter = ',',
        requires = "with_vtk"
    )]
    pub vtk_mappers: Option<Vec<String>>,
    /// Stop before running when the estimate (from small probe renders)
    /// is over this many seconds.
    #[arg(long, value_parser = parse_positive, default_value_t = 3600.0)]
    pub max_seconds: f64,
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Camera azimuth in degrees (views turn from it).
    #[arg(long, value_parser = super::args::parse_finite, default_value_t = 0.0, allow_hyphen_values = true)]
    pub azimuth: f64,
    /// Camera elevation in degrees.
    #[arg(long, value_parser = super::args::parse_finite, default_value_t = 0.0, allow_hyphen_values = true)]
    pub elevation: f64,
    /// Camera roll in degrees.
    #[arg(long, value_parser = super::args::parse_finite, default_value_t = 0.0, allow_hyphen_values = true)]
    pub roll: f64,
    /// Zoom factor (1.25 = closer).
    #[arg(long, value_parser = parse_positive, default_value_t = 1.0)]
    pub zoom: f64,
    /// Orthographic projection.
    #[arg(long)]
    pub ortho: bool,
    /// `--split all`: the projected modes draw every cell as its tets (and
    /// are measured against the ray caster on `tets`).
    #[arg(long, value_parser = ["all"])]
    pub split: Option<String>,
    /// Isosurfaces (as for render): every mode that can draws them, and
    /// `all` includes --mode iso.
    #[arg(long, value_parser = super::render::parse_iso, allow_hyphen_values = true, value_name = "V[:STYLE],..")]
    pub iso: Option<IsoList>,
    /// Light of the isosurfaces: smooth, flat or none.
    #[arg(long, value_enum, default_value_t = Lighting::Smooth)]
    pub shading: Lighting,
    /// Background colour R,G,B in [0,1] (errors are measured over it).
    #[arg(long, value_parser = parse_rgb, default_value = "0,0,0")]
    pub background: [f32; 3],
    /// GPU backend (default: WGPU_BACKEND, else the best available).
    #[arg(long)]
    pub backend: Option<Backend>,
    /// Use the software adapter even where a GPU exists.
    #[arg(long)]
    pub cpu_adapter: bool,
}

fn load(args: &BenchArgs) -> Result<(Geometry, Shading, f64)> {
    let t0 = std::time::Instant::now();
    let (geometry, shading) = args.scene.load(&args.file)?;
    Ok((geometry, shading, t0.elapsed().as_secs_f64()))
}

fn base_options(args: &BenchArgs) -> RenderOptions {
    RenderOptions {
        camera: CameraParams {
            width: 512,
            height: 512,
            azimuth: args.azimuth,
            elevation: args.elevation,
            roll: args.roll,
            zoom: args.zoom,
            ortho: args.ortho,
            ..Default::default()
        },
        mode: Mode::Exact,
        gpu: GpuOptions {
            backend: args.backend,
            cpu_adapter: args.cpu_adapter,
        },
        accum: AccumFormat::Auto,
        projected: ProjectedOptions {
            split_all: args.split.is_some(),
            ..Default::default()
        },
        iso: IsoOptions {
            surfaces: args.iso.as_ref().map(|l| l.0.clone()).unwrap_or_default(),
            lighting: args.shading,
            ..Default::default()
        },
        ..Default::default()
    }
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let surfaces = args.iso.is_some();
    let modes = match &args.modes.0 {
        Some(m) => m.clone(),
        None => bench::all_modes(surfaces),
    };
    if !surfaces && modes.contains(&Mode::Iso) {
        bail!(super::UsageError(
            "--modes iso draws isosurfaces: give them with --iso V,V,...".into()
        ));
    }
    if args.repeats == 0 {
        bail!(super::UsageError("--repeats must be at least 1".into()));
    }
    let mappers: Vec<String> = match &args.vtk_mappers {
        Some(m) => {
            for name in m {
                if !vtk::MAPPERS.contains(&name.as_str()) {
                    bail!(super::UsageError(format!(
                        "unknown VTK mapper '{name}' (mappers: {})",
                        vtk::MAPPERS.join(", ")
                    )));
                }
            }
            m.clone()
        }
        None => vtk::MAPPERS.iter().map(|s| s.to_string()).collect(),
    };
    for dir in args.images.iter() {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the image directory '{}'", dir.display()))?;
    }
    let base = base_options(args);
    let gpu = modes.iter().any(|m| m.info().gpu);
    let pending = gpu.then(|| zoovr::gpu::Context::spawn(&base.gpu));
    let (geometry, shading, load_s) = load(args)?;
    let config = BenchConfig {
        entries: bench::entries_for(&modes),
        sizes: args.sizes.0.clone(),
        views: bench::views(args.views.max(1)),
        base,
        warmup: args.warmup,
        repeats: args.repeats,
        background: args.background,
        load_s,
        max_seconds: args.max_seconds,
        keep_references: args.with_vtk.is_some(),
    };
    let mut renderer = Renderer::new(geometry.clone());
    if let Some(p) = pending {
        renderer.set_pending_gpu(p);
    }
    let mut bar = progress();
    let out = bench::run(
        &mut renderer,
        &shading,
        &config,
        args.images.as_deref(),
        &mut bar,
    )
    .with_context(|| format!("{}", args.file.display()))?;
    let mut rows = out.rows;
    if let Some(python) = &args.with_vtk {
        let dir = tempfile::tempdir().context("creating a directory for the VTK run")?;
        let opts = vtk::VtkOptions {
            python,
            dir: dir.path(),
            mappers,
            warmup: args.warmup,
            repeats: args.repeats,
            background: args.background,
            load_s: 0.0,
        };
        eprintln!("zoovr: running VTK's mappers with {}", python.display());
        let vtk_rows = vtk::run(&opts, &geometry, &shading, &out.frames)
            .with_context(|| format!("{}", args.file.display()))?;
        if let Some(dir_out) = &args.images {
            for r in vtk_rows.iter().filter(|r| r.error.is_none()) {
                let src = dir
                    .path()
                    .join(format!("vtk_{}_{}_v{}.png", r.mode, r.size, r.view));
                let _ = std::fs::copy(&src, dir_out.join(bench::image_name(r)));
            }
        }
        rows.extend(vtk_rows);
    }
    print!("{}", report::table(&rows));
    let failed = rows.iter().filter(|r| r.error.is_some()).count();
    if failed > 0 {
        eprintln!("zoovr: warning: {failed} rows failed (their reason is in the table)");
    }
    let info = report::RunInfo {
        file: args.file.display().to_string(),
        cells: geometry.mesh.cells.len(),
        points: geometry.mesh.points.len(),
        adapter: renderer.gpu_info(),
        warmup: args.warmup,
        repeats: args.repeats,
        zoovr_version: env!("CARGO_PKG_VERSION"),
    };
    if let Some(p) = &args.csv {
        report::write_csv(p, &rows)?;
    }
    if let Some(p) = &args.json {
        report::write_json(p, &info, &rows)?;
    }
    if let Some(p) = &args.plot {
        let name = args
            .file
            .file_name()
            .map_or_else(|| "scene".into(), |n| n.to_string_lossy().into_owned());
        let title = format!(
            "zoovr bench: {name} ({} cells){}",
            info.cells,
            info.adapter.as_ref().map_or(String::new(), |a| {
                // The adapter's name, without its backend details.
                format!(
                    ", {}",
                    a.split(" (Vulkan")
                        .next()
                        .unwrap_or(a)
                        .split(" (Gl")
                        .next()
                        .unwrap_or(a)
                )
            })
        );
        bench::plot::write_plot(p, &rows, &title)?;
    }
    std::mem::forget(renderer);
    Ok(())
}

/// A progress bar on stderr when it is a terminal.
fn progress() -> impl FnMut(&str, usize, usize) {
    let bar = indicatif::ProgressBar::new(0);
    if std::io::stderr().is_terminal() {
        bar.set_style(
            indicatif::ProgressStyle::with_template("bench [{bar:30}] {pos}/{len} ({eta}) {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    move |what, done, total| {
        if done == 0 && what.starts_with("estimated") {
            // One line, also off a terminal: what the run will cost.
            bar.suspend(|| eprintln!("zoovr: bench: {what} for {total} renders"));
        }
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(what.to_string());
        if done >= total {
            bar.finish_and_clear();
        }
    }
}
