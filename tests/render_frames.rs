//! One `Renderer` across frames: built once from a geometry, it renders
//! one shading after another (the steps of a time series) and each image is
//! the one a fresh renderer makes of that shading, bit for bit; a field of
//! another mesh is a typed error, not a panic.
//!
//! The projected mode runs on its CPU twin, so no adapter is needed.

mod render_util;

use std::sync::Arc;

use render_util::time_step;
use zoovr::camera::CameraParams;
use zoovr::field::{Association, ScalarField};
use zoovr::image::Image;
use zoovr::io::{self, ReadOptions};
use zoovr::render::{
    Compositor, Geometry, Mode, ProjectedOptions, RenderError, RenderOptions, Renderer, SceneSpec,
    Shading, StepChange,
};
use zoovr::testdata::mesh_file;

fn geometry() -> Geometry {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    Geometry::build(mesh, false).unwrap()
}

fn options(mode: Mode) -> RenderOptions {
    RenderOptions {
        camera: CameraParams {
            width: 64,
            height: 48,
            azimuth: 30.0,
            elevation: 25.0,
            ..Default::default()
        },
        mode,
        projected: ProjectedOptions {
            compositor: Compositor::Cpu,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Step `k` of a synthetic series: a point field that changes per step,
/// mapped by the shading of step 0 (the same transfer function and range).
fn step(geometry: &Geometry, first: &Shading, k: usize) -> Shading {
    time_step(geometry, first, k, |p, k| {
        (p.x * 1.3 + p.y * 0.4 + k * 0.7).sin() + p.z * 0.2
    })
}

fn fresh(geometry: &Geometry, shading: &Shading, opts: &RenderOptions) -> Image {
    Renderer::new(geometry.clone())
        .render(shading, opts, |_, _| {})
        .unwrap()
        .0
}

#[test]
fn swapping_the_field_matches_a_fresh_renderer_bit_for_bit() {
    let geometry = geometry();
    let first = Shading::build(&geometry, &SceneSpec::default()).unwrap();
    for mode in [Mode::Exact, Mode::Raycast] {
        let opts = options(mode);
        let mut renderer = Renderer::new(geometry.clone());
        let mut images = Vec::new();
        for k in 0..3 {
            let shading = step(&geometry, &first, k);
            let (img, _) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
            assert_eq!(img.count_non_finite(), 0);
            let want = fresh(&geometry, &shading, &opts);
            assert!(
                img.pixels == want.pixels,
                "{mode:?} step {k}: the reused renderer's image differs from a fresh one"
            );
            images.push(img);
        }
        // The steps differ, so the renderer did not keep an old field.
        assert!(images[0].pixels != images[1].pixels, "{mode:?}");
        assert!(images[1].pixels != images[2].pixels, "{mode:?}");
        // The renderer kept its geometry: shared, not copied.
        assert!(Arc::ptr_eq(&renderer.geometry().mesh, &geometry.mesh));
    }
}

#[test]
fn a_field_of_another_mesh_is_a_typed_error() {
    let geometry = geometry();
    let mut shading = Shading::build(&geometry, &SceneSpec::default()).unwrap();
    let n = geometry.mesh.points.len();
    shading.field = Some(Arc::new(ScalarField::new(
        "short".into(),
        Association::Point,
        vec![0.0; n - 1],
    )));
    for mode in [Mode::Exact, Mode::Raycast] {
        let err = Renderer::new(geometry.clone())
            .render(&shading, &options(mode), |_, _| {})
            .unwrap_err();
        assert!(
            matches!(err, RenderError::FieldLength { got, want, .. } if got == n - 1 && want == n),
            "{mode:?}: {err}"
        );
    }
}

/// The steps of a series mapped onto the geometry of step 0
/// (`Geometry::next_step`): the change is detected exactly, the topology is
/// shared while the cells are the same, and a renderer that moves on with
/// `set_geometry` draws each step as a fresh renderer does, bit for bit.
#[test]
fn later_steps_keep_what_did_not_change_and_match_fresh_renderers() {
    let read = || io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let geometry = geometry();
    let spec = SceneSpec::default();
    let first = Shading::build(&geometry, &spec).unwrap();
    let fixed = SceneSpec {
        range: Some(first.range),
        ..spec
    };
    let opts = options(Mode::Exact);
    let mut renderer = Renderer::new(geometry.clone());
    renderer.render(&first, &opts, |_, _| {}).unwrap();

    // Same file again: values only.
    let (same, change) = geometry.next_step(read(), false).unwrap();
    assert_eq!(change, StepChange::Values);
    assert!(Arc::ptr_eq(&same.topology, &geometry.topology));

    // Points moved, cells kept: the topology is shared.
    let mut moved = read();
    for p in &mut moved.points {
        p.x += 0.05 * p.y * p.y;
        p.z -= 0.03 * p.x;
    }
    let (g1, change) = geometry.next_step(moved, false).unwrap();
    assert_eq!(change, StepChange::Points);
    assert!(Arc::ptr_eq(&g1.topology, &geometry.topology));
    let s1 = Shading::build(&g1, &fixed).unwrap();
    renderer.set_geometry(g1.clone(), change);
    let (img, _) = renderer.render(&s1, &opts, |_, _| {}).unwrap();
    assert!(img.pixels == fresh(&g1, &s1, &opts).pixels, "moved points");

    // Back to the first points: values only relative to step 0, but the
    // renderer holds g1, so it is a points change again.
    let (g2, change) = g1.next_step(read(), false).unwrap();
    assert_eq!(change, StepChange::Points);
    renderer.set_geometry(g2.clone(), change);
    let s2 = Shading::build(&g2, &fixed).unwrap();
    let (img, _) = renderer.render(&s2, &opts, |_, _| {}).unwrap();
    assert!(
        img.pixels == fresh(&g2, &s2, &opts).pixels,
        "points restored"
    );

    // Other cells: a new topology.
    let other = io::read(&mesh_file("hexahedron.vtu"), &ReadOptions::default()).unwrap();
    let (g3, change) = g2.next_step(other, false).unwrap();
    assert_eq!(change, StepChange::Cells);
    assert!(!Arc::ptr_eq(&g3.topology, &geometry.topology));
    renderer.set_geometry(g3.clone(), change);
    let s3 = Shading::build(&g3, &SceneSpec::default()).unwrap();
    let (img, _) = renderer.render(&s3, &opts, |_, _| {}).unwrap();
    assert!(img.pixels == fresh(&g3, &s3, &opts).pixels, "other cells");
}
