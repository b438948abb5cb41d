//! The whole-piece quads' CPU side and twin against `f64` geometry: the
//! packing, which pieces go whole, and every pixel's segment against the
//! exact chord of its ray.

use super::*;
use crate::camera::CameraParams;
use crate::projection::ViewMap;
use glam::DVec2;

const SIZE: u32 = 40;

fn camera(ortho: bool, azimuth: f64, elevation: f64) -> Camera {
    let params = CameraParams {
        width: SIZE,
        height: SIZE,
        azimuth,
        elevation,
        zoom: 1.3,
        ortho,
        ..Default::default()
    };
    Camera::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], &params)
}

/// A hexahedron with corners `world` (VTK order), seen by `camera`.
fn hex(world: [DVec3; 8], camera: &Camera) -> Polyhedron {
    const QUADS: [[u32; 4]; 6] = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    let mut p = Polyhedron::default();
    for (k, w) in world.iter().enumerate() {
        p.points.push(camera.to_view(*w));
        p.world.push(*w);
        p.scalars.push(0.1 * k as f64 + w.x * w.y);
    }
    for [a, b, c, d] in QUADS {
        p.triangles.push([a, b, c]);
        p.triangles.push([a, c, d]);
    }
    p.orient_outward();
    p
}

/// A convex hexahedron: a box, sheared, its top face tilted.
fn skewed_box() -> [DVec3; 8] {
    let mut c = [DVec3::ZERO; 8];
    for (k, p) in c.iter_mut().enumerate() {
        let (x, y, z) = (
            [0, 1, 1, 0][k % 4] as f64,
            [0, 0, 1, 1][k % 4] as f64,
            (k / 4) as f64,
        );
        *p = DVec3::new(
            -0.7 + 1.3 * x + 0.2 * z,
            -0.6 + 1.1 * y,
            -0.5 + z * (0.9 + 0.2 * x),
        );
    }
    c
}

/// Every triangle of `part` the ray `o + t d` (view space) meets, as
/// (t, scalar), in `f64`.
fn hits(part: &Polyhedron, o: DVec3, d: DVec3) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for t in &part.triangles {
        let [a, b, c] = t.map(|i| part.points[i as usize]);
        let (e1, e2) = (b - a, c - a);
        let h = d.cross(e2);
        let det = e1.dot(h);
        if det.abs() < 1e-15 {
            continue;
        }
        let s = o - a;
        let u = s.dot(h) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            continue;
        }
        let [sa, sb, sc] = t.map(|i| part.scalars[i as usize]);
        out.push((e2.dot(q) / det, (1.0 - u - v) * sa + u * sb + v * sc));
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0));
    out
}

/// The twin's segment at pixel `(i, j)` of the quad carrying `v`.
fn twin_segment(v: &QuadVertex, camera: &Camera, i: u32, j: u32) -> Seg {
    let mapper = ClipMapper::for_camera(camera);
    let (ndc, _) = mapper.ndc(i as f64 + 0.5, j as f64 + 0.5).unwrap();
    let q = v.with_clip([ndc[0], ndc[1], 0.5, 1.0]);
    segment_at(
        &SegmentView::of(camera),
        &mapper,
        [&q, &q, &q],
        [1.0, 0.0, 0.0],
    )
}

const UNIT: ScalarMap = ScalarMap {
    offset: 0.0,
    scale: 1.0,
};

