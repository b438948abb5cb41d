//! The brute-force traversal (`raycast::brute`) against the walk and
//! against physics:
//! - on conforming meshes (every cell kind, curvilinear, zoo, a non-convex
//!   ring, the shared datasets that are conforming) brute force equals the
//!   walk to 1e-9 on every pixel of the f32 image, for `faces` and `tets`,
//!   orthographic and perspective, eye outside and inside the mesh, and
//!   rays exactly through vertices, along edges and in faces;
//! - a T-face (two half cells against one big face) renders like the
//!   conforming mesh; a duplicated cell and two overlapping cells add their
//!   extinctions (the closed form of constant glow along exact chords);
//! - zero-volume cells contribute nothing and make no NaN;
//! - `native` is a typed error in the library and a usage error (exit 2)
//!   on the command line.

mod raycast_util;

use std::path::Path;
use std::process::Command;

use glam::DVec3;
use raycast_util::{box_planes, convex_chord, grid, shuffle, to_tets, topo, TestMaterial};
use zoovr::camera::{Camera, CameraParams};
use zoovr::image::Image;
use zoovr::integrate::RayMaterial;
use zoovr::io;
use zoovr::mesh::{CellKind, Mesh};
use zoovr::raycast::brute::Brute;
use zoovr::raycast::{
    render, FieldModel, RayTracer, RaycastError, RaycastOptions, Raycaster, Scalars, Scene,
    Traversal,
};
use zoovr::render::SceneSpec;
use zoovr::testdata::{mesh_file, shared_file, Rng};
use zoovr::tf::TransferFunction;

const MODELS: [FieldModel; 2] = [FieldModel::Faces, FieldModel::Tets];
const TOL: f64 = 1e-9;

/// A transfer function over `lo..hi` with a few linear pieces and jumps in
/// colour and opacity (breakpoints inside most cells), extinction per
/// `unit` length: cheaper to integrate than a 256-sample preset.
fn test_tf(lo: f64, hi: f64, unit: f64) -> TransferFunction {
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        (lo - 1.0, lo + 1.0)
    };
    let s = |x: f64| lo + (hi - lo) * x;
    let json = format!(
        r#"{{"unit_distance": {unit:e},
         "opacity_points": [{{"s": {}, "opacity": 0.0}}, {{"s": {}, "opacity": 0.4}},
            {{"s": {}, "opacity": 0.1}}, {{"s": {}, "opacity": 0.8}}, {{"s": {}, "opacity": 1.0}}],
         "color_points": [{{"s": {}, "rgb": [0.1, 0.2, 0.9]}}, {{"s": {}, "rgb": [0.2, 0.9, 0.3]}},
            {{"s": {}, "rgb": [1.0, 0.5, 0.0]}}, {{"s": {}, "rgb": [0.9, 0.1, 0.4]}}]}}"#,
        s(0.0),
        s(0.35),
        s(0.5),
        s(0.5),
        s(1.0),
        s(0.0),
        s(0.4),
        s(0.4),
        s(1.0)
    );
    TransferFunction::from_json_str(&json, unit).unwrap()
}

fn max_diff(a: &Image, b: &Image) -> f64 {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..4).map(move |k| (p[k] as f64 - q[k] as f64).abs()))
        .fold(0.0, f64::max)
}

fn covered(img: &Image) -> usize {
    img.pixels.iter().filter(|p| p[3] > 0.0).count()
}

