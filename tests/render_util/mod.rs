//! Helpers shared by the render tests: whether a GPU adapter is there, the
//! options of one render by mode, split and field model, and the steps of a
//! synthetic series.
#![allow(dead_code)]

use std::sync::Arc;

use glam::DVec3;
use zoovr::field::{Association, ScalarField};
use zoovr::gpu::{Context, GpuOptions};
use zoovr::raycast::FieldModel;
use zoovr::render::{Geometry, Mode, ProjectedOptions, ReferenceOptions, RenderOptions, Shading};

/// Step `k` of a synthetic series over `geometry`: the point field
/// `value(p, k)`, mapped by the shading of step 0 (`first`: the same
/// transfer function and range).
pub fn time_step(
    geometry: &Geometry,
    first: &Shading,
    k: usize,
    value: impl Fn(DVec3, f64) -> f64,
) -> Shading {
    let values = geometry
        .mesh
        .points
        .iter()
        .map(|&p| value(p, k as f64))
        .collect();
    Shading {
        field: Some(Arc::new(ScalarField::new(
            format!("step{k}"),
            Association::Point,
            values,
        ))),
        ..first.clone()
    }
}

/// Whether a GPU adapter opens with the default options; when none does,
/// says so on stderr (the caller then skips its GPU part).
pub fn gpu_available() -> bool {
    match Context::new(&GpuOptions::default()) {
        Ok(_) => true,
        Err(e) => {
            eprintln!("skipping the GPU part: no adapter ({e})");
            false
        }
    }
}

/// Whether the default GPU context accumulates in f16 (GL on llvmpipe,
/// which cannot blend f32 targets); false without an adapter.
pub fn gpu_accumulates_f16() -> bool {
    use zoovr::gpu::AccumFormat;
    static F16: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *F16.get_or_init(|| {
        Context::new(&GpuOptions::default())
            .and_then(|c| c.resolve_format(AccumFormat::Auto))
            .is_ok_and(|f| f == AccumFormat::F16)
    })
}

/// Options of one render in `mode`: every cell drawn as its consistent tets
/// when `split_all` (projected-cell modes), the ray caster's field `model`;
/// the default camera, GPU and accumulation.
pub fn options(mode: Mode, split_all: bool, model: FieldModel) -> RenderOptions {
    RenderOptions {
        mode,
        projected: ProjectedOptions {
            split_all,
            ..Default::default()
        },
        reference: ReferenceOptions {
            model,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Which cells the last projected-cell render of `renderer` drew as tets
/// (split for a breakpoint, a problem face, a cycle or `--split all`), of
/// `cells` cells.
pub fn split_cells(renderer: &zoovr::render::Renderer, cells: usize) -> Vec<bool> {
    use zoovr::visibility::Piece;
    let order = renderer.last_order().expect("a projected render before");
    let mut split = vec![false; cells];
    for p in &order.pieces {
        match *p {
            Piece::Cell(_) => {}
            Piece::Tet { cell, .. } | Piece::Slab { cell, .. } | Piece::Frag { cell, .. } => {
                split[cell as usize] = true
            }
        }
    }
    split
}

/// The pixels of `camera` whose ray (the ray caster's `faces` walk) meets
/// a cell marked in `split`: where a whole-cell render integrates the
/// `tets` field instead of `faces` (a model difference).
pub fn split_mask(
    scene: &zoovr::render::Scene,
    camera: &zoovr::camera::Camera,
    split: &[bool],
) -> Vec<bool> {
    let rc = zoovr::raycast::Raycaster::new(scene.ray_scene(), FieldModel::Faces).unwrap();
    let t_near = if camera.ortho { 0.0 } else { camera.near };
    let mut mask = Vec::with_capacity((camera.width * camera.height) as usize);
    for j in 0..camera.height {
        for i in 0..camera.width {
            let segs = rc.segments(&camera.pixel_ray(i, j), t_near);
            mask.push(segs.iter().any(|s| split[s.cell as usize]));
        }
    }
    mask
}

/// The largest display difference (PNG values, every channel) between two
/// images over the pixels not in `mask`, and the pixel where it is.
pub fn max_outside(
    actual: &zoovr::image::Image,
    expected: &zoovr::image::Image,
    mask: &[bool],
) -> (f64, (u32, u32)) {
    let (_, diff) = zoovr::image::compare_display(actual, expected, [0.0; 3]).unwrap();
    let mut worst = (0.0, (0, 0));
    for (k, p) in diff.pixels.iter().enumerate() {
        if mask[k] {
            continue;
        }
        let d = p.iter().take(3).fold(0.0f64, |m, &v| m.max(v as f64));
        if d > worst.0 {
            worst = (d, (k as u32 % diff.width, k as u32 / diff.width));
        }
    }
    worst
}

/// Sets the generated mesh's point field `f` to `f(p)` at every point.
pub fn set_point_field(mesh: &mut zoovr::mesh::Mesh, f: impl Fn(DVec3) -> f64) {
    let values: Vec<f64> = mesh.points.iter().map(|&p| f(p)).collect();
    let a = mesh
        .point_data
        .iter_mut()
        .find(|a| a.name == "f")
        .expect("generated field");
    a.data = zoovr::field::ArrayData::F64(values);
    a.vtk_type = "Float64".into();
}

/// A pixel beyond the tolerance: where, what it was, what it should be.
pub type BadPixel = ((u32, u32), [f32; 4], [f64; 4]);

/// An image against a closed form: the pixels checked, the largest
/// difference (any channel, linear premultiplied), and the pixels beyond
/// the tolerance.
pub struct ClosedForm {
    pub checked: usize,
    pub worst: f64,
    pub bad: Vec<BadPixel>,
}

/// Compares every pixel of `img` for which `expect` gives a value (`None`:
/// not checked) with it, beyond `tol` a bad pixel.
pub fn against_closed_form(
    img: &zoovr::image::Image,
    tol: f64,
    mut expect: impl FnMut(u32, u32) -> Option<[f64; 4]>,
) -> ClosedForm {
    let mut out = ClosedForm {
        checked: 0,
        worst: 0.0,
        bad: Vec::new(),
    };
    for j in 0..img.height {
        for i in 0..img.width {
            let Some(want) = expect(i, j) else {
                continue;
            };
            let got = img.pixels[(j * img.width + i) as usize];
            let d = (0..4)
                .map(|c| (got[c] as f64 - want[c]).abs())
                .fold(0.0, f64::max);
            if d > tol {
                out.bad.push(((i, j), got, want));
            }
            out.worst = out.worst.max(d);
            out.checked += 1;
        }
    }
    out
}