#[test]
fn every_pixel_takes_the_exact_chord() {
    for ortho in [true, false] {
        let cam = camera(ortho, 30.0, 20.0);
        let part = hex(skewed_box(), &cam);
        let v = QuadVertex::whole(&part, &UNIT, &cam, || 1.0).expect("drawn whole");
        assert_eq!(v.triangles(), 12);
        let map = ViewMap::of(&cam);
        let (mut inside, mut worst) = (0, 0.0f64);
        for j in 0..SIZE {
            for i in 0..SIZE {
                let u = map.plane(DVec2::new(i as f64 + 0.5, j as f64 + 0.5));
                let (o, d) = if ortho {
                    (DVec3::new(u.x, u.y, 0.0), DVec3::Z)
                } else {
                    (DVec3::ZERO, DVec3::new(u.x, u.y, 1.0))
                };
                let h = hits(&part, o, d);
                let seg = twin_segment(&v, &cam, i, j);
                let meets = h.len() >= 2 && h[h.len() - 1].0 - h[0].0 > 1e-9;
                assert_eq!(
                    seg.ok, meets,
                    "ortho {ortho} pixel ({i}, {j}): {seg:?} {h:?}"
                );
                if !meets {
                    continue;
                }
                inside += 1;
                let (f, b) = (h[0], h[h.len() - 1]);
                let l = (b.0 - f.0) * d.length();
                let err = [
                    (seg.s_f as f64 - f.1).abs(),
                    (seg.s_b as f64 - b.1).abs(),
                    (seg.l as f64 - l).abs(),
                ];
                worst = err.iter().fold(worst, |m, &e| m.max(e));
            }
        }
        assert!(inside > 200, "ortho {ortho}: {inside} pixels inside");
        // f32 geometry on coordinates of order 1 to 10.
        assert!(worst < 2e-5, "ortho {ortho}: worst {worst:.2e}");
    }
}

#[test]
fn the_tets_of_a_box_add_up_to_its_chord_at_every_pixel() {
    // The box's five-tet split: every pixel centre of the box is in the
    // tets' quads for their whole lengths, none twice, none left out.
    const TETS: [[usize; 4]; 5] = [
        [0, 1, 3, 4],
        [1, 2, 3, 6],
        [1, 4, 5, 6],
        [3, 4, 6, 7],
        [1, 3, 4, 6],
    ];
    for (ortho, az, el) in [(true, 30.0, 20.0), (false, -50.0, 35.0), (true, 90.0, 0.0)] {
        let cam = camera(ortho, az, el);
        let corners = skewed_box();
        let whole = hex(corners, &cam);
        let Some(hv) = QuadVertex::whole(&whole, &UNIT, &cam, || 1.0) else {
            // Seen along a face: the region path draws it.
            assert_eq!((az, el), (90.0, 0.0));
            continue;
        };
        let tets: Vec<QuadVertex> = TETS
            .iter()
            .filter_map(|t| {
                let w = t.map(|k| corners[k]);
                let s = t.map(|k| whole.scalars[k]);
                let mut p = Polyhedron::from_world_tet(w, s, &cam);
                p.orient_outward();
                QuadVertex::whole(&p, &UNIT, &cam, || 1.0)
            })
            .collect();
        assert_eq!(tets.len(), 5);
        for j in 0..SIZE {
            for i in 0..SIZE {
                let box_seg = twin_segment(&hv, &cam, i, j);
                let sum: f32 = tets
                    .iter()
                    .map(|t| twin_segment(t, &cam, i, j))
                    .filter(|s| s.ok)
                    .map(|s| s.l)
                    .sum();
                let want = if box_seg.ok { box_seg.l } else { 0.0 };
                assert!(
                    (sum - want).abs() <= 1e-5,
                    "ortho {ortho} pixel ({i}, {j}): tets {sum} box {want}"
                );
            }
        }
    }
}

