//! Single cells of every kind against hand-derived values and exact chords.

mod raycast_util;

use glam::DVec3;
use raycast_util::*;
use zoovr::mesh::{CellKind, Cells, Mesh};
use zoovr::raycast::{trace_ray, FieldModel, Raycaster, Scalars, Scene};

const MODELS: [FieldModel; 3] = [FieldModel::Faces, FieldModel::Tets, FieldModel::Native];

fn one_cell(kind: CellKind, pts: &[[f64; 3]]) -> Mesh {
    let mut cells = Cells::default();
    let ids: Vec<u32> = (0..pts.len() as u32).collect();
    cells.push(kind, &ids);
    Mesh {
        points: pts.iter().map(|p| DVec3::from_array(*p)).collect(),
        cells,
        ..Default::default()
    }
}

fn polygon(n: usize, z: f64) -> Vec<[f64; 3]> {
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64 + 0.3;
            [a.cos(), a.sin(), z]
        })
        .collect()
}

fn zoo() -> Vec<(&'static str, Mesh)> {
    let mut out = vec![
        (
            "tet",
            one_cell(
                CellKind::Tetra,
                &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            ),
        ),
        (
            "pyramid",
            one_cell(
                CellKind::Pyramid,
                &[
                    [0., 0., 0.],
                    [1., 0., 0.],
                    [1., 1., 0.],
                    [0., 1., 0.],
                    [0.5, 0.4, 1.],
                ],
            ),
        ),
        (
            "wedge",
            one_cell(
                CellKind::Wedge,
                &[
                    [0., 0., 0.],
                    [0., 1., 0.],
                    [1., 0., 0.],
                    [0., 0., 1.],
                    [0., 1., 1.],
                    [1., 0., 1.],
                ],
            ),
        ),
        (
            "hex",
            one_cell(
                CellKind::Hexahedron,
                &[
                    [0., 0., 0.],
                    [1., 0., 0.],
                    [1., 1., 0.],
                    [0., 1., 0.],
                    [0., 0., 1.],
                    [1., 0., 1.],
                    [1., 1., 1.],
                    [0., 1., 1.],
                ],
            ),
        ),
    ];
    let mut p5 = polygon(5, 0.0);
    p5.extend(polygon(5, 1.0));
    out.push(("pentagonal prism", one_cell(CellKind::PentagonalPrism, &p5)));
    let mut p6 = polygon(6, 0.0);
    p6.extend(polygon(6, 1.0));
    out.push(("hexagonal prism", one_cell(CellKind::HexagonalPrism, &p6)));
    // A cube as a general polyhedron (faces outward).
    let cube = [
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    let mut cells = Cells::default();
    cells.push_polyhedron(vec![
        vec![0, 3, 2, 1],
        vec![4, 5, 6, 7],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ]);
    out.push((
        "polyhedron",
        Mesh {
            points: cube.iter().map(|p| DVec3::from_array(*p)).collect(),
            cells,
            ..Default::default()
        },
    ));
    out
}

#[test]
fn ray_through_a_tet_has_the_hand_derived_thickness() {
    let mesh = &zoo()[0].1;
    let topology = topo(mesh);
    let scene = Scene {
        mesh,
        topology: &topology,
        scalars: Scalars::Constant(0.0),
    };
    // Up the z axis at (0.2, 0.3): enters z = 0, leaves x + y + z = 1 at z = 0.5.
    let r = ray(DVec3::new(0.2, 0.3, -1.0), DVec3::Z);
    let tau = 2.0;
    let m = TestMaterial::constant(tau, [1.0, 0.5, 0.25]);
    for model in MODELS {
        let rc = Raycaster::new(scene, model).unwrap();
        let segs = rc.segments(&r, 0.0);
        assert_eq!(segs.len(), 1);
        assert!((segs[0].t_in - 1.0).abs() < 1e-15 && (segs[0].t_out - 1.5).abs() < 1e-15);
        let acc = trace_ray(&scene, &m, &r, &opts(model)).unwrap();
        let alpha = 1.0 - (-tau * 0.5f64).exp();
        assert!((acc.alpha() - alpha).abs() < 1e-14, "{model:?}");
        assert!((acc.color[1] - 0.5 * alpha).abs() < 1e-14);
    }
}

/// A few rays through each cell, from outside, in many directions.
fn rays_through(mesh: &Mesh) -> Vec<zoovr::camera::Ray> {
    let nodes = mesh.cells.nodes(0);
    let c: DVec3 = nodes
        .iter()
        .map(|&v| mesh.points[v as usize])
        .sum::<DVec3>()
        / nodes.len() as f64;
    let mut out = Vec::new();
    for k in 0..40 {
        let a = k as f64 * 2.399;
        let z = 1.0 - 2.0 * ((k as f64 + 0.5) / 40.0);
        let d = DVec3::new(
            (1.0 - z * z).sqrt() * a.cos(),
            (1.0 - z * z).sqrt() * a.sin(),
            z,
        );
        let off = DVec3::new(
            (k as f64 * 0.37).sin(),
            (k as f64 * 0.91).cos(),
            (k as f64 * 0.13).sin(),
        ) * 0.25;
        let target = c + off;
        out.push(ray(target - d * 5.0, d));
    }
    out
}

#[test]
fn constant_extinction_in_every_kind_matches_the_exact_chord() {
    let tau = 1.3;
    let m = TestMaterial::constant(tau, [0.2, 0.7, 1.0]);
    for (name, mesh) in zoo() {
        let topology = topo(&mesh);
        let planes = cell_planes(&mesh, 0);
        let scene = Scene {
            mesh: &mesh,
            topology: &topology,
            scalars: Scalars::Constant(0.5),
        };
        for model in MODELS {
            let rc = Raycaster::new(scene, model).unwrap();
            let mut hit = 0;
            for r in rays_through(&mesh) {
                let chord = convex_chord(&r, &planes, 0.0);
                let acc = rc.trace(&m, &r, 0.0, &opts(model), &mut Default::default());
                let want = -(-tau * chord).exp_m1();
                assert!(
                    (acc.alpha() - want).abs() < 1e-13,
                    "{name} {model:?}: alpha {} vs {want} (chord {chord})",
                    acc.alpha()
                );
                assert!((acc.color[2] - want).abs() < 1e-13);
                hit += (chord > 0.0) as usize;
            }
            assert!(hit > 20, "{name}: only {hit} rays hit");
        }
    }
}

#[test]
fn linear_field_in_every_kind_is_integrated_exactly_by_all_models() {
    // s linear in position: every model's field is exactly this s (the
    // iso-parametric maps reproduce linear functions), so each ray's integral
    // is the material integral between the analytic entry and exit scalars.
    let m = TestMaterial {
        s: vec![0.0, 0.6, 2.0],
        tau: vec![0.5, 2.0, 0.2],
        color: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.2, 1.0]],
    };
    let sf = |p: DVec3| 0.3 + 0.5 * p.x + 0.2 * p.y - 0.1 * p.z;
    for (name, mesh) in zoo() {
        let topology = topo(&mesh);
        let planes = cell_planes(&mesh, 0);
        let s: Vec<f64> = mesh.points.iter().map(|&p| sf(p)).collect();
        let scene = Scene {
            mesh: &mesh,
            topology: &topology,
            scalars: Scalars::Point(&s),
        };
        for model in MODELS {
            let rc = Raycaster::new(scene, model).unwrap();
            let tol = if model == FieldModel::Native {
                1e-7
            } else {
                1e-12
            };
            for r in rays_through(&mesh) {
                let chord = convex_chord(&r, &planes, 0.0);
                if chord < 1e-9 {
                    continue;
                }
                // Entry depth: the largest entering plane parameter.
                let t_in = planes
                    .iter()
                    .filter(|(n, _)| n.dot(r.dir) < 0.0)
                    .map(|(n, off)| (off - n.dot(r.origin)) / n.dot(r.dir))
                    .fold(f64::NEG_INFINITY, f64::max);
                let p_in = r.origin + r.dir * t_in;
                let p_out = p_in + r.dir * chord;
                let want = zoovr::integrate::RayMaterial::segment(&m, chord, sf(p_in), sf(p_out));
                let acc = rc.trace(&m, &r, 0.0, &opts(model), &mut Default::default());
                assert!(
                    (acc.depth - want.depth).abs() < tol * (1.0 + want.depth),
                    "{name} {model:?}: depth {} vs {}",
                    acc.depth,
                    want.depth
                );
                for k in 0..3 {
                    assert!(
                        (acc.color[k] - want.color[k]).abs() < tol,
                        "{name} {model:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn native_trilinear_field_matches_independent_quadrature() {
    // Unit cube: the iso-parametric map is the identity, so s(t) is the
    // trilinear interpolant evaluated directly; compare with a fine
    // composite quadrature of the nested integral done here.
    let (name, mesh) = zoo().swap_remove(3);
    assert_eq!(name, "hex");
    let topology = topo(&mesh);
    let s = vec![0.0, 1.0, 0.2, 0.9, 0.7, 0.1, 1.0, 0.3];
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Point(&s),
    };
    let tri = |p: DVec3| {
        let (x, y, z) = (p.x, p.y, p.z);
        let c = |i: usize, a: f64, b: f64, cc: f64| s[i] * a * b * cc;
        c(0, 1. - x, 1. - y, 1. - z)
            + c(1, x, 1. - y, 1. - z)
            + c(2, x, y, 1. - z)
            + c(3, 1. - x, y, 1. - z)
            + c(4, 1. - x, 1. - y, z)
            + c(5, x, 1. - y, z)
            + c(6, x, y, z)
            + c(7, 1. - x, y, z)
    };
    // Breakpoints inside the range, and a jump-free kink at 0.5.
    let m = TestMaterial {
        s: vec![0.25, 0.5, 0.75],
        tau: vec![0.2, 3.0, 0.5],
        color: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.5], [0.3, 0.3, 1.0]],
    };
    let rc = Raycaster::new(scene, FieldModel::Native).unwrap();
    let faces = Raycaster::new(scene, FieldModel::Faces).unwrap();
    let planes = box_planes(DVec3::ZERO, DVec3::ONE);
    let mut model_gap = 0.0f64;
    for r in rays_through(&mesh).into_iter().step_by(3) {
        let chord = convex_chord(&r, &planes, 0.0);
        if chord < 1e-6 {
            continue;
        }
        let segs = rc.segments(&r, 0.0);
        assert_eq!(segs.len(), 1);
        let (a, b) = (segs[0].t_in, segs[0].t_out);
        assert!((b - a - chord).abs() < 1e-12);
        // Reference: 200k-step midpoint rule for depth and colour.
        let n = 200_000;
        let h = (b - a) / n as f64;
        let mut depth = 0.0;
        let mut color = [0.0; 3];
        for i in 0..n {
            let t = a + h * (i as f64 + 0.5);
            let mat = zoovr::integrate::RayMaterial::material(&m, tri(r.origin + r.dir * t));
            let e = (-(depth + 0.5 * h * mat.tau)).exp();
            for (c, g) in color.iter_mut().zip(mat.source) {
                *c += h * g * e;
            }
            depth += h * mat.tau;
        }
        let acc = trace_one(&rc, &m, &r, FieldModel::Native);
        assert!(
            (acc.depth - depth).abs() < 1e-7 * (1.0 + depth),
            "{} vs {depth}",
            acc.depth
        );
        for k in 0..3 {
            assert!(
                (acc.color[k] - color[k]).abs() < 1e-7,
                "{:?} vs {color:?}",
                acc.color
            );
        }
        let f = trace_one(&faces, &m, &r, FieldModel::Faces);
        model_gap = model_gap.max((f.depth - depth).abs());
    }
    // The test discriminates: the faces field differs from the trilinear one.
    assert!(model_gap > 1e-3, "faces vs native gap {model_gap}");
}
