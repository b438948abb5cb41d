//! Isosurfaces (`--mode iso`, `--iso` with the segment modes and with the
//! exact mode, and the ray caster's reference): an analytic scene with closed-form pixels, the
//! modes against the reference over every pixel, and the degenerate
//! isovalues (at vertex values, at the field's minimum and maximum).
//!
//! Every GPU mode is checked through its CPU twin (no adapter needed) and,
//! where an adapter exists, on the GPU.
//!
//! Bounds (linear premultiplied RGBA, any channel of any pixel): a pixel is
//! *off* when it differs from the reference by more than `PIXEL_TOL`
//! (`PIXEL_TOL_F16` where the GPU accumulates in f16); the
//! tests allow a measured number of off pixels per image, each where a ray
//! grazes a surface (its scalars within the `f32` stages' rounding of the
//! value) or meets it at the mesh boundary, and bound every other pixel by
//! `PIXEL_TOL`. Where a surface meets a face between two pieces (RKE's
//! "patch edge" artefacts), the centres next to the face's iso line are
//! decided exactly in both pieces (`render::ties` seams).

mod render_util;

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::image::Image;
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::iso::{IsoMix, IsoOptions, IsoSpec, Lighting};
use zoovr::render::{
    Compositor, Mode, ProjectedOptions, ReferenceOptions, RenderOptions, Renderer, Scene, SceneSpec,
};
use zoovr::testdata::{mesh_file, shared_file};

use render_util::gpu_available;

const SIZE: u32 = 96;

/// The largest difference of a pixel that is not "off" (f32 crossings and
/// light; the segment's volume within the mode's own bound).
const PIXEL_TOL: f64 = 2e-3;

/// `PIXEL_TOL` where the GPU accumulates in f16 (GL on llvmpipe, which
/// cannot blend f32 targets): every blend rounds to 11 significant bits,
/// half an ulp (2.4e-4 at 0.5 to 1) per layer a ray meets. Measured up to
/// 2.5e-3 against the reference on zoo_3x3x3 (about ten layers).
const PIXEL_TOL_F16: f64 = 4e-3;

/// The closed-form plane's bound: f32 crossings and light, or one f16 ulp
/// at 1 where the GPU accumulates in f16 (measured 4.7e-4 at 0.78: a
/// rounded fragment value and a rounded blend).
const PLANE_TOL: f64 = 1e-5;
const PLANE_TOL_F16: f64 = 1e-3;

/// Whether `c` accumulates in f16.
fn f16(c: Compositor) -> bool {
    c == Compositor::Gpu && render_util::gpu_accumulates_f16()
}

/// The off-pixel threshold of a render through `c`.
fn pixel_tol(c: Compositor) -> f64 {
    if f16(c) {
        PIXEL_TOL_F16
    } else {
        PIXEL_TOL
    }
}

fn camera_params(ortho: bool) -> CameraParams {
    CameraParams {
        width: SIZE,
        height: SIZE,
        azimuth: 25.0,
        elevation: 30.0,
        zoom: 1.2,
        ortho,
        ..Default::default()
    }
}

fn iso(list: &str, lighting: Lighting, alone: bool) -> IsoOptions {
    IsoOptions {
        surfaces: zoovr::render::iso::parse_list(list).unwrap(),
        lighting,
        alone,
        mix: Default::default(),
    }
}

fn options(mode: Mode, ortho: bool, iso: &IsoOptions, compositor: Compositor) -> RenderOptions {
    RenderOptions {
        camera: camera_params(ortho),
        mode,
        projected: ProjectedOptions {
            compositor,
            ..Default::default()
        },
        iso: iso.clone(),
        ..Default::default()
    }
}

fn render(r: &mut Renderer, scene: &Scene, opts: &RenderOptions) -> Image {
    let (img, _) = r
        .render(&scene.shading(), opts, |_, _| {})
        .unwrap_or_else(|e| panic!("{:?}: {e}", opts.mode));
    assert_eq!(img.count_non_finite(), 0);
    img
}

fn compositors() -> Vec<Compositor> {
    let mut c = vec![Compositor::Cpu];
    if gpu_available() {
        c.push(Compositor::Gpu);
    }
    c
}

/// Pixels of `a` differing from `b` by more than `tol`, and the largest
/// difference elsewhere.
fn off_pixels(a: &Image, b: &Image, tol: f64) -> (Vec<(u32, u32, f64)>, f64) {
    let mut off = Vec::new();
    let mut max = 0.0f64;
    for (k, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        let d = (0..4)
            .map(|c| (p[c] as f64 - q[c] as f64).abs())
            .fold(0.0, f64::max);
        if d > tol {
            off.push((k as u32 % a.width, k as u32 / a.width, d));
        } else {
            max = max.max(d);
        }
    }
    (off, max)
}

