//! `zoovr render FILE -o out.png [...]`: one image of a dataset.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use clap::Args;

use zoovr::camera::CameraParams;
use zoovr::gpu::{AccumFormat, Backend, GpuOptions};
use zoovr::raycast::{FieldModel, Traversal};
use zoovr::render::{
    Geometry, Mode, PieceDraw, ProjectedOptions, ReferenceOptions, RenderOptions, RenderStats,
    Renderer, SceneSpec, Shading, TableBuild, TableOptions,
};

use zoovr::render::iso::{IsoMix, IsoOptions, IsoSpec, Lighting};

use super::args::{parse_finite, parse_positive, parse_rgb, parse_size, parse_table_size};
use super::scene::SceneArgs;

/// The parsed `--iso` list.
#[derive(Clone, Debug)]
pub struct IsoList(pub Vec<IsoSpec>);

pub fn parse_iso(s: &str) -> Result<IsoList, String> {
    zoovr::render::iso::parse_list(s)
        .map(IsoList)
        .map_err(|e| e.to_string())
}

/// Options shared by `render` and `animate`: field, transfer function,
/// camera, mode and output encoding.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Image size WxH.
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    pub size: (u32, u32),
    /// Degrees about the view-up (vtkCamera::Azimuth).
    #[arg(long, value_parser = parse_finite, default_value_t = 0.0, allow_hyphen_values = true)]
    pub azimuth: f64,
    /// Degrees about the right axis (vtkCamera::Elevation).
    #[arg(long, value_parser = parse_finite, default_value_t = 0.0, allow_hyphen_values = true)]
    pub elevation: f64,
    /// Degrees about the view direction (vtkCamera::Roll).
    #[arg(long, value_parser = parse_finite, default_value_t = 0.0, allow_hyphen_values = true)]
    pub roll: f64,
    /// Zoom factor (> 1 is closer).
    #[arg(long, value_parser = parse_positive, default_value_t = 1.0)]
    pub zoom: f64,
    /// Orthographic projection instead of perspective (30 degree view angle).
    #[arg(long)]
    pub ortho: bool,
    /// Rendering mode: exact (projection + exact vertex integrals, wgpu),
    /// exact-frag (the exact integral per fragment), preint3d, preint2d,
    /// preint2d-cyl (pre-integrated tables, see --table), iso (the --iso
    /// surfaces alone), or raycast (CPU reference).
    #[arg(long, value_enum, default_value_t = Mode::Exact)]
    pub mode: Mode,
    /// Field model of the ray caster: faces (default), tets or native. The
    /// exact mode integrates `faces` for whole cells and `tets` with
    /// `--split all`. All three draw --iso surfaces (native: where the
    /// iso-parametric field reaches the value along each ray).
    #[arg(long)]
    pub model: Option<FieldModel>,
    /// How the ray caster finds the cells along each ray: walk (default) or
    /// brute.
    ///
    /// `walk` goes from cell to cell across shared faces (face adjacency).
    /// `brute` ignores adjacency: it tests every cell whose bounding box the
    /// ray meets (a bounding volume hierarchy), whole (`--model faces`) or
    /// as its consistent tets (`--model tets`), with the walk's exact
    /// crossing test, and composites all their segments of positive
    /// length in depth order; where pieces overlap, their extinctions add.
    /// On a conforming mesh both give the same image (to rounding: the walk
    /// may also report pieces a ray meets in a vertex or along an edge,
    /// for no length); brute force is slower and is the
    /// reference where adjacency cannot be trusted: non-conforming faces
    /// that only partly overlap (faults in corner-point grids, hanging
    /// nodes), overlapping or duplicated cells, duplicated points. Both
    /// draw --iso surfaces. `brute` is not available with `--model native`.
    #[arg(long)]
    pub traversal: Option<Traversal>,
    /// Pre-integrated table modes (preint3d, preint2d, preint2d-cyl):
    /// samples per table axis (default 128 for preint3d and preint2d-cyl,
    /// whose tables are N x N x N and N x N x 2N planes, 512 for preint2d).
    /// At least 2; at most what one storage buffer of the adapter holds
    /// (128 MiB on lavapipe and GL llvmpipe: N = 203 for preint3d, 161 for
    /// preint2d-cyl, 2896 for preint2d) and 2^28 texels.
    #[arg(long, value_name = "N", value_parser = parse_table_size)]
    pub table: Option<u32>,
    /// How the pre-integrated tables are built: auto (the GPU compute pass
    /// when drawing on a GPU, else exact), exact (exact integrals on the CPU), fast
    /// (integral functions on the CPU: exact opacity, approximate colour)
    /// or gpu (exact integrals in a wgpu compute pass).
    #[arg(long, value_enum, default_value_t = TableBuild::Auto)]
    pub table_build: TableBuild,
    /// Isosurfaces, comma-separated: V[:COLOUR[:OPACITY[:BACKCOLOUR[:BACKOPACITY]]]].
    ///
    /// Drawn alone by --mode iso, mixed with the volume in the exact order
    /// by exact, exact-frag, preint3d, preint2d, preint2d-cyl and raycast
    /// (any --model and --traversal). The projected modes find the
    /// crossings per fragment between the segment's end scalars, on whole
    /// cells; with surfaces, exact integrates per fragment as exact-frag
    /// does (its vertex integrals cannot hold a crossing inside a
    /// segment). COLOUR is #rrggbb or `tf` (the
    /// transfer function's colour at V, the default); OPACITY in [0, 1]
    /// (default 1, opaque). The front side is the one a ray meets while
    /// the field rises; the back side takes the front's style unless
    /// BACKCOLOUR/BACKOPACITY are given. Example: --iso
    /// 0.3:#ff8000:0.5,0.7:tf:1:#0040ff. At most 1024 surfaces; they need a
    /// point field (see --cell-to-point).
    #[arg(long, value_parser = parse_iso, allow_hyphen_values = true, value_name = "V[:STYLE],..")]
    pub iso: Option<IsoList>,
    /// Light of the isosurfaces: smooth (default; a headlight on the
    /// points' gradients interpolated like the field), flat (one gradient
    /// per cell or tet) or none (their colours as given).
    #[arg(long, value_enum, default_value_t = Lighting::Smooth)]
    pub shading: Lighting,
    /// Draw the --iso surfaces without the volume, in any mode (what --mode
    /// iso draws; with --mode raycast, its reference).
    #[arg(long, requires = "iso")]
    pub iso_only: bool,
    /// How the volume and the --iso surfaces combine inside a cell: exact
    /// (default: the volume split at each crossing, in order along the ray)
    /// or blend (Roettger-Kraus-Ertl's smooth approximation: the cell's
    /// whole volume between the surfaces' front layer, weighted by the
    /// crossing's distance from the back, and their back layer; for
    /// comparison).
    #[arg(long, value_enum, default_value_t = IsoMix::Exact, requires = "iso")]
    pub iso_mix: IsoMix,
    /// `--split all`: draw every cell as its consistent tetrahedra.
    #[arg(long, value_parser = ["all"])]
    pub split: Option<String>,
    /// Exact mode: colour refinement tolerance (default 0.004). A region
    /// triangle whose optical depth times glow spread exceeds T is split
    /// at its edge midpoints (up to 6 levels): lower is slower and closer
    /// to the ray caster, higher draws fewer triangles. Not used with
    /// --iso (the exact mode then integrates per fragment, see --iso).
    #[arg(long, value_name = "T", value_parser = parse_positive)]
    pub refine_tol: Option<f64>,
    /// exact-frag and the table modes (preint3d, preint2d, preint2d-cyl):
    /// how pieces are drawn. `regions`: each piece projected into regions
    /// on the CPU. `quads`: each piece drawn whole as one polygon over its
    /// outline (its projected points' hull, or its pixel bounding box),
    /// every fragment intersecting its own ray with the piece
    /// (view-independent cell projection): the CPU does no subdivision, at
    /// the same accuracy (pieces that f32 cannot settle are projected as
    /// regions). `auto`: quads on a hardware GPU, regions on a software
    /// adapter (llvmpipe, lavapipe), where triangles cost more than the
    /// quads' fragments.
    #[arg(long, value_name = "HOW", default_value = "auto")]
    pub piece_draw: PieceDraw,
    /// Projected modes: draw the pieces hidden behind opaque ones too. By
    /// default a front-to-back pass over the order leaves out every piece
    /// whose pixels already lie behind an optical depth that lets through
    /// less than 1e-7 of its light, or behind an opaque --iso surface (the
    /// image changes by at most that); this flag turns the pass off, to
    /// compare or measure it.
    #[arg(long)]
    pub no_occlusion: bool,
    /// Background colour R,G,B in [0,1] for PNG output.
    #[arg(long, value_parser = parse_rgb, default_value = "0,0,0")]
    pub background: [f32; 3],
    /// Write RGBA PNGs with straight alpha instead of compositing over the
    /// background (colour 0 where the alpha byte is 0).
    #[arg(long)]
    pub alpha: bool,
    /// GPU backend (default: WGPU_BACKEND, else the best available).
    #[arg(long)]
    pub backend: Option<Backend>,
    /// Force the software (CPU) adapter even where a GPU exists.
    #[arg(long)]
    pub cpu_adapter: bool,
    /// Draw a colour legend into the PNG: a bar of the transfer function's
    /// colours over the range, the field name and the range's ends (and,
    /// for `animate`, the time value of the step).
    #[arg(long)]
    pub legend: bool,
    /// Print timings and counts to stderr.
    #[arg(long)]
    pub stats: bool,
    /// With --stats: print them as one JSON object on stdout instead (the
    /// mode, times in seconds, the adapter, and the mode's own counters).
    #[arg(long, requires = "stats")]
    pub json: bool,
}

