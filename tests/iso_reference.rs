//! The ray caster's isosurfaces with `--model native` and `--traversal
//! brute`: a closed-form scene (a trilinear field whose crossings are known
//! exactly), the native model against `faces` and `tets` where all three
//! are the same field (an affine field on parallelepipeds), and the brute
//! traversal against the walk on conforming meshes. Every bound is the
//! largest difference over every pixel and channel (linear premultiplied
//! RGBA), with the value measured when it was set.

mod render_util;

use glam::{DMat3, DVec3};
use zoovr::camera::{Camera, CameraParams};
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::image::Image;
use zoovr::integrate::{Material, RayMaterial, SegmentValue};
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::iso::{Empty, IsoReference};
use zoovr::raycast::{self, FieldModel, RayTracer, RaycastOptions, Raycaster, Traversal};
use zoovr::render::iso::{IsoMix, IsoOptions, IsoSet, Lighting};
use zoovr::render::{Mode, ModeStats, ReferenceOptions, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::mesh_file;

const SIZE: u32 = 64;

/// A unit cube of `n^3` hexahedra, its points mapped by `map`, with the
/// point field `f(p)` (of the mapped points).
fn grid_scene(n: usize, map: impl Fn(DVec3) -> DVec3, f: impl Fn(DVec3) -> f64) -> Scene {
    let mut mesh = warped_hex_grid(
        n,
        &Warp {
            amplitude: 0.0,
            seed: 1,
        },
    );
    for p in &mut mesh.points {
        *p = map(*p);
    }
    render_util::set_point_field(&mut mesh, f);
    Scene::build(mesh, &SceneSpec::default()).unwrap()
}

fn iso(list: &str, lighting: Lighting, alone: bool, mix: IsoMix) -> IsoOptions {
    IsoOptions {
        surfaces: zoovr::render::iso::parse_list(list).unwrap(),
        lighting,
        alone,
        mix,
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

fn reference(
    r: &mut Renderer,
    scene: &Scene,
    iso: &IsoOptions,
    ortho: bool,
    model: FieldModel,
    traversal: Traversal,
) -> Image {
    let opts = RenderOptions {
        camera: camera_params(ortho),
        mode: Mode::Raycast,
        reference: ReferenceOptions {
            model,
            traversal,
            ..Default::default()
        },
        iso: iso.clone(),
        ..Default::default()
    };
    let (img, stats) = r
        .render(&scene.shading(), &opts, |_, _| {})
        .unwrap_or_else(|e| panic!("{model:?} {traversal:?}: {e}"));
    assert_eq!(img.count_non_finite(), 0);
    let ModeStats::Raycast(rs) = stats.detail else {
        panic!("raycast stats");
    };
    if model == FieldModel::Native {
        // Every interval through the iso-parametric field, none fell back.
        assert!(
            rs.native.intervals > 0 && !rs.native.any_fallback(),
            "{:?}",
            rs.native
        );
    }
    img
}

/// The largest difference over every pixel and channel.
fn max_diff(a: &Image, b: &Image) -> f64 {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..4).map(move |c| (p[c] as f64 - q[c] as f64).abs()))
        .fold(0.0, f64::max)
}

/// Pixels with any alpha.
fn covered(a: &Image) -> usize {
    a.pixels.iter().filter(|p| p[3] > 1e-3).count()
}

/// A glow of constant extinction `tau` and source `g` at every scalar: over
/// a length `l` its colour is `g / tau (1 - e^(-tau l))`, its alpha
/// `1 - e^(-tau l)`.
struct Constant {
    tau: f64,
    g: [f64; 3],
}

impl RayMaterial for Constant {
    fn segment(&self, l: f64, _s_f: f64, _s_b: f64) -> SegmentValue {
        let depth = self.tau * l;
        let a = -(-depth).exp_m1();
        SegmentValue {
            color: self.g.map(|g| g / self.tau * a),
            alpha: a,
            depth,
        }
    }
    fn breakpoints(&self) -> &[f64] {
        &[]
    }
    fn material(&self, _s: f64) -> Material {
        Material {
            tau: self.tau,
            source: self.g,
        }
    }
}

/// `s = x y z` on the unit cube (trilinear, so the native field is exactly
/// `x y z` in every hexahedron of the grid), seen along the z axis: the ray
/// through `(x, y)` has `s = x y z`, crossing `V` at `z = V / (x y)` where
/// `x y > V`. Opaque red surface, no light. Alone, a pixel is exactly the
/// surface's colour where the ray crosses it and empty elsewhere; over a
/// constant glow, `red = e^(-tau L)` and `green = g/tau (1 - e^(-tau L))`
/// give the length `L` of volume in front of the surface, which is the
/// closed form's. Both sides (the ray falls through `V` looking down -z,
/// rises looking along +z) are checked, on one hexahedron and on a 3-grid
/// (crossings in every layer of cells).
#[test]
fn native_crossings_of_a_trilinear_field_match_the_closed_form() {
    let v = 0.2;
    let (tau, g) = (1.5, [0.0, 0.6, 0.3]);
    let material = Constant { tau, g };
    let mut worst_alone = 0.0f64;
    let mut worst_depth = 0.0f64;
    let mut worst_colour = 0.0f64;
    for n in [1, 3] {
        let scene = grid_scene(n, |p| p, |p| p.x * p.y * p.z);
        let values: Vec<f64> = scene.mesh.points.iter().map(|p| p.x * p.y * p.z).collect();
        let rs = raycast::Scene {
            mesh: &scene.mesh,
            topology: &scene.topology,
            scalars: raycast::Scalars::Point(&values),
        };
        let rc = Raycaster::new(rs, FieldModel::Native).unwrap();
        let set = IsoSet::new(
            &iso(&format!("{v}:#ff0000"), Lighting::None, true, IsoMix::Exact),
            &scene.tf,
        );
        for azimuth in [0.0, 180.0] {
            // Looking down the z axis (-z) or up it (+z); orthographic:
            // every ray parallel to the axis.
            let params = CameraParams {
                width: SIZE,
                height: SIZE,
                azimuth,
                zoom: 1.1,
                ortho: true,
                ..Default::default()
            };
            let cam = Camera::fit(scene.mesh.bounds(), &params);
            let down = cam.forward.z < 0.0;
            assert!(
                (cam.forward.z.abs() - 1.0).abs() < 1e-12,
                "{:?}",
                cam.forward
            );
            let tracer = IsoReference::new(&rc, &set, cam.forward, None, &values);
            let opts = RaycastOptions {
                model: FieldModel::Native,
                early_termination: 0.0,
                ..Default::default()
            };
            let alone = tracer.render(&Empty, &cam, &opts);
            let mixed = tracer.render(&material, &cam, &opts);
            let mut crossing = 0;
            for j in 0..SIZE {
                for i in 0..SIZE {
                    let ray = cam.pixel_ray(i, j);
                    let o = ray.origin + ray.dir * (0.5 - ray.origin.z) / ray.dir.z;
                    let (x, y) = (o.x, o.y);
                    let inside = x.min(1.0 - x).min(y).min(1.0 - y);
                    let p = x * y;
                    // Pixels on the cube's outline or whose ray grazes the
                    // surface's edge (p = V, the crossing at z = 1) are
                    // left out.
                    if inside.abs() < 1e-3 || (p - v).abs() < 1e-3 {
                        continue;
                    }
                    let k = (j * SIZE + i) as usize;
                    let (a, m) = (alone.pixels[k], mixed.pixels[k]);
                    let hit = inside > 0.0 && p > v;
                    // Alone: exact.
                    let want = if hit { [1.0, 0.0, 0.0, 1.0] } else { [0.0; 4] };
                    for c in 0..4 {
                        worst_alone = worst_alone.max((a[c] - want[c]).abs() as f64);
                    }
                    if inside < 0.0 {
                        assert_eq!(m, [0.0; 4]);
                        continue;
                    }
                    // Mixed: the length of volume in front of the surface.
                    let z = v / p;
                    let l = if !hit {
                        1.0
                    } else if down {
                        1.0 - z
                    } else {
                        z
                    };
                    let e = (-tau * l).exp();
                    let want = [
                        if hit { e } else { 0.0 },
                        g[1] / tau * (1.0 - e),
                        g[2] / tau * (1.0 - e),
                        if hit { 1.0 } else { 1.0 - e },
                    ];
                    for c in 0..4 {
                        worst_colour = worst_colour.max((m[c] as f64 - want[c]).abs());
                    }
                    if hit {
                        crossing += 1;
                        let measured = -(1.0 - m[1] as f64 * tau / g[1]).ln() / tau;
                        worst_depth = worst_depth.max((measured - l).abs());
                    }
                }
            }
            eprintln!("n = {n}, down = {down}: {crossing} pixels cross the surface");
            assert!(crossing > (SIZE * SIZE / 8) as usize, "{crossing}");
            let stats = rc.native_stats();
            assert!(!stats.any_fallback(), "{stats:?}");
        }
    }
    eprintln!(
        "alone: max {worst_alone:.2e}; mixed: colour max {worst_colour:.2e}, \
         depth of the crossing max {worst_depth:.2e}"
    );
    // Measured 0 (alone), 3.0e-8 (colour: f32 rounding), 9.8e-8 (depth,
    // read back from an f32 colour: its rounding over the glow's slope).
    // Moving each crossing by 1e-3 of its piece's length fails both (1.8e-4).
    assert_eq!(worst_alone, 0.0);
    assert!(worst_colour <= 2e-7, "{worst_colour:.3e}");
    assert!(worst_depth <= 1e-6, "{worst_depth:.3e}");
}

/// An affine field on parallelepipeds (a sheared, stretched grid) is the
/// same field in the `native`, `faces` and `tets` models, with the same
/// gradients (flat and smooth: all equal the field's gradient), so their
/// isosurface images agree to rounding: 1, 2 and 10 isovalues, translucent
/// and opaque, with and without the volume, exact and RKE's blend, both
/// projections, every light (the blend against `faces` only: it mixes per
/// segment, and a `tets` segment is a part of a cell's).
#[test]
fn native_equals_faces_and_tets_on_an_affine_field() {
    let shear = DMat3::from_cols(
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.35, 1.1, 0.0),
        DVec3::new(-0.2, 0.25, 0.9),
    );
    let grad = DVec3::new(1.0, -0.6, 0.45);
    let scene = grid_scene(
        3,
        |p| shear * p + DVec3::new(0.1, -0.2, 0.3),
        |p| grad.dot(p),
    );
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
    let mut r = Renderer::new(scene.geometry());
    let mut worst = 0.0f64;
    for list in &lists {
        for lighting in [Lighting::Smooth, Lighting::Flat, Lighting::None] {
            for ortho in [true, false] {
                for (alone, mix) in [
                    (false, IsoMix::Exact),
                    (true, IsoMix::Exact),
                    (false, IsoMix::Blend),
                ] {
                    let set = iso(list, lighting, alone, mix);
                    let native = reference(
                        &mut r,
                        &scene,
                        &set,
                        ortho,
                        FieldModel::Native,
                        Traversal::Walk,
                    );
                    assert!(covered(&native) > 300, "{}", covered(&native));
                    // RKE's blend is per segment: a cell's, not its tets'.
                    let models = if mix == IsoMix::Blend {
                        &[FieldModel::Faces][..]
                    } else {
                        &[FieldModel::Faces, FieldModel::Tets][..]
                    };
                    for &model in models {
                        let other = reference(&mut r, &scene, &set, ortho, model, Traversal::Walk);
                        let d = max_diff(&native, &other);
                        let n = list.split(',').count();
                        eprintln!(
                            "{n} surfaces {lighting:?} ortho={ortho} alone={alone} {mix:?}: \
                             native vs {model:?} {d:.2e}"
                        );
                        assert!(d <= 1e-5, "{model:?}: {d:.3e}");
                        worst = worst.max(d);
                    }
                }
            }
        }
    }
    // Measured 0: the native volume's adaptive quadrature agrees with the
    // closed form far below f32 rounding here, and the crossings to a few
    // ulps. Moving each native crossing by 1e-3 of its piece's length
    // fails (2.4e-5 with this faint default transfer function).
    eprintln!("native vs faces and tets: max {worst:.2e}");
}