/// The unit cube as an unwarped `n`-grid with the point field `f(p)`.
fn box_scene(n: usize, f: impl Fn(DVec3) -> f64) -> Scene {
    let mut mesh = warped_hex_grid(
        n,
        &Warp {
            amplitude: 0.0,
            seed: 1,
        },
    );
    render_util::set_point_field(&mut mesh, f);
    Scene::build(mesh, &SceneSpec::default()).unwrap()
}

/// The closed-form image of the plane `g . p = v` inside the unit cube,
/// drawn opaque or translucent in linear colour `c` with the headlight on
/// `g`: `(colour, alpha)` at pixels whose ray meets the plane at least
/// `margin` inside the cube, `None` at pixels whose ray meets it at least
/// `margin` outside, and pixels in between (the outline) skipped.
fn plane_pixel(
    cam: &Camera,
    i: u32,
    j: u32,
    g: DVec3,
    v: f64,
    margin: f64,
) -> Option<Option<DVec3>> {
    let ray = cam.ray_at(i as f64 + 0.5, j as f64 + 0.5);
    let den = g.dot(ray.dir);
    if den.abs() < 1e-12 {
        return Some(None);
    }
    let t = (v - g.dot(ray.origin)) / den;
    let x = ray.origin + ray.dir * t;
    let inside = (0..3)
        .map(|k| x[k].min(1.0 - x[k]))
        .fold(f64::INFINITY, f64::min);
    if inside >= margin {
        Some(Some(x))
    } else if inside <= -margin {
        Some(None)
    } else {
        None
    }
}

/// A planar isosurface in a box (linear field, flat cells nowhere): every
/// pixel inside is the surface's colour times the headlight's factor, in
/// closed form, in every mode and the reference, both projections, every
/// light; translucent at a value that lies on a layer of vertices (drawn
/// once, not twice or never).
#[test]
fn planar_isosurface_matches_its_closed_form() {
    let g = DVec3::new(1.0, 0.5, 0.25);
    let scene = box_scene(4, |p| g.dot(p));
    // 0.875 = g . (0.5, 0.5, 0.5): the plane passes through grid vertices.
    for (value, opacity) in [(0.6, 1.0), (0.875, 0.5)] {
        check_plane(&scene, g, value, opacity);
    }
}

/// A field that reaches the isovalue on the plane x = 0.5 and stays there
/// (the cells beyond are flat at V, s_f = s_b = V): the surface is the plane;
/// the flat cells add nothing. The whole surface lies on mesh faces;
/// opaque and translucent, alone and over a zero-extinction volume, it is
/// drawn at every pixel once (in perspective 2 of 9,080 centres were missed
/// over a volume of zero extinction until wide triangles reaching an
/// isovalue were drawn with exact values at their snapped corners,
/// src/render/ties).
#[test]
fn a_flat_region_at_the_isovalue_is_not_a_surface() {
    let scene = box_scene(4, |p| p.x.min(0.5));
    check_plane(&scene, DVec3::X, 0.5, 1.0);
    check_plane(&scene, DVec3::X, 0.5, 0.5);
}

