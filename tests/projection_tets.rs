//! Tetrahedra reproduce the four Shirley-Tuchman classes, with the thick
//! vertex carrying the exact thickness and scalars.

mod projection_util;

use glam::{DVec2, DVec3};
use projection_util::*;
use zoovr::camera::{Camera, CameraParams};
use zoovr::projection::{Polyhedron, Projected, Projector, RegionVertex};

fn ortho() -> Camera {
    let p = CameraParams {
        width: 64,
        height: 64,
        ortho: true,
        ..Default::default()
    };
    let mut c = Camera::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], &p);
    c.parallel_scale = 1.0;
    c
}

fn project(t: [DVec3; 4], s: [f64; 4]) -> (Projected, Polyhedron) {
    let poly = Polyhedron::from_tet(t, s);
    let mut pr = Projector::new();
    pr.check_each_insertion = true;
    let mut out = Projected::default();
    pr.project(&poly, &ortho(), &mut out).unwrap();
    pr.arrangement().sanity_check().unwrap();
    (out, poly)
}

fn thick(out: &Projected) -> RegionVertex {
    *out.vertices
        .iter()
        .max_by(|a, b| a.l.total_cmp(&b.l))
        .unwrap()
}

fn pix(cam: &Camera, x: f64, y: f64) -> DVec2 {
    let (px, py, _) = cam.view_to_pixel(DVec3::new(x, y, 1.0)).unwrap();
    DVec2::new(px, py)
}

const S: [f64; 4] = [1.0, 2.0, 3.0, 5.0];

#[test]
fn class_1_three_triangles() {
    let (out, _) = project(
        [
            DVec3::new(0., 0., 2.),
            DVec3::new(1., 0., 2.),
            DVec3::new(0., 1., 2.),
            DVec3::new(0.25, 0.25, 3.),
        ],
        S,
    );
    assert_eq!(out.regions.len(), 3);
    assert_eq!(out.triangles.len(), 3);
    assert_eq!(out.vertices.len(), 4);
    let t = thick(&out);
    assert_eq!(t.pos(), pix(&ortho(), 0.25, 0.25));
    assert_eq!(t.l, 1.0);
    // Front: plane of the base at (0.25, 0.25): 1 + 0.25 + 0.5 = 1.75.
    assert!((t.s_front - 1.75).abs() < 1e-15 && t.s_back == 5.0);
    assert_eq!(out.vertices.iter().filter(|v| v.profile).count(), 3);
}

#[test]
fn class_2_four_triangles() {
    let (out, _) = project(
        [
            DVec3::new(0., 0., 2.),
            DVec3::new(1., 1., 2.),
            DVec3::new(1., 0., 3.),
            DVec3::new(0., 1., 3.),
        ],
        S,
    );
    assert_eq!(out.regions.len(), 4);
    assert_eq!(out.triangles.len(), 4);
    assert_eq!(out.vertices.len(), 5);
    let t = thick(&out);
    assert_eq!(t.pos(), pix(&ortho(), 0.5, 0.5));
    assert!((t.l - 1.0).abs() < 1e-14);
    assert!((t.s_front - 1.5).abs() < 1e-14 && (t.s_back - 4.0).abs() < 1e-14);
    assert!(!t.profile);
}

#[test]
fn class_3_two_triangles() {
    let (out, _) = project(
        [
            DVec3::new(0., 0., 2.),
            DVec3::new(1., 0., 2.),
            DVec3::new(0., 1., 2.),
            DVec3::new(0.5, 0., 3.),
        ],
        S,
    );
    assert_eq!(out.regions.len(), 2);
    assert_eq!(out.triangles.len(), 2);
    let t = thick(&out);
    assert_eq!(t.pos(), pix(&ortho(), 0.5, 0.0));
    assert_eq!(t.l, 1.0);
    assert!((t.s_front - 1.5).abs() < 1e-15 && t.s_back == 5.0);
}

#[test]
fn class_4_one_triangle() {
    let (out, _) = project(
        [
            DVec3::new(0., 0., 2.),
            DVec3::new(1., 0., 2.),
            DVec3::new(0., 1., 2.),
            DVec3::new(0., 0., 3.),
        ],
        S,
    );
    assert_eq!(out.regions.len(), 1);
    assert_eq!(out.triangles.len(), 1);
    let t = thick(&out);
    assert_eq!(t.pos(), pix(&ortho(), 0.0, 0.0));
    assert_eq!((t.l, t.s_front, t.s_back), (1.0, 1.0, 5.0));
}

#[test]
fn random_tets_are_class_1_or_2() {
    let mut rng = Rng(31337);
    let cam = ortho();
    let (mut c1, mut c2) = (0, 0);
    for _ in 0..300 {
        let t: [DVec3; 4] = std::array::from_fn(|_| {
            DVec3::new(
                rng.range(-0.8, 0.8),
                rng.range(-0.8, 0.8),
                rng.range(2.0, 3.0),
            )
        });
        let s: [f64; 4] = std::array::from_fn(|_| rng.range(0.0, 1.0));
        let (out, poly) = project(t, s);
        match out.regions.len() {
            3 => c1 += 1,
            4 => c2 += 1,
            n => panic!("{n} regions"),
        }
        assert_eq!(out.triangles.len(), out.regions.len());
        // The thick vertex is exact against a direct ray.
        let th = thick(&out);
        let (l, _, _, sf, sb) = ray_hit(&poly, &out.view, th.pos()).unwrap();
        assert!((th.l - l).abs() < 1e-12, "{} vs {l}", th.l);
        assert!((th.s_front - sf).abs() < 1e-9 && (th.s_back - sb).abs() < 1e-9);
        // All other vertices are profile vertices.
        assert_eq!(
            out.vertices.iter().filter(|v| v.profile).count(),
            out.vertices.len() - 1
        );
        let _ = &cam;
    }
    assert!(c1 > 30 && c2 > 30, "{c1} {c2}");
}
