//! The exact mode (wgpu) against the reference ray caster.
//!
//! Every case renders the same scene twice at 256 x 256 and compares PNG
//! display values: whole-cell exact mode against `--model faces`, and
//! `--split all` against `--model tets`; orthographic and perspective; the
//! default transfer function and one whose extinction has kinks inside the
//! cells (so breakpoint slabs are exercised). Bounds are on the maximum
//! over every pixel (2/255 with f32 accumulation, `F16_MAX` where the GPU
//! accumulates in f16) and the RMS (2e-3), except where a constant
//! below names the model difference that explains more, with its measured
//! value. Failing cases write actual/expected/diff
//! PNGs under target/test-output. Skips cleanly without a GPU adapter or
//! without the shared data.

mod render_util;
use render_util::{gpu_available, max_outside, options, split_cells, split_mask};

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

use zoovr::camera::{Camera, CameraParams};
use zoovr::image::{check_images_with, Bounds, Image};
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::{Mode, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::{mesh_file, shared_file};
use zoovr::tf::{EmissionModel, TransferFunction};

/// Bound on every pixel (PNG values): 2/255 (the same field, f32
/// accumulation; `F16_MAX` with f16), and an RMS bound.
const MAX: f64 = 2.0 / 255.0;
const RMS: f64 = 2e-3;
/// The bound on every pixel where the GPU accumulates in f16 (GL on
/// llvmpipe, which cannot blend f32 targets; `tests/gpu_exact.rs`
/// measures the store): each blend rounds to 11 significant bits, up to
/// half an ulp (2.4e-4 at 0.5 to 1) per layer the ray meets, so the
/// error grows with the layers of a pixel. Measured up to 1.16e-2 where
/// f32 is within 2/255 (bluntfin and AngularSector split into tets,
/// kinked TF; both modes, both projections).
const F16_MAX: f64 = 1.6e-2;
/// One optically thick cell filling the view: inside a region the glow
/// colour `C/alpha` is interpolated, which is exact only for constant colour
/// (docs/math.md 8.1); colour refinement bounds it, but a single cell seen
/// whole keeps up to 2.25e-2 (voxel and hexahedron, orthographic, default
/// TF).
const THICK_CELL_MAX: f64 = 2.5e-2;
/// Whole-cell exact vs `faces` where cells holding a breakpoint are drawn
/// as their consistent tets: there the exact mode integrates the `tets`
/// field and the reference the `faces` field (a model difference, not an
/// error). Measured up to 7.65e-2 (ring_hole, perspective, kinked TF).
const MODEL_DIFF: (f64, f64) = (0.1, 4e-2);
/// can_crush: crushed, self-intersecting cells (overlapping pieces, which
/// the exact mode integrates both where the ray caster's walk follows one
/// layer) and 24,569 nonplanar faces. Measured 0.136 (both comparisons).
const CAN_CRUSH: (f64, f64) = (0.15, 4e-3);

/// A TF over `range` whose extinction has kinks at 30 %, 50 % and 70 % of
/// the range and whose colour varies.
fn kinked_tf(range: (f64, f64), unit: f64) -> TransferFunction {
    let (lo, hi) = range;
    let at = |x: f64| lo + (hi - lo) * x;
    let tau = [
        (at(0.0), [0.0]),
        (at(0.3), [0.2 / unit]),
        (at(0.5), [1.5 / unit]),
        (at(0.7), [0.3 / unit]),
        (at(1.0), [0.8 / unit]),
    ];
    let col = [
        (at(0.0), [0.1, 0.2, 0.9]),
        (at(0.5), [0.2, 0.9, 0.3]),
        (at(1.0), [1.0, 0.3, 0.1]),
    ];
    TransferFunction::from_channels(&tau, &col, None, EmissionModel::Glow).unwrap()
}

/// The view every comparison here is made in.
fn view(ortho: bool) -> CameraParams {
    CameraParams {
        width: 256,
        height: 256,
        azimuth: 20.0,
        elevation: 35.0,
        zoom: 1.25,
        ortho,
        ..Default::default()
    }
}

/// Renders `scene` with `renderer` (made from its geometry, so a GPU
/// device is opened once per scene).
fn render(
    renderer: &mut Renderer,
    scene: &Scene,
    mode: Mode,
    model: FieldModel,
    split_all: bool,
    ortho: bool,
) -> Image {
    let opts = RenderOptions {
        camera: view(ortho),
        ..options(mode, split_all, model)
    };
    let (img, _) = renderer.render(&scene.shading(), &opts, |_, _| {}).unwrap();
    assert_eq!(img.count_non_finite(), 0, "non-finite pixels");
    img
}

/// The reference ray caster's image of `scene` (`key` names its file and
/// transfer function) with `model`: rendered once per test binary, as the
/// exact and the exact-frag checks compare with the same images.
fn reference(key: &str, scene: &Scene, model: FieldModel, ortho: bool) -> Arc<Image> {
    type Slot = Arc<OnceLock<Arc<Image>>>;
    static IMAGES: OnceLock<Mutex<HashMap<String, Slot>>> = OnceLock::new();
    let key = format!("{key} {model:?} ortho={ortho}");
    let slot = IMAGES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(key)
        .or_default()
        .clone();
    slot.get_or_init(|| {
        let mut renderer = Renderer::new(scene.geometry());
        Arc::new(render(
            &mut renderer,
            scene,
            Mode::Raycast,
            model,
            false,
            ortho,
        ))
    })
    .clone()
}

/// Compares exact (whole cells) vs faces and exact --split all vs tets, both
/// projections, default and kinked TFs.
fn check_file(path: &Path, name: &str, whole_bounds: (f64, f64), split_bounds: (f64, f64)) {
    check_mode(Mode::Exact, path, name, whole_bounds, split_bounds);
}

/// [`check_file`] for `mode`: a mode that does not slice at breakpoints
/// (exact-frag) draws cells holding one whole, so its whole-cell image is
/// compared with `faces` without the model difference.
fn check_mode(
    mode: Mode,
    path: &Path,
    name: &str,
    whole_bounds: (f64, f64),
    split_bounds: (f64, f64),
) {
    let slices = mode.info().slices_at_breakpoints;
    let f16 = |(m, r): (f64, f64)| {
        if render_util::gpu_accumulates_f16() {
            (m.max(F16_MAX), r)
        } else {
            (m, r)
        }
    };
    let (whole_bounds, split_bounds) = (f16(whole_bounds), f16(split_bounds));
    let single_cell = name.ends_with("prism")
        || ["tetra", "pyramid", "wedge", "hexahedron", "voxel"].contains(&name);
    let mesh = io::read(path, &ReadOptions::default()).unwrap();
    for kinked in [false, true] {
        let mut scene = Scene::build(mesh.clone(), &SceneSpec::default()).unwrap();
        if kinked {
            scene.tf = kinked_tf(scene.range, scene.unit_distance);
        }
        let mut renderer = Renderer::new(scene.geometry());
        let key = format!("{} kinked={kinked}", path.display());
        for ortho in [false, true] {
            let tag = format!(
                "{name}_{mode}_{}_{}",
                if kinked { "kinked" } else { "default" },
                if ortho { "ortho" } else { "persp" }
            );
            let exact = render(&mut renderer, &scene, mode, FieldModel::Faces, false, ortho);
            // A single cell holding breakpoints is drawn entirely as its
            // consistent tets, so its reference is the `tets` model; with
            // several cells, only those holding a breakpoint are split and the
            // whole-cell comparison against `faces` is a bounded model
            // difference.
            let whole_as_tets = slices && kinked && single_cell;
            let reference_model = if whole_as_tets {
                FieldModel::Tets
            } else {
                FieldModel::Faces
            };
            let faces = reference(&key, &scene, reference_model, ortho);
            let model_diff = slices && kinked && !single_cell;
            if model_diff {
                // The model difference only where the rays meet a split
                // cell: elsewhere the whole-cell bound holds.
                let split = split_cells(&renderer, scene.mesh.cells.len());
                let camera = Camera::fit(scene.mesh.bounds(), &view(ortho));
                let mask = split_mask(&scene, &camera, &split);
                let (d, at) = max_outside(&exact, faces.as_ref(), &mask);
                let n = mask.iter().filter(|&&m| m).count();
                eprintln!("{tag} whole vs faces outside the {n} pixels of split cells: max {d:.2e} at {at:?}");
                assert!(
                    d <= whole_bounds.0,
                    "{tag}: whole vs faces outside split cells: {d:.3e} at {at:?} (bound {:.1e})",
                    whole_bounds.0
                );
            }
            let (m, r) = if model_diff {
                (
                    MODEL_DIFF.0.max(whole_bounds.0),
                    MODEL_DIFF.1.max(whole_bounds.1),
                )
            } else {
                whole_bounds
            };
            let b = Bounds {
                max_abs: m,
                p999: m,
                rms: r,
            };
            let d = check_images_with(&format!("{tag}_whole"), &exact, faces.as_ref(), &b)
                .unwrap_or_else(|e| panic!("{e}"));
            eprintln!(
                "{tag} whole vs {}: max {:.2e} p99.9 {:.2e} rms {:.2e}",
                if whole_as_tets { "tets" } else { "faces" },
                d.max_abs,
                d.p999,
                d.rms
            );
            let split = render(&mut renderer, &scene, mode, FieldModel::Faces, true, ortho);
            let tets = reference(&key, &scene, FieldModel::Tets, ortho);
            let b = Bounds {
                max_abs: split_bounds.0,
                p999: split_bounds.0,
                rms: split_bounds.1,
            };
            let d = check_images_with(&format!("{tag}_split"), &split, tets.as_ref(), &b)
                .unwrap_or_else(|e| panic!("{e}"));
            eprintln!(
                "{tag} split vs tets: max {:.2e} p99.9 {:.2e} rms {:.2e}",
                d.max_abs, d.p999, d.rms
            );
        }
    }
}

#[test]
fn single_cells_of_every_kind() {
    if !gpu_available() {
        return;
    }
    for name in [
        "tetra",
        "pyramid",
        "wedge",
        "hexahedron",
        "voxel",
        "pentagonal_prism",
        "hexagonal_prism",
    ] {
        // One optically thick cell filling the view: the interpolated C/alpha
        // inside its regions errs up to ~1.2e-2 (docs/math.md 8.1) even after
        // colour refinement.
        check_file(
            &mesh_file(&format!("{name}.vtk")),
            name,
            (THICK_CELL_MAX, RMS),
            (THICK_CELL_MAX, RMS),
        );
    }
}

#[test]
fn project_meshes() {
    if !gpu_available() {
        return;
    }
    for name in ["curvilinear_4x4x4.vtu", "ring_hole.vtu", "zoo_3x3x3.vtu"] {
        check_file(&mesh_file(name), name, (MAX, RMS), (MAX, RMS));
    }
}

/// The shared datasets both modes are compared on (skipped when absent).
const SHARED: [&str; 6] = [
    "bluntfin/bluntfin_converted.vts",
    "su2_sphere_hybrid/sphere_hybrid_converted.vtu",
    "angular_sector/AngularSector.vtk",
    "prisms_zoo/PentaHexa.vtk",
    "fea_bracket_qtet/kiefer_bracket.vtu",
    "can_crush/can.vtu",
];

/// Shared datasets. Whole-cell comparisons include the cells
/// the exact mode splits into tets (problem and breakpoint cells), where the
/// `faces` reference integrates a different field (MODEL_DIFF).
#[test]
fn shared_datasets() {
    if !gpu_available() {
        return;
    }
    for rel in SHARED {
        let Some(path) = shared_file(rel) else {
            continue;
        };
        // PentaHexa and AngularSector were up to 1.11e-2 before the pixel
        // centres next to outlines and inside slivers were decided on the
        // ray caster's own numbers (src/render/ties/); now within 2.9e-3.
        let whole = if rel.starts_with("can_crush") {
            CAN_CRUSH
        } else {
            (MAX, RMS)
        };
        check_file(&path, rel.split('/').next().unwrap_or(rel), whole, whole);
    }
}

/// Coverage culling (`projection::coverage`) only leaves out triangles that
/// contain no pixel centre, so the image is the same with and without it,
/// in both projections, with slabs (kinked TF) and whole cells: bit for
/// bit; and it does leave triangles out (so this test can fail).
#[test]
fn coverage_culling_changes_no_pixel() {
    if !gpu_available() {
        return;
    }
    let mut files = vec![
        mesh_file("curvilinear_4x4x4.vtu"),
        mesh_file("zoo_3x3x3.vtu"),
    ];
    files.extend(shared_file("bluntfin/bluntfin_converted.vts"));
    // Parts left thin at their outline ([`zoovr::render::ties`]), with
    // culling: the images must not depend on culling there either.
    let mut thin_seen = 0;
    for path in files {
        let mesh = io::read(&path, &ReadOptions::default()).unwrap();
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let mut renderer = Renderer::new(scene.geometry());
        for kinked in [false, true] {
            if kinked {
                scene.tf = kinked_tf(scene.range, scene.unit_distance);
            }
            for ortho in [false, true] {
                let mut triangles = [0u64; 2];
                let mut thin = [0usize; 2];
                let mut images = Vec::new();
                for (k, cull) in [false, true].into_iter().enumerate() {
                    let opts = RenderOptions {
                        camera: CameraParams {
                            // Small enough that many triangles miss every
                            // pixel centre.
                            width: 96,
                            height: 80,
                            azimuth: 20.0,
                            elevation: 35.0,
                            ortho,
                            ..Default::default()
                        },
                        projected: ProjectedOptions {
                            cull_to_pixels: cull,
                            ..Default::default()
                        },
                        ..Default::default()
                    };
                    let (img, stats) = renderer.render(&scene.shading(), &opts, |_, _| {}).unwrap();
                    triangles[k] = stats.projected().unwrap().gpu.triangles;
                    thin[k] = stats.projected().unwrap().thin_outlines;
                    images.push(img);
                }
                let tag = format!("{} kinked={kinked} ortho={ortho}", path.display());
                assert!(
                    triangles[1] < triangles[0],
                    "{tag}: culling dropped nothing ({triangles:?})"
                );
                thin_seen += thin[1];
                let (a, b) = (&images[0], &images[1]);
                for j in 0..a.height {
                    for i in 0..a.width {
                        assert_eq!(a.get(i, j), b.get(i, j), "{tag}: pixel ({i}, {j})");
                    }
                }
            }
        }
    }
    assert!(thin_seen > 0, "no part was left thin at its outline");
}

/// The exact-frag mode on the same cases: no table, no colour
/// interpolation, no slicing, so the thick single cells and the kinked
/// transfer function need no model-difference bound.
#[test]
fn exact_frag_single_cells_and_project_meshes() {
    if !gpu_available() {
        return;
    }
    for name in [
        "tetra",
        "pyramid",
        "wedge",
        "hexahedron",
        "voxel",
        "pentagonal_prism",
        "hexagonal_prism",
    ] {
        let path = mesh_file(&format!("{name}.vtk"));
        check_mode(Mode::ExactFrag, &path, name, (MAX, RMS), (MAX, RMS));
    }
    // Whole cells: cells with nonplanar faces are drawn as their tets (the
    // `tets` field) against `faces`: the model difference of MODEL_DIFF
    // (measured 2.22e-2 on ring_hole, perspective, kinked TF, p99.9
    // 1.75e-2; 1.18e-2 on zoo_3x3x3 in tests/modes.rs).
    const PROBLEM_CELLS: (f64, f64) = MODEL_DIFF;
    // One isolated pixel of curvilinear_4x4x4 (perspective, kinked TF,
    // pixel (193, 217)) measured 1.02e-2 here before sliver centres were
    // decided on the exact triangles (src/render/ties/); now 9.7e-4.
    for name in ["curvilinear_4x4x4.vtu", "ring_hole.vtu", "zoo_3x3x3.vtu"] {
        let split = (MAX, RMS);
        check_mode(
            Mode::ExactFrag,
            &mesh_file(name),
            name,
            PROBLEM_CELLS,
            split,
        );
    }
}

/// The exact-frag mode on the shared datasets.
#[test]
fn exact_frag_shared_datasets() {
    if !gpu_available() {
        return;
    }
    for rel in SHARED {
        let Some(path) = shared_file(rel) else {
            continue;
        };
        let name = rel.split('/').next().unwrap_or(rel);
        // can_crush's self-overlapping cells: the model difference named
        // at CAN_CRUSH (measured 0.123 here). AngularSector's tet sliver
        // whose silhouette missed a centre after snapping (1.03e-2) is
        // decided exactly by src/render/ties/: now 5.75e-3.
        let b = if rel.starts_with("can_crush") {
            CAN_CRUSH
        } else {
            (MAX, RMS)
        };
        check_mode(Mode::ExactFrag, &path, name, b, b);
    }
}