/// The views of the comparisons: perspective, orthographic, a close-up,
/// and perspective eyes inside the bounds (at the centre, which is a vertex
/// of symmetric meshes, and off it).
fn views(bounds: [f64; 6], size: u32) -> Vec<(String, Camera)> {
    let p = |az: f64, el: f64, zoom: f64, ortho: bool| CameraParams {
        width: size,
        height: size,
        azimuth: az,
        elevation: el,
        zoom,
        ortho,
        ..Default::default()
    };
    let mut v = vec![
        (
            "persp".to_string(),
            Camera::fit(bounds, &p(20.0, 35.0, 1.0, false)),
        ),
        (
            "ortho".to_string(),
            Camera::fit(bounds, &p(-30.0, 20.0, 1.0, true)),
        ),
        (
            "close".to_string(),
            Camera::fit(bounds, &p(65.0, -40.0, 3.0, false)),
        ),
    ];
    let c = DVec3::new(
        0.5 * (bounds[0] + bounds[1]),
        0.5 * (bounds[2] + bounds[3]),
        0.5 * (bounds[4] + bounds[5]),
    );
    let d = DVec3::new(
        bounds[1] - bounds[0],
        bounds[3] - bounds[2],
        bounds[5] - bounds[4],
    );
    for (name, eye) in [
        ("inside-centre", c),
        ("inside", c + d * DVec3::new(0.113, -0.071, 0.052)),
    ] {
        let mut cam = Camera::fit(bounds, &p(-50.0, 25.0, 0.6, false));
        cam.position = eye;
        v.push((name.to_string(), cam));
    }
    v
}

/// Renders `scene` with both traversals for both models in every view and
/// checks that they agree to [`TOL`] on every pixel; returns the largest
/// difference. With `conforming`, brute force must also see no
/// overlapping segments.
fn walk_vs_brute<M: RayMaterial>(
    name: &str,
    scene: &Scene,
    material: &M,
    cams: &[(String, Camera)],
    conforming: bool,
) -> f64 {
    let opts = RaycastOptions::default();
    let mut worst: f64 = 0.0;
    for model in MODELS {
        let walk = Raycaster::new(*scene, model).unwrap();
        let brute = Brute::new(*scene, model).unwrap();
        let mut line = format!("{name} {}:", model.name());
        for (view, cam) in cams {
            let a = walk.render(material, cam, &opts);
            let b = brute.render(material, cam, &opts);
            assert_eq!(b.count_non_finite(), 0, "{name} {model:?} {view}: NaN");
            let d = max_diff(&a, &b);
            line += &format!(" {view} {d:.1e} ({} px)", covered(&b));
            assert!(
                d <= TOL,
                "{name} {model:?} {view}: walk vs brute max difference {d:e}"
            );
            worst = worst.max(d);
        }
        let st = brute.stats();
        line += &format!(
            "; {} pieces ({} flat), {} overlapping segments",
            brute.piece_count(),
            brute.flat_pieces(),
            st.overlapping_segments
        );
        eprintln!("{line}");
        if conforming {
            assert_eq!(st.overlapping_segments, 0, "{name} {model:?}: overlaps");
        }
    }
    worst
}

