//! Regions kept across frames whose values change
//! (`ProjectedOptions::keep_regions`): every frame of a values-only series
//! is the image a fresh renderer makes of it, bit for bit, in every
//! projected mode (slabs, split cells, surfaces, a close-up whose pieces
//! reach past the image and the near plane), while the parts' regions come
//! from the frame before; a camera or points change empties the store.
//!
//! The projected modes run on their CPU twin, so no adapter is needed.

mod render_util;

use render_util::time_step;
use zoovr::camera::CameraParams;
use zoovr::image::Image;
use zoovr::io::{self, ReadOptions};
use zoovr::render::iso::{IsoOptions, Lighting};
use zoovr::render::{
    Compositor, Geometry, Mode, ModeStats, ProjectedOptions, ProjectedStats, RenderOptions,
    Renderer, SceneSpec, Shading, StepChange,
};
use zoovr::testdata::mesh_file;

fn geometry() -> Geometry {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    Geometry::build(mesh, false).unwrap()
}

/// A view of the whole mesh, or a close-up from inside it (pieces cut by
/// the near plane and clipped to the image).
fn options(mode: Mode, close: bool, keep: bool) -> RenderOptions {
    RenderOptions {
        camera: CameraParams {
            width: 72,
            height: 53,
            azimuth: 30.0,
            elevation: 25.0,
            zoom: if close { 6.0 } else { 1.0 },
            ..Default::default()
        },
        mode,
        projected: ProjectedOptions {
            compositor: Compositor::Cpu,
            keep_regions: keep,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Step `k`: a point field that changes per step (some cells dark in one
/// step and not the next), mapped by the shading of step 0.
fn step(geometry: &Geometry, first: &Shading, k: usize) -> Shading {
    time_step(geometry, first, k, |p, k| {
        (p.x * 1.7 + p.y * 0.6 + k * 0.9).sin() * 2.0 + p.z * 0.3
    })
}

fn fresh(geometry: &Geometry, shading: &Shading, opts: &RenderOptions) -> Image {
    let mut opts = opts.clone();
    opts.projected.keep_regions = false;
    Renderer::new(geometry.clone())
        .render(shading, &opts, |_, _| {})
        .unwrap()
        .0
}

fn projected(stats: &zoovr::render::RenderStats) -> &ProjectedStats {
    match &stats.detail {
        ModeStats::Projected(p) => p,
        other => panic!("not a projected mode: {other:?}"),
    }
}

#[test]
fn values_only_frames_with_kept_regions_equal_fresh_renders() {
    let geometry = geometry();
    let first = Shading::build(&geometry, &SceneSpec::default()).unwrap();
    let surfaces = IsoOptions {
        surfaces: zoovr::render::iso::parse_list("-0.5,0.8").unwrap(),
        lighting: Lighting::default(),
        alone: false,
        mix: Default::default(),
    };
    let cases: Vec<(&str, RenderOptions)> = {
        let mut v = Vec::new();
        for close in [false, true] {
            for mode in [Mode::Exact, Mode::ExactFrag, Mode::Preint3d, Mode::Preint2d] {
                v.push((mode.name(), options(mode, close, true)));
            }
            let mut split = options(Mode::ExactFrag, close, true);
            split.projected.split_all = true;
            v.push(("exact-frag --split all", split));
            let mut ortho = options(Mode::Exact, close, true);
            ortho.camera.ortho = true;
            v.push(("exact --ortho", ortho));
            let mut iso = options(Mode::ExactFrag, close, true);
            iso.iso = surfaces.clone();
            v.push(("exact-frag --iso", iso));
            let mut alone = options(Mode::Iso, close, true);
            alone.iso = surfaces.clone();
            v.push(("iso", alone));
        }
        v
    };
    for (name, opts) in &cases {
        let close = opts.camera.zoom > 1.0;
        let mut renderer = Renderer::new(geometry.clone());
        let mut reused = Vec::new();
        let mut images = Vec::new();
        for k in 0..3 {
            let shading = step(&geometry, &first, k);
            let (img, stats) = renderer.render(&shading, opts, |_, _| {}).unwrap();
            let p = projected(&stats);
            reused.push(p.regions_reused);
            assert!(p.regions_kept_bytes > 0, "{name}: nothing kept");
            let want = fresh(&geometry, &shading, opts);
            assert!(
                img.pixels == want.pixels,
                "{name} (close-up {close}) step {k}: kept regions give another image"
            );
            images.push(img);
        }
        assert!(images[0].pixels != images[1].pixels, "{name}: steps alike");
        println!("{name} close-up {close}: reused {reused:?}");
        assert_eq!(reused[0], 0, "{name}: the first frame has nothing kept");
        assert!(
            reused[1] + reused[2] > 0,
            "{name} (close-up {close}): regions reused per frame {reused:?}"
        );
    }
}

#[test]
fn a_camera_or_points_change_empties_the_kept_regions() {
    let read = || io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let geometry = geometry();
    let first = Shading::build(&geometry, &SceneSpec::default()).unwrap();
    let fixed = SceneSpec {
        range: Some(first.range),
        ..SceneSpec::default()
    };
    let mut opts = options(Mode::ExactFrag, false, true);
    let mut renderer = Renderer::new(geometry.clone());
    let render = |r: &mut Renderer, s: &Shading, o: &RenderOptions| {
        let (img, stats) = r.render(s, o, |_, _| {}).unwrap();
        (img, projected(&stats).regions_reused)
    };
    let (_, n) = render(&mut renderer, &first, &opts);
    assert_eq!(n, 0);
    let (_, n) = render(&mut renderer, &step(&geometry, &first, 1), &opts);
    assert!(n > 0);
    // Another camera: nothing reused, the image a fresh one.
    opts.camera.azimuth += 10.0;
    let s2 = step(&geometry, &first, 2);
    let (img, n) = render(&mut renderer, &s2, &opts);
    assert_eq!(n, 0, "a new camera reuses nothing");
    assert!(img.pixels == fresh(&geometry, &s2, &opts).pixels);
    // Moved points: the store is emptied with the geometry's change.
    let mut moved = read();
    for p in &mut moved.points {
        p.x += 0.05 * p.y * p.y;
    }
    let (g1, change) = geometry.next_step(moved, false).unwrap();
    assert_eq!(change, StepChange::Points);
    renderer.set_geometry(g1.clone(), change);
    let s3 = Shading::build(&g1, &fixed).unwrap();
    let (img, n) = render(&mut renderer, &s3, &opts);
    assert_eq!(n, 0, "moved points reuse no regions");
    assert!(img.pixels == fresh(&g1, &s3, &opts).pixels);
    // Switched off: the store is freed.
    opts.projected.keep_regions = false;
    let (_, stats) = renderer.render(&s3, &opts, |_, _| {}).unwrap();
    assert_eq!(projected(&stats).regions_kept_bytes, 0);
    assert_eq!(projected(&stats).regions_reused, 0);
}
