//! Fields with NaN and infinite values ("Bad values" in README): every
//! projected mode renders them (no error), a part holding a non-finite
//! scalar is drawn empty, and split into tets that is the reference's
//! image (`--model tets`: a ray through a tet with a NaN corner has a NaN
//! end, an empty segment), at every pixel.
//!
//! The projected modes run on their CPU twin, so no adapter is needed.

mod render_util;

use render_util::time_step;
use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::image::compare_display;
use zoovr::io::{self, ReadOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::{
    Compositor, Geometry, Mode, ModeStats, RenderOptions, Renderer, SceneSpec, Shading,
};
use zoovr::testdata::mesh_file;
use zoovr::tf::{EmissionModel, TransferFunction};

/// render_util's options (the `tets` reference field) on a small view,
/// drawn by the CPU twins.
fn options(mode: Mode, split_all: bool) -> RenderOptions {
    let mut o = render_util::options(mode, split_all, FieldModel::Tets);
    o.camera = CameraParams {
        width: 80,
        height: 60,
        azimuth: 35.0,
        elevation: 20.0,
        ..Default::default()
    };
    o.projected.compositor = Compositor::Cpu;
    o
}

#[test]
fn nan_cells_are_empty_as_in_the_reference() {
    let mesh = io::read(&mesh_file("zoo_3x3x3.vtu"), &ReadOptions::default()).unwrap();
    let geometry = Geometry::build(mesh, false).unwrap();
    let first = Shading::build(&geometry, &SceneSpec::default()).unwrap();
    // A smooth field with NaN on a band of points.
    let nan = time_step(&geometry, &first, 0, |p, _| {
        if (p.x + 0.5 * p.y - 1.2).abs() < 0.3 {
            f64::NAN
        } else {
            (p.x * 1.3 + p.z).sin()
        }
    });
    let field = nan.field.as_ref().unwrap();
    let holes = field.values.iter().filter(|v| v.is_nan()).count();
    assert!(holes > 0 && holes < field.values.len() / 2, "{holes}");
    let render = |opts: &RenderOptions| {
        Renderer::new(geometry.clone())
            .render(&nan, opts, |_, _| {})
            .unwrap()
            .0
    };
    let reference = render(&options(Mode::Raycast, false));
    let finite = time_step(&geometry, &first, 0, |p, _| (p.x * 1.3 + p.z).sin());
    let full = Renderer::new(geometry.clone())
        .render(&finite, &options(Mode::Raycast, false), |_, _| {})
        .unwrap()
        .0;
    assert!(reference.pixels != full.pixels, "the holes show");
    for mode in [Mode::Exact, Mode::ExactFrag, Mode::Preint3d] {
        let img = render(&options(mode, true));
        assert_eq!(img.count_non_finite(), 0);
        let (d, _) = compare_display(&img, &reference, [0.0; 3]).unwrap();
        assert!(
            d.max_abs <= 2.0 / 255.0,
            "{mode:?} --split all against --model tets: {} at {:?}",
            d.max_abs,
            d.worst
        );
        // Whole cells render too (the `faces` field keeps some rays of a
        // cell with a NaN corner that are drawn empty here).
        assert_eq!(render(&options(mode, false)).count_non_finite(), 0);
    }
    // Nearly opaque: pieces behind opaque ones are left out, and a cell
    // with a NaN corner, drawn empty, must hide nothing.
    let grid = Geometry::build(warped_hex_grid(10, &Warp::default()), false).unwrap();
    let base = Shading::build(&grid, &SceneSpec::default()).unwrap();
    let mut opaque = time_step(&grid, &base, 0, |p, _| {
        if (p.x - p.y).abs() < 0.15 {
            f64::NAN
        } else {
            p.x + 0.3 * p.z
        }
    });
    let (lo, hi) = (-1.0, 2.0);
    let tau = 60.0 / grid.mesh.diagonal();
    opaque.tf = TransferFunction::from_channels(
        &[(lo, [tau]), (hi, [2.0 * tau])],
        &[(lo, [0.1, 0.2, 0.9]), (hi, [1.0, 0.5, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let render_grid = |opts: &RenderOptions| {
        Renderer::new(grid.clone())
            .render(&opaque, opts, |_, _| {})
            .unwrap()
    };
    let reference = render_grid(&options(Mode::Raycast, false)).0;
    for mode in [Mode::Exact, Mode::ExactFrag] {
        let (img, stats) = render_grid(&options(mode, true));
        let ModeStats::Projected(p) = &stats.detail else {
            panic!("projected")
        };
        assert!(
            p.hidden_pieces > 0,
            "{mode:?}: the occlusion pass hid nothing"
        );
        let (d, _) = compare_display(&img, &reference, [0.0; 3]).unwrap();
        assert!(
            d.max_abs <= 2.0 / 255.0,
            "{mode:?} opaque: {} at {:?} ({} pieces hidden)",
            d.max_abs,
            d.worst,
            p.hidden_pieces
        );
    }
    // Infinities: rendered, their cells empty.
    let inf = time_step(&geometry, &first, 0, |p, _| {
        if p.x > 1.5 {
            f64::INFINITY
        } else {
            (p.x * 1.3 + p.z).sin()
        }
    });
    for mode in [Mode::Exact, Mode::ExactFrag] {
        let (img, _) = Renderer::new(geometry.clone())
            .render(&inf, &options(mode, false), |_, _| {})
            .unwrap();
        assert_eq!(img.count_non_finite(), 0);
    }
}
