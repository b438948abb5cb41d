//! Walking rays through meshes: rays through vertices and edges and along
//! faces (no gaps, no double layers), 5-tet vs 6-tet splits, non-convex and
//! disconnected meshes, inverted and degenerate cells, eyes inside the mesh.
//! The oracle for meshes of axis-aligned boxes is the sum of the exact chords
//! of the boxes (their interiors are disjoint).

mod raycast_util;

use glam::DVec3;
use raycast_util::*;
use zoovr::camera::{Camera, CameraParams, Ray};
use zoovr::image::check_float_images;
use zoovr::mesh::{CellKind, Mesh};
use zoovr::raycast::{render, FieldModel, Raycaster, Scalars, Scene};

const TAU: f64 = 0.7;

/// Boxes of a grid mesh whose points lie on integer coordinates.
fn boxes(mesh: &Mesh) -> Vec<(DVec3, DVec3)> {
    (0..mesh.cells.len())
        .map(|c| {
            let n = mesh.cells.nodes(c);
            let mut lo = DVec3::splat(f64::INFINITY);
            let mut hi = -lo;
            for &v in n {
                lo = lo.min(mesh.points[v as usize]);
                hi = hi.max(mesh.points[v as usize]);
            }
            (lo, hi)
        })
        .collect()
}

/// Sum of the exact box chords of the boxes whose interior the ray enters
/// once it is displaced the way the ray caster's tie-breaking rule displaces
/// it (first along `u`, then along `v = d x u`, `raycast::geometry::tie_basis`:
/// the image's right and down directions for a pixel ray). A ray along a
/// shared face or edge thus counts in exactly one of the boxes around it.
fn oracle(bx: &[(DVec3, DVec3)], r: &Ray, t0: f64) -> f64 {
    let (u, v) = zoovr::raycast::geometry::tie_basis(r);
    let moved = Ray::new(r.origin + u * 1e-7 + v * 1e-10, r.dir);
    bx.iter()
        .filter(|&&(lo, hi)| convex_chord(&moved, &box_planes(lo, hi), t0) > 0.0)
        .map(|&(lo, hi)| convex_chord(r, &box_planes(lo, hi), t0))
        .sum()
}

/// Checks every ray against the oracle for all models; also checks that the
/// segments tile the ray without overlap.
fn check_rays(name: &str, mesh: &Mesh, bx: &[(DVec3, DVec3)], rays: &[Ray], models: &[FieldModel]) {
    let topology = topo(mesh);
    let scene = Scene {
        mesh,
        topology: &topology,
        scalars: Scalars::Constant(1.0),
    };
    let m = TestMaterial::constant(TAU, [1.0, 1.0, 1.0]);
    for &model in models {
        let rc = Raycaster::new(scene, model).unwrap();
        for r in rays {
            let want = oracle(bx, r, 0.0);
            let segs = rc.segments(r, 0.0);
            for w in segs.windows(2) {
                assert!(
                    w[1].t_in >= w[0].t_out - 1e-12,
                    "{name} {model:?}: overlapping segments"
                );
            }
            let len: f64 = segs.iter().map(|s| s.t_out - s.t_in).sum();
            assert!(
                (len - want).abs() < 1e-9 * (1.0 + want),
                "{name} {model:?}: length {len} vs {want} for {r:?}"
            );
            let acc = rc.trace(&m, r, 0.0, &opts(model), &mut Default::default());
            assert!(acc.alpha().is_finite() && acc.color.iter().all(|c| c.is_finite()));
            assert!(
                (acc.depth - TAU * want).abs() < 1e-9 * (1.0 + want),
                "{name} {model:?}"
            );
        }
    }
}

fn unit_grid(n: [usize; 3], perm: Option<&[u32]>) -> Mesh {
    grid(n, DVec3::new, perm)
}

/// Rays along grid lines (through edges and vertices), along faces, through
/// face centres and along body diagonals through vertices.
fn grid_line_rays(n: f64) -> Vec<Ray> {
    let mut rays = Vec::new();
    for i in 1..n as usize {
        for j in 1..n as usize {
            let (x, y) = (i as f64, j as f64);
            rays.push(ray(DVec3::new(x, y, -1.0), DVec3::Z));
            rays.push(ray(DVec3::new(x, y + 0.5, -1.0), DVec3::Z));
            rays.push(ray(DVec3::new(x - 0.5, y - 0.5, -1.0), DVec3::Z));
            rays.push(ray(DVec3::new(-1.0, x, y), DVec3::X));
            rays.push(ray(DVec3::new(x, -1.0, y - 0.5), DVec3::Y));
        }
    }
    rays.push(ray(DVec3::splat(-1.0), DVec3::ONE));
    rays.push(ray(
        DVec3::new(n + 1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, 1.0),
    ));
    rays.push(ray(DVec3::new(-1.0, 0.0, 2.0), DVec3::new(1.0, 1.0, 0.0)));
    rays.push(ray(DVec3::new(-1.0, 1.0, -1.0), DVec3::new(1.0, 0.0, 1.0)));
    rays.push(ray(DVec3::new(-2.0, -1.0, 0.5), DVec3::new(2.0, 1.0, 0.0)));
    rays
}

