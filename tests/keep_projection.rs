//! A transfer-function change that keeps the extinction re-uses the order
//! and the projection (`ProjectedOptions::keep_projection`): the frame
//! draws the kept triangles with the new colours, and its image is the one
//! a fresh renderer makes, bit for bit, in exact-frag and each table mode.
//! Any change the triangles depend on projects again: new extinction, a
//! new camera, new values, independent emission; the exact mode, whose
//! payload holds the colours, never keeps.

mod render_util;

use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::image::Image;
use zoovr::render::{Mode, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec, Shading};
use zoovr::tf::{EmissionModel, TransferFunction};

fn scene() -> Scene {
    let mesh = warped_hex_grid(
        8,
        &Warp {
            amplitude: 0.08,
            seed: 5,
        },
    );
    Scene::build(mesh, &SceneSpec::default()).unwrap()
}

/// `tf` with its colours replaced by `f` of each node's colour, or its
/// extinction scaled by `tau`.
fn edited(tf: &TransferFunction, f: impl Fn([f64; 3]) -> [f64; 3], tau: f64) -> TransferFunction {
    let nodes: Vec<_> = tf
        .nodes()
        .into_iter()
        .map(|mut n| {
            n.color = f(n.color);
            n.tau *= tau;
            n
        })
        .collect();
    TransferFunction::from_nodes(&nodes, tf.model()).unwrap()
}

fn opts(mode: Mode, keep: bool, azimuth: f64) -> RenderOptions {
    RenderOptions {
        mode,
        camera: CameraParams {
            width: 96,
            height: 80,
            azimuth,
            elevation: 25.0,
            ..Default::default()
        },
        projected: ProjectedOptions {
            keep_projection: keep,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Renders with `renderer`; the image and whether the kept triangles were
/// drawn.
fn render(renderer: &mut Renderer, shading: &Shading, o: &RenderOptions) -> (Image, bool) {
    let (img, stats) = renderer.render(shading, o, |_, _| {}).unwrap();
    (img, stats.projected().unwrap().projection_reused)
}

/// The image a renderer that kept nothing makes.
fn fresh(scene: &Scene, shading: &Shading, o: &RenderOptions) -> Image {
    let mut r = Renderer::new(scene.geometry());
    let mut o = o.clone();
    o.projected.keep_projection = false;
    r.render(shading, &o, |_, _| {}).unwrap().0
}

#[test]
fn colour_edits_draw_the_kept_triangles_and_match_a_fresh_render() {
    if !render_util::gpu_available() {
        return;
    }
    let scene = scene();
    let base = scene.shading();
    let mut recoloured = base.clone();
    recoloured.tf = edited(&base.tf, |c| [c[2], 0.5 * c[0], 1.0 - c[1]], 1.0);
    let mut denser = base.clone();
    denser.tf = edited(&base.tf, |c| c, 2.0);
    for mode in [
        Mode::ExactFrag,
        Mode::Preint3d,
        Mode::Preint2d,
        Mode::Preint2dCyl,
    ] {
        let mut r = Renderer::new(scene.geometry());
        let o = opts(mode, true, 30.0);
        let (first, reused) = render(&mut r, &base, &o);
        assert!(!reused, "{mode:?}: nothing was kept yet");
        assert_eq!(first.pixels, fresh(&scene, &base, &o).pixels, "{mode:?}");
        // New colours, the same extinction: the kept triangles, and the
        // image of a fresh render of the new colours.
        let (img, reused) = render(&mut r, &recoloured, &o);
        assert!(reused, "{mode:?}: a colour edit projects again");
        let want = fresh(&scene, &recoloured, &o);
        assert_eq!(
            img.pixels, want.pixels,
            "{mode:?}: kept triangles, new colours"
        );
        assert_ne!(
            img.pixels, first.pixels,
            "{mode:?}: the colours changed nothing"
        );
        // Back to the first colours: still the same triangles.
        let (img, reused) = render(&mut r, &base, &o);
        assert!(reused && img.pixels == first.pixels, "{mode:?}");
        // New extinction: projected again, and right.
        let (img, reused) = render(&mut r, &denser, &o);
        assert!(!reused, "{mode:?}: new extinction must project again");
        assert_eq!(img.pixels, fresh(&scene, &denser, &o).pixels, "{mode:?}");
        // A new camera: projected again.
        let o2 = opts(mode, true, 31.0);
        let (img, reused) = render(&mut r, &denser, &o2);
        assert!(!reused, "{mode:?}: a new camera must project again");
        assert_eq!(img.pixels, fresh(&scene, &denser, &o2).pixels, "{mode:?}");
    }
}

#[test]
fn what_the_triangles_depend_on_projects_again() {
    if !render_util::gpu_available() {
        return;
    }
    let scene = scene();
    let base = scene.shading();
    let o = opts(Mode::ExactFrag, true, 30.0);
    // New values (same order: exact-frag splits nothing), same TF.
    let mut r = Renderer::new(scene.geometry());
    render(&mut r, &base, &o);
    let mut shifted = base.clone();
    let mut field = base.field.as_deref().expect("a field").clone();
    for x in &mut field.values {
        *x = 0.9 * *x + 0.05 * base.range.1;
    }
    shifted.field = Some(std::sync::Arc::new(field));
    let (img, reused) = render(&mut r, &shifted, &o);
    assert!(!reused, "new values must project again");
    assert_eq!(img.pixels, fresh(&scene, &shifted, &o).pixels);
    // Independent emission: the rate depends on the emission.
    let mut independent = base.clone();
    let nodes: Vec<_> = base
        .tf
        .nodes()
        .into_iter()
        .map(|mut n| {
            n.emission = [n.tau * 0.5; 3];
            n
        })
        .collect();
    independent.tf = TransferFunction::from_nodes(&nodes, EmissionModel::Independent).unwrap();
    render(&mut r, &independent, &o);
    let (_, reused) = render(&mut r, &independent, &o);
    assert!(!reused, "independent emission is never kept");
    // Off by default, and never in the exact mode.
    let plain = opts(Mode::ExactFrag, false, 30.0);
    render(&mut r, &base, &plain);
    assert!(!render(&mut r, &base, &plain).1);
    let exact = opts(Mode::Exact, true, 30.0);
    render(&mut r, &base, &exact);
    assert!(!render(&mut r, &base, &exact).1);
}
