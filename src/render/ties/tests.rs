//! Unit tests of the tie decisions.

use super::*;
use crate::camera::CameraParams;
use crate::projection::ViewMap;

/// A 16 x 16 camera, its rays, and the world-space point at pixel
/// position `(px, py)` and depth `z`.
fn setup(ortho: bool) -> (TieRays, Camera, impl Fn(f64, f64, f64) -> DVec3) {
    let camera = Camera::fit(
        [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0],
        &CameraParams {
            width: 16,
            height: 16,
            ortho,
            ..Default::default()
        },
    );
    let view = ViewMap::of(&camera);
    let rays = TieRays::new(&camera, [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0]);
    let c = camera;
    let at = move |px: f64, py: f64, z: f64| {
        let u = view.plane(DVec2::new(px, py));
        let v = if view.ortho {
            DVec3::new(u.x, u.y, z)
        } else {
            DVec3::new(u.x * z, u.y * z, z)
        };
        c.position + c.right * v.x + c.up * v.y + c.forward * v.z
    };
    (rays, camera, at)
}

fn tet(camera: &Camera, p: [DVec3; 4]) -> Polyhedron {
    Polyhedron::from_world_tet(p, [0.0, 1.0, 2.0, 3.0], camera)
}

fn length(r: RayThrough) -> f64 {
    match r {
        RayThrough::Crosses(v, _) => v.l,
        RayThrough::Misses => 0.0,
        RayThrough::Undecided => f64::NAN,
    }
}

/// A ray through the inside of a tet crosses it with the segment's
/// length and scalars; one beside it misses.
#[test]
fn inside_and_outside() {
    let (rays, camera, at) = setup(true);
    let z0 = 4.0;
    // A tet whose face at depth z0 covers pixels (2..10, 2..10) and
    // whose apex is behind (4, 4).
    let p = tet(
        &camera,
        [
            at(2.0, 2.0, z0),
            at(10.0, 2.0, z0),
            at(2.0, 10.0, z0),
            at(4.0, 4.0, z0 + 1.0),
        ],
    );
    let mut scratch = Vec::new();
    let r = ray_through(&p, &rays, DVec2::new(4.0, 4.0), &mut scratch);
    assert!((length(r) - 1.0).abs() < 1e-12, "{r:?}");
    let RayThrough::Crosses(v, _) = r else {
        unreachable!()
    };
    assert!((v.s_back - 3.0).abs() < 1e-9, "{v:?}");
    let r = ray_through(&p, &rays, DVec2::new(12.5, 12.5), &mut scratch);
    assert_eq!(r, RayThrough::Misses);
}

/// Pixel centres exactly on the edges and vertices of a fan of tets
/// seen edge-on (every tet has a face containing the view direction,
/// as when looking down an axis of a hex split into tets): each centre
/// is crossed by exactly one tet of each layer, so the lengths add up
/// to the layer thickness. Orthographic and perspective.
#[test]
fn a_centre_on_shared_edges_is_given_to_one_part() {
    for ortho in [true, false] {
        let (rays, camera, at) = setup(ortho);
        let z0 = 5.0;
        // Four triangular prisms around the centre (8.5, 8.5), each cut
        // into 3 tets with the consistent smallest-vertex rule; the
        // prisms' corners sit on pixel centres, so their side faces are
        // seen exactly edge-on and centres lie on edges and vertices.
        let c = (8.5, 8.5);
        let ring = [(4.5, 4.5), (12.5, 4.5), (12.5, 12.5), (4.5, 12.5)];
        let mut parts = Vec::new();
        for k in 0..4 {
            let (a, b) = (ring[k], ring[(k + 1) % 4]);
            let bottom = [c, a, b].map(|q| at(q.0, q.1, z0));
            let top = [c, a, b].map(|q| at(q.0, q.1, z0 + 1.0));
            parts.push(tet(&camera, [bottom[0], bottom[1], bottom[2], top[0]]));
            parts.push(tet(&camera, [bottom[1], bottom[2], top[0], top[1]]));
            parts.push(tet(&camera, [bottom[2], top[0], top[1], top[2]]));
        }
        let mut scratch = Vec::new();
        for j in 0..16 {
            for i in 0..16 {
                let q = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                let inside = (4.5..12.5).contains(&q.x) && (4.5..12.5).contains(&q.y);
                let mut sum = 0.0;
                for p in &parts {
                    let r = ray_through(p, &rays, q, &mut scratch);
                    assert_ne!(r, RayThrough::Undecided, "{i} {j}");
                    sum += length(r);
                }
                // The ray's length per unit of depth (1 orthographic).
                let want = if inside {
                    if ortho {
                        1.0
                    } else {
                        (at(q.x, q.y, 1.0) - camera.position).length()
                    }
                } else {
                    0.0
                };
                // In perspective the corners are rounded off the eye
                // rays, so the outer walls are not exactly edge-on: a
                // ray through a centre on the outer outline may miss,
                // graze a thin wedge of the wall or cross it all.
                // Inside, on the shared edges and faces, the layers
                // still add up exactly.
                let outline = [4.5, 12.5].contains(&q.x) || [4.5, 12.5].contains(&q.y);
                let d = (at(q.x, q.y, 1.0) - camera.position).length();
                let ok = (sum - want).abs() < 1e-9
                    || (!ortho && outline && (0.0..=d + 1e-9).contains(&sum));
                assert!(ok, "{ortho} {i} {j} {sum} {want}");
            }
        }
    }
}