/// Checks the renders of the plane `g . p = value` (the isosurface of the
/// scene's field at `value`) against the closed form, opacity `opacity`.
fn check_plane(scene: &Scene, g: DVec3, value: f64, opacity: f64) {
    let mut r = Renderer::new(scene.geometry());
    for lighting in [Lighting::None, Lighting::Flat, Lighting::Smooth] {
        let set = iso(&format!("{value}:#ff0000:{opacity}"), lighting, true);
        for ortho in [true, false] {
            let cam = Camera::fit(scene.mesh.bounds(), &camera_params(ortho));
            let light = match lighting {
                Lighting::None => 1.0,
                _ => 0.25 + 0.75 * (g.normalize().dot(cam.forward)).abs(),
            };
            let mut renders = vec![(
                "raycast".to_string(),
                options(Mode::Raycast, ortho, &set, Compositor::Cpu),
            )];
            for c in compositors() {
                renders.push((format!("iso {c:?}"), options(Mode::Iso, ortho, &set, c)));
                // The exact mode mixes the surface into a volume, here
                // one of zero extinction: its surfaces alone.
                let mixed = IsoOptions {
                    alone: false,
                    ..set.clone()
                };
                let mut opts = options(Mode::Exact, ortho, &mixed, c);
                opts.projected.split_all = true;
                renders.push((format!("exact, dark volume, {c:?}"), opts));
            }
            for (name, opts) in renders {
                let mut shading = scene.shading();
                if opts.mode == Mode::Exact {
                    let (lo, hi) = shading.range;
                    shading.tf = zoovr::tf::TransferFunction::from_channels(
                        &[(lo, [0.0]), (hi, [0.0])],
                        &[(lo, [0.5, 0.5, 0.5]), (hi, [0.5, 0.5, 0.5])],
                        None,
                        zoovr::tf::EmissionModel::Glow,
                    )
                    .unwrap();
                }
                let (img, _) = r.render(&shading, &opts, |_, _| {}).unwrap();
                assert_eq!(img.count_non_finite(), 0);
                let tol = if f16(opts.projected.compositor) {
                    PLANE_TOL_F16
                } else {
                    PLANE_TOL
                };
                let c = render_util::against_closed_form(&img, tol, |i, j| {
                    let expect = plane_pixel(&cam, i, j, g, value, 0.01)?;
                    Some(match expect {
                        Some(_) => [light * opacity, 0.0, 0.0, opacity],
                        None => [0.0; 4],
                    })
                });
                eprintln!(
                    "plane {value} {lighting:?} ortho={ortho} {name}: max {:.2e} over {} pixels",
                    c.worst, c.checked
                );
                assert!(c.checked > (SIZE * SIZE / 2) as usize);
                assert!(
                    c.worst <= tol,
                    "plane {value} {lighting:?} ortho={ortho} {name}: {:.3e} at {} pixels \
                     (pixel, got, want): {:?}",
                    c.worst,
                    c.bad.len(),
                    &c.bad[..c.bad.len().min(6)]
                );
            }
        }
    }
}

/// An isovalue exactly at a transfer-function breakpoint (where the
/// volume's integral changes piece) mixes with the volume as any other.
#[test]
fn an_isovalue_at_a_breakpoint_matches_the_reference() {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let breaks = zoovr::integrate::RayMaterial::breakpoints(&scene.tf);
    let v = breaks[breaks.len() / 2];
    compare_with_reference(
        &scene,
        "zoo at a breakpoint",
        &[format!("{v}:tf:0.7")],
        true,
    );
}

/// Surfaces alone and mixed with the volume (exact-frag, preint3d) against
/// the reference on the project's meshes: `--split all` against `tets`
/// (the same field), 1, 2 and 10 surfaces, opaque and translucent, both
/// projections, every light.
#[test]
fn isosurfaces_match_the_reference_on_the_project_meshes() {
    for name in ["zoo_3x3x3.vtu", "curvilinear_4x4x4.vtu"] {
        let mesh = io::read(&mesh_file(name), &ReadOptions::default()).unwrap();
        let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let (lo, hi) = scene.range;
        let at = |x: f64| lo + (hi - lo) * x;
        let ten: Vec<String> = (1..=10)
            .map(|k| format!("{}:tf:0.3", at(k as f64 / 11.0)))
            .collect();
        let lists = [
            format!("{}", at(0.5)),
            format!("{}:#ff8000:0.6:#2040ff:0.6,{}", at(0.35), at(0.7)),
            ten.join(","),
        ];
        compare_with_reference(&scene, name, &lists, true);
    }
}

