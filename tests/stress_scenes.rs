//! Numerical stress scenes: generated meshes in the corners of the
//! domain, each rendered in every mode that exists (exact and exact-frag,
//! whole cells and `--split all`, ray caster `faces` and `tets`), with no
//! NaN/Inf and the projected modes within the bounds of
//! `tests/render_exact.rs` against the ray caster: `--split all` vs `tets`
//! (same field) and whole cells vs `faces`.
//!
//! Scenes: cells 1e-12 thin and sliver tets; an axis-aligned grid seen
//! exactly edge-on and along a face diagonal (vertices projecting onto
//! vertices and edges); extinction up to 1e6 (opaque); scalars spanning
//! 1e-12 around 1 and 1e12; coordinates offset by 1e7 (UTM-like);
//! perspective with the eye close to and inside the mesh (near-plane
//! clipping). Skips the GPU modes cleanly without an adapter.

mod render_util;
use render_util::{gpu_available, max_outside, options, split_cells, split_mask};

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::generate::{warped_hex_grid, zoo_grid, Warp};
use zoovr::image::{check_images_with, Bounds, Image};
use zoovr::mesh::Mesh;
use zoovr::raycast::FieldModel;
use zoovr::render::iso::IsoOptions;
use zoovr::render::{Mode, PieceDraw, Renderer, Scene, SceneSpec};
use zoovr::tf::{EmissionModel, TransferFunction};

/// Bounds with the same field (`--split all` vs `tets`), max over every
/// pixel: 2/255. Measured up to 3.3e-3 (eye inside the mesh; was 8.5e-3
/// on the axis-aligned grid before pixel centres next to outlines and
/// inside slivers were decided on the ray caster's own numbers,
/// src/render/ties/).
const SPLIT_MAX: f64 = 2.0 / 255.0;
const P999: f64 = 1e-2;
/// Isosurfaces against the ray caster's: a pixel is off beyond 2/255.
const ISO_PIXEL_TOL: f64 = 2.0 / 255.0;
/// Pixels off per view (surface silhouettes and the edges of faces that
/// hold the isovalue may differ on single pixels). Measured 0 in every
/// scene and view, Vulkan and GL; the field spanning 1e-12 around 1 had
/// up to 38 before every renderer moved such a field's scalars to an
/// origin in its middle (`zoovr::render::origin`: interpolating the raw
/// values, whose ulps are 2.2e-4 of that range, moved the reference's
/// crossings, and the projected modes' decisions at shared faces read
/// them too).
const ISO_OFF_MAX: usize = 2;
const RMS: f64 = 2e-3;
/// exact-frag whole cells against `faces`: cells with nonplanar faces are
/// drawn as tets (model difference, measured up to 4.86e-2).
const OUTLIER_MAX: f64 = 0.15;