impl ViewArgs {
    /// The scene specification.
    pub fn scene_spec(&self) -> SceneSpec {
        self.scene.spec()
    }

    /// The render options (camera from the flags).
    pub fn render_options(&self) -> RenderOptions {
        RenderOptions {
            camera: CameraParams {
                width: self.size.0,
                height: self.size.1,
                azimuth: self.azimuth,
                elevation: self.elevation,
                roll: self.roll,
                zoom: self.zoom,
                ortho: self.ortho,
                ..Default::default()
            },
            mode: self.mode,
            reference: ReferenceOptions {
                model: self.model.unwrap_or_default(),
                traversal: self.traversal.unwrap_or_default(),
                early_termination: true,
            },
            projected: ProjectedOptions {
                split_all: self.split.is_some(),
                refine_tol: self
                    .refine_tol
                    .unwrap_or(zoovr::numeric::tolerance::COLOR_REFINE_TOL),
                occlusion: (!self.no_occlusion)
                    .then_some(zoovr::numeric::tolerance::OCCLUSION_TRANSMITTANCE),
                piece_draw: self.piece_draw,
                ..Default::default()
            },
            gpu: GpuOptions {
                backend: self.backend,
                cpu_adapter: self.cpu_adapter,
            },
            accum: AccumFormat::Auto,
            tables: TableOptions {
                size: self.table,
                build: self.table_build,
            },
            iso: IsoOptions {
                surfaces: self.iso.as_ref().map(|l| l.0.clone()).unwrap_or_default(),
                lighting: self.shading,
                alone: self.iso_only,
                mix: self.iso_mix,
            },
        }
    }