/// Surfaces in a nearly uniform field: bluntfin's density is 1 within a
/// few 1e-4 over much of the grid (the free stream), so a surface at or
/// next to 1 meets faces on long lines, at grazing angles, and along rays
/// whose scalars stay within 1e-6 of the value. Two rules used to draw it
/// wrong there (145 to 656 of about 4,000 covered pixels off, 49 to 476 of
/// them by more than 0.05, up to 0.95):
/// a piece claimed an opaque crossing where its front scalar was within a
/// snap bound of the value (which grows the surface wherever the field
/// comes that close without crossing), and the `f32` stages counted a
/// scalar within 1e-6 of the whole normalised range below the value as
/// reaching it (which hides the dips of this field below its free
/// stream). Now the centres next to the lines where a face's scalar is an
/// isovalue are decided exactly in both pieces (the seams of
/// `render::ties`), and the margin is relative to the value. Exact-frag,
/// surfaces mixed with the volume, opaque, whole cells against `faces`.
/// Skipped without the shared data.
#[test]
fn surfaces_in_a_nearly_uniform_field() {
    let Some(path) = shared_file("bluntfin/bluntfin_converted.vts") else {
        eprintln!("skipping: no shared data");
        return;
    };
    let mesh = io::read(&path, &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let mut r = Renderer::new(scene.geometry());
    let mut worst = 0;
    for list in ["0.9999", "1", "1.0001"] {
        for ortho in [false, true] {
            let set = iso(list, Lighting::Smooth, false);
            let mut ref_opts = options(Mode::Raycast, ortho, &set, Compositor::Cpu);
            ref_opts.reference = ReferenceOptions {
                model: FieldModel::Faces,
                ..Default::default()
            };
            let expected = render(&mut r, &scene, &ref_opts);
            let covered = expected.pixels.iter().filter(|p| p[3] > 0.0).count();
            for c in compositors() {
                let got = render(&mut r, &scene, &options(Mode::ExactFrag, ortho, &set, c));
                let (off, max) = off_pixels(&got, &expected, pixel_tol(c));
                let far: Vec<_> = off.iter().filter(|o| o.2 > 0.05).collect();
                eprintln!(
                    "bluntfin {list} ortho={ortho} {c:?}: {} off ({} by more than 0.05) of \
                     {covered} covered, max {max:.2e} elsewhere {:?}",
                    off.len(),
                    far.len(),
                    &off[..off.len().min(4)]
                );
                assert!(max <= pixel_tol(c), "{list} {c:?}: {max:.3e}");
                assert!(far.is_empty(), "{list} ortho={ortho} {c:?}: {far:?}");
                assert!(
                    off.len() <= NEAR_UNIFORM_MAX_OFF,
                    "{list} ortho={ortho} {c:?}: {} off",
                    off.len()
                );
                worst = worst.max(off.len());
            }
        }
    }
    eprintln!("bluntfin: at most {worst} off pixels per image");
}

/// Surfaces on a tet mesh in views that once left wrong pixels, now right
/// at every pixel (no off pixels allowed): CylinderLinear, whose cells are
/// a few pixels wide with steep fields, three opaque surfaces, the surfaces
/// alone.
/// - In perspective the lines where a face's scalar is an isovalue (the
///   seams whose centres the pieces on both sides decide exactly) were put
///   where `s / z`, not `s`, reaches the value: up to 0.02 px off, so a
///   centre next to the true line was left to the snapped triangles, and
///   one piece put it below the value and the other above (a hole: 0.18).
/// - A ray leaving a cell 3e-7 of the range below a value crosses it in the
///   reference; the tie quad of that centre carried the exact segment, but
///   the `f32` stage compared it with a level 1e-6 below the value and saw
///   no crossing (the surface drawn at the next crossing: 0.04).
///
/// Skipped without the shared data.
#[test]
fn surfaces_on_a_tet_mesh_at_every_pixel() {
    let Some(path) = shared_file("tets_small/CylinderLinear.vtk") else {
        eprintln!("skipping: no shared data");
        return;
    };
    let mesh = io::read(&path, &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let (lo, hi) = scene.range;
    let list = [0.3, 0.5, 0.7]
        .map(|t| format!("{}", lo + (hi - lo) * t))
        .join(",");
    let set = iso(&list, Lighting::Smooth, true);
    let mut r = Renderer::new(scene.geometry());
    // (azimuth, elevation, zoom, width, height, orthographic)
    let views = [
        (9.0, -84.0, 1.7, 84, 142, false),
        (348.0, -32.0, 1.27, 247, 193, false),
        (162.0, -23.0, 1.6, 187, 120, false),
        (312.0, -57.0, 1.23, 135, 191, true),
    ];
    for (azimuth, elevation, zoom, width, height, ortho) in views {
        let camera = CameraParams {
            width,
            height,
            azimuth,
            elevation,
            zoom,
            ortho,
            ..Default::default()
        };
        let mut ref_opts = options(Mode::Raycast, ortho, &set, Compositor::Cpu);
        ref_opts.camera = camera;
        let expected = render(&mut r, &scene, &ref_opts);
        for c in compositors() {
            let mut opts = options(Mode::Iso, ortho, &set, c);
            opts.camera = camera;
            let got = render(&mut r, &scene, &opts);
            let (off, max) = off_pixels(&got, &expected, pixel_tol(c));
            eprintln!(
                "CylinderLinear {azimuth}/{elevation} {width}x{height} ortho={ortho} {c:?}: \
                 max {max:.2e}, off {off:?}"
            );
            assert!(
                off.is_empty() && max <= pixel_tol(c),
                "{azimuth}/{elevation} {c:?}: {off:?}"
            );
        }
    }
}

/// A surface far from the transfer function's first node where the field
/// changes slowly: `f = 1000 u^3 + u + 0.05 y` (`u = 2x - 1`) spans about
/// -1000 to 1000, and the surface at 0 lies where it changes by about 1e-2
/// per pixel. Normalised from the first node, the `f32` stages' level lies
/// 1e-3 below the value (a quarter of a pixel) and the two pieces sharing
/// a face put centres next to it on different sides unless the seams'
/// band holds that margin (the surface missing or drawn twice: 0.5 at 3
/// pixels here before either); centred on the value
/// (`ScalarMap::centred`) the level is the value. Every pixel,
/// translucent, `--mode iso` and exact-frag, both projections. (The band
/// alone: `iso_seams` tests; it still matters for the table modes' map.)
#[test]
fn a_surface_far_from_the_first_node_where_the_field_is_gentle() {
    let scene = box_scene(11, |p| {
        let u = 2.0 * p.x - 1.0;
        1000.0 * u * u * u + u + 0.05 * p.y
    });
    let set = iso("0:#ff0000:0.5", Lighting::Smooth, true);
    let mut r = Renderer::new(scene.geometry());
    // (azimuth, elevation, zoom, orthographic)
    let views = [
        (60.0, 20.0, 1.0, false),
        (75.0, -30.0, 1.5, false),
        (60.0, 20.0, 1.0, true),
        (100.0, 50.0, 1.3, false),
    ];
    for (azimuth, elevation, zoom, ortho) in views {
        let camera = CameraParams {
            width: 400,
            height: 300,
            azimuth,
            elevation,
            zoom,
            ortho,
            ..Default::default()
        };
        every_pixel_right(&mut r, &scene, &set, camera, &[Mode::Iso, Mode::ExactFrag]);
    }
}

/// Surfaces close together where a field of a wide range changes slowly:
/// `f = 24.6 + 7350 u^5 + u + 0.1 y` (`u = 2x - 1 + 0.2 (y - 1/2)`) spans
/// about -7,300 to 7,400, and the values 24.55, 24.555 and 24.56 lie where
/// it changes by about 5e-3 per pixel. Normalised from the first node,
/// the `f32` stages put their levels 7e-3 (`ISO_LEVEL_F32` of 7,350) below
/// each value, a pixel and a half; centred on the values
/// (`ScalarMap::centred`) every pixel matches (translucent, alone and mixed
/// with exact-frag's volume, both projections).
#[test]
fn close_surfaces_far_from_the_first_node_are_resolved() {
    let scene = box_scene(12, |p| {
        let u = 2.0 * p.x - 1.0 + 0.2 * (p.y - 0.5);
        24.6 + 7350.0 * u.powi(5) + u + 0.1 * p.y
    });
    let mut r = Renderer::new(scene.geometry());
    for alone in [true, false] {
        let set = iso(
            "24.55:#ff8000:0.5,24.555:#0080ff:0.5,24.56:#80ff00:0.5",
            Lighting::Smooth,
            alone,
        );
        for (azimuth, elevation, ortho) in [(30.0, 25.0, false), (-20.0, 60.0, true)] {
            let camera = CameraParams {
                width: 300,
                height: 240,
                azimuth,
                elevation,
                zoom: 1.3,
                ortho,
                ..Default::default()
            };
            let modes: &[Mode] = if alone {
                &[Mode::Iso, Mode::ExactFrag]
            } else {
                &[Mode::ExactFrag, Mode::Preint3d, Mode::Preint2dCyl]
            };
            every_pixel_right(&mut r, &scene, &set, camera, modes);
        }
    }
}

/// Renders `set` over `scene` through `camera` with each of `modes`, on
/// the CPU twin and the GPU, and asserts that every pixel is within the
/// pixel tolerance of the ray caster's (`faces`).
fn every_pixel_right(
    r: &mut Renderer,
    scene: &Scene,
    set: &IsoOptions,
    camera: CameraParams,
    modes: &[Mode],
) {
    let ortho = camera.ortho;
    let mut ref_opts = options(Mode::Raycast, ortho, set, Compositor::Cpu);
    ref_opts.camera = camera;
    let expected = render(r, scene, &ref_opts);
    for &mode in modes {
        for c in compositors() {
            let mut opts = options(mode, ortho, set, c);
            opts.camera = camera;
            let got = render(r, scene, &opts);
            let (off, max) = off_pixels(&got, &expected, pixel_tol(c));
            let (a, e) = (camera.azimuth, camera.elevation);
            eprintln!(
                "{a}/{e} ortho={ortho} alone={} {mode:?} {c:?}: max {max:.2e}, {} off {:?}",
                set.alone,
                off.len(),
                &off[..off.len().min(4)]
            );
            assert!(
                off.is_empty() && max <= pixel_tol(c),
                "{a}/{e} ortho={ortho} {mode:?} {c:?}: {off:?}"
            );
        }
    }
}

/// Off pixels allowed per 96 x 96 image of bluntfin's nearly uniform field
/// (about 4,000 covered), none by more than 0.05: measured at most 7 (12
/// on GL's f16), all within 9e-3 (grazing rays' light). Normalised from the
/// first node, not centred (`ScalarMap::centred`), 32, 3 by more than 0.05.
const NEAR_UNIFORM_MAX_OFF: usize = 16;

/// Whole cells against the `faces` field, on a mesh whose faces are planar
/// (an unwarped grid: no cell is split) with a nonlinear field.
#[test]
fn whole_cells_match_the_faces_reference() {
    let scene = box_scene(5, |p| (3.0 * p.x).sin() + p.y * p.y + 0.5 * p.z);
    let (lo, hi) = scene.range;
    let at = |x: f64| lo + (hi - lo) * x;
    let lists = [
        format!("{}", at(0.5)),
        format!("{}:tf:0.5,{}:#00ff00:1:#ff00ff:1", at(0.3), at(0.6)),
    ];
    compare_with_reference(&scene, "grid 5, nonlinear", &lists, false);
    // A radial field: nested closed surfaces (spheres, as the faces field
    // draws them).
    let c = DVec3::new(0.45, 0.5, 0.55);
    let scene = box_scene(6, |p| (p - c).length());
    let lists = ["0.2:#ff0000:0.5,0.35,0.5:tf:0.4".to_string()];
    compare_with_reference(&scene, "grid 6, radial", &lists, false);
}

fn compare_with_reference(scene: &Scene, name: &str, lists: &[String], split: bool) {
    let mut r = Renderer::new(scene.geometry());
    let model = if split {
        FieldModel::Tets
    } else {
        FieldModel::Faces
    };
    let mut total_off = 0;
    for list in lists {
        for lighting in [Lighting::Smooth, Lighting::Flat, Lighting::None] {
            for ortho in [false, true] {
                // The exact mode with surfaces integrates per fragment on
                // whole cells, as exact-frag: the same field as the
                // reference's, split or not.
                let modes = [
                    (Mode::Iso, true),
                    (Mode::ExactFrag, false),
                    (Mode::Preint3d, false),
                    (Mode::Exact, false),
                ];
                for (mode, alone) in modes {
                    let set = iso(list, lighting, alone);
                    let mut ref_opts = options(Mode::Raycast, ortho, &set, Compositor::Cpu);
                    ref_opts.reference = ReferenceOptions {
                        model,
                        ..Default::default()
                    };
                    let expected = render(&mut r, scene, &ref_opts);
                    for c in compositors() {
                        let mut opts = options(mode, ortho, &set, c);
                        opts.projected.split_all = split;
                        let got = render(&mut r, scene, &opts);
                        let (off, max) = off_pixels(&got, &expected, pixel_tol(c));
                        let n = list.split(',').count();
                        eprintln!(
                            "{name} {n} surfaces {lighting:?} ortho={ortho} {mode} {c:?}: \
                             max {max:.2e} elsewhere, {} off {:?}",
                            off.len(),
                            &off[..off.len().min(4)]
                        );
                        // Preint3d's table adds its own error to the volume.
                        let tol = if mode == Mode::Preint3d {
                            1.2e-2
                        } else {
                            pixel_tol(c)
                        };
                        assert!(max <= tol, "{name} {mode} {c:?}: {max:.3e}");
                        assert!(
                            off.len() <= MAX_OFF,
                            "{name} {mode} {c:?}: {} off",
                            off.len()
                        );
                        total_off += off.len();
                    }
                }
            }
        }
    }
    eprintln!("{name}: {total_off} off pixels in all");
}

/// Off pixels allowed per image of 96 x 96 (see the module docs): measured
/// at most 2 (zoo_3x3x3, the exact mode, by 2.7e-3), 0 in 436 of the 444
/// images. (At most 11 before the seams' lines were placed right in
/// perspective and tie quads were read on the reference's side of each
/// level.)
const MAX_OFF: usize = 3;

/// An isovalue at the field's minimum is never crossed: the image is the
/// volume's alone, pixel for pixel. At the maximum only rays touching it
/// cross it. The exact mode with surfaces draws exact-frag's frame (the
/// integral per fragment, not at region vertices as its volume frame
/// does), so its plain image is exact-frag's; `--split all` as well. The
/// wide triangles whose scalars reach the value take the exact triangle's
/// values at their snapped corners (src/render/ties), which moves the
/// volume's colour there by up to 9.0e-5 (measured; 2.4e-4 where the GPU
/// accumulates in f16): `STEEP_COLOUR_TOL`, `STEEP_COLOUR_TOL_F16`.
const STEEP_COLOUR_TOL: f64 = 2e-4;
const STEEP_COLOUR_TOL_F16: f64 = 1e-3;

#[test]
fn isovalues_at_the_field_extremes() {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let field = scene.field.as_ref().unwrap();
    let (lo, hi) = field.range;
    let mut r = Renderer::new(scene.geometry());
    for c in compositors() {
        for (mode, split) in [(Mode::ExactFrag, false), (Mode::Exact, true)] {
            let mut opts = options(Mode::ExactFrag, false, &IsoOptions::default(), c);
            opts.projected.split_all = split;
            let plain = render(&mut r, &scene, &opts);
            for v in [lo, hi] {
                let set = iso(&format!("{v}:#ff0000"), Lighting::Smooth, false);
                let mut opts = options(mode, false, &set, c);
                opts.projected.split_all = split;
                let got = render(&mut r, &scene, &opts);
                let (off, max) = off_pixels(&got, &plain, pixel_tol(c));
                eprintln!(
                    "isovalue {v} {mode} {c:?}: {} off, max {max:.2e} elsewhere",
                    off.len()
                );
                let tol = if f16(c) {
                    STEEP_COLOUR_TOL_F16
                } else {
                    STEEP_COLOUR_TOL
                };
                assert!(max <= tol, "{v} {mode}: {max:.3e}");
                assert!(
                    off.len() <= if v == lo { 0 } else { 2 },
                    "{v} {mode}: {off:?}"
                );
            }
        }
    }
}

/// Cells whose scalar range holds no isovalue are not drawn by `--mode iso`:
/// most of them are left out of the sort (the visible subset,
/// src/render/visible.rs), the pieces of the others that hold none are
/// skipped.
#[test]
fn pieces_without_a_surface_are_skipped() {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let (lo, hi) = scene.range;
    let mut r = Renderer::new(scene.geometry());
    let set = iso(&format!("{}", lo + 0.9 * (hi - lo)), Lighting::Flat, true);
    let (_, stats) = r
        .render(
            &scene.shading(),
            &options(Mode::Iso, false, &set, Compositor::Cpu),
            |_, _| {},
        )
        .unwrap();
    let zoovr::render::ModeStats::Projected(p) = stats.detail else {
        panic!("projected stats");
    };
    eprintln!(
        "{} pieces, {} culled, {} dark cells left out of the sort",
        p.pieces, p.culled_pieces, p.dark_cells_left_out
    );
    let cells = scene.mesh.cells.len();
    assert!(
        p.dark_cells_left_out * 2 >= cells,
        "{} of {cells}",
        p.dark_cells_left_out,
    );
    assert_eq!(p.order.cells + p.dark_cells_left_out, cells);
}

#[test]
fn styles_parse_into_linear_colours() {
    let s: IsoSpec = "1.5:#ffffff:0.5:#000000:1".parse().unwrap();
    assert_eq!(s.front.color, Some([1.0; 3]));
    assert_eq!(s.back.opacity, 1.0);
}

/// The nearest hit of `o + t d` (t > 0) on `tris`, Moller-Trumbore.
fn nearest_hit(o: DVec3, d: DVec3, tris: &[[DVec3; 3]]) -> Option<f64> {
    let mut best: Option<f64> = None;
    for t in tris {
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-300 {
            continue;
        }
        let s = o - t[0];
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let w = e2.dot(q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && w > 0.0 && best.is_none_or(|b| w < b) {
            best = Some(w);
        }
    }
    best
}

/// The cross-check: marching tetrahedra of the same isovalues, drawn with a
/// depth test (a ray per pixel centre, nearest triangle), against `--mode
/// iso --split all` (the same `tets` field) with opaque, unlit surfaces.
/// The surfaces are the same piecewise-planar sheets, so the images agree
/// except on single pixels at the sheets' edges and where they meet mesh
/// faces: measured 2 to 8 of 9,216 pixels (about 4,300 covered) on
/// zoo_3x3x3 and curvilinear_4x4x4, both projections.
#[test]
fn marching_tetrahedra_agree_with_mode_iso() {
    for name in ["zoo_3x3x3.vtu", "curvilinear_4x4x4.vtu"] {
        let mesh = io::read(&mesh_file(name), &ReadOptions::default()).unwrap();
        let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let (lo, hi) = scene.range;
        let values = [lo + 0.35 * (hi - lo), lo + 0.65 * (hi - lo)];
        let colours = [[1.0f32, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let zoovr::render::ScalarsRef::Point(s) = scene.scalars() else {
            panic!("point field")
        };
        let tris: Vec<Vec<[DVec3; 3]>> = values
            .iter()
            .map(|&v| zoovr::render::marching::marching_tets(&scene.mesh, s, v))
            .collect();
        let set = iso(
            &format!("{}:#ff0000,{}:#0000ff", values[0], values[1]),
            Lighting::None,
            true,
        );
        let mut r = Renderer::new(scene.geometry());
        for ortho in [false, true] {
            let cam = Camera::fit(scene.mesh.bounds(), &camera_params(ortho));
            let mut opts = options(Mode::Iso, ortho, &set, Compositor::Cpu);
            opts.projected.split_all = true;
            let img = render(&mut r, &scene, &opts);
            let (mut differ, mut covered) = (0, 0);
            for j in 0..SIZE {
                for i in 0..SIZE {
                    let ray = cam.ray_at(i as f64 + 0.5, j as f64 + 0.5);
                    let hit = (0..2)
                        .filter_map(|k| nearest_hit(ray.origin, ray.dir, &tris[k]).map(|t| (t, k)))
                        .min_by(|a, b| a.0.total_cmp(&b.0));
                    let want = match hit {
                        Some((_, k)) => {
                            covered += 1;
                            let c = colours[k];
                            [c[0], c[1], c[2], 1.0]
                        }
                        None => [0.0; 4],
                    };
                    let got = img.pixels[(j * SIZE + i) as usize];
                    if (0..4).any(|c| (got[c] - want[c]).abs() > 1e-4) {
                        differ += 1;
                    }
                }
            }
            eprintln!(
                "{name} ortho={ortho}: {differ} of {} pixels differ ({covered} covered)",
                SIZE * SIZE
            );
            assert!(covered > 1000, "{name}: {covered}");
            assert!(differ <= 12, "{name} ortho={ortho}: {differ} pixels differ");
        }
    }
}

/// RKE's blend (`--iso-mix blend`), the approximation it replaces, renders
/// as its own reference does (the same formula in the ray caster), and
/// differs visibly from the exact mixing where surfaces cut thick cells.
#[test]
fn rke_blend_matches_its_reference_and_differs_from_exact() {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let (lo, hi) = scene.range;
    let list = format!(
        "{}:#ff8000:0.6,{}",
        lo + 0.35 * (hi - lo),
        lo + 0.7 * (hi - lo)
    );
    let mut r = Renderer::new(scene.geometry());
    let mut images = Vec::new();
    for mix in [IsoMix::Exact, IsoMix::Blend] {
        let mut set = iso(&list, Lighting::Smooth, false);
        set.mix = mix;
        let mut ref_opts = options(Mode::Raycast, false, &set, Compositor::Cpu);
        ref_opts.reference.model = FieldModel::Tets;
        let expected = render(&mut r, &scene, &ref_opts);
        for c in compositors() {
            let mut opts = options(Mode::ExactFrag, false, &set, c);
            opts.projected.split_all = true;
            let got = render(&mut r, &scene, &opts);
            let (off, max) = off_pixels(&got, &expected, pixel_tol(c));
            eprintln!("{mix:?} {c:?}: {} off, max {max:.2e} elsewhere", off.len());
            assert!(max <= pixel_tol(c) && off.len() <= MAX_OFF, "{mix:?} {c:?}");
        }
        images.push(expected);
    }
    let (off, _) = off_pixels(&images[1], &images[0], PIXEL_TOL);
    let worst = off.iter().map(|o| o.2).fold(0.0, f64::max);
    eprintln!(
        "blend against exact: {} pixels differ by more than {PIXEL_TOL}, at most {worst:.3}",
        off.len()
    );
    assert!(off.len() > 100 && worst > 0.05, "{} {worst}", off.len());
}
