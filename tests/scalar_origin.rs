//! A field far from zero next to its span renders as the field itself:
//! `1 + k 2^-52` (a range of 2^-40, about 9e-13, around 1, where one ulp
//! of the values is 1/4096 of the range) against `k / 4096`, with the
//! transfer function and the isovalues mapped the same way. Both are
//! exact in `f64`, and the renderers move the far field to the middle of
//! its range (`zoovr::render::origin`), which makes the two scenes the
//! same up to an exact power-of-two scale and an offset: every pixel of
//! every mode, with and without isosurfaces, both projections, must agree.
//!
//! Before the move, the ray caster interpolated the raw values (its
//! surfaces moved by ulps of the value, thousandths of the range) and the
//! projected modes' exact decisions at shared faces read them too: single
//! pixels of the surfaces were missing or doubled, up to 127/255 on up to
//! 26 pixels of a 160 x 150 view.

mod render_util;

use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::image::Image;
use zoovr::render::iso::{parse_list, IsoOptions, Lighting};
use zoovr::render::{
    Compositor, Mode, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec,
};
use zoovr::tf::{EmissionModel, TransferFunction};

use render_util::gpu_available;

const SIZE: u32 = 80;
/// Levels of the quantised field: `k / LEVELS` (wide) or `1 + k 2^-52`
/// (far), `k` in `0..=LEVELS`.
const LEVELS: f64 = 4096.0;
/// Largest difference between the two images, any pixel, any channel
/// (linear premultiplied): the two compute the same numbers up to the
/// rounding of sums near different magnitudes (measured 0 in every mode,
/// both compositors, both projections).
const TOL: f64 = 1e-6;

/// The far value of level `k` (exact: `k 2^-52` is one ulp of 1 per level).
fn far(k: f64) -> f64 {
    1.0 + k * f64::EPSILON
}

/// The scene with the field's levels mapped by `map`; the transfer
/// function's nodes at levels 0, 1536 and 4096 mapped the same way.
fn scene(map: impl Fn(f64) -> f64) -> Scene {
    let mut mesh = warped_hex_grid(
        5,
        &Warp {
            amplitude: 0.06,
            seed: 3,
        },
    );
    render_util::set_point_field(&mut mesh, |p| {
        // A smooth field over the unit cube, 0 and 1 at two corners.
        let g = (p.x + p.y * p.y + 0.5 * p.z) / 2.5;
        map((g.clamp(0.0, 1.0) * LEVELS).round())
    });
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[
            (map(0.0), [0.0]),
            (map(1536.0), [4.0]),
            (map(LEVELS), [1.0]),
        ],
        &[(map(0.0), [0.1, 0.2, 0.9]), (map(LEVELS), [1.0, 0.5, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    scene
}

fn max_diff(a: &Image, b: &Image) -> f64 {
    let mut worst = 0.0f64;
    for j in 0..a.height {
        for i in 0..a.width {
            let (p, q) = (a.get(i, j), b.get(i, j));
            for c in 0..4 {
                worst = worst.max((p[c] as f64 - q[c] as f64).abs());
            }
        }
    }
    worst
}

#[test]
fn a_field_far_from_zero_renders_as_the_field_itself() {
    let wide = scene(|k| k / LEVELS);
    let narrow = scene(far);
    let (lo, hi) = narrow.range;
    assert_eq!((lo, hi), (1.0, far(LEVELS)), "the far field's range");
    // Isovalues at levels (`1 + k 2^-52` has no values between them), one
    // at the middle of the range, one at the transfer function's
    // breakpoint.
    let levels = [1001.0, 2048.0, 1536.0, 3001.0];
    let list = |map: &dyn Fn(f64) -> f64| {
        levels
            .iter()
            .map(|&k| format!("{:e}:tf:0.6", map(k)))
            .collect::<Vec<_>>()
            .join(",")
    };
    let iso_wide = parse_list(&list(&|k| k / LEVELS)).unwrap();
    let iso_far = parse_list(&list(&far)).unwrap();
    // The far isovalues are the levels exactly (no rounding in parsing).
    for (s, &k) in iso_far.iter().zip(&levels) {
        assert_eq!(s.value, far(k));
    }
    let mut compositors = vec![Compositor::Cpu];
    if gpu_available() {
        compositors.push(Compositor::Gpu);
    }
    let mut cases = Vec::new();
    for mode in [
        Mode::Raycast,
        Mode::Exact,
        Mode::ExactFrag,
        Mode::Preint3d,
        Mode::Iso,
    ] {
        for surfaces in [false, true] {
            if mode == Mode::Iso && !surfaces {
                continue;
            }
            for alone in [false, true] {
                if alone && !surfaces || mode == Mode::Iso && !alone {
                    continue;
                }
                for &c in &compositors {
                    if mode == Mode::Raycast && c == Compositor::Gpu {
                        continue;
                    }
                    cases.push((mode, surfaces, alone, c));
                }
            }
        }
    }
    let (mut rw, mut rn) = (
        Renderer::new(wide.geometry()),
        Renderer::new(narrow.geometry()),
    );
    let (sw, sn) = (wide.shading(), narrow.shading());
    for ortho in [false, true] {
        for &(mode, surfaces, alone, compositor) in &cases {
            let opts = |surfaces_list: &Vec<zoovr::render::iso::IsoSpec>| RenderOptions {
                mode,
                camera: CameraParams {
                    width: SIZE,
                    height: SIZE,
                    azimuth: 30.0,
                    elevation: 25.0,
                    zoom: 1.3,
                    ortho,
                    ..Default::default()
                },
                projected: ProjectedOptions {
                    compositor,
                    ..Default::default()
                },
                iso: IsoOptions {
                    surfaces: if surfaces {
                        surfaces_list.clone()
                    } else {
                        Vec::new()
                    },
                    lighting: Lighting::Smooth,
                    alone,
                    mix: Default::default(),
                },
                ..Default::default()
            };
            let (a, _) = rw.render(&sw, &opts(&iso_wide), |_, _| {}).unwrap();
            let (b, _) = rn.render(&sn, &opts(&iso_far), |_, _| {}).unwrap();
            let d = max_diff(&a, &b);
            let name =
                format!("{mode:?} surfaces={surfaces} alone={alone} {compositor:?} ortho={ortho}");
            eprintln!("{name}: max {d:.2e}");
            assert_eq!(a.count_non_finite() + b.count_non_finite(), 0, "{name}");
            assert!(d <= TOL, "{name}: the far field's image differs by {d:.3e}");
        }
    }
}
