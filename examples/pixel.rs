//! Takes one pixel of a projected mode (`--mode NAME`, default exact) apart: renders a file with the CPU twin
//! of the GPU stage (`zoovr::gpu::cpu`) and the reference ray caster, and
//! prints both values at the pixel, the fragments that coloured it (piece,
//! interpolated thickness, extinction, glow) and the ray caster's segments.
//!
//! ```sh
//! cargo run --release --example pixel -- FILE I J [WIDTH] [--height H] [--ortho] [--azimuth A] [--elevation E] [--zoom Z] [--split] [--mode NAME] [--no-cull] [--tf FILE] [--refine-tol T] [--iso V1,V2,..]
//! ```

use anyhow::{anyhow, Context as _, Result};
use zoovr::camera::{Camera, CameraParams};
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::{
    Compositor, Mode, ProjectedOptions, ReferenceOptions, RenderOptions, Renderer, Scene, SceneSpec,
};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let file = args
        .first()
        .ok_or_else(|| anyhow!("usage: pixel FILE I J [SIZE] [flags]"))?;
    let num = |k: usize| -> Result<u32> {
        args.get(k)
            .context("missing pixel")?
            .parse()
            .context("pixel index")
    };
    let (i, j) = (num(1)?, num(2)?);
    let flag = |name: &str| -> Option<f64> {
        args.iter()
            .position(|a| a == name)
            .and_then(|k| args.get(k + 1)?.parse().ok())
    };
    let size = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(512);
    let height = flag("--height").map_or(size, |h| h as u32);

    let camera = CameraParams {
        width: size,
        height,
        ortho: args.iter().any(|a| a == "--ortho"),
        azimuth: flag("--azimuth").unwrap_or(0.0),
        elevation: flag("--elevation").unwrap_or(0.0),
        zoom: flag("--zoom").unwrap_or(1.0),
        ..Default::default()
    };
    let split_all = args.iter().any(|a| a == "--split");
    let mode: Mode = match args.iter().position(|a| a == "--mode") {
        Some(k) => args
            .get(k + 1)
            .context("--mode NAME")?
            .parse()
            .map_err(|e: String| anyhow!(e))?,
        None => Mode::Exact,
    };
    let mesh = io::read(std::path::Path::new(file), &ReadOptions::default())?;
    let tf_file = args
        .iter()
        .position(|a| a == "--tf")
        .and_then(|k| args.get(k + 1))
        .map(std::path::PathBuf::from);
    let spec = SceneSpec {
        tf_file,
        ..Default::default()
    };
    let scene = Scene::build(mesh, &spec)?;
    let mut renderer = Renderer::new(scene.geometry());
    // Surfaces: with `--mode iso` alone, in the mode and in the reference
    // below; with the volume in the other modes.
    let iso = match args.iter().position(|a| a == "--iso") {
        Some(k) => zoovr::render::iso::IsoOptions {
            surfaces: zoovr::render::iso::parse_list(args.get(k + 1).context("--iso LIST")?)?,
            alone: mode == Mode::Iso,
            ..Default::default()
        },
        None => Default::default(),
    };
    let opts = RenderOptions {
        camera,
        mode,
        iso,
        projected: ProjectedOptions {
            split_all,
            compositor: Compositor::Cpu,
            watch: Some((i, j)),
            cull_to_pixels: !args.iter().any(|a| a == "--no-cull"),
            refine_tol: flag("--refine-tol").unwrap_or(zoovr::numeric::tolerance::COLOR_REFINE_TOL),
            ..Default::default()
        },
        ..Default::default()
    };
    let (img, stats) = renderer.render(&scene.shading(), &opts, |_, _| {})?;
    let model = if split_all {
        FieldModel::Tets
    } else {
        FieldModel::Faces
    };
    let ropts = RenderOptions {
        mode: Mode::Raycast,
        reference: ReferenceOptions {
            model,
            ..opts.clone().reference
        },
        ..opts.clone()
    };
    let (reference, _) = renderer.render(&scene.shading(), &ropts, |_, _| {})?;
    let gopts = RenderOptions {
        projected: ProjectedOptions {
            compositor: Compositor::Gpu,
            ..opts.clone().projected
        },
        ..opts.clone()
    };
    match renderer.render(&scene.shading(), &gopts, |_, _| {}) {
        Ok((g, _)) => {
            println!("{mode} (gpu)      {:?}", g.get(i, j));
            let (d, _) = zoovr::image::compare_display(&g, &img, [0.0; 3])?;
            println!(
                "gpu vs twin: max {:.3e} at {:?}, rms {:.3e}",
                d.max_abs, d.worst, d.rms
            );
        }
        Err(e) => println!("{mode} (gpu)      unavailable: {e}"),
    }
    println!("{mode} (cpu twin) {:?}", img.get(i, j));
    println!("raycast ({})    {:?}", model.name(), reference.get(i, j));
    for f in &stats
        .projected()
        .map(|e| e.watched.clone())
        .unwrap_or_default()
    {
        println!("  fragment {f:?}");
    }
    let cam = Camera::fit(scene.mesh.bounds(), &opts.camera);
    let rc = zoovr::raycast::Raycaster::new(
        zoovr::raycast::Scene {
            mesh: &scene.mesh,
            topology: &scene.topology,
            scalars: match scene.scalars() {
                zoovr::render::ScalarsRef::Point(v) => zoovr::raycast::Scalars::Point(v),
                zoovr::render::ScalarsRef::Cell(v) => zoovr::raycast::Scalars::Cell(v),
                zoovr::render::ScalarsRef::Constant(c) => zoovr::raycast::Scalars::Constant(c),
            },
        },
        model,
    )?;
    for s in rc.segments(&cam.pixel_ray(i, j), if cam.ortho { 0.0 } else { cam.near }) {
        println!("  segment {s:?}");
    }
    Ok(())
}
