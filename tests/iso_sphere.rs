//! An analytic isosurface with closed-form pixels: the sphere `|p - c| = R`
//! of the radial field `f(p) = |p - c|` on a hexahedral grid of the unit
//! cube, in every projected isosurface mode (CPU twin and GPU), the mixed
//! exact-frag frame over a volume of zero extinction, and the ray caster
//! with each field model, both projections.
//!
//! No interpolated field reproduces a sphere exactly: linear interpolation
//! of the convex `|p - c|` over a cell of side `h` overestimates it by at
//! most `(2 h^2 + 3 h^2) / 8` over the least distance from `c` in the cell
//! (on a face triangle of diameter `sqrt(2) h`, then along a chord of at
//! most `sqrt(3) h`; the trilinear and `tets` fields by less), so every
//! drawn surface lies between the spheres of radii `R - delta` and `R`.
//! Pixels whose ray passes within `delta` of the sphere's outline are not
//! checked; every other pixel is: without light, exactly the surface's
//! colour where the ray meets the sphere (a translucent sphere: its back
//! side's style where the ray enters, falling, then its front side's where
//! it leaves, rising), and nothing where it misses. With smooth light,
//! the headlight's factor on the sphere's true normal within
//! `SMOOTH_LIGHT_TOL` (the points' gradients, means of the tetrahedra's
//! linear gradients, differ from the normal by a fraction of `h / R`).

mod render_util;

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::raycast::FieldModel;
use zoovr::render::iso::{IsoOptions, Lighting};
use zoovr::render::{
    Compositor, Mode, ProjectedOptions, ReferenceOptions, RenderOptions, Renderer, Scene, SceneSpec,
};
use zoovr::tf::{EmissionModel, TransferFunction};

use render_util::{gpu_accumulates_f16, gpu_available};

const SIZE: u32 = 96;
/// Cells per side of the grid.
const CELLS: usize = 24;
/// The sphere's centre (off the grid's points) and radius.
const CENTRE: DVec3 = DVec3::new(0.48, 0.51, 0.5);
const RADIUS: f64 = 0.3;

/// A checked pixel's bound without light: `f32` crossings (measured 0 in
/// every mode and model, both projections), or one f16 ulp per layer
/// where the GPU accumulates in f16.
const EXACT_TOL: f64 = 1e-5;
const EXACT_TOL_F16: f64 = 2e-3;
/// A checked pixel's bound with smooth light against the sphere's true
/// normal: measured 3.1e-2 over the modes, models and views (the normal
/// off by about 0.04 rad, an eighth of `h / R`), against 6.1e-2 for a
/// light along each ray instead of the view direction.
const SMOOTH_LIGHT_TOL: f64 = 4e-2;

/// The most the drawn surface lies inside the sphere (module docs).
fn delta() -> f64 {
    let h = 1.0 / CELLS as f64;
    5.0 * h * h / (8.0 * (RADIUS - 3f64.sqrt() * h))
}