#[test]
fn rays_through_grid_vertices_and_edges_give_the_exact_alpha() {
    let n = 4;
    let mesh = unit_grid([n, n, n], None);
    let bx = boxes(&mesh);
    let rays = grid_line_rays(n as f64);
    check_rays(
        "grid",
        &mesh,
        &bx,
        &rays,
        &[FieldModel::Faces, FieldModel::Tets],
    );
    // Interior grid lines see the full depth n: alpha = 1 - exp(-tau n).
    let topology = topo(&mesh);
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Constant(1.0),
    };
    let m = TestMaterial::constant(TAU, [1.0; 3]);
    let rc = Raycaster::new(scene, FieldModel::Faces).unwrap();
    let acc = rc.trace(
        &m,
        &rays[0],
        0.0,
        &opts(FieldModel::Faces),
        &mut Default::default(),
    );
    assert!((acc.alpha() - (1.0 - (-TAU * n as f64).exp())).abs() < 1e-14);
    // The same grid as tets with scrambled point numbering (different
    // diagonals everywhere).
    let perm = shuffle(mesh.points.len(), 7);
    let tets = to_tets(&unit_grid([n, n, n], Some(&perm)));
    check_rays("grid tets", &tets, &bx, &rays, &[FieldModel::Faces]);
}

/// Labellings of a unit cube giving the 5-tet and the 6-tet split.
fn cube_splits() -> (Mesh, Mesh) {
    let mut five = None;
    let mut six = None;
    for seed in 0..200 {
        let perm = shuffle(8, seed);
        let t = to_tets(&unit_grid([1, 1, 1], Some(&perm)));
        match t.cells.len() {
            5 if five.is_none() => five = Some(t),
            6 if six.is_none() => six = Some(t),
            _ => {}
        }
    }
    (five.unwrap(), six.unwrap())
}