/// A TF over `range` with extinction from 0 to `tau_max` (per unit length),
/// a kink in the middle, and varying colour.
fn tf(range: (f64, f64), tau_max: f64) -> TransferFunction {
    let (lo, hi) = range;
    let at = |x: f64| lo + (hi - lo) * x;
    TransferFunction::from_channels(
        &[
            (at(0.0), [0.0]),
            (at(0.5), [0.6 * tau_max]),
            (at(1.0), [tau_max]),
        ],
        &[(at(0.0), [0.1, 0.2, 0.9]), (at(1.0), [1.0, 0.5, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap()
}

/// Replaces the point scalar `f` by `map(f)`.
fn map_field(mesh: &mut Mesh, map: impl Fn(f64) -> f64) {
    let a = mesh
        .point_data
        .iter_mut()
        .find(|a| a.name == "f")
        .expect("generated field");
    let values: Vec<f64> = (0..a.tuples()).map(|i| map(a.component(i, 0))).collect();
    a.data = zoovr::field::ArrayData::F64(values);
    a.vtk_type = "Float64".into();
}

fn transform(mesh: &mut Mesh, f: impl Fn(DVec3) -> DVec3) {
    for p in &mut mesh.points {
        *p = f(*p);
    }
}

struct Case<'a> {
    name: &'a str,
    mesh: Mesh,
    /// Scalar range of the TF, and its largest extinction per unit length.
    range: (f64, f64),
    tau_max: f64,
    views: Vec<View>,
    /// A known gap of the exact mode (documented where the case is defined): the comparison is
    /// measured and printed, and only non-finite pixels fail.
    gap: Option<&'a str>,
}

#[derive(Clone, Copy)]
enum View {
    /// Fitted camera with these azimuth, elevation, projection.
    Fit(f64, f64, bool),
    /// Fitted perspective camera with the eye moved towards the focal
    /// point to this fraction of its distance.
    Dolly(f64, f64, f64),
}

fn camera(mesh: &Mesh, v: View, size: u32) -> Camera {
    let p = |az, el, ortho| CameraParams {
        width: size,
        height: size,
        azimuth: az,
        elevation: el,
        ortho,
        ..Default::default()
    };
    match v {
        View::Fit(az, el, ortho) => Camera::fit(mesh.bounds(), &p(az, el, ortho)),
        View::Dolly(az, el, frac) => {
            let mut c = Camera::fit(mesh.bounds(), &p(az, el, false));
            c.position = c.focal_point + (c.position - c.focal_point) * frac;
            c
        }
    }
}

fn run(case: Case, gpu: bool) {
    let size = 96;
    let mut scene = Scene::build(case.mesh, &SceneSpec::default()).unwrap();
    scene.tf = tf(case.range, case.tau_max);
    let mut r = Renderer::new(scene.geometry());
    for (vi, &v) in case.views.iter().enumerate() {
        let cam = camera(&scene.mesh, v, size);
        // The cells the last projected render drew as tets.
        let last_split = std::cell::RefCell::new(Vec::new());
        let mut render =
            |mode: Mode, model: FieldModel, split_all: bool, draw: PieceDraw| -> Image {
                let mut opts = options(mode, split_all, model);
                opts.projected.piece_draw = draw;
                let (img, _) = r
                    .render_with_camera(&scene.shading(), &opts, &cam, |_, _| {})
                    .unwrap_or_else(|e| panic!("{} view {vi} {mode:?}: {e}", case.name));
                if mode != Mode::Raycast {
                    *last_split.borrow_mut() = split_cells(&r, scene.mesh.cells.len());
                }
                assert_eq!(
                    img.count_non_finite(),
                    0,
                    "{} view {vi} {mode:?} {model:?} split {split_all}: non-finite pixels",
                    case.name
                );
                img
            };
        let faces = render(Mode::Raycast, FieldModel::Faces, false, PieceDraw::Regions);
        let tets = render(Mode::Raycast, FieldModel::Tets, false, PieceDraw::Regions);
        let covered = faces.pixels.iter().filter(|p| p[3] > 1e-3).count();
        eprintln!("{} view {vi}: {covered} covered pixels", case.name);
        if !gpu {
            continue;
        }
        let loose = Bounds {
            max_abs: 1.0,
            p999: 1.0,
            rms: 1.0,
        };
        if let Some(why) = case.gap {
            eprintln!("{} view {vi}: KNOWN GAP, not bounded: {why}", case.name);
        }
        let b = if case.gap.is_some() {
            loose
        } else {
            Bounds {
                max_abs: SPLIT_MAX,
                p999: P999,
                rms: RMS,
            }
        };
        // The table modes: finite everywhere (render() checks), whole
        // cells and split, their pieces projected and drawn whole.
        for mode in [Mode::Preint3d, Mode::Preint2d, Mode::Preint2dCyl] {
            for draw in [PieceDraw::Regions, PieceDraw::Quads] {
                render(mode, FieldModel::Faces, false, draw);
                render(mode, FieldModel::Faces, true, draw);
            }
        }
        let split = render(Mode::Exact, FieldModel::Faces, true, PieceDraw::Regions);
        let d = check_images_with(
            &format!("stress_{}_{vi}_split", case.name),
            &split,
            &tets,
            &b,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "{} view {vi} split vs tets: max {:.2e} p99.9 {:.2e} rms {:.2e}",
            case.name, d.max_abs, d.p999, d.rms
        );
        let whole = render(Mode::Exact, FieldModel::Faces, false, PieceDraw::Regions);
        // Outside the pixels whose rays meet a split cell, the whole-cell
        // image integrates the `faces` field itself: the split bound holds.
        let mask = split_mask(&scene, &cam, &last_split.borrow());
        let (d, at) = max_outside(&whole, &faces, &mask);
        assert!(
            d <= b.max_abs,
            "{} view {vi}: whole vs faces outside the split cells' pixels: {d:.3e} at {at:?}",
            case.name
        );
        eprintln!(
            "{} view {vi} whole vs faces outside the {} pixels of split cells: max {d:.2e}",
            case.name,
            mask.iter().filter(|&&m| m).count()
        );
        // Cells holding the TF's kink are drawn as tets: compare the whole-
        // cell image with the reference of the same field where every cell
        // holds it, else with `faces` (model difference bounded as in
        // tests/render_exact.rs).
        let d = check_images_with(
            &format!("stress_{}_{vi}_whole", case.name),
            &whole,
            &faces,
            &if case.gap.is_some() {
                loose
            } else {
                // Model difference: cells holding the TF's kink carry the
                // `tets` field (tests/render_exact.rs MODEL_DIFF; a single
                // pixel measured 0.363 on the 1e-12 thin grid).
                Bounds {
                    max_abs: 0.5,
                    p999: 0.35,
                    rms: 4e-2,
                }
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "{} view {vi} whole vs faces: max {:.2e} p99.9 {:.2e} rms {:.2e}",
            case.name, d.max_abs, d.p999, d.rms
        );
        // The exact-frag mode (no table, no slicing) at the exact mode's
        // split bounds; its whole cells integrate the `faces` field itself
        // except in cells with nonplanar faces, which the order draws as
        // tets (model difference measured up to 4.86e-2 on the warped
        // grids, the same as the exact mode's there).
        // Those cells up to OUTLIER_MAX. The tau_1e3 scene (optically
        // thick cells seen nearly along a face) was at 4.8e-2 here while
        // its wide, steep triangles carried the exact corners' values to
        // the snapped corners; with the exact triangle's values there
        // (`render::ties::snap_is_steep`) it is at 2.6e-5 split and
        // 3.4e-3 whole (against `faces`, with the tets of its problem
        // cells), within the split bound.
        let frag_split = b;
        let frag_whole = if case.gap.is_some() || case.name == "tau_1e3" {
            b
        } else {
            Bounds {
                max_abs: OUTLIER_MAX,
                p999: 0.05,
                rms: 1e-2,
            }
        };
        // Its whole-piece quads (`--piece-draw quads`) at the same bounds.
        for (split_all, draw) in [
            (true, PieceDraw::Regions),
            (false, PieceDraw::Regions),
            (true, PieceDraw::Quads),
            (false, PieceDraw::Quads),
        ] {
            let got = render(Mode::ExactFrag, FieldModel::Faces, split_all, draw);
            let (reference, what) = if split_all {
                (&tets, "split vs tets")
            } else {
                (&faces, "whole vs faces")
            };
            let d = check_images_with(
                &format!("stress_{}_{vi}_frag_{split_all}_{draw:?}", case.name),
                &got,
                reference,
                if split_all { &frag_split } else { &frag_whole },
            )
            .unwrap_or_else(|e| panic!("{e}"));
            eprintln!(
                "{} view {vi} exact-frag {draw:?} {what}: max {:.2e} p99.9 {:.2e} rms {:.2e}",
                case.name, d.max_abs, d.p999, d.rms
            );
        }
        // Isosurfaces (at 37 % of the range and at the field's minimum,
        // a value only points hold), alone and mixed with the volume,
        // against the ray caster's (`faces` field, whole cells).
        let (lo, hi) = case.range;
        let min = match scene.scalars() {
            zoovr::render::ScalarsRef::Point(v) => v.iter().copied().fold(f64::INFINITY, f64::min),
            _ => lo,
        };
        let list = format!("{:e},{:e}", lo + 0.37 * (hi - lo), min);
        let iso = IsoOptions {
            surfaces: zoovr::render::iso::parse_list(&list).unwrap(),
            ..Default::default()
        };
        // The exact mode with surfaces integrates per fragment, as
        // exact-frag, split or whole. Whole cells are compared outside the pixels of the cells the
        // order drew as tets (cells with nonplanar faces: their surfaces
        // are the `tets` field's, a model difference), split ones
        // everywhere.
        for (mode, alone, split) in [
            (Mode::Iso, true, false),
            (Mode::Iso, true, true),
            (Mode::ExactFrag, false, false),
            (Mode::ExactFrag, false, true),
            (Mode::Exact, false, false),
            (Mode::Exact, false, true),
        ] {
            let model = if split {
                FieldModel::Tets
            } else {
                FieldModel::Faces
            };
            let mut opts = options(mode, split, model);
            opts.iso = IsoOptions {
                alone,
                ..iso.clone()
            };
            let mut reference = opts.clone();
            reference.mode = Mode::Raycast;
            let go = |r: &mut Renderer, o: &zoovr::render::RenderOptions| {
                let (img, _) = r
                    .render_with_camera(&scene.shading(), o, &cam, |_, _| {})
                    .unwrap_or_else(|e| panic!("{} view {vi} iso {mode:?}: {e}", case.name));
                assert_eq!(
                    img.count_non_finite(),
                    0,
                    "{} view {vi} iso {mode:?}: non-finite pixels",
                    case.name
                );
                img
            };
            let got = go(&mut r, &opts);
            let mask = if split {
                vec![false; got.pixels.len()]
            } else {
                split_mask(&scene, &cam, &split_cells(&r, scene.mesh.cells.len()))
            };
            let want = go(&mut r, &reference);
            let (mut off, mut max) = (0usize, 0.0f64);
            for ((p, q), _) in got
                .pixels
                .iter()
                .zip(&want.pixels)
                .zip(&mask)
                .filter(|(_, &m)| !m)
            {
                let d = (0..4)
                    .map(|c| (p[c] as f64 - q[c] as f64).abs())
                    .fold(0.0, f64::max);
                if d > ISO_PIXEL_TOL {
                    off += 1;
                } else {
                    max = max.max(d);
                }
            }
            eprintln!(
                "{} view {vi} iso {mode:?} split {split}: {off} pixels off by more than {ISO_PIXEL_TOL:.1e}, max elsewhere {max:.2e} ({} pixels of split cells left out)",
                case.name,
                mask.iter().filter(|&&m| m).count()
            );
            assert!(
                off <= ISO_OFF_MAX,
                "{} view {vi} iso {mode:?}: {off} pixels off",
                case.name
            );
        }
    }
}

fn grid(n: usize, amplitude: f64) -> Mesh {
    warped_hex_grid(n, &Warp { amplitude, seed: 7 })
}

fn oblique() -> Vec<View> {
    vec![View::Fit(20.0, 35.0, false), View::Fit(-30.0, 10.0, true)]
}

#[test]
fn thin_cells_and_slivers() {
    let gpu = gpu_available();
    // A warped grid squashed to 1e-12 of its size in z: every cell a sheet,
    // its tets slivers. Extinction scaled so the optical depth is ~1.
    let mut m = grid(4, 0.05);
    transform(&mut m, |p| DVec3::new(p.x, p.y, p.z * 1e-12));
    run(
        Case {
            name: "thin",
            mesh: m,
            range: (0.0, 1.0),
            tau_max: 1e12,
            // Oblique, and face-on (the rays cross the 1e-12 layers).
            views: vec![View::Fit(20.0, 35.0, false), View::Fit(0.0, 0.0, true)],
            gap: None,
        },
        gpu,
    );
    // A zoo grid (tets, pyramids, wedges, hexes) flattened to 1e-9.
    let mut m = zoo_grid(3, &Warp::default());
    transform(&mut m, |p| DVec3::new(p.x, p.y * 1e-9, p.z));
    run(
        Case {
            name: "flat_zoo",
            mesh: m,
            range: (0.0, 1.0),
            tau_max: 1e9,
            // Oblique, and face-on from above.
            views: vec![View::Fit(10.0, 60.0, false), View::Fit(0.0, 90.0, true)],
            gap: None,
        },
        gpu,
    );
}

#[test]
fn edge_on_faces_and_coincident_projections() {
    let gpu = gpu_available();
    // An unwarped grid: looking down an axis (ortho and perspective) every
    // side face is edge-on and vertices project onto vertices; along a face
    // diagonal, vertices project onto edges.
    run(
        Case {
            name: "axis_aligned",
            mesh: grid(4, 0.0),
            range: (0.0, 1.0),
            tau_max: 10.0,
            views: vec![
                View::Fit(0.0, 0.0, true),
                View::Fit(0.0, 0.0, false),
                View::Fit(45.0, 0.0, true),
                View::Fit(45.0, 35.264_389_682_754_654, true),
            ],
            gap: None,
        },
        gpu,
    );
}

/// The exact tie decisions (src/render/ties/) are what puts the
/// outline pixels right: on the CPU twin, the opaque warped grid (tau 1e6)
/// seen obliquely is within SPLIT_MAX of the ray caster with them, and a
/// whole pixel off without them (`ProjectedOptions::exact_ties`, off only to measure their
/// cost in benches/ties.rs).
#[test]
fn outline_pixels_need_the_exact_tie_decisions() {
    let mut scene = Scene::build(grid(4, 0.05), &SceneSpec::default()).unwrap();
    scene.tf = tf((0.0, 1.0), 1e6);
    let mut r = Renderer::new(scene.geometry());
    let cam = camera(&scene.mesh, View::Fit(-30.0, 10.0, true), 96);
    let mut render = |mode: Mode, model: FieldModel, ties: bool| {
        let mut opts = options(mode, true, model);
        opts.projected.compositor = zoovr::render::Compositor::Cpu;
        opts.projected.exact_ties = ties;
        r.render_with_camera(&scene.shading(), &opts, &cam, |_, _| {})
            .unwrap()
    };
    let (tets, _) = render(Mode::Raycast, FieldModel::Tets, true);
    let mut errors = Vec::new();
    for ties in [true, false] {
        let (img, stats) = render(Mode::Exact, FieldModel::Tets, ties);
        let p = stats.projected().unwrap();
        assert_eq!(p.tie_pixels > 0, ties, "tie pixels {}", p.tie_pixels);
        let (d, _) = zoovr::image::compare_float(&img, &tets).unwrap();
        errors.push(d.max_abs);
    }
    eprintln!(
        "max error with ties {:.2e}, without {:.2e}",
        errors[0], errors[1]
    );
    // Measured 7.3e-4 with them, 1.0 without.
    assert!(errors[0] <= SPLIT_MAX, "{errors:?}");
    assert!(errors[1] > 0.1, "{errors:?}");
}

/// Centres inside slivers take the exact segment (src/render/ties/): on
/// the AngularSector dataset at 128 x 128 (default field, transfer function
/// and view; skipped without the shared data) a sliver region of a slab
/// seen nearly edge-on holds pixel (108, 46), where the snapped corners
/// shifted the interpolated thickness by 17 % (0.023 off the ray caster);
/// with the exact segment every pixel is within SPLIT_MAX. On the CPU twin.
#[test]
fn sliver_pixels_take_the_exact_segment() {
    let Some(path) = zoovr::testdata::shared_file("angular_sector/AngularSector.vtk") else {
        eprintln!("skipping: no shared data");
        return;
    };
    let mesh = zoovr::io::read(&path, &Default::default()).unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let mut r = Renderer::new(scene.geometry());
    let cam = Camera::fit(
        scene.mesh.bounds(),
        &CameraParams {
            width: 128,
            height: 128,
            ..Default::default()
        },
    );
    let mut render = |mode: Mode, ties: bool| {
        let mut opts = options(mode, true, FieldModel::Tets);
        opts.projected.compositor = zoovr::render::Compositor::Cpu;
        opts.projected.exact_ties = ties;
        r.render_with_camera(&scene.shading(), &opts, &cam, |_, _| {})
            .unwrap()
            .0
    };
    let tets = render(Mode::Raycast, true);
    let with = zoovr::image::compare_float(&render(Mode::Exact, true), &tets)
        .unwrap()
        .0;
    let without = zoovr::image::compare_float(&render(Mode::Exact, false), &tets)
        .unwrap()
        .0;
    eprintln!(
        "max with ties {:.2e}, without {:.2e}",
        with.max_abs, without.max_abs
    );
    assert!(with.max_abs <= SPLIT_MAX, "{with:?}");
    assert!(without.max_abs > 1.5e-2, "{without:?}");
}

#[test]
fn extinction_up_to_1e6() {
    let gpu = gpu_available();
    for (name, tau) in [("tau_0", 0.0), ("tau_1e3", 1e3), ("tau_1e6", 1e6)] {
        run(
            Case {
                name,
                mesh: grid(4, 0.05),
                range: (0.0, 1.0),
                tau_max: tau,
                views: oblique(),
                gap: None,
            },
            gpu,
        );
    }
}

#[test]
fn scalar_ranges_1e_minus_12_and_1e12() {
    let gpu = gpu_available();
    // 1 + 1e-12 f: the whole range is 1e-12 wide, far from zero.
    let mut m = grid(4, 0.05);
    map_field(&mut m, |f| 1.0 + 1e-12 * f);
    run(
        Case {
            name: "range_1e-12",
            mesh: m,
            range: (1.0, 1.0 + 1e-12),
            tau_max: 10.0,
            views: oblique(),
            gap: None,
        },
        gpu,
    );
    let mut m = grid(4, 0.05);
    map_field(&mut m, |f| 1e12 * f);
    run(
        Case {
            name: "range_1e12",
            mesh: m,
            range: (0.0, 1e12),
            tau_max: 10.0,
            views: oblique(),
            gap: None,
        },
        gpu,
    );
}

#[test]
fn coordinates_far_from_the_origin() {
    let gpu = gpu_available();
    // UTM-like: a unit-sized grid 1e7 away from the origin.
    let mut m = grid(4, 0.05);
    transform(&mut m, |p| p + DVec3::new(1e7, -3e6, 2e7));
    run(
        Case {
            name: "offset_1e7",
            mesh: m,
            range: (0.0, 1.0),
            tau_max: 10.0,
            views: oblique(),
            gap: None,
        },
        gpu,
    );
}

#[test]
fn eye_close_to_and_inside_the_mesh() {
    let gpu = gpu_available();
    // The fitted eye sits at ~3.9 bounding radii; 0.35 puts it just outside
    // the grid's corner region, 0.1 inside the mesh (cells cross the near
    // plane and are clipped; rays start at the eye).
    run(
        Case {
            name: "eye_close",
            mesh: grid(4, 0.05),
            range: (0.0, 1.0),
            tau_max: 3.0,
            views: vec![View::Dolly(20.0, 35.0, 0.35)],
            gap: None,
        },
        gpu,
    );
    run(
        Case {
            name: "eye_inside",
            mesh: grid(4, 0.05),
            range: (0.0, 1.0),
            tau_max: 3.0,
            views: vec![View::Dolly(20.0, 35.0, 0.1)],
            gap: None,
        },
        gpu,
    );
}

/// The eye inside a block of constant extinction: every pixel's opacity is
/// `1 - exp(-tau L)` with `L` the distance from the eye to where its ray
/// leaves the box, so both renderers are checked against a closed form.
#[test]
fn eye_inside_a_constant_block_matches_the_closed_form() {
    let gpu = gpu_available();
    let mut mesh = grid(3, 0.0);
    map_field(&mut mesh, |_| 0.5);
    let tau = 1.3;
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(0.0, [tau]), (1.0, [tau])],
        &[(0.0, [0.9, 0.6, 0.3]), (1.0, [0.9, 0.6, 0.3])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let size = 64;
    let cam = camera(&scene.mesh, View::Dolly(20.0, 35.0, 0.05), size);
    let [x0, x1, y0, y1, z0, z1] = scene.mesh.bounds();
    assert!(
        (x0..=x1).contains(&cam.position.x)
            && (y0..=y1).contains(&cam.position.y)
            && (z0..=z1).contains(&cam.position.z),
        "the eye is inside the block"
    );
    let mut want = Image::new(size, size);
    for j in 0..size {
        for i in 0..size {
            let ray = cam.pixel_ray(i, j);
            // Exit distance of the ray from the box (the origin is inside).
            let mut l = f64::INFINITY;
            for k in 0..3 {
                let (o, d) = (ray.origin[k], ray.dir[k]);
                let (lo, hi) = ([x0, y0, z0][k], [x1, y1, z1][k]);
                if d > 0.0 {
                    l = l.min((hi - o) / d);
                } else if d < 0.0 {
                    l = l.min((lo - o) / d);
                }
            }
            let a = -(-tau * l).exp_m1();
            want.pixels[(j * size + i) as usize] = [0.9 * a, 0.6 * a, 0.3 * a, a].map(|v| v as f32);
        }
    }
    let mut r = Renderer::new(scene.geometry());
    let mut modes = vec![(Mode::Raycast, FieldModel::Faces, false)];
    if gpu {
        modes.push((Mode::Exact, FieldModel::Faces, false));
        modes.push((Mode::Exact, FieldModel::Faces, true));
        for m in [Mode::Preint3d, Mode::Preint2d, Mode::Preint2dCyl] {
            modes.push((m, FieldModel::Faces, false));
        }
    }
    for (mode, model, split_all) in modes {
        let opts = options(mode, split_all, model);
        let (img, _) = r
            .render_with_camera(&scene.shading(), &opts, &cam, |_, _| {})
            .unwrap();
        let d = check_images_with(
            &format!("stress_eye_inside_block_{mode:?}_{split_all}"),
            &img,
            &want,
            &Bounds {
                max_abs: OUTLIER_MAX,
                p999: P999,
                rms: RMS,
            },
        );
        eprintln!("{mode:?} split {split_all}: {d:?}");
    }
}

/// Geometry faults in one file: an inverted hexahedron and wedge,
/// a flat (zero-volume) hexahedron, a tetrahedron with a repeated index,
/// five disconnected components, a non-manifold face and coincident points
/// (merged). Every mode renders it without NaN, and the exact mode matches
/// the ray caster: inverted cells are drawn as they are (orientation never
/// matters to projection or ray casting), zero-volume cells add nothing.
#[test]
fn geometry_faults_render_consistently() {
    let gpu = gpu_available();
    let path = zoovr::testdata::mesh_file("degenerate.vtk");
    let mesh = zoovr::io::read(&path, &Default::default()).unwrap();
    let report = zoovr::mesh::report::MeshReport::compute(&mesh);
    assert_eq!(
        (
            report.inverted_cells,
            report.degenerate_cells,
            report.repeated_index_cells
        ),
        (2, 2, 1)
    );
    for (vi, view) in [View::Fit(20.0, 35.0, false), View::Fit(-40.0, 20.0, true)]
        .into_iter()
        .enumerate()
    {
        run(
            Case {
                name: &format!("faults_{vi}"),
                mesh: mesh.clone(),
                range: (0.0, 1.0),
                tau_max: 8.0,
                views: vec![view],
                gap: None,
            },
            gpu,
        );
    }
}

/// Watertightness through the GPU: a warped block of many cells
/// (nonplanar faces, problem cells split per view) with constant extinction
/// and colour. Every pixel's opacity is `1 - exp(-tau L)` for the ray's
/// chord `L` through the block, which the ray caster computes exactly; a
/// seam (a pixel centre no region covers) or a double cover would change a
/// pixel by up to its whole opacity. No outlier allowance: every pixel
/// within 1e-2.
#[test]
fn constant_block_has_no_seams_or_double_cover() {
    if !gpu_available() {
        return;
    }
    let mut mesh = grid(6, 0.06);
    map_field(&mut mesh, |_| 0.5);
    let tau = 2.5;
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(0.0, [tau]), (1.0, [tau])],
        &[(0.0, [0.2, 0.7, 0.9]), (1.0, [0.2, 0.7, 0.9])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let mut r = Renderer::new(scene.geometry());
    for (vi, view) in [
        View::Fit(20.0, 35.0, false),
        View::Fit(-50.0, 10.0, true),
        View::Fit(0.0, 0.0, true),
    ]
    .into_iter()
    .enumerate()
    {
        let cam = camera(&scene.mesh, view, 128);
        let mut img = |mode, split_all| {
            let opts = options(mode, split_all, FieldModel::default());
            r.render_with_camera(&scene.shading(), &opts, &cam, |_, _| {})
                .unwrap()
                .0
        };
        let reference = img(Mode::Raycast, false);
        for split_all in [false, true] {
            let exact = img(Mode::Exact, split_all);
            let bounds = Bounds {
                max_abs: 1e-2,
                p999: 1e-2,
                rms: RMS,
            };
            let d = check_images_with(
                &format!("watertight_{vi}_{split_all}"),
                &exact,
                &reference,
                &bounds,
            )
            .unwrap_or_else(|e| panic!("{e}"));
            eprintln!("watertight view {vi} split {split_all}: {d:?}");
        }
    }
}