/// On conforming meshes the brute-force traversal gives the walk's image
/// with isosurfaces too, in both of its models: the same segments, the
/// same gradients.
#[test]
fn brute_equals_walk_with_isosurfaces() {
    let mut worst = 0.0f64;
    for name in ["zoo_3x3x3.vtu", "curvilinear_4x4x4.vtu"] {
        let mesh = io::read(&mesh_file(name), &ReadOptions::default()).unwrap();
        let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let (lo, hi) = scene.range;
        let at = |x: f64| lo + (hi - lo) * x;
        let lists = [
            format!("{}", at(0.5)),
            format!("{}:#ff8000:0.6:#2040ff:0.6,{}:tf:0.4", at(0.3), at(0.7)),
        ];
        let mut r = Renderer::new(scene.geometry());
        for list in &lists {
            for lighting in [Lighting::Smooth, Lighting::Flat, Lighting::None] {
                for (ortho, alone, mix) in [
                    (false, false, IsoMix::Exact),
                    (true, true, IsoMix::Exact),
                    (false, false, IsoMix::Blend),
                ] {
                    let set = iso(list, lighting, alone, mix);
                    for model in [FieldModel::Faces, FieldModel::Tets] {
                        let walk = reference(&mut r, &scene, &set, ortho, model, Traversal::Walk);
                        let brute = reference(&mut r, &scene, &set, ortho, model, Traversal::Brute);
                        assert!(covered(&walk) > 200);
                        let d = max_diff(&walk, &brute);
                        eprintln!(
                            "{name} {list} {lighting:?} ortho={ortho} alone={alone} {mix:?} \
                             {model:?}: brute vs walk {d:.2e}"
                        );
                        assert!(d <= 1e-6, "{name} {model:?}: {d:.3e}");
                        worst = worst.max(d);
                    }
                }
            }
        }
    }
    // Measured 0: the same segments (bit-identical depths and scalars)
    // and the same gradients, composited in the same order.
    eprintln!("brute vs walk: max {worst:.2e}");
}