    /// A warning for each isovalue outside the field's range `(lo, hi)`
    /// (its surface is not drawn).
    pub fn iso_range_warnings(&self, shading: &Shading) {
        let (Some(list), Some(field)) = (&self.iso, &shading.field) else {
            return;
        };
        let (lo, hi) = field.range;
        for s in &list.0 {
            if !(s.value >= lo && s.value <= hi) {
                eprintln!(
                    "zoovr: warning: isovalue {} is outside the range [{lo}, {hi}] of field '{}': \
                     that surface is not drawn",
                    s.value, field.name
                );
            }
        }
    }

    /// A warning where the field of `file` has NaN or infinite values:
    /// what the mode makes of them (README, "Bad values").
    pub fn non_finite_warning(&self, shading: &Shading, file: &std::path::Path) {
        let Some(field) = shading.field.as_ref().filter(|f| !f.all_finite) else {
            return;
        };
        let n = field.values.iter().filter(|v| !v.is_finite()).count();
        let what = if self.mode.info().gpu {
            "ray segments entering or leaving a cell through a face holding one are empty \
             (a tet, slab or cell cut by the near plane with one wholly)"
        } else {
            "ray segments with one at an end are empty"
        };
        eprintln!(
            "zoovr: warning: {}: {n} values of field '{}' are NaN or infinite, \
             taken as missing: {what}",
            file.display(),
            field.name
        );
    }

    /// Flag combinations that are usage errors (beyond what clap checks).
    pub fn usage_error(&self) -> Option<String> {
        if self.mode == Mode::Iso && self.iso.is_none() {
            return Some("--mode iso draws isosurfaces only: give them with --iso V,V,...".into());
        }
        if self.piece_draw == PieceDraw::Quads
            && (!self.mode.info().draws_pieces_whole || self.iso.is_some())
        {
            return Some(
                "--piece-draw quads is for exact-frag, preint3d, preint2d and preint2d-cyl \
                 (without --iso): give one of those with --mode"
                    .into(),
            );
        }
        if self.traversal == Some(Traversal::Brute) && self.model == Some(FieldModel::Native) {
            return Some(
                "--traversal brute supports --model faces and --model tets, not --model native \
                 (the native model's cells are bounded by bilinear patches, not triangles)"
                    .into(),
            );
        }
        None
    }

    /// Reads the file and builds its geometry and shading.
    pub fn load_scene(&self, file: &std::path::Path) -> Result<(Geometry, Shading)> {
        self.scene.load(file)
    }
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The dataset (VTK legacy/XML, .pvd/.series: first step, PLOT3D grid).
    pub file: PathBuf,
    /// Output PNG (8-bit; see --background and --alpha).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write the linear premultiplied RGBA float image (OpenEXR).
    #[arg(long)]
    pub float: Option<PathBuf>,
    #[command(flatten)]
    pub view: ViewArgs,
}