#[test]
fn pieces_f32_cannot_settle_are_projected() {
    let cam = camera(true, 30.0, 20.0);
    let part = hex(skewed_box(), &cam);
    assert!(QuadVertex::whole(&part, &UNIT, &cam, || 1.0).is_some());
    // Optically thick beyond what f32 geometry settles.
    assert!(QuadVertex::whole(&part, &UNIT, &cam, || 1e9).is_none());
    // A face seen edge-on: an axis-aligned box along its axis.
    let axis = camera(true, 0.0, 0.0);
    let boxed: [DVec3; 8] = std::array::from_fn(|k| {
        DVec3::new(
            [0, 1, 1, 0][k % 4] as f64,
            [0, 0, 1, 1][k % 4] as f64,
            (k / 4) as f64,
        ) - 0.5
    });
    assert!(QuadVertex::whole(&hex(boxed, &axis), &UNIT, &axis, || 1.0).is_none());
    // Reaching the near plane.
    let mut near = camera(false, 30.0, 20.0);
    near.position = near.focal_point + (near.position - near.focal_point) * 0.01;
    near.near = 1e-3;
    assert!(QuadVertex::whole(&hex(skewed_box(), &near), &UNIT, &near, || 1.0).is_none());
    // Nine points.
    let mut nine = part.clone();
    nine.points.push(DVec3::ZERO);
    nine.scalars.push(0.0);
    assert!(QuadVertex::whole(&nine, &UNIT, &cam, || 1.0).is_none());
}

#[test]
fn packing_keeps_every_triangle_front_first() {
    let cam = camera(false, 30.0, 20.0);
    let part = hex(skewed_box(), &cam);
    let v = QuadVertex::whole(&part, &UNIT, &cam, || 1.0).unwrap();
    let (m, front, n) = (v.topo[0] >> 27, v.topo[1] >> 27, v.topo[2] >> 27);
    assert_eq!((m, n), (12, 8));
    assert!((4..=8).contains(&front), "{front} front triangles");
    // Points numbered by view position; every triangle's corners distinct,
    // and the 12 triangles the part's (as point sets).
    let order: Vec<[f32; 3]> = v.points.iter().map(|p| [p[0], p[1], p[2]]).collect();
    assert!(order.windows(2).all(|w| w[0] <= w[1]));
    let key = |t: [u32; 3]| {
        let mut k = t.map(|i| {
            let p = v.points[i as usize];
            [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()]
        });
        k.sort();
        k
    };
    let mut got: Vec<_> = (0..m).map(|k| key(corners(v.topo, k))).collect();
    let mut want: Vec<_> = part
        .triangles
        .iter()
        .map(|t| {
            let mut k = t.map(|i| {
                let p = part.points[i as usize];
                [
                    (p.x as f32).to_bits(),
                    (p.y as f32).to_bits(),
                    (p.z as f32).to_bits(),
                ]
            });
            k.sort();
            k
        })
        .collect();
    got.sort();
    want.sort();
    assert_eq!(got, want);
}

#[test]
fn a_region_vertex_carries_the_segment_payload() {
    let seg = SegmentVertex {
        pos: [0.1, 0.2, 0.5, 1.0],
        front: [0.3, 1.0],
        back: [0.7, 1.0],
        thick: 0.25,
        piece: 3,
    };
    let v = QuadVertex::region(seg);
    assert_eq!(v.triangles(), 0);
    let cam = camera(true, 30.0, 20.0);
    let mapper = ClipMapper::for_camera(&cam);
    let s = segment_at(
        &SegmentView::of(&cam),
        &mapper,
        [&v, &v, &v],
        [1.0, 0.0, 0.0],
    );
    assert_eq!((s.s_f, s.s_b, s.l, s.ok), (0.3, 0.7, 0.25, true));
    assert_eq!(v.transparent().thick, 0.0);
}

#[test]
fn layout_matches_struct() {
    assert_eq!(std::mem::size_of::<QuadVertex>(), 216);
    let offs: Vec<u64> = QuadVertex::ATTRIBUTES.iter().map(|a| a.offset).collect();
    assert_eq!(offs[0], 0);
    assert_eq!(offs[1], std::mem::offset_of!(QuadVertex, points) as u64);
    assert_eq!(offs[9], std::mem::offset_of!(QuadVertex, depth) as u64);
    assert_eq!(offs[11], std::mem::offset_of!(QuadVertex, topo) as u64);
    assert_eq!(offs[12], std::mem::offset_of!(QuadVertex, seg) as u64);
    assert_eq!(offs[13], std::mem::offset_of!(QuadVertex, thick) as u64);
    assert_eq!(offs[14], std::mem::offset_of!(QuadVertex, piece) as u64);
}
