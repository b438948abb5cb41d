//! Randomised comparison of the exact mode (and of exact-frag with its
//! pieces drawn whole, `--piece-draw quads`) with the reference ray caster:
//! seeded random dataset x view x size, `--split all` against `--model
//! tets` (the same field), bounded over every pixel; the last cases look
//! along the axes at odd sizes.
//!
//! The exact mode is composited by the CPU twin of the GPU stage
//! (`gpu::cpu`, the GPU's own pixels to ~1e-4, see `tests/coverage.rs` for
//! its coverage), so the test runs without an adapter. On failure it
//! prints the pixel, both values, the fragments that coloured it (piece,
//! thickness, extinction, glow) and writes a crop of both images around it
//! to `target/test-output/`.

use zoovr::camera::CameraParams;
use zoovr::image::{compare_display, Image};
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::{
    Compositor, Mode, PieceDraw, ProjectedOptions, ReferenceOptions, RenderOptions, Renderer,
    Scene, SceneSpec,
};
use zoovr::testdata::{mesh_file, shared_file};

/// Bound over every pixel (PNG values): 2/255, every case. The seeded
/// cases reach 6.6e-3 (CylinderLinear); tetraMesh's 8.9e-3 went with the
/// exact decisions on the ray caster's own numbers (`src/render/ties/`).
const MAX: f64 = 2.0 / 255.0;

fn crop(img: &Image, i: u32, j: u32, r: u32) -> Image {
    let (i0, j0) = (i.saturating_sub(r), j.saturating_sub(r));
    let (i1, j1) = ((i + r + 1).min(img.width), (j + r + 1).min(img.height));
    let mut out = Image::new(i1 - i0, j1 - j0);
    for y in j0..j1 {
        for x in i0..i1 {
            out.set(x - i0, y - j0, img.get(x, y));
        }
    }
    out
}