/// The scene of a file as the CLI builds it (points merged, default field
/// and transfer function).
fn file_scene(path: &std::path::Path, opts: &io::ReadOptions) -> zoovr::render::Scene {
    let mesh = io::read(path, opts).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    zoovr::render::Scene::build(mesh, &SceneSpec::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn ray_scene(s: &zoovr::render::Scene) -> Scene<'_> {
    s.ray_scene()
}

#[test]
fn own_meshes_brute_equals_walk() {
    for file in [
        "tetra.vtu",
        "pyramid.vtu",
        "wedge.vtu",
        "hexahedron.vtu",
        "voxel.vtk",
        "pentagonal_prism.vtu",
        "hexagonal_prism.vtu",
        "polyhedron.vtu",
        "curvilinear_4x4x4.vtu",
        "zoo_3x3x3.vtu",
        "ring_hole.vtu",
    ] {
        let s = file_scene(&mesh_file(file), &Default::default());
        let cams = views(s.mesh.bounds(), 64);
        let tf = test_tf(s.range.0, s.range.1, s.unit_distance);
        walk_vs_brute(file, &ray_scene(&s), &tf, &cams, true);
    }
}

/// Shared datasets whose cells do not overlap (the walk and brute force
/// must agree), small enough for a test.
const SHARED_CONFORMING: &[&str] = &[
    "tets_small/tetraMesh.vtk",
    "tets_small/CylinderLinear.vtk",
    "prisms_zoo/PentaHexa.vtk",
    "prisms_zoo/hexa.vtk",
    "prisms_zoo/uGridEx.vtk",
    "angular_sector/AngularSector.vtk",
    "office_kitchen/kitchen.vtk",
    "fire_room/fire_ug.vtu",
    "su2_sphere_hybrid/sphere_hybrid_converted.vtu",
    "disk_out_ref/disk_out_ref_converted.vtu",
    "notch/notch_disp.vtu",
    "bluntfin/bluntfin_converted.vts",
    "blood_vessels_pvtu/blood_vessels/T0000000500.pvtu",
    "fea_bracket_qtet/kiefer_bracket.vtu",
    "synthetic/mixed.vtk",
];

/// Shared datasets whose cells overlap in space: the crushed can folds
/// through itself.
const SHARED_OVERLAPPING: &[&str] = &["can_crush/can.vtu"];

#[test]
fn shared_datasets_brute_equals_walk() {
    let mut done = 0;
    for rel in SHARED_CONFORMING {
        let Some(path) = shared_file(rel) else {
            continue;
        };
        let s = file_scene(&path, &zoovr::testdata::read_options(rel));
        let cams: Vec<_> = views(s.mesh.bounds(), 64).into_iter().take(2).collect();
        let t = std::time::Instant::now();
        let tf = test_tf(s.range.0, s.range.1, s.unit_distance);
        walk_vs_brute(rel, &ray_scene(&s), &tf, &cams, true);
        eprintln!("  {rel}: {:.2} s", t.elapsed().as_secs_f64());
        done += 1;
    }
    eprintln!("compared {done} shared datasets");
}

/// Where pieces overlap in space, brute force integrates every layer and
/// the walk follows one: the images differ, but only on rays along which
/// brute force finds overlapping segments.
#[test]
fn shared_overlapping_datasets_differ_only_where_pieces_overlap() {
    for rel in SHARED_OVERLAPPING {
        let Some(path) = shared_file(rel) else {
            continue;
        };
        let s = file_scene(&path, &zoovr::testdata::read_options(rel));
        let scene = ray_scene(&s);
        let tf = test_tf(s.range.0, s.range.1, s.unit_distance);
        let slack = 1e-9 * s.mesh.diagonal();
        let opts = RaycastOptions::default();
        for model in MODELS {
            let walk = Raycaster::new(scene, model).unwrap();
            let brute = Brute::new(scene, model).unwrap();
            for (view, cam) in views(s.mesh.bounds(), 64).iter().take(2) {
                let a = walk.render(&tf, cam, &opts);
                let b = brute.render(&tf, cam, &opts);
                assert_eq!(b.count_non_finite(), 0);
                let t_near = if cam.ortho { 0.0 } else { cam.near };
                let (mut differ, mut overlapped, mut worst) = (0, 0, 0.0f64);
                for j in 0..cam.height {
                    for i in 0..cam.width {
                        let (p, q) = (a.get(i, j), b.get(i, j));
                        let d = (0..4)
                            .map(|k| (p[k] as f64 - q[k] as f64).abs())
                            .fold(0.0, f64::max);
                        let segs = brute.segments(&cam.pixel_ray(i, j), t_near);
                        let mut end = f64::NEG_INFINITY;
                        let mut overlap = false;
                        for sg in &segs {
                            overlap |= end.min(sg.t_out) - sg.t_in > slack;
                            end = end.max(sg.t_out);
                        }
                        overlapped += overlap as usize;
                        if d > TOL {
                            differ += 1;
                            worst = worst.max(d);
                            assert!(
                                overlap,
                                "{rel} {model:?} {view}: pixel ({i}, {j}) differs by {d:e} \
                                 without overlapping pieces"
                            );
                        }
                    }
                }
                eprintln!(
                    "{rel} {} {view}: walk vs brute max {worst:.2e} on {differ} pixels; \
                     {overlapped} pixels see overlapping pieces",
                    model.name()
                );
            }
        }
    }
}

/// A grid of unit cubes with point ids shuffled (so the quad diagonals
/// vary), vertices on integer coordinates.
fn shuffled_grid(n: usize) -> Mesh {
    let np = (n + 1) * (n + 1) * (n + 1);
    let perm = shuffle(np, 7);
    grid([n, n, n], DVec3::new, Some(&perm))
}

/// An orthographic camera looking along `-axis` whose pixel centres fall
/// on a lattice of spacing 1/8 containing the integer points (rays through
/// vertices, along edges and inside faces), 64 x 64.
fn lattice_camera(axis: usize) -> Camera {
    let (forward, up, right) = match axis {
        0 => (-DVec3::X, DVec3::Z, DVec3::Y),
        1 => (-DVec3::Y, DVec3::X, DVec3::Z),
        _ => (-DVec3::Z, DVec3::Y, DVec3::X),
    };
    // Pixel (i, j) samples right * (-0.5 + i / 8) + up * (6.5 - j / 8).
    let centre = right * 3.4375 + up * 2.5625 - forward * 50.0;
    Camera {
        position: centre,
        focal_point: centre + forward * 50.0,
        up,
        right,
        forward,
        view_angle: 30.0,
        parallel_scale: 4.0,
        ortho: true,
        width: 64,
        height: 64,
        near: 1e-6,
    }
}

#[test]
fn rays_through_vertices_edges_and_faces() {
    let cam = lattice_camera(2);
    // The lattice is exact: pixel (4, 52) looks along the grid line x = 0,
    // y = 0 (through a vertex of every layer).
    let r = cam.pixel_ray(4, 52);
    assert_eq!((r.origin.x, r.origin.y), (0.0, 0.0));
    let r = cam.pixel_ray(12, 12);
    assert_eq!((r.origin.x, r.origin.y), (1.0, 5.0));
    let hex = shuffled_grid(6);
    let tets = to_tets(&hex);
    let mut rng = Rng(0x5eed);
    let pv: Vec<f64> = (0..hex.points.len()).map(|_| rng.f64()).collect();
    let tf = test_tf(0.0, 1.0, 1.5);
    let mut cams: Vec<(String, Camera)> = (0..3)
        .map(|a| (format!("lattice{a}"), lattice_camera(a)))
        .collect();
    // A perspective eye on a grid line: the centre pixel of an odd image
    // looks exactly along it.
    let mut p = lattice_camera(2);
    p.ortho = false;
    p.width = 65;
    p.height = 65;
    p.position = DVec3::new(3.0, 2.0, 20.0);
    p.focal_point = DVec3::new(3.0, 2.0, 0.0);
    let r = p.pixel_ray(32, 32);
    assert_eq!((r.origin, r.dir), (p.position, -DVec3::Z));
    cams.push(("persp-grid-line".into(), p));
    cams.extend(views(hex.bounds(), 48));
    for (name, mesh) in [("hex grid", &hex), ("tet grid", &tets)] {
        let topology = topo(mesh);
        let cv: Vec<f64> = (0..mesh.cells.len())
            .map(|c| (c % 7) as f64 / 6.0)
            .collect();
        for (sname, scalars) in [
            ("point", Scalars::Point(&pv)),
            ("cell", Scalars::Cell(&cv)),
            ("constant", Scalars::Constant(0.6)),
        ] {
            let scene = Scene {
                mesh,
                topology: &topology,
                scalars,
            };
            walk_vs_brute(&format!("{name} {sname}"), &scene, &tf, &cams, true);
        }
    }
}

/// Unit-cube hexahedra `cells` (lower corners) over their own points
/// (corners shared only within a cell), scalar `f(p)` per point.
fn loose_cubes(cells: &[(DVec3, DVec3)]) -> Mesh {
    let mut mesh = Mesh::default();
    for &(lo, hi) in cells {
        let base = mesh.points.len() as u32;
        for k in 0..8 {
            let (x, y, z) = (k & 1, (k >> 1) & 1, (k >> 2) & 1);
            mesh.points.push(DVec3::new(
                if x == 1 { hi.x } else { lo.x },
                if y == 1 { hi.y } else { lo.y },
                if z == 1 { hi.z } else { lo.z },
            ));
        }
        let n = |x: u32, y: u32, z: u32| base + x + 2 * y + 4 * z;
        mesh.cells.push(
            CellKind::Hexahedron,
            &[
                n(0, 0, 0),
                n(1, 0, 0),
                n(1, 1, 0),
                n(0, 1, 0),
                n(0, 0, 1),
                n(1, 0, 1),
                n(1, 1, 1),
                n(0, 1, 1),
            ],
        );
    }
    mesh
}

fn brute_image<M: RayMaterial>(
    mesh: &Mesh,
    scalars: Scalars,
    model: FieldModel,
    m: &M,
    cam: &Camera,
) -> Image {
    let topology = topo(mesh);
    let scene = Scene {
        mesh,
        topology: &topology,
        scalars,
    };
    let opts = RaycastOptions {
        model,
        traversal: Traversal::Brute,
        early_termination: 0.0,
        ..Default::default()
    };
    render(&scene, m, cam, &opts).unwrap()
}

fn walk_image<M: RayMaterial>(
    mesh: &Mesh,
    scalars: Scalars,
    model: FieldModel,
    m: &M,
    cam: &Camera,
) -> Image {
    let topology = topo(mesh);
    let scene = Scene {
        mesh,
        topology: &topology,
        scalars,
    };
    let opts = RaycastOptions {
        model,
        early_termination: 0.0,
        ..Default::default()
    };
    render(&scene, m, cam, &opts).unwrap()
}

/// Two half-size cells against one big cell's face (a T-face: hanging
/// nodes, no shared face in the topology) render like the conforming mesh
/// where the big cell is split in two, for a linear point field (exact on
/// every triangle, so both meshes carry the same field) and cell data.
#[test]
fn t_face_renders_like_the_conforming_mesh() {
    let v = |x, y, z| DVec3::new(x, y, z);
    let small = [
        (v(1.0, 0.0, 0.0), v(2.0, 1.0, 1.0)),
        (v(1.0, 1.0, 0.0), v(2.0, 2.0, 1.0)),
    ];
    let t_face = loose_cubes(&[(v(0.0, 0.0, 0.0), v(1.0, 2.0, 1.0)), small[0], small[1]]);
    let conforming = loose_cubes(&[
        (v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0)),
        (v(0.0, 1.0, 0.0), v(1.0, 2.0, 1.0)),
        small[0],
        small[1],
    ]);
    let lin = |m: &Mesh| -> Vec<f64> {
        m.points
            .iter()
            .map(|p| 0.1 + 0.2 * p.x + 0.15 * p.y + 0.1 * p.z)
            .collect()
    };
    let tf = test_tf(0.0, 1.0, 0.5);
    let bounds = t_face.bounds();
    let mut cams = views(bounds, 64);
    cams.push((
        "along x".into(),
        Camera::fit(
            bounds,
            &CameraParams {
                width: 64,
                height: 64,
                azimuth: 90.0,
                ortho: true,
                ..Default::default()
            },
        ),
    ));
    let (pt, pc) = (lin(&t_face), lin(&conforming));
    let (ct, cc) = (vec![0.3, 0.7, 0.9], vec![0.3, 0.3, 0.7, 0.9]);
    for model in MODELS {
        for (view, cam) in &cams {
            let cases = [
                ("point", Scalars::Point(&pt), Scalars::Point(&pc)),
                ("cell", Scalars::Cell(&ct), Scalars::Cell(&cc)),
            ];
            for (sname, st, sc) in cases {
                let a = brute_image(&t_face, st, model, &tf, cam);
                let b = brute_image(&conforming, sc, model, &tf, cam);
                let w = walk_image(&t_face, st, model, &tf, cam);
                let d = max_diff(&a, &b);
                eprintln!(
                    "T-face {model:?} {view} {sname}: brute vs conforming {d:.1e}, walk vs conforming {:.1e} ({} px)",
                    max_diff(&w, &b),
                    covered(&b)
                );
                assert!(covered(&b) > 0);
                assert!(d <= 1e-6, "T-face {model:?} {view} {sname}: {d:e}");
            }
        }
    }
}

