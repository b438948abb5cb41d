//! The exact mode across the data and the backends: every dataset in
//! `../shared/data` renders in the exact mode at 256 x 256 with the CLI's
//! defaults (field, transfer function, camera) and no NaN; a full render of a
//! mesh agrees between Vulkan and GL with the same accumulation format
//! forced; `--backend` and `--cpu-adapter` select what they say. Skips
//! cleanly without an adapter or without the shared data.

use zoovr::camera::CameraParams;
use zoovr::gpu::{AccumFormat, Backend, Context, GpuOptions};
use zoovr::image::{check_images_with, Bounds, Image};
use zoovr::io::{self, ReadOptions};
use zoovr::render::{Mode, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::{mesh_file, shared_file};

fn gpu(opts: &GpuOptions) -> Option<Context> {
    match Context::new(opts) {
        Ok(c) => Some(c),
        Err(e) => {
            eprintln!("skipping: {e}");
            None
        }
    }
}

#[test]
fn every_shared_dataset_renders_exact_at_256_without_nan() {
    if gpu(&GpuOptions::default()).is_none() {
        return;
    }
    let mut rendered = 0;
    let mut found = 0;
    for rel in zoovr::testdata::SHARED_DATASETS {
        let Some(path) = shared_file(rel) else {
            continue;
        };
        found += 1;
        let ro = zoovr::testdata::read_options(rel);
        let mesh = io::read(&path, &ro).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let scene =
            Scene::build(mesh, &SceneSpec::default()).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let opts = RenderOptions {
            camera: CameraParams {
                width: 256,
                height: 256,
                ..Default::default()
            },
            ..Default::default()
        };
        let (img, stats) = Renderer::new(scene.geometry())
            .render(&scene.shading(), &opts, |_, _| {})
            .unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(img.count_non_finite(), 0, "{rel}: non-finite pixels");
        let covered = img.pixels.iter().filter(|p| p[3] > 1e-3).count();
        let e = stats.projected().unwrap();
        eprintln!(
            "{rel}: {covered} covered pixels, {} pieces, {} triangles, {:.2} s",
            e.pieces, e.triangles, stats.total_s
        );
        assert!(covered > 100, "{rel}: almost nothing visible");
        rendered += 1;
    }
    assert_eq!(rendered, found);
}

fn render_mesh(ctx_opts: GpuOptions, accum: AccumFormat) -> Option<Image> {
    gpu(&ctx_opts)?;
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let opts = RenderOptions {
        camera: CameraParams {
            width: 128,
            height: 128,
            azimuth: 20.0,
            elevation: 35.0,
            ..Default::default()
        },
        mode: Mode::Exact,
        gpu: ctx_opts,
        accum,
        ..Default::default()
    };
    let (img, _) = Renderer::new(scene.geometry())
        .render(&scene.shading(), &opts, |_, _| {})
        .unwrap();
    Some(img)
}

/// The same scene through Vulkan and GL, f16 accumulation forced on both
/// (GL cannot blend f32): the same blend maths on the same vertices, so the
/// images differ by f16 rounding of the fragments only.
#[test]
fn vulkan_and_gl_full_renders_agree() {
    let vk = GpuOptions {
        backend: Some(Backend::Vulkan),
        cpu_adapter: false,
    };
    let gl = GpuOptions {
        backend: Some(Backend::Gl),
        cpu_adapter: false,
    };
    let (Some(a), Some(b)) = (
        render_mesh(vk, AccumFormat::F16),
        render_mesh(gl, AccumFormat::F16),
    ) else {
        return;
    };
    let d = check_images_with(
        "backends_vulkan_vs_gl",
        &a,
        &b,
        &Bounds {
            max_abs: 4e-3,
            p999: 2e-3,
            rms: 2e-4,
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("vulkan vs gl: {d:?}");
}

/// `--backend` picks that backend's adapter; `--cpu-adapter` gives a
/// software adapter (on these machines every adapter is one).
#[test]
fn backend_and_cpu_adapter_select_the_adapter() {
    for (b, name) in [(Backend::Vulkan, "Vulkan"), (Backend::Gl, "Gl")] {
        let Some(ctx) = gpu(&GpuOptions {
            backend: Some(b),
            cpu_adapter: false,
        }) else {
            continue;
        };
        assert_eq!(ctx.info().backend, name, "{}", ctx.info());
    }
    if let Some(ctx) = gpu(&GpuOptions {
        backend: None,
        cpu_adapter: true,
    }) {
        assert_eq!(ctx.info().device_type, "Cpu", "{}", ctx.info());
    }
}

/// A context opened on another thread while the scene is built
/// (`Context::spawn`, what the CLI does) is the one the render uses, and
/// the image is the same as with a context opened on the spot; a pending
/// context for other options is not used.
#[test]
fn pending_context_is_used_and_gives_the_same_image() {
    if gpu(&GpuOptions::default()).is_none() {
        return;
    }
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let opts = RenderOptions {
        camera: CameraParams {
            width: 96,
            height: 96,
            azimuth: 20.0,
            elevation: 35.0,
            ..Default::default()
        },
        ..Default::default()
    };
    let (direct, _) = Renderer::new(scene.geometry())
        .render(&scene.shading(), &opts, |_, _| {})
        .unwrap();
    let mut r = Renderer::new(scene.geometry());
    r.set_pending_gpu(Context::spawn(&opts.gpu));
    let (img, stats) = r.render(&scene.shading(), &opts, |_, _| {}).unwrap();
    assert!(stats.gpu_adapter.is_some());
    assert_eq!(img.pixels, direct.pixels);
    // Options that differ from the render's: a context of its own.
    let mut r = Renderer::new(scene.geometry());
    let other = GpuOptions {
        cpu_adapter: !opts.gpu.cpu_adapter,
        ..opts.gpu
    };
    r.set_pending_gpu(Context::spawn(&other));
    let (img, _) = r.render(&scene.shading(), &opts, |_, _| {}).unwrap();
    assert_eq!(img.pixels, direct.pixels);
}