fn sphere_scene() -> Scene {
    let mut mesh = warped_hex_grid(
        CELLS,
        &Warp {
            amplitude: 0.0,
            seed: 1,
        },
    );
    render_util::set_point_field(&mut mesh, |p| (p - CENTRE).length());
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    // A volume of zero extinction: the mixed frames draw the surfaces only.
    let (lo, hi) = scene.range;
    scene.tf = TransferFunction::from_channels(
        &[(lo, [0.0]), (hi, [0.0])],
        &[(lo, [0.5, 0.5, 0.5]), (hi, [0.5, 0.5, 0.5])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    scene
}

/// Where pixel `(i, j)`'s ray meets the sphere first (entering), with the
/// view direction (the headlight's); `Some(None)` where it misses it,
/// `None` where it passes within `band` of its outline.
fn sphere_pixel(cam: &Camera, i: u32, j: u32, band: f64) -> Option<Option<(DVec3, DVec3)>> {
    let ray = cam.ray_at(i as f64 + 0.5, j as f64 + 0.5);
    let d = ray.dir.normalize();
    let t = (CENTRE - ray.origin).dot(d);
    let closest = (ray.origin + d * t - CENTRE).length();
    if (closest - RADIUS).abs() <= band {
        return None;
    }
    if closest > RADIUS {
        return Some(None);
    }
    let x = ray.origin + d * (t - (RADIUS * RADIUS - closest * closest).sqrt());
    Some(Some((x, cam.forward)))
}

/// The renders checked: the reference with each field model, and each
/// projected mode through each compositor.
fn renders(ortho: bool, iso: &IsoOptions) -> Vec<(String, RenderOptions)> {
    let camera = CameraParams {
        width: SIZE,
        height: SIZE,
        azimuth: 35.0,
        elevation: 25.0,
        zoom: 1.6,
        ortho,
        ..Default::default()
    };
    let mut out = Vec::new();
    for model in [FieldModel::Faces, FieldModel::Tets, FieldModel::Native] {
        out.push((
            format!("raycast {model:?}"),
            RenderOptions {
                mode: Mode::Raycast,
                camera,
                reference: ReferenceOptions {
                    model,
                    ..Default::default()
                },
                iso: iso.clone(),
                ..Default::default()
            },
        ));
    }
    let mut compositors = vec![Compositor::Cpu];
    if gpu_available() {
        compositors.push(Compositor::Gpu);
    }
    for c in compositors {
        for (mode, alone) in [(Mode::Iso, true), (Mode::ExactFrag, false)] {
            out.push((
                format!("{mode:?} alone={alone} {c:?}"),
                RenderOptions {
                    mode,
                    camera,
                    projected: ProjectedOptions {
                        compositor: c,
                        ..Default::default()
                    },
                    iso: IsoOptions {
                        alone,
                        ..iso.clone()
                    },
                    ..Default::default()
                },
            ));
        }
    }
    out
}

/// Renders the sphere styled `list` with `lighting` and checks every pixel
/// outside the outline's band against `want` (the ray's entry point and the
/// view direction; `None` where it misses), within `tol` (f32) or
/// `tol_f16`.
fn check(
    list: &str,
    lighting: Lighting,
    want: impl Fn(Option<(DVec3, DVec3)>) -> [f64; 4],
    tol: f64,
    tol_f16: f64,
) {
    let scene = sphere_scene();
    let shading = scene.shading();
    let mut r = Renderer::new(scene.geometry());
    let iso = IsoOptions {
        surfaces: zoovr::render::iso::parse_list(list).unwrap(),
        lighting,
        alone: true,
        mix: Default::default(),
    };
    for ortho in [false, true] {
        for (name, opts) in renders(ortho, &iso) {
            let cam = Camera::fit(scene.mesh.bounds(), &opts.camera);
            let (img, _) = r.render(&shading, &opts, |_, _| {}).unwrap();
            assert_eq!(img.count_non_finite(), 0);
            let f16 = opts.projected.compositor == Compositor::Gpu && gpu_accumulates_f16();
            let tol = if f16 { tol_f16 } else { tol };
            let mut hits = 0;
            let c = render_util::against_closed_form(&img, tol, |i, j| {
                let hit = sphere_pixel(&cam, i, j, delta())?;
                hits += hit.is_some() as usize;
                Some(want(hit))
            });
            eprintln!(
                "sphere {list} {lighting:?} ortho={ortho} {name}: max {:.2e} over {} pixels \
                 ({hits} on the sphere)",
                c.worst, c.checked
            );
            assert!(hits > 2000 && c.checked > (SIZE * SIZE * 9 / 10) as usize);
            assert!(
                c.worst <= tol,
                "sphere {list} {lighting:?} ortho={ortho} {name}: {:.3e} at {} pixels \
                 (pixel, got, want): {:?}",
                c.worst,
                c.bad.len(),
                &c.bad[..c.bad.len().min(6)]
            );
        }
    }
}

#[test]
fn an_opaque_sphere_without_light_is_exact_outside_its_outline() {
    check(
        &format!("{RADIUS}:#00ff00:1"),
        Lighting::None,
        |hit| match hit {
            Some(_) => [0.0, 1.0, 0.0, 1.0],
            None => [0.0; 4],
        },
        EXACT_TOL,
        EXACT_TOL_F16,
    );
}

/// Entering, the field falls: the back side's style (blue, 0.25); leaving,
/// it rises: the front side's (red, 0.5), behind it.
#[test]
fn a_translucent_sphere_shows_its_back_style_over_its_front_style() {
    check(
        &format!("{RADIUS}:#ff0000:0.5:#0000ff:0.25"),
        Lighting::None,
        |hit| match hit {
            Some(_) => [0.75 * 0.5, 0.0, 0.25, 1.0 - 0.75 * 0.5],
            None => [0.0; 4],
        },
        EXACT_TOL,
        EXACT_TOL_F16,
    );
}

/// The headlight (along the view direction) on the sphere's normal where
/// the ray enters it.
#[test]
fn smooth_light_follows_the_spheres_normal() {
    check(
        &format!("{RADIUS}:#ffffff:1"),
        Lighting::Smooth,
        |hit| match hit {
            Some((x, d)) => {
                let n = (x - CENTRE).normalize();
                let k = 0.25 + 0.75 * n.dot(d).abs();
                [k, k, k, 1.0]
            }
            None => [0.0; 4],
        },
        SMOOTH_LIGHT_TOL,
        SMOOTH_LIGHT_TOL,
    );
}