#[test]
fn random_views_match_the_reference_on_every_pixel() {
    let mut files = vec![
        mesh_file("curvilinear_4x4x4.vtu"),
        mesh_file("zoo_3x3x3.vtu"),
        mesh_file("ring_hole.vtu"),
    ];
    for rel in [
        "tets_small/CylinderLinear.vtk",
        "tets_small/tetraMesh.vtk",
        "prisms_zoo/PentaHexa.vtk",
        "prisms_zoo/hexa.vtk",
        "angular_sector/AngularSector.vtk",
        "synthetic/mixed.vtk",
    ] {
        files.extend(shared_file(rel));
    }
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let scenes: Vec<(String, Scene)> = files
        .iter()
        .map(|p| {
            let mesh = io::read(p, &ReadOptions::default()).unwrap();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, Scene::build(mesh, &SceneSpec::default()).unwrap())
        })
        .collect();
    // Cases 15 on look along the mesh's axes (azimuth and elevation
    // multiples of 90 degrees) at odd sizes, whose middle row and column
    // of pixel centres lie in the planes through the bounds' centre: rows
    // of centres in the planes of faces, cells seen end-on.
    for case in 0..21 {
        let (name, scene) = &scenes[(next() * scenes.len() as f64) as usize % scenes.len()];
        let size = 64 + (next() * 192.0) as u32;
        let mut camera = CameraParams {
            width: size,
            height: 64 + (next() * 192.0) as u32,
            azimuth: next() * 360.0,
            elevation: next() * 180.0 - 90.0,
            zoom: 0.7 + next() * 1.3,
            ortho: next() < 0.5,
            ..Default::default()
        };
        if case >= 15 {
            camera.width |= 1;
            camera.height |= 1;
            camera.azimuth = (camera.azimuth / 90.0).floor() * 90.0;
            camera.elevation = (camera.elevation / 90.0).round() * 90.0;
        }
        let tag = format!("case {case}: {name} {camera:?}");
        let mut renderer = Renderer::new(scene.geometry());
        let exact = RenderOptions {
            camera,
            projected: ProjectedOptions {
                split_all: true,
                compositor: Compositor::Cpu,
                ..Default::default()
            },
            ..Default::default()
        };
        let (img, _) = renderer
            .render(&scene.shading(), &exact, |_, _| {})
            .unwrap();
        let reference = RenderOptions {
            mode: Mode::Raycast,
            reference: ReferenceOptions {
                model: FieldModel::Tets,
                ..exact.reference
            },
            ..exact.clone()
        };
        let (want, _) = renderer
            .render(&scene.shading(), &reference, |_, _| {})
            .unwrap();
        assert_eq!(img.count_non_finite(), 0, "{tag}: non-finite pixels");
        let (d, _) = compare_display(&img, &want, [0.0; 3]).unwrap();
        eprintln!("{tag}: max {:.2e} rms {:.2e}", d.max_abs, d.rms);
        // exact-frag with its pieces drawn whole (`--piece-draw quads`):
        // the same bound, every pixel.
        let quads = RenderOptions {
            mode: Mode::ExactFrag,
            projected: ProjectedOptions {
                piece_draw: PieceDraw::Quads,
                ..exact.projected
            },
            ..exact.clone()
        };
        let (qimg, qstats) = renderer
            .render(&scene.shading(), &quads, |_, _| {})
            .unwrap();
        assert_eq!(qimg.count_non_finite(), 0, "{tag}: non-finite quad pixels");
        let (dq, _) = compare_display(&qimg, &want, [0.0; 3]).unwrap();
        let whole = qstats.projected().map_or(0, |e| e.whole_pieces);
        eprintln!(
            "{tag}: quads max {:.2e} rms {:.2e} ({whole} pieces whole)",
            dq.max_abs, dq.rms
        );
        assert!(whole > 0, "{tag}: no piece drawn whole");
        if dq.max_abs > MAX {
            let (i, j) = dq.worst;
            let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_random");
            let _ = std::fs::create_dir_all(&dir);
            let _ = crop(&qimg, i, j, 8).write_png(
                &dir.join(format!("case{case}_quads.png")),
                [0.0; 3],
                false,
            );
            panic!(
                "{tag}: quads pixel ({i}, {j}) differs by {:.3e} > {MAX:.3e}: quads {:?}, reference {:?} (crop in {})",
                dq.max_abs,
                qimg.get(i, j),
                want.get(i, j),
                dir.display()
            );
        }
        // PentaHexa reached 2.37e-2 (case 13) on the image's centre column:
        // a face seen nearly edge-on whose thickness rises from 0 to 0.4
        // across 0.02 px, refined into slivers that collapsed on the
        // rasteriser's grid, so the centre took the neighbouring
        // triangle's values. Slivers are now found among the exact
        // triangles (src/render/ties/).
        let bound = MAX;
        if d.max_abs > bound {
            let (i, j) = d.worst;
            let watch = RenderOptions {
                projected: ProjectedOptions {
                    watch: Some((i, j)),
                    ..exact.projected
                },
                ..exact.clone()
            };
            let (_, stats) = renderer
                .render(&scene.shading(), &watch, |_, _| {})
                .unwrap();
            let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("render_random");
            let _ = std::fs::create_dir_all(&dir);
            let _ = crop(&img, i, j, 8).write_png(
                &dir.join(format!("case{case}_exact.png")),
                [0.0; 3],
                false,
            );
            let _ = crop(&want, i, j, 8).write_png(
                &dir.join(format!("case{case}_ref.png")),
                [0.0; 3],
                false,
            );
            let frags = stats
                .projected()
                .map(|e| e.watched.clone())
                .unwrap_or_default();
            panic!(
                "{tag}: pixel ({i}, {j}) differs by {:.3e} > {bound:.3e}: exact {:?}, reference {:?}; \
                 fragments (crops in {}):\n{frags:#?}",
                d.max_abs,
                img.get(i, j),
                want.get(i, j),
                dir.display()
            );
        }
    }
}