/// Optical depth of constant extinction `tau` along the chords of `boxes`
/// (overlaps counted once per box: extinction adds).
fn chord_depth(boxes: &[(DVec3, DVec3)], cam: &Camera, i: u32, j: u32, tau: f64) -> f64 {
    let r = cam.pixel_ray(i, j);
    let t0 = if cam.ortho { 0.0 } else { cam.near };
    boxes
        .iter()
        .map(|&(lo, hi)| tau * convex_chord(&r, &box_planes(lo, hi), t0))
        .sum()
}

/// A duplicated cell and two cells that overlap in space: extinctions add.
/// With constant glow of one colour the image is the closed form
/// `c (1 - exp(-tau L))` with `L` the sum of the boxes' exact chords.
#[test]
fn duplicated_and_overlapping_cells_add_extinction() {
    let v = |x, y, z| DVec3::new(x, y, z);
    let a = (v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0));
    let b = (v(0.5, 0.25, 0.3), v(1.5, 1.25, 1.3));
    let (tau, color) = (1.3, [0.9, 0.5, 0.2]);
    let m = TestMaterial::constant(tau, color);
    let mut dup = loose_cubes(&[a]);
    let n: Vec<u32> = dup.cells.nodes(0).to_vec();
    dup.cells.push(CellKind::Hexahedron, &n);
    for (name, mesh, boxes) in [
        ("duplicate", dup, vec![a, a]),
        ("overlap", loose_cubes(&[a, b]), vec![a, b]),
    ] {
        for (view, cam) in views(mesh.bounds(), 48).iter().take(3) {
            for model in MODELS {
                let img = brute_image(&mesh, Scalars::Constant(0.0), model, &m, cam);
                let walk = walk_image(&mesh, Scalars::Constant(0.0), model, &m, cam);
                let mut err: f64 = 0.0;
                for j in 0..cam.height {
                    for i in 0..cam.width {
                        let depth = chord_depth(&boxes, cam, i, j, tau);
                        let alpha = -(-depth).exp_m1();
                        let want = [color[0] * alpha, color[1] * alpha, color[2] * alpha, alpha];
                        let got = img.get(i, j);
                        for k in 0..4 {
                            err = err.max((got[k] as f64 - want[k]).abs());
                        }
                    }
                }
                eprintln!(
                    "{name} {view} {model:?}: brute vs closed form {err:.1e}; walk vs brute {:.1e}",
                    max_diff(&walk, &img)
                );
                assert!(covered(&img) > 0);
                assert!(err <= 1e-6, "{name} {view} {model:?}: {err:e}");
            }
        }
    }
}

