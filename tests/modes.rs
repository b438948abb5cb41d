//! The mode registry and the one comparison harness: every mode of
//! `Mode::ALL` against the reference ray caster, at the bounds its registry
//! entry gives, over every pixel.
//!
//! A GPU mode is compared through its CPU twin (no adapter needed, so this
//! runs everywhere) and, where an adapter exists, on the GPU too:
//! `--split all` against `tets` (the same field), and whole cells against
//! the ray caster's `faces` model (a model difference inside the cells the
//! mode splits), in perspective and orthographic views, on the project's own
//! meshes with the default transfer function. The registry test fails when
//! a mode lacks its stage (shader), its CPU twin or its bounds, or a shader
//! function lacks its same-named twin (`render::modes::twins`).

mod render_util;

use zoovr::camera::CameraParams;
use zoovr::image::{compare_display, Image};
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::iso::IsoOptions;
use zoovr::render::modes::twins::missing_twins;
use zoovr::render::modes::SHADERS;
use zoovr::render::{
    Compositor, Mode, PieceDraw, ProjectedOptions, ReferenceOptions, RenderOptions, Renderer,
    Scene, SceneSpec,
};
use zoovr::testdata::mesh_file;

use render_util::gpu_available;

fn scene(name: &str) -> Scene {
    let mesh = io::read(&mesh_file(name), &ReadOptions::default()).unwrap();
    Scene::build(mesh, &SceneSpec::default()).unwrap()
}

fn options(mode: Mode, ortho: bool) -> RenderOptions {
    // `--mode iso` draws the isosurfaces it is given (the harness below
    // gives one per scene; tests/iso.rs many more).
    let iso = if mode == Mode::Iso {
        IsoOptions {
            surfaces: zoovr::render::iso::parse_list("0.5").unwrap(),
            ..Default::default()
        }
    } else {
        IsoOptions::default()
    };
    RenderOptions {
        iso,
        camera: CameraParams {
            width: 96,
            height: 80,
            azimuth: 25.0,
            elevation: 30.0,
            zoom: 1.2,
            ortho,
            ..Default::default()
        },
        mode,
        ..Default::default()
    }
}

/// Renders `scene` with `renderer` (made from its geometry: one per scene,
/// so the GPU device and its tables are opened once).
fn render(renderer: &mut Renderer, scene: &Scene, opts: &RenderOptions) -> Image {
    let (img, _) = renderer
        .render(&scene.shading(), opts, |_, _| {})
        .unwrap_or_else(|e| panic!("{:?}: {e}", opts.mode));
    assert_eq!(img.count_non_finite(), 0);
    img
}

#[test]
fn registry_is_complete() {
    let names = Mode::names();
    for &mode in Mode::ALL {
        let info = mode.info();
        assert_eq!(info.name.parse::<Mode>(), Ok(mode));
        assert_eq!(
            names.iter().filter(|n| **n == info.name).count(),
            1,
            "{} named twice",
            info.name
        );
        assert!(
            !info.emission.is_empty(),
            "{}: no emission model",
            info.name
        );
        if info.gpu {
            let stage = info
                .stage
                .unwrap_or_else(|| panic!("{}: a GPU mode without a stage", info.name));
            assert!(
                SHADERS
                    .iter()
                    .any(|(n, s)| *n == stage.name && stage.wgsl.ends_with(s)),
                "{}: its shader {} is not in SHADERS",
                info.name,
                stage.name
            );
            assert!(info.bounds.is_some(), "{}: no comparison bounds", info.name);
            // The CPU twin exists and draws: a render through it.
            let s = scene("tetra.vtu");
            let opts = RenderOptions {
                projected: ProjectedOptions {
                    compositor: Compositor::Cpu,
                    ..options(mode, false).projected
                },
                ..options(mode, false)
            };
            let img = render(&mut Renderer::new(s.geometry()), &s, &opts);
            assert!(
                img.pixels.iter().any(|p| p[3] > 0.0),
                "{}: empty",
                info.name
            );
        } else {
            assert!(info.stage.is_none(), "{}", info.name);
        }
    }
    // The reference exists.
    assert!(Mode::ALL.iter().any(|m| m.info().bounds.is_none()));
    // Every shader function has its CPU twin of the same name.
    assert_eq!(missing_twins(), Vec::<String>::new());
}

