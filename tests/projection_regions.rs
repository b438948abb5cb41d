//! Regions of random convex cells under random views: the subdivision stays
//! valid after every insertion, regions tile the silhouette, and the values
//! interpolated on regions equal a direct ray-polyhedron intersection.

mod projection_util;

use glam::{DVec2, DVec3};
use projection_util::*;
use zoovr::camera::{Camera, CameraParams};
use zoovr::numeric::tolerance::PERSPECTIVE_INTERP_REL;
use zoovr::projection::{slice_tet, Polyhedron, Projected, Projector};

fn projector() -> Projector {
    let mut p = Projector::new();
    p.check_each_insertion = true;
    p
}

fn check_area(proj: &Projected, poly: &Polyhedron, cam: &Camera) {
    let hull = hull_area(&pixels(poly, cam));
    let ra = proj.region_area();
    let ta = proj.triangle_area();
    assert!(
        (ra - hull).abs() <= 1e-9 * hull.max(1e-9),
        "regions {ra} hull {hull}"
    );
    assert!(
        (ta - hull).abs() <= 1e-9 * hull.max(1e-9),
        "triangles {ta} hull {hull}"
    );
}

#[test]
fn random_cells_orthographic_exact() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    let mut pr = projector();
    let mut out = Projected::default();
    for kind in KINDS {
        let (mut regions, mut verts, mut n) = (0usize, 0usize, 0usize);
        for _ in 0..40 {
            let (pts, cells, sc) = random_cell(kind, &mut rng);
            let cam = random_camera(&mut rng, bounds(&pts), true);
            let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
            assert!(poly.volume() > 0.0);
            pr.project(&poly, &cam, &mut out).unwrap();
            pr.arrangement().sanity_check().unwrap();
            check_area(&out, &poly, &cam);
            let (el, es, _) = check_values(&out, &poly, &mut rng, 4);
            assert!(
                el < 1e-9 && es < 1e-9,
                "{kind:?}: l err {el:e}, s err {es:e}"
            );
            // Profile vertices: l = 0 and equal scalars.
            for v in &out.vertices {
                assert!(v.l >= 0.0);
                if v.profile {
                    assert_eq!(v.l, 0.0);
                    assert_eq!(v.s_front, v.s_back);
                }
            }
            regions += out.regions.len();
            verts += out.vertices.len();
            n += 1;
        }
        println!(
            "{kind:?}: {:.1} regions, {:.1} vertices on average",
            regions as f64 / n as f64,
            verts as f64 / n as f64
        );
    }
}

#[test]
fn random_cells_perspective_error_bounded() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut pr = projector();
    let mut out = Projected::default();
    let (mut worst_l, mut worst_s, mut raw_s) = (0.0f64, 0.0f64, 0.0f64);
    for kind in KINDS {
        for _ in 0..25 {
            let (pts, cells, sc) = random_cell(kind, &mut rng);
            // Wide angle and close: strong perspective.
            let p = CameraParams {
                width: 200,
                height: 150,
                azimuth: rng.range(-180.0, 180.0),
                elevation: rng.range(-80.0, 80.0),
                zoom: 0.5,
                view_angle: 60.0,
                ..Default::default()
            };
            let cam = Camera::fit(bounds(&pts), &p);
            let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
            pr.project(&poly, &cam, &mut out).unwrap();
            check_area(&out, &poly, &cam);
            let (el, es, ew) = check_values(&out, &poly, &mut rng, 3);
            worst_l = worst_l.max(el);
            worst_s = worst_s.max(ew);
            raw_s = raw_s.max(es);
        }
    }
    println!(
        "perspective: max l error {worst_l:e} (of diameter), s error x l/diameter {worst_s:e} \
         (of range; unweighted {raw_s:e}, largest next to silhouettes where l -> 0)"
    );
    assert!(worst_l < 2.0 * PERSPECTIVE_INTERP_REL, "l {worst_l}");
    assert!(worst_s < 2.0 * PERSPECTIVE_INTERP_REL, "s {worst_s}");
}