/// Flat cells (a collapsed layer inside a grid, and loose flat cells) add
/// nothing and make no NaN; a flat layer between conforming cells leaves
/// brute force equal to the walk.
#[test]
fn zero_volume_cells_contribute_nothing() {
    // Planes k = 1 and k = 2 coincide: the middle layer is flat.
    let flat_layer = grid(
        [3, 3, 3],
        |i, j, k| DVec3::new(i, j, if k >= 2.0 { k - 1.0 } else { k }),
        None,
    );
    let two_layers = grid([3, 3, 2], DVec3::new, None);
    let tf = test_tf(0.0, 1.0, 1.0);
    let cams = views(two_layers.bounds(), 48);
    for model in MODELS {
        for (view, cam) in &cams {
            let a = brute_image(&flat_layer, Scalars::Constant(0.5), model, &tf, cam);
            let b = brute_image(&two_layers, Scalars::Constant(0.5), model, &tf, cam);
            assert_eq!(a.count_non_finite(), 0);
            let d = max_diff(&a, &b);
            assert!(d <= 1e-9, "flat layer {model:?} {view}: {d:e}");
        }
    }
    let pv: Vec<f64> = flat_layer
        .points
        .iter()
        .map(|p| (p.x * 0.3 + p.y * 0.2 + p.z * 0.1) / 2.0)
        .collect();
    let topology = topo(&flat_layer);
    let scene = Scene {
        mesh: &flat_layer,
        topology: &topology,
        scalars: Scalars::Point(&pv),
    };
    walk_vs_brute("flat layer", &scene, &tf, &cams, true);
    for model in MODELS {
        let b = Brute::new(scene, model).unwrap();
        assert!(b.flat_pieces() >= 9, "{model:?}: {}", b.flat_pieces());
    }

    // Loose flat cells: a hex squashed into a plane, a hex with repeated
    // nodes that span a plane, a flat tet, all inside a cube's volume.
    let v = |x, y, z| DVec3::new(x, y, z);
    let base = loose_cubes(&[(v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0))]);
    let mut with_flat = loose_cubes(&[
        (v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0)),
        (v(0.2, 0.2, 0.5), v(0.8, 0.8, 0.5)),
    ]);
    let n: Vec<u32> = with_flat.cells.nodes(0)[..4].to_vec();
    with_flat.cells.push(
        CellKind::Hexahedron,
        &[n[0], n[1], n[2], n[3], n[0], n[1], n[2], n[3]],
    );
    with_flat
        .cells
        .push(CellKind::Tetra, &[n[0], n[1], n[2], n[3]]);
    let pb: Vec<f64> = base.points.iter().map(|p| 0.2 + 0.5 * p.x).collect();
    let pf: Vec<f64> = with_flat.points.iter().map(|p| 0.2 + 0.5 * p.x).collect();
    for model in MODELS {
        for (view, cam) in &views(base.bounds(), 48) {
            let a = brute_image(&with_flat, Scalars::Point(&pf), model, &tf, cam);
            let b = brute_image(&base, Scalars::Point(&pb), model, &tf, cam);
            assert_eq!(a.count_non_finite(), 0);
            let d = max_diff(&a, &b);
            assert!(d == 0.0, "loose flat cells {model:?} {view}: {d:e}");
        }
        let topology = topo(&with_flat);
        let scene = Scene {
            mesh: &with_flat,
            topology: &topology,
            scalars: Scalars::Constant(0.5),
        };
        let b = Brute::new(scene, model).unwrap();
        assert!(b.flat_pieces() >= 3, "{model:?}: {}", b.flat_pieces());
    }
}