#[test]
fn every_mode_matches_the_reference_on_zoo() {
    every_mode_matches_the_reference("zoo_3x3x3.vtu");
}

#[test]
fn every_mode_matches_the_reference_on_curvilinear() {
    every_mode_matches_the_reference("curvilinear_4x4x4.vtu");
}

#[test]
fn every_mode_matches_the_reference_on_ring() {
    every_mode_matches_the_reference("ring_hole.vtu");
}

/// Every mode of `Mode::ALL` against the reference on the project mesh
/// `name`, through its CPU twin and, where an adapter exists, on the GPU.
fn every_mode_matches_the_reference(name: &str) {
    let gpu = gpu_available();
    let s = scene(name);
    let mut renderer = Renderer::new(s.geometry());
    for ortho in [false, true] {
        for split in [false, true] {
            let reference = RenderOptions {
                reference: ReferenceOptions {
                    model: if split {
                        FieldModel::Tets
                    } else {
                        FieldModel::Faces
                    },
                    ..options(Mode::Raycast, ortho).reference
                },
                ..options(Mode::Raycast, ortho)
            };
            let expected = render(&mut renderer, &s, &reference);
            for &mode in Mode::ALL {
                let Some(bounds) = mode.info().bounds else {
                    continue;
                };
                assert_eq!(bounds.reference, FieldModel::Faces);
                // `--mode iso` draws a surface at mid-range, the reference
                // the same surface alone.
                let (lo, hi) = s.range;
                let surface = IsoOptions {
                    surfaces: zoovr::render::iso::parse_list(&format!("{}", 0.5 * (lo + hi)))
                        .unwrap(),
                    alone: true,
                    ..Default::default()
                };
                let iso_expected = (mode == Mode::Iso).then(|| {
                    let opts = RenderOptions {
                        iso: surface.clone(),
                        ..reference.clone()
                    };
                    render(&mut renderer, &s, &opts)
                });
                let expected = iso_expected.as_ref().unwrap_or(&expected);
                let mut compositors = vec![Compositor::Cpu];
                if gpu {
                    compositors.push(Compositor::Gpu);
                }
                // exact-frag and the table modes draw their pieces as
                // regions and whole, as quads, at the same bounds.
                let draws: &[PieceDraw] = if mode.info().draws_pieces_whole {
                    &[PieceDraw::Regions, PieceDraw::Quads]
                } else {
                    &[PieceDraw::Regions]
                };
                for (compositor, &draw) in compositors
                    .iter()
                    .flat_map(|&c| draws.iter().map(move |d| (c, d)))
                {
                    let opts = RenderOptions {
                        projected: ProjectedOptions {
                            split_all: split,
                            compositor,
                            piece_draw: draw,
                            ..options(mode, ortho).projected
                        },
                        iso: if mode == Mode::Iso {
                            surface.clone()
                        } else {
                            IsoOptions::default()
                        },
                        ..options(mode, ortho)
                    };
                    let got = render(&mut renderer, &s, &opts);
                    let (d, diff) = compare_display(&got, expected, [0.0; 3]).unwrap();
                    eprintln!(
                        "{mode} {name} ortho={ortho} split={split} {compositor:?} {draw:?}: max {:.2e} at {:?}",
                        d.max_abs, d.worst
                    );
                    let (bound, outliers) = if split {
                        (bounds.split_max, bounds.split_outliers)
                    } else {
                        (bounds.whole_max, bounds.whole_outliers)
                    };
                    // Over every pixel, but the few the mode's entry names.
                    let beyond = diff
                        .pixels
                        .iter()
                        .filter(|p| p[..3].iter().any(|&c| c as f64 > bound))
                        .count();
                    eprintln!("  {beyond} pixels beyond {bound:.2e}");
                    assert!(
                        outliers == 0 || beyond <= outliers,
                        "{mode} {name} ortho={ortho} split={split} {compositor:?}: {beyond} pixels beyond {bound:.3e}"
                    );
                    assert!(
                        outliers > 0 || d.max_abs <= bound,
                        "{mode} {name} ortho={ortho} split={split} {compositor:?}: max {:.3e} at {:?} > {:.3e}",
                        d.max_abs,
                        d.worst,
                        bound
                    );
                }
            }
        }
    }
}