/// A surface on a layer of faces: `s = x + (x - 1/2) y z` (trilinear) is
/// exactly `1/2` on the plane `x = 1/2`, a layer of the 4-grid's faces, and
/// nowhere else. Translucent and alone, it is drawn once on every ray that
/// meets it (not twice by the two cells sharing the face, nor never): the
/// native reference's pixels are exactly the surface's colour and opacity
/// there, nothing elsewhere, in both projections.
#[test]
fn native_surface_on_a_layer_of_faces_is_drawn_once() {
    let scene = grid_scene(4, |p| p, |p| p.x + (p.x - 0.5) * p.y * p.z);
    let mut r = Renderer::new(scene.geometry());
    let set = iso("0.5:#ff0000:0.5", Lighting::None, true, IsoMix::Exact);
    let mut worst = 0.0f64;
    for ortho in [true, false] {
        let img = reference(
            &mut r,
            &scene,
            &set,
            ortho,
            FieldModel::Native,
            Traversal::Walk,
        );
        let cam = Camera::fit(scene.mesh.bounds(), &camera_params(ortho));
        let mut checked = 0;
        for j in 0..SIZE {
            for i in 0..SIZE {
                let ray = cam.pixel_ray(i, j);
                let t = (0.5 - ray.origin.x) / ray.dir.x;
                let x = ray.origin + ray.dir * t;
                let inside = x.y.min(1.0 - x.y).min(x.z).min(1.0 - x.z);
                if inside.abs() < 1e-2 {
                    continue;
                }
                let want = if inside > 0.0 {
                    checked += 1;
                    [0.5, 0.0, 0.0, 0.5]
                } else {
                    [0.0; 4]
                };
                let got = img.pixels[(j * SIZE + i) as usize];
                for c in 0..4 {
                    worst = worst.max((got[c] as f64 - want[c]).abs());
                }
            }
        }
        assert!(checked > 500, "{checked}");
    }
    // Measured 0.
    eprintln!("surface on faces: max {worst:.2e}");
    assert!(worst <= 1e-7, "{worst:.3e}");
}

