//! Breakpoint slabs of a tetrahedron: volumes, scalar bands, exact cut
//! scalars and back-to-front order.

mod projection_util;

use glam::{DVec2, DVec3};
use projection_util::*;
use zoovr::camera::Camera;
use zoovr::projection::{slice_tet, Polyhedron, ViewMap};

fn tet_volume(p: &[DVec3; 4]) -> f64 {
    // View space is left-handed: same sign convention as Polyhedron::volume.
    -(p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])).abs() * -1.0 / 6.0
}

fn random_tet(rng: &mut Rng) -> ([DVec3; 4], [f64; 4]) {
    let p = std::array::from_fn(|_| {
        DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(2.0, 4.0),
        )
    });
    let s = std::array::from_fn(|_| rng.range(0.0, 10.0));
    (p, s)
}

fn entry_t(poly: &Polyhedron, view: &ViewMap, q: DVec2) -> Option<f64> {
    ray_hit(poly, view, q).filter(|h| h.0 > 1e-9).map(|h| h.1)
}

fn check(cam: &Camera, seed: u64) {
    let mut rng = Rng(seed);
    let mut compared = 0;
    let mut multi = 0;
    for _ in 0..200 {
        let (p, s) = random_tet(&mut rng);
        let mut bps: Vec<f64> = (0..rng.next_u64() % 4)
            .map(|_| rng.range(-1.0, 11.0))
            .collect();
        if rng.f64() < 0.3 {
            // A breakpoint exactly at a corner's scalar.
            bps.push(s[1]);
        }
        let slabs = slice_tet(p, s, &bps, cam);
        let (smin, smax) = (
            s.iter().copied().fold(f64::INFINITY, f64::min),
            s.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let inside: Vec<f64> = bps
            .iter()
            .copied()
            .filter(|&b| b > smin && b < smax)
            .collect();
        // Volumes.
        let vol: f64 = slabs.iter().map(|x| x.volume()).sum();
        let v0 = tet_volume(&p);
        assert!((vol - v0).abs() <= 1e-12 * v0, "{vol} vs {v0}");
        assert!(slabs.iter().all(|x| x.volume() > -1e-15));
        if inside.is_empty() {
            assert_eq!(slabs.len(), 1);
        } else {
            multi += 1;
        }
        for slab in &slabs {
            slab.validate().unwrap();
            let lo = slab.scalars.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = slab
                .scalars
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                !inside.iter().any(|&b| b > lo && b < hi),
                "breakpoint inside slab [{lo}, {hi}]"
            );
            // New points carry a breakpoint scalar exactly.
            for (q, sc) in slab.points.iter().zip(&slab.scalars) {
                if !p.contains(q) {
                    assert!(inside.contains(sc), "cut point scalar {sc}");
                }
            }
        }
        // Back to front: along a ray, a slab drawn later is entered earlier.
        let view = ViewMap::of(cam);
        for _ in 0..20 {
            let c = (p[0] + p[1] + p[2] + p[3]) / 4.0;
            let w = rng.range(0.0, 1.0);
            let k = (rng.next_u64() % 4) as usize;
            let target = c * (1.0 - w) + p[k] * w;
            let Some((px, py, _)) = cam.view_to_pixel(target) else {
                continue;
            };
            let q = DVec2::new(px, py);
            let ts: Vec<Option<f64>> = slabs.iter().map(|x| entry_t(x, &view, q)).collect();
            for i in 0..ts.len() {
                for j in i + 1..ts.len() {
                    if let (Some(a), Some(b)) = (ts[i], ts[j]) {
                        compared += 1;
                        assert!(
                            b <= a + 1e-9,
                            "slab {j} (t {b}) drawn after slab {i} (t {a}) but behind it"
                        );
                    }
                }
            }
        }
    }
    assert!(
        compared > 200 && multi > 50,
        "{compared} comparisons, {multi} sliced tets"
    );
}

#[test]
fn slabs_orthographic() {
    let mut rng = Rng(3);
    let cam = random_camera(&mut rng, [-1.0, 1.0, -1.0, 1.0, 2.0, 4.0], true);
    check(&cam, 11);
}

#[test]
fn slabs_perspective_eye_between_planes() {
    // The eye (view origin) is close: iso-planes pass on both sides of it.
    let mut rng = Rng(4);
    let cam = random_camera(&mut rng, [-1.0, 1.0, -1.0, 1.0, 2.0, 4.0], false);
    check(&cam, 12);
}

#[test]
fn no_breakpoint_inside_keeps_the_tet() {
    let p = [
        DVec3::new(0., 0., 2.),
        DVec3::new(1., 0., 2.),
        DVec3::new(0., 1., 2.),
        DVec3::new(0., 0., 3.),
    ];
    let s = [0.0, 1.0, 2.0, 3.0];
    let mut rng = Rng(1);
    let cam = random_camera(&mut rng, [0.0, 1.0, 0.0, 1.0, 2.0, 3.0], true);
    // Breakpoints at the range ends are not strictly inside.
    let slabs = slice_tet(p, s, &[0.0, 3.0, 7.0], &cam);
    assert_eq!(slabs.len(), 1);
    assert_eq!(slabs[0], Polyhedron::from_tet(p, s));
    assert_eq!(slice_tet(p, s, &[1.5], &cam).len(), 2);
    assert_eq!(slice_tet(p, s, &[1.0, 2.0], &cam).len(), 3);
}
