//! The projected modes against the reference ray caster in views along a
//! mesh's own axes, where the random and oblique views of the other image
//! tests rarely go: rows of pixel centres lying in planes of faces, cells
//! seen exactly end-on, and faces whose points are off those planes only
//! by rounding (`r sin(pi)` is 1.2e-16 r, not 0).
//!
//! - **A half annulus of hexahedra** seen down its axis, at odd sizes, so
//!   the middle row of pixel centres lies in the plane `y = 0`, which holds
//!   the faces at `theta = pi` up to their points' rounding. A ray in that
//!   plane runs along such a face for its whole length and is inside the
//!   cell on one side of it for part of the way only: the segment the tie
//!   decisions give must be the exact one even where the rasteriser agrees
//!   that the cell holds the centre.
//! - **The same solid, long and seen end-on in an orthographic view**, with
//!   a transfer function whose colour turns inside the field's range: a
//!   region triangle reaching from a thick corner where the field maps to
//!   little extinction to silhouette corners where it maps to much is
//!   optically deep inside though shallow at every corner, so the exact
//!   mode's colour refinement must bound the depth inside the triangle.
//! - **The shared datasets** in the axis views where these two showed
//!   (skipped without the shared data).
//!
//! Bounds are on every pixel (2/255 with f32 accumulation, the f16 bound of
//! `tests/render_exact.rs` where the GPU accumulates in f16): `--split all`
//! against `--model tets`, and whole cells against `--model faces` outside
//! the cells the mode splits. Failing cases write actual, expected and diff
//! PNGs under target/test-output. Skips cleanly without a GPU adapter.