/// An isovalue at the field's minimum is never crossed: with the native
/// model (on a mesh of every cell kind: native cells and walk segments)
/// the image is the volume's alone, bit for bit.
#[test]
fn native_isovalue_at_the_minimum_leaves_the_volume_unchanged() {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let lo = scene.field.as_ref().unwrap().range.0;
    let mut r = Renderer::new(scene.geometry());
    let none = IsoOptions::default();
    for ortho in [true, false] {
        let plain = reference(
            &mut r,
            &scene,
            &none,
            ortho,
            FieldModel::Native,
            Traversal::Walk,
        );
        for lighting in [Lighting::Smooth, Lighting::Flat] {
            let set = iso(&format!("{lo}:#ff0000"), lighting, false, IsoMix::Exact);
            let got = reference(
                &mut r,
                &scene,
                &set,
                ortho,
                FieldModel::Native,
                Traversal::Walk,
            );
            assert!(covered(&plain) > 500);
            assert_eq!(max_diff(&plain, &got), 0.0, "{lighting:?} ortho={ortho}");
        }
    }
    // And a surface inside the range is drawn on that mesh.
    let (a, b) = scene.range;
    let set = iso(
        &format!("{}:#ff0000", 0.5 * (a + b)),
        Lighting::Smooth,
        true,
        IsoMix::Exact,
    );
    let img = reference(
        &mut r,
        &scene,
        &set,
        false,
        FieldModel::Native,
        Traversal::Walk,
    );
    assert!(covered(&img) > 200, "{}", covered(&img));
}
