//! The three field models against each other: they coincide on tetrahedral
//! meshes and on affine hexahedra carrying a linear field; on warped grids
//! (nonplanar, non-convex cells) `faces` and `tets` bound the same volume.

mod raycast_util;

use glam::DVec3;
use raycast_util::*;
use zoovr::camera::{Camera, CameraParams};
use zoovr::image::check_float_images;
use zoovr::mesh::Mesh;
use zoovr::raycast::{render, FieldModel, Raycaster, Scalars, Scene};

fn material() -> TestMaterial {
    TestMaterial {
        s: vec![0.1, 0.4, 0.45, 0.9],
        tau: vec![0.0, 1.5, 4.0, 0.3],
        color: vec![
            [0.2, 0.1, 1.0],
            [1.0, 0.3, 0.0],
            [0.0, 1.0, 0.2],
            [1.0, 1.0, 1.0],
        ],
    }
}

fn images(mesh: &Mesh, s: &[f64], cams: &[Camera]) -> Vec<Vec<zoovr::image::Image>> {
    let topology = topo(mesh);
    let scene = Scene {
        mesh,
        topology: &topology,
        scalars: Scalars::Point(s),
    };
    let m = material();
    cams.iter()
        .map(|cam| {
            [FieldModel::Faces, FieldModel::Tets, FieldModel::Native]
                .iter()
                .map(|&model| render(&scene, &m, cam, &opts(model)).unwrap())
                .collect()
        })
        .collect()
}

fn cameras(mesh: &Mesh) -> Vec<Camera> {
    [(20.0, 35.0, false), (-60.0, 10.0, true), (0.0, 0.0, true)]
        .iter()
        .map(|&(az, el, ortho)| {
            let p = CameraParams {
                width: 32,
                height: 32,
                azimuth: az,
                elevation: el,
                zoom: 1.2,
                ortho,
                ..Default::default()
            };
            Camera::fit(mesh.bounds(), &p)
        })
        .collect()
}

#[test]
fn models_agree_on_a_parallelepiped_grid_with_a_linear_field() {
    let mesh = grid(
        [3, 3, 3],
        |i, j, k| DVec3::new(0.4 * i + 0.1 * j, 0.35 * j + 0.05 * k, 0.3 * k + 0.08 * i),
        None,
    );
    let s: Vec<f64> = mesh
        .points
        .iter()
        .map(|p| 0.05 + 0.5 * p.x + 0.3 * p.y + 0.4 * p.z)
        .collect();
    let cams = cameras(&mesh);
    for imgs in images(&mesh, &s, &cams) {
        let mut seen = 0.0f32;
        for p in &imgs[0].pixels {
            seen = seen.max(p[3]);
        }
        assert!(seen > 0.3, "the scene must be visible");
        for k in 1..3 {
            check_float_images(&format!("models_grid_{k}"), &imgs[k], &imgs[0], 2e-6, 2e-6)
                .unwrap_or_else(|e| panic!("model {k}: {e}"));
        }
    }
}

#[test]
fn models_agree_on_a_tet_mesh() {
    let warped = grid(
        [3, 2, 2],
        |i, j, k| {
            DVec3::new(
                i + 0.2 * (j * k).sin(),
                j + 0.15 * (i * 1.3).cos(),
                k + 0.1 * i * j,
            )
        },
        Some(&shuffle(36, 3)),
    );
    let mesh = to_tets(&warped);
    let s: Vec<f64> = (0..mesh.points.len())
        .map(|i| 0.5 + 0.45 * (i as f64 * 1.7).sin())
        .collect();
    let cams = cameras(&mesh);
    for imgs in images(&mesh, &s, &cams) {
        for k in 1..3 {
            check_float_images(&format!("models_tets_{k}"), &imgs[k], &imgs[0], 1e-6, 1e-6)
                .unwrap_or_else(|e| panic!("model {k}: {e}"));
        }
    }
}

#[test]
fn faces_and_tets_bound_the_same_volume_on_a_warped_grid() {
    // Strongly warped curvilinear grid: nonplanar faces, non-convex cells.
    let mesh = grid(
        [4, 4, 3],
        |i, j, k| {
            let r = 2.0 + i * 0.5;
            let a = j * 0.4 + 0.15 * (k * 2.1).sin();
            DVec3::new(
                r * a.cos() + 0.2 * (k + j).sin(),
                r * a.sin(),
                k * 0.6 + 0.25 * (i * 1.9).cos(),
            )
        },
        None,
    );
    let topology = topo(&mesh);
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Constant(0.0),
    };
    let m = TestMaterial::constant(0.8, [1.0; 3]);
    let faces = Raycaster::new(scene, FieldModel::Faces).unwrap();
    let tets = Raycaster::new(scene, FieldModel::Tets).unwrap();
    let native = Raycaster::new(scene, FieldModel::Native).unwrap();
    let cams = cameras(&mesh);
    let mut hits = 0;
    for cam in &cams {
        for j in 0..32 {
            for i in 0..32 {
                let r = cam.pixel_ray(i, j);
                let a = trace_one(&faces, &m, &r, FieldModel::Faces);
                let b = trace_one(&tets, &m, &r, FieldModel::Tets);
                let c = trace_one(&native, &m, &r, FieldModel::Native);
                assert!(
                    (a.depth - b.depth).abs() < 1e-10 * (1.0 + a.depth),
                    "pixel {i},{j}"
                );
                assert!((a.depth - c.depth).abs() < 1e-10 * (1.0 + a.depth));
                hits += (a.depth > 0.0) as usize;
            }
        }
    }
    assert!(hits > 500, "{hits}");
    // A linear point field over the same warped grid: faces and tets are
    // both exact for it wherever it is linear on every face triangle and
    // tet, which it is (linear in position).
    let s: Vec<f64> = mesh
        .points
        .iter()
        .map(|p| 0.1 + 0.1 * p.x + 0.05 * p.y + 0.3 * p.z)
        .collect();
    let scene = Scene {
        scalars: Scalars::Point(&s),
        ..scene
    };
    let mat = material();
    let fa = render(&scene, &mat, &cams[0], &opts(FieldModel::Faces)).unwrap();
    let te = render(&scene, &mat, &cams[0], &opts(FieldModel::Tets)).unwrap();
    check_float_images("models_faces_vs_tets_warped", &te, &fa, 2e-6, 2e-6)
        .unwrap_or_else(|e| panic!("{e}"));
}