mod render_util;
use render_util::{
    gpu_accumulates_f16, gpu_available, max_outside, options, split_cells, split_mask,
};

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::generate::{warped_hex_grid_dims, Warp};
use zoovr::image::{check_images_with, Bounds, Image};
use zoovr::io::{self, ReadOptions};
use zoovr::mesh::data::ArrayData;
use zoovr::mesh::Mesh;
use zoovr::raycast::FieldModel;
use zoovr::render::{Mode, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::shared_file;
use zoovr::tf::{EmissionModel, TransferFunction};

/// Bound on every pixel with f32 accumulation (PNG values).
const MAX: f64 = 2.0 / 255.0;
/// With f16 accumulation (as `tests/render_exact.rs`'s `F16_MAX`).
const F16_MAX: f64 = 1.6e-2;

/// The RMS bound: 2e-3 (as `tests/render_exact.rs`), 3e-3 with f16
/// accumulation, whose rounding touches every pixel (measured 2.03e-3 on
/// `prisms_zoo/hexa.vtk`, a few hexahedra filling the view, with the
/// turning colour on GL).
fn rms_bound() -> f64 {
    if gpu_accumulates_f16() {
        3e-3
    } else {
        2e-3
    }
}

fn max_bound() -> f64 {
    if gpu_accumulates_f16() {
        F16_MAX
    } else {
        MAX
    }
}

/// A half annulus of `nr x nt x nz` hexahedra: radius 0.5 to 1.5, angle
/// pi/2 to 3 pi/2 (so `theta = pi` is a layer of faces when `nt` is even),
/// height `length` along z. The points of that layer get `y = noise k`,
/// `k` in -2..=2 by point (a grid written from angles carries such
/// roundings: `r sin(pi)` is 1.2e-16 r, and a solver's output others), so
/// their faces are tilted this way and that against the plane `y = 0`.
/// The field is the generator's `f` of the unit-cube grid it is mapped
/// from, or with `radial` one falling from the inner wall to 0 at the
/// outer one (as a pipe flow's speed does), varying a little along z.
fn half_annulus(dims: [usize; 3], length: f64, noise: f64, radial: bool) -> Mesh {
    let mut mesh = warped_hex_grid_dims(
        dims,
        &Warp {
            amplitude: 0.0,
            seed: 1,
        },
    );
    for (n, p) in mesh.points.iter_mut().enumerate() {
        let (r, t) = (
            0.5 + p.x,
            std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * p.y,
        );
        let mut y = r * t.sin();
        if y.abs() < 1e-9 {
            y = noise * ((n * 7919 % 5) as f64 - 2.0);
        }
        *p = DVec3::new(r * t.cos(), y, length * p.z);
    }
    if radial {
        let values = mesh
            .points
            .iter()
            .map(|p| ((1.5 - p.truncate().length()) * (1.0 + 0.3 * (0.7 * p.z).sin())) as f32)
            .collect();
        mesh.point_data[0].data = ArrayData::F32(values);
    }
    mesh
}

/// A transfer function over `range` with an extinction ramp from 0 and a
/// colour that turns at a fifth of the range (no extinction kink: the
/// exact mode does not slice there, its colour refinement does the work).
fn turning_colour_tf(range: (f64, f64), unit: f64) -> TransferFunction {
    let (lo, hi) = range;
    let tau = [(lo, [0.0]), (hi, [1.0 / unit])];
    let col = [
        (lo, [0.0, 0.0, 1.0]),
        (lo + 0.2 * (hi - lo), [0.0, 1.0, 0.0]),
        (hi, [1.0, 1.0, 0.0]),
    ];
    TransferFunction::from_channels(&tau, &col, None, EmissionModel::Glow).unwrap()
}

/// Renders `scene` with `opts` on `renderer`.
fn render(renderer: &mut Renderer, scene: &Scene, opts: &RenderOptions) -> Image {
    let (img, _) = renderer.render(&scene.shading(), opts, |_, _| {}).unwrap();
    assert_eq!(img.count_non_finite(), 0, "non-finite pixels");
    img
}

/// Checks `modes` against the ray caster on `scene` in `camera`: split
/// into tets against `tets` on every pixel, whole cells against `faces`
/// outside the cells the mode split. Returns the failures.
fn check(scene: &Scene, camera: CameraParams, modes: &[Mode], tag: &str) -> Vec<String> {
    let mut failures = Vec::new();
    let mut renderer = Renderer::new(scene.geometry());
    let with = |mode, split, model| RenderOptions {
        camera,
        ..options(mode, split, model)
    };
    let tets = render(
        &mut renderer,
        scene,
        &with(Mode::Raycast, false, FieldModel::Tets),
    );
    let faces = render(
        &mut renderer,
        scene,
        &with(Mode::Raycast, false, FieldModel::Faces),
    );
    let bounds = Bounds {
        max_abs: max_bound(),
        p999: max_bound(),
        rms: rms_bound(),
    };
    let fitted = Camera::fit(scene.mesh.bounds(), &camera);
    for &mode in modes {
        let split = render(&mut renderer, scene, &with(mode, true, FieldModel::Faces));
        let name = format!("aligned {tag} {mode} split").replace([' ', '/'], "_");
        if let Err(e) = check_images_with(&name, &split, &tets, &bounds) {
            failures.push(e);
        }
        let whole = render(&mut renderer, scene, &with(mode, false, FieldModel::Faces));
        let mask = split_mask(
            scene,
            &fitted,
            &split_cells(&renderer, scene.mesh.cells.len()),
        );
        let (worst, at) = max_outside(&whole, &faces, &mask);
        if worst > max_bound() {
            let name = format!("aligned {tag} {mode} whole").replace([' ', '/'], "_");
            let _ = check_images_with(&name, &whole, &faces, &bounds);
            failures.push(format!(
                "{tag} {mode} whole cells against faces: {worst:.3e} at {at:?} outside split cells (bound {:.1e})",
                max_bound()
            ));
        }
    }
    failures
}

fn assert_none(failures: Vec<String>) {
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_row_of_centres_in_the_plane_of_faces_tilted_by_rounding() {
    if !gpu_available() {
        return;
    }
    let mesh = half_annulus([6, 12, 8], 20.0, 3e-16, false);
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let mut failures = Vec::new();
    for size in [63, 97] {
        for ortho in [false, true] {
            let camera = CameraParams {
                width: size,
                height: size,
                ortho,
                ..Default::default()
            };
            let tag = format!("half annulus {size} ortho={ortho}");
            failures.extend(check(&scene, camera, &[Mode::Exact, Mode::ExactFrag], &tag));
        }
    }
    assert_none(failures);
}

#[test]
fn long_cells_seen_end_on_with_a_turning_colour() {
    if !gpu_available() {
        return;
    }
    let mut failures = Vec::new();
    // One cell and two along the length; end-on and turned by half a
    // degree (thin silhouette regions of no length at their outer corners).
    let cases = [
        ([3, 6, 1], 20.0, [(2.0, 0.0), (5.0, 0.0)]),
        ([3, 6, 2], 12.0, [(5.0, 0.0), (5.0, 0.5)]),
    ];
    for (dims, length, views) in cases {
        let mesh = half_annulus(dims, length, 0.0, true);
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let unit = scene.unit_distance;
        scene.tf = turning_colour_tf(scene.range, unit);
        for (zoom, azimuth) in views {
            let camera = CameraParams {
                width: 80,
                height: 80,
                zoom,
                azimuth,
                ortho: true,
                ..Default::default()
            };
            let tag = format!("long half annulus {dims:?} zoom={zoom} az={azimuth}");
            failures.extend(check(&scene, camera, &[Mode::Exact, Mode::ExactFrag], &tag));
        }
    }
    assert_none(failures);
}

/// The shared datasets in the views where these cases showed, with the
/// default transfer function and the turning colour.
#[test]
fn shared_datasets_in_axis_views() {
    if !gpu_available() {
        return;
    }
    let cases: [(&str, u32, f64, f64, bool); 5] = [
        (
            "disk_out_ref/disk_out_ref_converted.vtu",
            97,
            0.0,
            0.0,
            false,
        ),
        (
            "disk_out_ref/disk_out_ref_converted.vtu",
            97,
            0.0,
            0.0,
            true,
        ),
        ("notch/notch_disp.vtu", 97, 0.0, 90.0, false),
        ("prisms_zoo/hexa.vtk", 97, 90.0, 0.0, false),
        ("tets_small/CylinderLinear.vtk", 97, 0.5, 0.0, true),
    ];
    let mut failures = Vec::new();
    for (rel, size, azimuth, elevation, ortho) in cases {
        let Some(path) = shared_file(rel) else {
            eprintln!("skipping {rel}: no shared data");
            continue;
        };
        let mesh = io::read(&path, &ReadOptions::default()).unwrap();
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let camera = CameraParams {
            width: size,
            height: size,
            azimuth,
            elevation,
            ortho,
            ..Default::default()
        };
        let tag = format!("{rel} az={azimuth} el={elevation} ortho={ortho}");
        failures.extend(check(&scene, camera, &[Mode::Exact, Mode::ExactFrag], &tag));
        let unit = scene.unit_distance;
        scene.tf = turning_colour_tf(scene.range, unit);
        let tag = format!("{tag} turning colour");
        failures.extend(check(&scene, camera, &[Mode::Exact], &tag));
    }
    assert_none(failures);
}