/// A progress reporter on stderr when it is a terminal.
pub fn progress_bar(label: &str) -> impl FnMut(usize, usize) {
    let tty = std::io::stderr().is_terminal();
    let bar = indicatif::ProgressBar::new(0);
    if tty {
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_message(label.to_string());
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    move |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        if done >= total {
            bar.finish_and_clear();
        }
    }
}

/// Prints the stats of a render to stderr.
pub fn print_stats(stats: &RenderStats, load_s: f64) {
    eprintln!("load+scene   {load_s:.3} s");
    eprintln!("{stats}");
}

/// Prints the stats of a render as one JSON object on stdout.
pub fn print_stats_json(stats: &RenderStats, load_s: f64, ghost_cells: usize) -> Result<()> {
    let mut v = serde_json::to_value(stats)?;
    if let Some(o) = v.as_object_mut() {
        o.insert("load_s".into(), load_s.into());
        o.insert("ghost_cells".into(), ghost_cells.into());
    }
    println!("{}", serde_json::to_string(&v)?);
    Ok(())
}

/// `-o` writes PNG and `--float` OpenEXR whatever the names say; a name
/// whose extension says the other format is a usage error rather than a
/// file whose contents belie its name.
fn check_extensions(png: Option<&std::path::Path>, exr: Option<&std::path::Path>) -> Result<()> {
    let cases = [
        (
            png,
            "exr",
            "-o writes PNG",
            "an OpenEXR",
            "--float",
            "float",
        ),
        (exr, "png", "--float writes OpenEXR", "a PNG", "-o", "8-bit"),
    ];
    for (path, ext, writes, names, flag, image) in cases {
        let Some(p) = path.filter(|p| {
            p.extension()
                .and_then(|x| x.to_str())
                .is_some_and(|x| x.eq_ignore_ascii_case(ext))
        }) else {
            continue;
        };
        let p = p.display();
        return Err(super::UsageError(format!(
            "{writes}, but '{p}' names {names} file: use {flag} {p} for the {image} image"
        ))
        .into());
    }
    Ok(())
}

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.output.is_none() && args.float.is_none() {
        bail!("nothing to write: give -o out.png and/or --float out.exr");
    }
    check_extensions(args.output.as_deref(), args.float.as_deref())?;
    let opts = args.view.render_options();
    // The exact mode's GPU device opens while the file is read and sorted.
    let pending = opts
        .mode
        .info()
        .gpu
        .then(|| zoovr::gpu::Context::spawn(&opts.gpu));
    let t0 = std::time::Instant::now();
    let (geometry, shading) = args.view.load_scene(&args.file)?;
    let load_s = t0.elapsed().as_secs_f64();
    args.view.iso_range_warnings(&shading);
    args.view.non_finite_warning(&shading, &args.file);
    let ghost_cells = geometry.ghost_cells;
    let mut renderer = Renderer::new(geometry);
    if let Some(p) = pending {
        renderer.set_pending_gpu(p);
    }
    let info = opts.mode.info();
    if info.gpu && args.view.model.is_some_and(|m| m != FieldModel::Faces) {
        eprintln!(
            "zoovr: note: --model is the ray caster's; the {} mode integrates the `faces` \
             field of whole cells, or `tets` with --split all",
            info.name
        );
    }
    if !info.gpu && opts.projected.split_all {
        eprintln!(
            "zoovr: note: --split all is for the projected-cell modes; the ray caster's field \
             is --model (`--model tets` integrates the consistent tets)"
        );
    }
    if opts.mode != Mode::Exact && args.view.refine_tol.is_some() {
        eprintln!(
            "zoovr: note: --refine-tol is the exact mode's; the {} mode does not interpolate \
             vertex colours",
            info.name
        );
    }
    if info.gpu && args.view.traversal.is_some() {
        eprintln!(
            "zoovr: note: --traversal is the ray caster's (--mode raycast); the {} mode \
             projects every cell",
            info.name
        );
    }
    let (image, stats) = renderer
        .render(&shading, &opts, progress_bar("rendering"))
        .with_context(|| format!("{}", args.file.display()))?;
    if let Some(out) = &args.output {
        super::legend::write_frame(&image, out, &args.view, &shading, None)?;
    }
    if let Some(out) = &args.float {
        image.write_exr(out)?;
    }
    if args.view.json {
        print_stats_json(&stats, load_s, ghost_cells)?;
    } else if args.view.stats {
        if ghost_cells > 0 {
            eprintln!(
                "ghost cells  {} left out (hidden or duplicate in vtkGhostType; --show-hidden draws them)",
                ghost_cells
            );
        }
        print_stats(&stats, load_s);
    }
    // The process ends right after: leave the mesh, the sort's state and
    // the GPU device to the operating system instead of freeing them piece
    // by piece (tens of milliseconds on large meshes).
    std::mem::forget(renderer);
    std::mem::forget(shading);
    Ok(())
}