#[test]
fn native_model_is_a_typed_error() {
    let mesh = shuffled_grid(1);
    let topology = topo(&mesh);
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Constant(0.0),
    };
    let e = Brute::new(scene, FieldModel::Native).err().unwrap();
    assert!(matches!(e, RaycastError::BruteModel("native")), "{e:?}");
    let msg = e.to_string();
    assert!(msg.contains("faces") && msg.contains("tets"), "{msg}");
    let cam = Camera::fit(mesh.bounds(), &CameraParams::default());
    let opts = RaycastOptions {
        model: FieldModel::Native,
        traversal: Traversal::Brute,
        ..Default::default()
    };
    let m = TestMaterial::constant(1.0, [1.0; 3]);
    assert!(render(&scene, &m, &cam, &opts).is_err());
    // Bad input is an error, not a panic.
    let s = [0.0; 3];
    let bad = Scene {
        scalars: Scalars::Point(&s),
        ..scene
    };
    assert!(Brute::new(bad, FieldModel::Faces).is_err());
}

fn zoovr(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_zoovr"))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run zoovr")
}

fn args<'a>(base: &[&'a str], more: &[&'a str]) -> Vec<&'a str> {
    base.iter().chain(more).copied().collect()
}

#[test]
fn cli_traversal_brute() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = mesh_file("zoo_3x3x3.vtu");
    let mesh = mesh.to_str().unwrap();
    let out = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let (walk, brute, native) = (out("walk.png"), out("brute.png"), out("native.png"));
    let base = ["render", mesh, "--size", "48x40", "--mode", "raycast"];
    let o = zoovr(&args(&base, &["-o", walk.as_str()]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = zoovr(&args(
        &base,
        &["-o", brute.as_str(), "--traversal", "brute", "--stats"],
    ));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("traversal brute") && e.contains("overlapping"),
        "{e}"
    );
    let a = Image::read(Path::new(&walk)).unwrap();
    let b = Image::read(Path::new(&brute)).unwrap();
    assert!(covered(&a) > 0);
    assert_eq!(a.pixels, b.pixels, "walk and brute PNGs differ");

    let o = zoovr(&args(
        &base,
        &[
            "-o",
            native.as_str(),
            "--traversal",
            "brute",
            "--model",
            "native",
        ],
    ));
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("--traversal brute") && e.contains("native") && e.contains("faces"),
        "{e}"
    );
    assert!(!Path::new(&native).exists());

    let o = zoovr(&args(
        &base,
        &["-o", native.as_str(), "--traversal", "sideways"],
    ));
    assert_eq!(o.status.code(), Some(2));
    let o = zoovr(&["render", "--help"]);
    let h = String::from_utf8_lossy(&o.stdout);
    assert!(h.contains("--traversal") && h.contains("conforming"), "{h}");
}