#[test]
fn perspective_without_refinement_is_worse() {
    // The refinement is what keeps the error bounded: without it the same
    // close-up views exceed the bound.
    let mut rng = Rng(77);
    let mut pr = projector();
    pr.perspective_refine = false;
    let mut out = Projected::default();
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let (pts, cells, sc) = random_cell(zoovr::mesh::CellKind::Hexahedron, &mut rng);
        let p = CameraParams {
            azimuth: rng.range(-180.0, 180.0),
            elevation: rng.range(-80.0, 80.0),
            zoom: 0.5,
            view_angle: 60.0,
            ..Default::default()
        };
        let cam = Camera::fit(bounds(&pts), &p);
        let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
        pr.project(&poly, &cam, &mut out).unwrap();
        let (el, es, _) = check_values(&out, &poly, &mut rng, 3);
        worst = worst.max(el).max(es);
    }
    assert!(
        worst > 4.0 * PERSPECTIVE_INTERP_REL,
        "unrefined error {worst}"
    );
}

#[test]
fn slabs_project_like_cells() {
    let mut rng = Rng(4242);
    let mut pr = projector();
    let mut out = Projected::default();
    for _ in 0..30 {
        let (pts, _, _) = random_cell(zoovr::mesh::CellKind::Tetra, &mut rng);
        let cam = random_camera(&mut rng, bounds(&pts), true);
        let v: [DVec3; 4] = std::array::from_fn(|i| cam.to_view(pts[i]));
        let s = [0.0, 1.0, 2.0, 3.0];
        for slab in slice_tet(v, s, &[0.5, 1.5, 2.25], &cam) {
            pr.project(&slab, &cam, &mut out).unwrap();
            check_area(&out, &slab, &cam);
            let (el, es, _) = check_values(&out, &slab, &mut rng, 3);
            assert!(el < 1e-9 && es < 1e-9, "slab: {el:e} {es:e}");
        }
    }
}

/// An orthographic camera for view-space pieces given directly.
fn ortho_camera() -> Camera {
    let p = CameraParams {
        width: 100,
        height: 100,
        ortho: true,
        ..Default::default()
    };
    Camera::fit([-2.0, 2.0, -2.0, 2.0, -2.0, 2.0], &p)
}