#[test]
fn five_and_six_tet_cubes_render_the_same_exact_image() {
    let (five, six) = cube_splits();
    let hex = unit_grid([1, 1, 1], None);
    let m = TestMaterial::constant(2.0, [0.9, 0.6, 0.3]);
    let bx = [(DVec3::ZERO, DVec3::ONE)];
    for (az, el, ortho) in [
        (0.0, 0.0, true),
        (20.0, 35.0, false),
        (45.0, 35.264389682754654, true),
        (90.0, 0.0, false),
    ] {
        let p = CameraParams {
            width: 40,
            height: 40,
            azimuth: az,
            elevation: el,
            ortho,
            ..Default::default()
        };
        let cam = Camera::fit([0.0, 1.0, 0.0, 1.0, 0.0, 1.0], &p);
        let mut imgs = Vec::new();
        for mesh in [&five, &six, &hex] {
            let topology = topo(mesh);
            let scene = Scene {
                mesh,
                topology: &topology,
                scalars: Scalars::Constant(0.0),
            };
            imgs.push(render(&scene, &m, &cam, &opts(FieldModel::Faces)).unwrap());
        }
        for k in 1..3 {
            check_float_images(
                &format!("walk_{az}_{el}_{k}"),
                &imgs[k],
                &imgs[0],
                1e-6,
                1e-6,
            )
            .unwrap_or_else(|e| panic!("az {az} el {el}: {e}"));
        }
        // Every pixel against the exact chord.
        for j in 0..40 {
            for i in 0..40 {
                let r = cam.pixel_ray(i, j);
                let want = -(-2.0 * oracle(&bx, &r, 0.0)).exp_m1();
                assert!((imgs[0].get(i, j)[3] as f64 - want).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn non_convex_meshes_are_left_and_re_entered() {
    // A C-shape: a 3x3x2 block without its middle column (i = 1, j >= 1).
    let full = unit_grid([3, 3, 2], None);
    let mut mesh = full.clone();
    mesh.cells = Default::default();
    for c in 0..full.cells.len() {
        let (i, j) = (c % 3, (c / 3) % 3);
        if !(i == 1 && j >= 1) {
            mesh.cells.push(CellKind::Hexahedron, full.cells.nodes(c));
        }
    }
    let bx = boxes(&mesh);
    let mut rays = vec![
        // Along x through the gap: two parts, each of length 1.
        ray(DVec3::new(-1.0, 2.5, 0.5), DVec3::X),
        ray(DVec3::new(-1.0, 1.0, 1.0), DVec3::X),
        ray(DVec3::new(-1.0, 2.0, 0.3), DVec3::new(1.0, 0.1, 0.05)),
    ];
    for k in 0..60 {
        let a = k as f64 * 0.71;
        let d = DVec3::new(a.cos(), a.sin(), 0.3 * (k as f64 * 1.3).sin());
        rays.push(ray(
            DVec3::new(1.5, 1.5, 1.0) - d * 6.0 + DVec3::new(0.0, 0.0, (k as f64 * 0.37).sin()),
            d,
        ));
    }
    let r0 = oracle(&bx, &rays[0], 0.0);
    assert!((r0 - 2.0).abs() < 1e-12);
    check_rays(
        "C-shape",
        &mesh,
        &bx,
        &rays,
        &[FieldModel::Faces, FieldModel::Tets, FieldModel::Native],
    );
    // Two disconnected blocks that touch along a face without sharing points.
    let a = grid([2, 2, 2], DVec3::new, None);
    let b = grid([2, 2, 2], |i, j, k| DVec3::new(i + 2.0, j, k), None);
    let mut two = a.clone();
    let off = a.points.len() as u32;
    two.points.extend(&b.points);
    for c in 0..b.cells.len() {
        let n: Vec<u32> = b.cells.nodes(c).iter().map(|v| v + off).collect();
        two.cells.push(CellKind::Hexahedron, &n);
    }
    let bx2 = boxes(&two);
    let rays2 = vec![
        ray(DVec3::new(-1.0, 0.5, 0.5), DVec3::X),
        ray(DVec3::new(-1.0, 1.0, 1.0), DVec3::X),
        ray(DVec3::new(-1.0, 0.2, 0.1), DVec3::new(1.0, 0.2, 0.3)),
        ray(DVec3::new(2.0, 1.0, -1.0), DVec3::Z),
    ];
    assert!((oracle(&bx2, &rays2[0], 0.0) - 4.0).abs() < 1e-12);
    check_rays(
        "touching blocks",
        &two,
        &bx2,
        &rays2,
        &[FieldModel::Faces, FieldModel::Tets],
    );
}

#[test]
fn inverted_and_degenerate_cells_and_eyes_inside() {
    let mut mesh = unit_grid([3, 3, 3], None);
    let bx = boxes(&mesh);
    // Invert every other cell's node order.
    let perm = CellKind::Hexahedron.reorder_for_inversion();
    for c in (0..mesh.cells.len()).step_by(2) {
        let old: Vec<u32> = mesh.cells.nodes(c).to_vec();
        let s = mesh.cells.offsets[c] as usize;
        for (i, &p) in perm.iter().enumerate() {
            mesh.cells.conn[s + i] = old[p as usize];
        }
    }
    let mut rays = grid_line_rays(3.0);
    // Perspective-like rays from an eye inside the mesh.
    let eye = DVec3::new(1.3, 1.6, 1.2);
    for k in 0..30 {
        let a = k as f64 * 0.9;
        rays.push(ray(
            eye,
            DVec3::new(a.cos(), a.sin(), (k as f64 * 0.3).cos()),
        ));
    }
    check_rays(
        "inverted",
        &mesh,
        &bx,
        &rays,
        &[FieldModel::Faces, FieldModel::Tets, FieldModel::Native],
    );

    // A zero-volume layer: planes k = 1 and k = 2 coincide.
    let flat = grid(
        [2, 2, 3],
        |i, j, k| DVec3::new(i, j, if k >= 2.0 { k - 1.0 } else { k }),
        None,
    );
    let bxf = boxes(&flat);
    let raysf = vec![
        ray(DVec3::new(0.5, 0.5, -1.0), DVec3::Z),
        ray(DVec3::new(1.0, 1.0, -1.0), DVec3::Z),
        ray(DVec3::new(-1.0, 0.5, 1.0), DVec3::X),
        ray(DVec3::new(-1.0, -1.0, -1.0), DVec3::new(1.0, 1.0, 1.0)),
    ];
    check_rays(
        "flat layer",
        &flat,
        &bxf,
        &raysf,
        &[FieldModel::Faces, FieldModel::Tets, FieldModel::Native],
    );
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut mesh = unit_grid([1, 1, 1], None);
    let topology = topo(&mesh);
    let s = vec![0.0; 3];
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Point(&s),
    };
    assert!(Raycaster::new(scene, FieldModel::Faces).is_err());
    let c = [0.0; 2];
    let scene = Scene {
        scalars: Scalars::Cell(&c),
        ..scene
    };
    assert!(Raycaster::new(scene, FieldModel::Faces).is_err());
    mesh.cells.conn[3] = 99;
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Constant(0.0),
    };
    assert!(Raycaster::new(scene, FieldModel::Faces).is_err());
    let mut mesh = unit_grid([1, 1, 1], None);
    mesh.points[2].x = f64::NAN;
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Constant(0.0),
    };
    assert!(Raycaster::new(scene, FieldModel::Faces).is_err());
    let other = topo(&unit_grid([2, 1, 1], None));
    let scene = Scene {
        topology: &other,
        ..scene
    };
    assert!(Raycaster::new(scene, FieldModel::Faces).is_err());
    // An empty mesh renders transparent.
    let empty = Mesh::default();
    let t = topo(&empty);
    let scene = Scene {
        mesh: &empty,
        topology: &t,
        scalars: Scalars::Constant(0.0),
    };
    let cam = Camera::fit(
        empty.bounds(),
        &CameraParams {
            width: 4,
            height: 4,
            ..Default::default()
        },
    );
    let img = render(
        &scene,
        &TestMaterial::constant(1.0, [1.0; 3]),
        &cam,
        &opts(FieldModel::Faces),
    )
    .unwrap();
    assert!(img.pixels.iter().all(|p| *p == [0.0; 4]));
}
