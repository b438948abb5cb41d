//! The ray caster's cell data (the homogeneous integral) and its early ray
//! termination, against closed forms.

use glam::DVec3;
use zoovr::camera::Ray;
use zoovr::generate::{warped_hex_grid_dims, Warp};
use zoovr::mesh::topology::Topology;
use zoovr::raycast::{trace_ray, FieldModel, RaycastOptions, Scalars, Scene};
use zoovr::tf::{EmissionModel, TransferFunction};

/// Extinction `tau(s) = 2 s`, colour from blue at 0 to red at 1.
fn tf() -> TransferFunction {
    TransferFunction::from_channels(
        &[(0.0, [0.0]), (1.0, [2.0])],
        &[(0.0, [0.0, 0.0, 1.0]), (1.0, [1.0, 0.0, 0.0])],
        None,
        EmissionModel::Glow,
    )
    .unwrap()
}

/// Two unit-height hexes side by side along x (x in [0, 0.5] and [0.5, 1]).
fn two_cells() -> zoovr::mesh::Mesh {
    let m = warped_hex_grid_dims(
        [2, 1, 1],
        &Warp {
            amplitude: 0.0,
            seed: 1,
        },
    );
    assert_eq!(m.cells.len(), 2);
    m
}

/// Cell scalars are constant in each cell: each cell's segment is the
/// homogeneous integral, `alpha = 1 - exp(-tau l)`, colour `c alpha`, and the
/// two compose front to back.
#[test]
fn cell_data_uses_the_homogeneous_integral() {
    let mesh = two_cells();
    let topology = Topology::build(&mesh.cells);
    let values = [0.3, 0.8];
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Cell(&values),
    };
    let tf = tf();
    for model in [FieldModel::Faces, FieldModel::Tets, FieldModel::Native] {
        for (dir, front) in [(DVec3::X, 0), (-DVec3::X, 1)] {
            let origin = if dir.x > 0.0 {
                DVec3::new(-1.0, 0.37, 0.61)
            } else {
                DVec3::new(2.0, 0.37, 0.61)
            };
            let ray = Ray::new(origin, dir);
            let opts = RaycastOptions {
                model,
                early_termination: 0.0,
                ..Default::default()
            };
            let acc = trace_ray(&scene, &tf, &ray, &opts).unwrap().rgba();
            // Front cell f, back cell b, each 0.5 long.
            let seg = |s: f64| {
                let tau = tf.tau_at(s);
                let a = -(-tau * 0.5).exp_m1();
                let c = [s, 0.0, 1.0 - s];
                (a, c.map(|x| x * a))
            };
            let (af, cf) = seg(values[front]);
            let (ab, cb) = seg(values[1 - front]);
            let alpha = af + (1.0 - af) * ab;
            let colour: [f64; 3] = std::array::from_fn(|k| cf[k] + (1.0 - af) * cb[k]);
            let got = [acc[0] as f64, acc[1] as f64, acc[2] as f64, acc[3] as f64];
            let want = [colour[0], colour[1], colour[2], alpha];
            for k in 0..4 {
                assert!(
                    (got[k] - want[k]).abs() < 1e-6,
                    "{model:?} dir {dir}: channel {k}: {} vs {}",
                    got[k],
                    want[k]
                );
            }
        }
    }
}

/// Stopping a ray once its transmittance falls below `eps` loses at most
/// `eps` of opacity (and of colour, the colours being at most 1), and the
/// opacity reached is at least `1 - eps` when the full ray gets there.
#[test]
fn early_termination_loses_at_most_its_threshold() {
    let mut mesh = warped_hex_grid_dims([12, 2, 2], &Warp::default());
    // Stretch along x so that the ray is optically thick.
    for p in &mut mesh.points {
        p.x *= 15.0;
    }
    let topology = Topology::build(&mesh.cells);
    let s: Vec<f64> = (0..mesh.points.len())
        .map(|i| 0.5 + 0.4 * (i as f64 * 0.7).sin())
        .collect();
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Point(&s),
    };
    let tf = tf();
    let ray = Ray::new(DVec3::new(-1.0, 0.41, 0.53), DVec3::X);
    let full = |eps: f64| {
        let opts = RaycastOptions {
            early_termination: eps,
            ..Default::default()
        };
        trace_ray(&scene, &tf, &ray, &opts).unwrap().rgba()
    };
    let exact = full(0.0);
    assert!(exact[3] > 0.999, "the ray must be thick: {}", exact[3]);
    for eps in [1e-6, 1e-3, 0.1, 0.5] {
        let got = full(eps);
        for k in 0..4 {
            assert!(
                (got[k] as f64 - exact[k] as f64).abs() <= eps + 1e-6,
                "eps {eps} channel {k}: {} vs {}",
                got[k],
                exact[k]
            );
        }
        assert!(got[3] as f64 >= 1.0 - eps - 1e-6, "eps {eps}: {}", got[3]);
    }
    // A large threshold really stops early: some opacity is left out.
    assert!(full(0.5)[3] < exact[3]);
}

/// Early ray termination, measured: on a scene opaque enough that most rays
/// reach transmittance 1e-6, stopping there leaves every pixel within that
/// fraction of the brightest glow (1) of the full integral, and the stats
/// count the rays that stopped (none with it off). A termination that
/// dropped visible cells would move some pixel by more.
#[test]
fn early_termination_changes_no_pixel_beyond_its_bound() {
    use zoovr::io::{self, ReadOptions};
    use zoovr::render::{Mode, ReferenceOptions, RenderOptions, Renderer, Scene, SceneSpec};
    let mesh = io::read(
        &zoovr::testdata::mesh_file("zoo_3x3x3.vtu"),
        &ReadOptions::default(),
    )
    .unwrap();
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let mut shading = scene.shading();
    let b = scene.mesh.bounds();
    let diag = ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt();
    let (lo, hi) = shading.range;
    // Extinction up to 400 per diagonal: rays through the middle are
    // opaque well before they leave.
    shading.tf = TransferFunction::from_channels(
        &[(lo, [40.0 / diag]), (hi, [400.0 / diag])],
        &[(lo, [0.2, 0.4, 1.0]), (hi, [1.0, 0.8, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let mut renderer = Renderer::new(scene.geometry());
    let render = |renderer: &mut Renderer, on: bool| {
        let opts = RenderOptions {
            mode: Mode::Raycast,
            camera: zoovr::camera::CameraParams {
                width: 64,
                height: 64,
                azimuth: 30.0,
                elevation: 20.0,
                ..Default::default()
            },
            reference: ReferenceOptions {
                early_termination: on,
                ..Default::default()
            },
            ..Default::default()
        };
        renderer.render(&shading, &opts, |_, _| {}).unwrap()
    };
    let (with, s_with) = render(&mut renderer, true);
    let (without, s_without) = render(&mut renderer, false);
    let stopped = s_with.raycast().unwrap().terminated_rays;
    assert!(stopped > 500, "{stopped} rays stopped early");
    assert_eq!(s_without.raycast().unwrap().terminated_rays, 0);
    let (d, _) = zoovr::image::compare_float(&with, &without).unwrap();
    // 1e-6 of a glow of at most 1, plus f32 rounding of the pixel values.
    assert!(d.max_abs <= 1e-6 + 2e-7, "{d:?}");
    assert!(d.max_abs > 0.0, "the termination changed nothing: {d:?}");
}