fn hex_from_view(c: [DVec3; 8]) -> Polyhedron {
    use zoovr::mesh::{CellKind, Cells};
    let mut cells = Cells::default();
    cells.push(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
    // Points are already in view space: mimic set_cell without to_view.
    let mut p = Polyhedron {
        points: c.to_vec(),
        scalars: (0..8).map(|i| i as f64 * 0.25).collect(),
        triangles: Vec::new(),
        gradients: Vec::new(),
        holes: Vec::new(),
        world: Vec::new(),
    };
    cells.for_each_face(0, |_, f| {
        zoovr::mesh::tetra::triangulate_face(f, |t| p.triangles.push(t));
    });
    p.orient_outward();
    p
}

fn degenerate_case(poly: &Polyhedron, expect_regions: Option<usize>) {
    let cam = ortho_camera();
    let mut pr = projector();
    let mut out = Projected::default();
    pr.project(poly, &cam, &mut out).unwrap();
    check_area(&out, poly, &cam);
    let mut rng = Rng(5);
    let (el, es, _) = check_values(&out, poly, &mut rng, 5);
    assert!(el < 1e-9 && es < 1e-9, "{el:e} {es:e}");
    if let Some(n) = expect_regions {
        assert_eq!(out.regions.len(), n);
    }
}

fn cube(f: impl Fn(DVec3) -> DVec3) -> [DVec3; 8] {
    let c = [
        (0., 0., 0.),
        (1., 0., 0.),
        (1., 1., 0.),
        (0., 1., 0.),
        (0., 0., 1.),
        (1., 0., 1.),
        (1., 1., 1.),
        (0., 1., 1.),
    ];
    c.map(|(x, y, z)| f(DVec3::new(x, y, z)))
}

#[test]
fn cube_face_on() {
    // Side faces exactly edge-on; front and back corners coincide. Two front
    // triangles and two back triangles whose diagonals may cross.
    let poly = hex_from_view(cube(|p| p + DVec3::new(-0.5, -0.5, 2.0)));
    degenerate_case(&poly, None);
}

#[test]
fn cube_edge_on() {
    // Rotated 45 degrees about y: two faces edge-on... exactly dyadic.
    let poly = hex_from_view(cube(|p| DVec3::new(p.x - p.z, p.y - 0.5, p.x + p.z + 2.0)));
    degenerate_case(&poly, None);
}

#[test]
fn parallelepiped_along_its_diagonal() {
    // e1 + e2 + e3 = (0, 0, 3): corners 0 and 6 project to one point.
    let (e1, e2, e3) = (
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(-0.5, 1.0, 1.0),
        DVec3::new(-0.5, -1.0, 1.0),
    );
    let poly = hex_from_view(cube(|p| {
        e1 * p.x + e2 * p.y + e3 * p.z + DVec3::new(0.0, 0.0, 2.0)
    }));
    degenerate_case(&poly, None);
    // The thick vertex is the merged corner pair, with l = |e1 + e2 + e3|.
    let cam = ortho_camera();
    let mut out = Projected::default();
    projector().project(&poly, &cam, &mut out).unwrap();
    let lmax = out.vertices.iter().map(|v| v.l).fold(0.0, f64::max);
    assert_eq!(lmax, 3.0);
}

#[test]
fn nearly_flat_hex() {
    let poly = hex_from_view(cube(|p| {
        DVec3::new(p.x * 0.7 + p.y * 0.2, p.y, 2.0 + 1e-13 * p.z + 0.3 * p.x)
    }));
    let cam = ortho_camera();
    let mut out = Projected::default();
    projector().project(&poly, &cam, &mut out).unwrap();
    check_area(&out, &poly, &cam);
    assert!(out.vertices.iter().all(|v| v.l >= 0.0 && v.l < 1e-12));
}

#[test]
fn totally_flat_hex_is_empty_or_zero() {
    // Seen exactly edge-on: every triangle has zero area.
    let poly = hex_from_view(cube(|p| DVec3::new(p.x, 0.0, 2.0 + p.y + 0.1 * p.z)));
    let cam = ortho_camera();
    let mut out = Projected::default();
    projector().project(&poly, &cam, &mut out).unwrap();
    assert_eq!(out.region_area(), 0.0);
}

#[test]
fn vertex_on_edge_and_vertex_on_vertex() {
    // Pyramid whose apex projects exactly onto a base edge, then onto a base
    // corner.
    use zoovr::mesh::{CellKind, Cells};
    for apex in [
        DVec3::new(0.5, 0.0, 3.0),
        DVec3::new(1.0, 1.0, 3.0),
        DVec3::new(0.5, 0.5, 3.0),
    ] {
        let base = [
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(1.0, 1.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
        ];
        let mut cells = Cells::default();
        cells.push(CellKind::Pyramid, &[0, 1, 2, 3, 4]);
        let mut p = Polyhedron {
            points: vec![base[0], base[1], base[2], base[3], apex],
            scalars: vec![0.0, 1.0, 2.0, 3.0, 4.0],
            triangles: Vec::new(),
            gradients: Vec::new(),
            holes: Vec::new(),
            world: Vec::new(),
        };
        cells.for_each_face(0, |_, f| {
            zoovr::mesh::tetra::triangulate_face(f, |t| p.triangles.push(t));
        });
        p.orient_outward();
        degenerate_case(&p, None);
    }
}

#[test]
fn near_plane_clipping() {
    // A hex around the eye: clipped, never fails, area equals the clipped
    // piece's hull.
    let mut rng = Rng(99);
    let mut pr = projector();
    let mut out = Projected::default();
    for _ in 0..20 {
        let (pts, cells, sc) = random_cell(zoovr::mesh::CellKind::Hexahedron, &mut rng);
        let cam0 = random_camera(&mut rng, bounds(&pts), false);
        // Put the eye inside the cell (its centroid), looking the same way.
        let c = pts.iter().copied().sum::<DVec3>() / 8.0;
        let mut cam = cam0;
        cam.position = c;
        let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
        pr.project(&poly, &cam, &mut out).unwrap();
        // The eye is inside: the whole (infinite) screen is covered; the
        // regions are finite but large and their values finite.
        assert!(out.region_area() > 0.0);
        assert!(out.vertices.iter().all(|v| v.l.is_finite() && v.l >= 0.0));
    }
}

#[test]
fn bad_input_is_an_error() {
    let cam = ortho_camera();
    let mut out = Projected::default();
    let mut pr = Projector::new();
    let mut p = Polyhedron::from_tet(
        [
            DVec3::new(0., 0., 2.),
            DVec3::X + DVec3::Z * 2.0,
            DVec3::Y + DVec3::Z * 2.0,
            DVec3::Z * 3.0,
        ],
        [0.0; 4],
    );
    p.triangles.push([0, 1, 9]);
    assert!(pr.project(&p, &cam, &mut out).is_err());
    p.triangles.pop();
    p.points[0].x = f64::NAN;
    assert!(pr.project(&p, &cam, &mut out).is_err());
    p.points[0].x = 0.0;
    p.scalars.pop();
    assert!(pr.project(&p, &cam, &mut out).is_err());
    let _ = DVec2::ZERO;
}

#[test]
fn fuzz_pentagonal_prism_edge_on_perspective() {
    // Fuzz input (21 bytes)
    // 2e 1d 15 00 00 00 3d 1c ff ff 00 00 00 63 ff 0b 1d 2a 1d 1d 1d
    // (fuzz target `projection`, f(i) = data[i] as i8 / 16): a
    // pentagonal prism whose pentagon faces contain the view direction, seen
    // in perspective, so many projected vertices are nearly collinear. Used
    // to fail with "euler formula violated: V=23 E=48 cycles=23".
    use glam::DMat3;
    use zoovr::mesh::{CellKind, Cells};
    let m = DMat3::from_cols_array(&[
        1.8125, 1.3125, 0.0, 0.0, 0.0, 3.8125, 1.75, -0.0625, -0.0625,
    ]);
    let pts: Vec<DVec3> = (0..10)
        .map(|i| {
            let a = std::f64::consts::TAU * (i % 5) as f64 / 5.0;
            m * DVec3::new(a.cos(), a.sin(), (i / 5) as f64)
        })
        .collect();
    let mut cells = Cells::default();
    cells.push(CellKind::PentagonalPrism, &(0..10).collect::<Vec<u32>>());
    let params = CameraParams {
        width: 64,
        height: 48,
        azimuth: 0.0,
        elevation: 0.0,
        roll: 0.0,
        ortho: false,
        ..Default::default()
    };
    let cam = Camera::fit([-8.0, 8.0, -8.0, 8.0, -8.0, 8.0], &params);
    let f = |b: u8| (b as i8) as f64 / 16.0;
    let data = [0xffu8, 0x0b, 0x1d, 0x2a, 0x1d, 0x1d];
    let s: Vec<f64> = (0..10).map(|i| f(data[i % 6])).collect();
    let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam).unwrap();
    let mut pr = projector();
    let mut out = Projected::default();
    pr.project(&poly, &cam, &mut out).unwrap();
    pr.arrangement().sanity_check().unwrap();
    check_area(&out, &poly, &cam);
    assert!(out.vertices.iter().all(|v| v.l.is_finite() && v.l >= 0.0));
}

/// Region vertices carry exact values (evaluated, never interpolated), in
/// orthographic and perspective views, through the fast path (which values
/// crossings along their front and back edges) and the general path alike:
/// each equals a direct ray-polyhedron intersection through its position.
#[test]
fn vertex_values_equal_ray_hits() {
    let mut rng = Rng(0x7e57_ed9e_0000_0001);
    let mut out = Projected::default();
    let mut checked = 0;
    for general in [false, true] {
        let mut pr = Projector::new();
        pr.fast_path = !general;
        pr.perspective_refine = false;
        for ortho in [true, false] {
            for kind in KINDS {
                for _ in 0..30 {
                    let (pts, cells, sc) = random_cell(kind, &mut rng);
                    let cam = random_camera(&mut rng, bounds(&pts), ortho);
                    let poly =
                        Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
                    pr.project(&poly, &cam, &mut out).unwrap();
                    let diameter = poly
                        .points
                        .iter()
                        .flat_map(|p| poly.points.iter().map(move |q| (*p - *q).length()))
                        .fold(0.0, f64::max);
                    let zscale = poly.points.iter().map(|p| p.z.abs()).fold(0.0, f64::max);
                    for v in &out.vertices {
                        // Rays grazing the silhouette may miss by rounding.
                        if v.l < 1e-3 * diameter {
                            continue;
                        }
                        let (l, zin, zout, sin, sout) = ray_hit(&poly, &out.view, v.pos())
                            .unwrap_or_else(|| panic!("{kind:?}: vertex {v:?} misses"));
                        let tol = 1e-9 * (diameter + zscale);
                        assert!((v.l - l).abs() <= tol, "{kind:?} {ortho}: l {} {l}", v.l);
                        assert!((v.z_front - zin).abs() <= tol, "{kind:?} {ortho}: zf");
                        assert!((v.z_back - zout).abs() <= tol, "{kind:?} {ortho}: zb");
                        // (Scalars are in [0, 1].)
                        assert!((v.s_front - sin).abs() <= 1e-9, "{kind:?} {ortho}: sf");
                        assert!((v.s_back - sout).abs() <= 1e-9, "{kind:?} {ortho}: sb");
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 2000, "{checked} vertices checked");
}

/// `Projected::leave_out_regions_on` keeps exactly the triangles of the
/// regions whose front and back triangles are not flagged (the regions of
/// a whole cell with a NaN corner: its holes' triangles flagged).
#[test]
fn regions_on_flagged_faces_are_left_out() {
    let cam = ortho_camera();
    let mut rng = Rng(11);
    for _ in 0..20 {
        let (jx, jy) = (0.1 * (rng.f64() - 0.5), 0.1 * (rng.f64() - 0.5));
        let c = cube(|p| {
            let q = p + DVec3::new(-0.5, -0.5, 2.0);
            DVec3::new(
                q.x + 0.3 * q.z + jx * q.y,
                q.y + 0.2 * q.z + jy * q.x,
                q.z + 0.4 * q.x,
            )
        });
        let poly = hex_from_view(c);
        let mut out = Projected::default();
        projector().project(&poly, &cam, &mut out).unwrap();
        let with_regions = |p: &Projected| -> Vec<([u32; 3], u32)> {
            p.triangles
                .iter()
                .copied()
                .zip(p.triangle_region.iter().copied())
                .collect()
        };
        let before = with_regions(&out);
        // The boundary triangles holding point 3 (as a NaN at point 3).
        let flags: Vec<bool> = poly.triangles.iter().map(|t| t.contains(&3)).collect();
        out.leave_out_regions_on(&flags);
        let clear = |r: u32| {
            let [f, b] = out.region_faces[r as usize];
            !flags[f as usize] && !flags[b as usize]
        };
        let expected: Vec<([u32; 3], u32)> =
            before.iter().copied().filter(|&(_, r)| clear(r)).collect();
        let kept = with_regions(&out);
        assert_eq!(kept, expected);
        assert!(
            kept.len() < before.len(),
            "point 3 is on the outline or inside"
        );
        assert!(!out.outline_profile);
    }
}