#[test]
fn band_holds_every_near_centre() {
    let mut out = Vec::new();
    let a = DVec2::new(0.5 - 0.002, 1.5 + 0.001);
    let b = DVec2::new(7.9, 3.3);
    near_centres(a, b, 10, 10, &mut out);
    assert!(out.contains(&(0, 1)));
    for j in 0..10u32 {
        for i in 0..10u32 {
            let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
            let t = ((c - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            if (a + (b - a) * t - c).length() <= TIE_BAND_PX {
                assert!(out.contains(&(i, j)), "{i} {j}");
            }
        }
    }
}

/// The float test is certain only away from the edges: inside a square
/// of two triangles, outside it, and undecided on its outline and on the
/// diagonal the two triangles share (each sees the centre on its edge).
#[test]
fn float_test_is_certain_only_away_from_edges() {
    let p = [
        DVec2::new(0.0, 0.0),
        DVec2::new(4.0, 0.0),
        DVec2::new(4.0, 4.0),
        DVec2::new(0.0, 4.0),
    ];
    let pos = |i: u32| p[i as usize];
    let tris = [[0, 1, 2], [0, 2, 3]];
    let m = 1e-6;
    assert_eq!(
        inside_by_float(&tris, &pos, DVec2::new(3.0, 1.0), m),
        Some(true)
    );
    assert_eq!(
        inside_by_float(&tris, &pos, DVec2::new(1.0, 3.0), m),
        Some(true)
    );
    assert_eq!(
        inside_by_float(&tris, &pos, DVec2::new(5.0, 1.0), m),
        Some(false)
    );
    assert_eq!(
        inside_by_float(&tris, &pos, DVec2::new(-1e-3, 2.0), m),
        Some(false)
    );
    // On the outline, and within the margin of it on either side.
    for x in [0.0, 5e-7, -5e-7] {
        assert_eq!(
            inside_by_float(&tris, &pos, DVec2::new(x, 2.0), m),
            None,
            "{x}"
        );
    }
    // On the shared diagonal: inside the square, but certain in neither.
    assert_eq!(inside_by_float(&tris, &pos, DVec2::new(2.0, 2.0), m), None);
    // A NaN position is never certain.
    let q = [p[0], p[1], DVec2::new(f64::NAN, 4.0)];
    let posq = |i: u32| q[i as usize];
    assert_eq!(
        inside_by_float(&[[0, 1, 2]], &posq, DVec2::new(3.0, 1.0), m),
        None
    );
}

/// The margin grows with the magnitude of the coordinates (a mesh far
/// from the origin rounds its projection more) and is refused where no
/// margin can be trusted.
#[test]
fn filter_margin_follows_the_rounding() {
    let (near, _, _) = setup(false);
    let m = near.filter_px(3.0, 16.0).expect("a margin");
    assert_eq!(m, RASTER_FILTER_PX);
    assert_eq!(near.filter_px(0.0, 16.0), None);
    assert_eq!(near.filter_px(f64::NAN, 16.0), None);
    assert_eq!(near.filter_px(3.0, 1e8), None);
    // The same view of a cube 1e9 from the origin.
    let lo = 1e9;
    let bounds = [lo - 1.0, lo + 1.0, lo - 1.0, lo + 1.0, lo - 1.0, lo + 1.0];
    let camera = Camera::fit(
        bounds,
        &CameraParams {
            width: 16,
            height: 16,
            ..Default::default()
        },
    );
    let far = TieRays::new(&camera, bounds);
    let m = far.filter_px(3.0, 16.0).expect("a margin");
    assert!(m > 1e-6 && m < TIE_BAND_PX, "{m}");
    // 1e11: rounding reaches the band; nothing is settled by floats.
    let lo = 1e11;
    let bounds = [lo - 1.0, lo + 1.0, lo - 1.0, lo + 1.0, lo - 1.0, lo + 1.0];
    let camera = Camera::fit(bounds, &CameraParams::default());
    assert_eq!(TieRays::new(&camera, bounds).filter_px(3.0, 16.0), None);
}

/// The edge walk over the culling's spans returns every centre within
/// the band of the segment, for segments of every length and direction,
/// of no length, and ending on or next to pixel centres.
#[test]
fn edge_walk_holds_every_near_centre() {
    use crate::projection::coverage::PixelGrid;
    use crate::testdata::Rng;
    let grid = PixelGrid::new(12, 9);
    let mut rng = Rng(7);
    for case in 0..20000 {
        // End points near the lattice (within a few bands of a centre)
        // half of the time.
        let point = |rng: &mut Rng| {
            let p = DVec2::new(rng.range(-1.0, 13.0), rng.range(-1.0, 10.0));
            if rng.below(2) == 0 {
                let c = (p - 0.5).round() + 0.5;
                c + DVec2::new(rng.range(-0.01, 0.01), rng.range(-0.01, 0.01))
            } else {
                p
            }
        };
        let a = point(&mut rng);
        let b = match rng.below(4) {
            0 => a,
            1 => a + DVec2::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3)),
            _ => point(&mut rng),
        };
        let span = grid.span(a).join(&grid.span(b));
        let mut out = Vec::new();
        near_edge(a, b, Some(span), 12, 9, &mut out);
        for j in 0..9u32 {
            for i in 0..12u32 {
                let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                let d = b - a;
                let t = if d.length_squared() > 0.0 {
                    ((c - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                if (a + d * t - c).length() <= TIE_BAND_PX {
                    assert!(out.contains(&(i, j)), "case {case}: {a} {b} misses {i} {j}");
                }
            }
        }
    }
}

/// The one pass over a part's triangles ([`scan_triangles`]) marks as
/// steep exactly the triangles [`snap_is_steep`] calls steep at both the
/// bound and the part's rate, and collects every centre within the band
/// of a sliver whose snap matters (brute force over the image), only
/// where asked: random triangles from slivers to wide ones, thickness
/// steep or flat, on a 12 x 10 image.
#[test]
fn one_pass_finds_the_steep_triangles_and_the_sliver_centres() {
    use crate::testdata::Rng;
    let mut rng = Rng(11);
    let (width, height) = (12u32, 10u32);
    let (mut steep_seen, mut sliver_seen) = (0, 0);
    for _ in 0..3000 {
        let mut proj = Projected::default();
        let n = 3 + rng.below(4);
        let o = DVec2::new(rng.range(0.0, 12.0), rng.range(0.0, 10.0));
        for _ in 0..n {
            // Sub-pixel to a few pixels; some vertices nearly collinear.
            let d = DVec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)) * rng.f64();
            proj.vertices.push(RegionVertex {
                px: o.x + d.x,
                py: o.y + d.y * [1.0, 1e-3][rng.below(2)],
                l: rng.range(0.0, 0.3) * [1.0, 1e-4][rng.below(2)],
                ..Default::default()
            });
        }
        for k in 1..n - 1 {
            proj.triangles.push([0, k as u32, k as u32 + 1]);
        }
        let l_range = (
            proj.vertices
                .iter()
                .map(|v| v.l)
                .fold(f64::INFINITY, f64::min),
            proj.vertices
                .iter()
                .map(|v| v.l)
                .fold(f64::NEG_INFINITY, f64::max),
        );
        let rate_bound = [1.0, 50.0, 1e3][rng.below(3)];
        let part_rate = rate_bound * [1.0, 0.3, 0.01][rng.below(3)];
        let rate = || part_rate;
        let part = PartTriangles {
            proj: &proj,
            drawn: &[],
            exact: &proj.triangles,
            width,
            height,
            rate: &rate,
            rate_bound,
            l_range,
            snap: &[],
            weighed: false,
            clipped: false,
            isovalues: &[],
            iso_origin: 0.0,
        };
        let slivers = rng.below(2) == 0;
        let mut scratch = TieScratch::default();
        scan_triangles(&part, slivers, &mut scratch);
        let pos = |i: u32| proj.vertices[i as usize].pos();
        let may_be_steep =
            rate_bound * (l_range.1 - l_range.0) * SNAP_PX > SLIVER_DEPTH_TOL * SLIVER_TIE_PX;
        let mut expected = Vec::new();
        for (k, t) in proj.triangles.iter().enumerate() {
            let p = t.map(pos);
            let l = t.map(|i| proj.vertices[i as usize].l);
            let steep =
                may_be_steep && snap_is_steep(p, l, rate_bound) && snap_is_steep(p, l, part_rate);
            assert_eq!(
                scratch.steep[k], steep,
                "{p:?} {l:?} {rate_bound} {part_rate}"
            );
            steep_seen += steep as usize;
            // A sliver: narrower than the widest width the part's
            // thickness range allows, with a snap that matters.
            let area2 = (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
            let long = [0, 1, 2]
                .map(|k| (p[(k + 1) % 3] - p[k]).length())
                .into_iter()
                .fold(0.0, f64::max);
            let widest = (rate_bound * (l_range.1 - l_range.0) * SNAP_PX / SLIVER_DEPTH_TOL)
                .min(SLIVER_TIE_PX);
            let w = area2 / long;
            let dl = l.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - l.iter().copied().fold(f64::INFINITY, f64::min);
            let matters = |r: f64| r * dl * SNAP_PX > SLIVER_DEPTH_TOL * w;
            if slivers && long > 0.0 && w < widest && matters(rate_bound) && matters(part_rate) {
                for j in 0..height {
                    for i in 0..width {
                        let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                        if band::in_grown_triangle(p, c) {
                            expected.push((i, j));
                        }
                    }
                }
            }
        }
        expected.sort_unstable();
        expected.dedup();
        let mut got = scratch.forced.clone();
        got.sort_unstable();
        got.dedup();
        assert_eq!(got, expected);
        sliver_seen += got.len();
    }
    // Both kinds are exercised.
    assert!(
        steep_seen > 100 && sliver_seen > 100,
        "{steep_seen} {sliver_seen}"
    );
}

/// The centres [`scan_triangles`] leaves for the tie decisions in the
/// optically thin part `proj` (a `width` x `height` image) with
/// `isovalues`.
fn sliver_centres(proj: &Projected, width: u32, height: u32, isovalues: &[f64]) -> Vec<(u32, u32)> {
    let rate = || 0.0;
    let part = PartTriangles {
        proj,
        drawn: &[],
        exact: &proj.triangles,
        width,
        height,
        rate: &rate,
        rate_bound: 0.0,
        l_range: (1e-6, 1e-6),
        snap: &[],
        weighed: false,
        clipped: false,
        isovalues,
        iso_origin: 0.0,
    };
    let mut scratch = TieScratch::default();
    scan_triangles(&part, true, &mut scratch);
    scratch.forced
}

/// A sliver (a region seen nearly edge-on) whose entry scalar runs from
/// 0.2 to 0.4 across its 0.02 px: the snap of its corners shifts the
/// interpolated scalar by far more than the distance of a centre inside
/// it from the isovalue 0.3, so with that isovalue the centre is decided
/// exactly; without it (an optically thin part) it is not, nor with an
/// isovalue the sliver does not come near.
#[test]
fn a_sliver_holding_an_isovalue_has_its_centres_decided() {
    let mut proj = Projected::default();
    // Centre (2.5, 1.5) lies in the sliver, where the scalar interpolates
    // to 0.3; (1.5, 1.5) and (3.5, 1.5) lie on its upper edges, where it
    // is 0.3 too.
    let v = |x: f64, y: f64, s: f64| RegionVertex {
        px: x,
        py: y,
        l: 1e-6,
        s_front: s,
        s_back: s,
        ..Default::default()
    };
    proj.vertices.push(v(0.5, 1.49, 0.2));
    proj.vertices.push(v(4.5, 1.49, 0.2));
    proj.vertices.push(v(2.5, 1.51, 0.4));
    proj.triangles.push([0, 1, 2]);
    let scan = |isovalues: &[f64]| sliver_centres(&proj, 6, 4, isovalues);
    assert_eq!(scan(&[0.3]), vec![(1, 1), (2, 1), (3, 1)]);
    assert!(scan(&[]).is_empty());
    assert!(scan(&[0.9]).is_empty());
}

/// A long sliver in perspective, its ends at depths 1 and 100: the GPU
/// interpolates the scalar at a centre perspective-correctly, so the
/// centres whose scalars come near an isovalue lie far from where an
/// affine interpolation along the sliver puts them. With the snap's
/// largest shift (0.14 of the scalar here, across a sliver 0.02 px wide)
/// the centres within it of the value are decided exactly, and only they.
#[test]
fn a_sliver_in_perspective_weighs_its_centres_perspective_correctly() {
    let mut proj = Projected::default();
    proj.view.ortho = false;
    let v = |x: f64, y: f64, s: f64, z: f64| RegionVertex {
        px: x,
        py: y,
        z_front: z,
        z_back: z,
        l: 1e-6,
        s_front: s,
        s_back: s,
        ..Default::default()
    };
    // The scalar along the sliver (screen fraction u at x = 0.5 + 20 u),
    // exact and affine; the third corner is on the exact line.
    let persp = |u: f64| (u / 100.0) / ((1.0 - u) + u / 100.0);
    let z_at = |u: f64| 1.0 / ((1.0 - u) + u / 100.0);
    proj.vertices.push(v(0.5, 1.49, 0.0, 1.0));
    proj.vertices.push(v(20.5, 1.49, 1.0, 100.0));
    proj.vertices.push(v(10.5, 1.51, persp(0.5), z_at(0.5)));
    proj.triangles.push([0, 1, 2]);
    let scan = |isovalues: &[f64]| sliver_centres(&proj, 24, 4, isovalues);
    let columns = |forced: Vec<(u32, u32)>| -> Vec<u32> {
        assert!(forced.iter().all(|&(_, j)| j == 1), "{forced:?}");
        forced.into_iter().map(|(i, _)| i).collect()
    };
    // The grown sliver holds the centres (i + 0.5, 1.5) for i in 4..=16.
    // The value at centre (10.5, 1.5), u = 1/2, is 1/101 (affine 1/2).
    // Within 0.14 of it: the centres up to u = 0.946 (x = 19.4), so all of
    // them; affine, those up to x = 3.5 only, so none.
    assert_eq!(columns(scan(&[persp(0.5)])), (4..=16).collect::<Vec<u32>>());
    // 0.7: within 0.14 of it only beyond x = 20.3, so none; affine from
    // x = 11.7 to 17.3 (12 to 16).
    assert_eq!(columns(scan(&[0.7])), Vec::<u32>::new());
}

/// A tet in general position has its outline at zero thickness
/// ([`Projected::outline_profile`]); the thickness at positions near the
/// outline, by the exact test, is within the gradient bound
/// [`thin_outline`] relies on; the test passes for a thin part and fails
/// for a thick one, for counting draws and for parts clipped at the near
/// plane.
#[test]
fn thin_outlines_are_left_to_the_rasteriser_only_where_the_bound_holds() {
    for ortho in [true, false] {
        let (rays, camera, at) = setup(ortho);
        let z0 = 4.0;
        let part = tet(
            &camera,
            [
                at(2.3, 2.1, z0),
                at(11.7, 3.2, z0 + 0.4),
                at(3.1, 12.6, z0 + 0.2),
                at(5.2, 5.9, z0 + 1.3),
            ],
        );
        let mut proj = Projected::default();
        crate::projection::project(&part, &camera, &mut proj).unwrap();
        assert!(proj.outline_profile, "ortho {ortho}");
        // The largest gradient of the thickness over the triangles.
        let g = proj
            .triangles
            .iter()
            .map(|t| {
                let v = t.map(|i| proj.vertices[i as usize]);
                let (e1, e2) = (v[1].pos() - v[0].pos(), v[2].pos() - v[0].pos());
                let num = e2 * (v[1].l - v[0].l) - e1 * (v[2].l - v[0].l);
                num.length() / e1.perp_dot(e2).abs()
            })
            .fold(0.0, f64::max);
        assert!(g > 0.0 && g.is_finite());
        // Positions just inside each outline edge (the silhouette: edges
        // between profile vertices): thickness at most the gradient times
        // the distance, within the perspective's slack.
        let mut scratch = Vec::new();
        let mut checked = 0;
        for t in &proj.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (va, vb) = (proj.vertices[a as usize], proj.vertices[b as usize]);
                if !(va.profile && vb.profile) {
                    continue;
                }
                let d = vb.pos() - va.pos();
                let inward = DVec2::new(-d.y, d.x).normalize();
                for s in [0.2, 0.5, 0.8] {
                    for dist in [1e-3, THIN_OUTLINE_PX] {
                        let c = va.pos() + d * s + inward * dist;
                        let l = length(ray_through(&part, &rays, c, &mut scratch));
                        assert!(
                            l <= 2.0 * g * dist,
                            "ortho {ortho}: l {l} at {dist} px, gradient {g}"
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked >= 18, "{checked}");
        let drawn: Vec<DrawnTriangle> = proj
            .triangles
            .iter()
            .enumerate()
            .map(|(k, t)| DrawnTriangle {
                corners: *t,
                grid: t.map(|i| {
                    let p = proj.vertices[i as usize].pos() * SUBPIXEL;
                    [p.x.round() as i64, p.y.round() as i64]
                }),
                exact: k as u32,
            })
            .collect();
        let test = |rate: f64, weighed: bool, clipped: bool| {
            let r = || rate;
            thin_outline(&PartTriangles {
                proj: &proj,
                drawn: &drawn,
                exact: &proj.triangles,
                width: 16,
                height: 16,
                rate: &r,
                rate_bound: rate,
                l_range: (0.0, 1.0),
                snap: &[],
                weighed,
                clipped,
                isovalues: &[],
                iso_origin: 0.0,
            })
        };
        let thin = 0.9 * SLIVER_DEPTH_TOL / (g * THIN_OUTLINE_PX);
        assert!(test(thin, true, false), "ortho {ortho}");
        assert!(!test(1.2 * thin / 0.9, true, false), "ortho {ortho}");
        assert!(!test(thin, false, false), "ortho {ortho}");
        assert!(!test(thin, true, true), "ortho {ortho}");
    }
}

/// A cube seen straight along an axis has faces edge-on: its outline's
/// thickness is not 0, and the projection does not claim it is.
#[test]
fn an_edge_on_face_leaves_the_outline_unknown() {
    let (_, camera, at) = setup(true);
    let corners: Vec<DVec3> = (0..8)
        .map(|k| {
            let (x, y, z) = ((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2) as f64);
            at(3.0 + 8.0 * x, 3.0 + 8.0 * y, 4.0 + z)
        })
        .collect();
    // Six tets of the cube, each with faces in the cube's side planes.
    for tet_corners in [
        [0, 1, 3, 7],
        [0, 1, 5, 7],
        [0, 2, 3, 7],
        [0, 2, 6, 7],
        [0, 4, 5, 7],
        [0, 4, 6, 7],
    ] {
        let p = tet(&camera, tet_corners.map(|i| corners[i]));
        let mut proj = Projected::default();
        crate::projection::project(&p, &camera, &mut proj).unwrap();
        assert!(!proj.outline_profile, "{tet_corners:?}");
    }
}
