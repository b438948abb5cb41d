//! Visibility cycles that no order resolves (issue 5's last resort): three
//! interlocked tetrahedra ([`generate::interlocked_tets`]) each in front of
//! the next where they cross. The sorter must report them as a group, and
//! the exact mode, which composites a group per pixel on the CPU, must match
//! the ray caster there as tightly as anywhere (issue 7's bounds). Drawing
//! the group in any fixed order would put one crossing the wrong way round.

use zoovr::camera::{Camera, CameraParams};
use zoovr::generate;
use zoovr::gpu::{Context, GpuOptions};
use zoovr::image::{check_images_with, Bounds};
use zoovr::raycast::FieldModel;
use zoovr::render::{Mode, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::tf::{EmissionModel, TransferFunction};
use zoovr::visibility::{sample_pixels, validate, Sorter, SplitPolicy};

fn scene() -> Scene {
    let mut scene = Scene::build(generate::interlocked_tets(), &SceneSpec::default()).unwrap();
    // Opaque enough that the wrong order at a crossing shows (each stick
    // ~0.5 thick there: opacity ~0.9), colour varying with the scalar.
    let (lo, hi) = scene.mesh.point_data[0].range(None).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(lo, [4.0]), (hi, [6.0])],
        &[(lo, [0.1, 0.3, 1.0]), (hi, [1.0, 0.4, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    scene
}

/// Views along `z` (the pinwheel's axis), from both sides, both projections.
fn cameras(scene: &Scene) -> Vec<Camera> {
    let mut out = Vec::new();
    for (az, el) in [(0.0, 0.0), (180.0, 0.0), (10.0, 15.0)] {
        for ortho in [true, false] {
            let p = CameraParams {
                width: 128,
                height: 128,
                azimuth: az,
                elevation: el,
                ortho,
                ..Default::default()
            };
            out.push(Camera::fit(scene.mesh.bounds(), &p));
        }
    }
    out
}

#[test]
fn interlocked_tets_form_a_group_in_every_view() {
    let scene = scene();
    let mut sorter = Sorter::new(&scene.mesh, &scene.topology);
    for cam in cameras(&scene) {
        let order = sorter.order(&cam, &SplitPolicy::default()).unwrap();
        assert_eq!(order.pieces.len(), 3);
        assert_eq!(order.stats.cycle_groups, 1, "{:?}", order.stats);
        assert_eq!(order.groups, vec![0..3]);
        // The validator accepts it only because the pairs are grouped.
        let pixels = sample_pixels(&cam, 128 * 128, 1);
        let v = validate(&scene.mesh, &order, &cam, &pixels);
        assert!(v.group_pairs > 0, "{v:?}");
        assert!(v.ok() && v.overlap_pairs == 0, "{v:?}");
    }
}

#[test]
fn groups_are_composited_per_pixel() {
    if let Err(e) = Context::new(&GpuOptions::default()) {
        eprintln!("skipping: no GPU adapter ({e})");
        return;
    }
    let scene = scene();
    let mut r = Renderer::new(&scene);
    for (k, cam) in cameras(&scene).iter().enumerate() {
        let opts = |mode| RenderOptions {
            mode,
            model: FieldModel::Faces,
            ..Default::default()
        };
        let (exact, stats) = r
            .render_with_camera(&opts(Mode::Exact), cam, |_, _| {})
            .unwrap();
        let (reference, _) = r
            .render_with_camera(&opts(Mode::Raycast), cam, |_, _| {})
            .unwrap();
        let e = stats.exact.expect("exact stats");
        assert_eq!(e.order.cycle_groups, 1);
        let covered = reference.pixels.iter().filter(|p| p[3] > 1e-3).count();
        assert!(
            e.group_pixels >= covered,
            "view {k}: {} layer pixels, {covered} covered",
            e.group_pixels
        );
        let d = check_images_with(
            &format!("cycles_interlocked_{k}"),
            &exact,
            &reference,
            &Bounds {
                max_abs: 1e-2,
                p999: 1e-2,
                rms: 2e-3,
            },
        )
        .unwrap_or_else(|e| panic!("view {k}: {e}"));
        eprintln!(
            "view {k}: max {:.2e} rms {:.2e} ({covered} px)",
            d.max_abs, d.rms
        );
    }
}
