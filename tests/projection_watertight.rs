//! Watertightness: every cell of a block is projected with the same camera;
//! at every pixel centre the number of covering region triangles (exact
//! point-in-triangle with a tie rule for centres on edges) equals the number
//! of cells the pixel ray crosses (ray casting). No seams, no double cover.

mod projection_util;

use glam::{DMat3, DVec2, DVec3};
use projection_util::*;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::{lattice_hex, CellKind, Cells};
use zoovr::numeric::predicates::{orient2d, Side};
use zoovr::projection::{Polyhedron, Projected, Projector};

/// A structured block of `n` hexes, mapped by `m`, `t`.
fn block(n: [usize; 3], m: DMat3, t: DVec3, rng: &mut Rng) -> (Vec<DVec3>, Cells, Vec<f64>) {
    let mut pts = Vec::new();
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                pts.push(m * DVec3::new(i as f64, j as f64, k as f64) + t);
            }
        }
    }
    let mut cells = Cells::default();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                cells.push(
                    CellKind::Hexahedron,
                    &lattice_hex(n[0] + 1, n[1] + 1, [i, j, k]),
                );
            }
        }
    }
    let s = (0..pts.len()).map(|_| rng.range(0.0, 1.0)).collect();
    (pts, cells, s)
}

/// Exact coverage of `p` by CCW triangle `t` with the tie rule: a point on
/// an edge `d = e1 - e0` belongs to the triangle iff `d.y < 0 || (d.y == 0 &&
/// d.x > 0)` (a symbolic shift of `p` by `(1, tiny)`), so a point on a shared
/// edge or vertex is counted exactly once.
fn covers(t: [DVec2; 3], p: DVec2) -> bool {
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        match orient2d(a, b, p) {
            Side::Positive => {}
            Side::Negative => return false,
            Side::On => {
                let d = b - a;
                if !(d.y < 0.0 || (d.y == 0.0 && d.x > 0.0)) {
                    return false;
                }
            }
        }
    }
    true
}

/// Per-pixel coverage counts of all cells' triangles, and the pieces.
fn coverage(pts: &[DVec3], cells: &Cells, s: &[f64], cam: &Camera) -> (Vec<u32>, Vec<Polyhedron>) {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut count = vec![0u32; w * h];
    let mut pr = Projector::new();
    let mut out = Projected::default();
    let mut polys = Vec::new();
    for c in 0..cells.len() {
        let poly = Polyhedron::from_cell(cells, c, pts, |i| s[i as usize], cam).unwrap();
        pr.project(&poly, cam, &mut out).unwrap();
        for t in &out.triangles {
            let tri = t.map(|i| out.vertices[i as usize].pos());
            let lo = tri[0].min(tri[1]).min(tri[2]);
            let hi = tri[0].max(tri[1]).max(tri[2]);
            let (i0, i1) = (
                (lo.x - 0.5).floor().max(0.0) as usize,
                ((hi.x - 0.5).ceil().max(0.0) as usize).min(w - 1),
            );
            let (j0, j1) = (
                (lo.y - 0.5).floor().max(0.0) as usize,
                ((hi.y - 0.5).ceil().max(0.0) as usize).min(h - 1),
            );
            for j in j0..=j1 {
                for i in i0..=i1 {
                    if covers(tri, DVec2::new(i as f64 + 0.5, j as f64 + 0.5)) {
                        count[j * w + i] += 1;
                    }
                }
            }
        }
        polys.push(poly);
    }
    (count, polys)
}

fn generic_view(ortho: bool, seed: u64) {
    let mut rng = Rng(seed);
    let (m, t) = random_affine(&mut rng);
    let (pts, cells, s) = block([3, 3, 2], m, t, &mut rng);
    let p = CameraParams {
        width: 48,
        height: 40,
        azimuth: rng.range(-180.0, 180.0),
        elevation: rng.range(-80.0, 80.0),
        roll: rng.range(-90.0, 90.0),
        ortho,
        ..Default::default()
    };
    let cam = Camera::fit(bounds(&pts), &p);
    let (count, polys) = coverage(&pts, &cells, &s, &cam);
    let diag = {
        let b = bounds(&pts);
        DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length()
    };
    let view = zoovr::projection::ViewMap::of(&cam);
    let (mut checked, mut skipped, mut covered) = (0, 0, 0);
    for j in 0..cam.height as usize {
        for i in 0..cam.width as usize {
            let q = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
            let mut expect = 0;
            let mut ambiguous = false;
            for poly in &polys {
                if let Some(hit) = ray_hit(poly, &view, q) {
                    if hit.0 > 1e-6 * diag {
                        expect += 1;
                    } else {
                        ambiguous = true;
                    }
                }
            }
            if ambiguous {
                skipped += 1;
                continue;
            }
            checked += 1;
            covered += (expect > 0) as usize;
            assert_eq!(
                count[j * cam.width as usize + i],
                expect,
                "pixel ({i}, {j})"
            );
        }
    }
    assert!(
        skipped * 50 < checked,
        "{skipped} ambiguous pixels of {checked}"
    );
    assert!(covered > 100, "block covers {covered} pixels");
}

#[test]
fn block_generic_orthographic() {
    for seed in [1, 2, 3] {
        generic_view(true, seed);
    }
}

#[test]
fn block_generic_perspective() {
    for seed in [4, 5, 6] {
        generic_view(false, seed);
    }
}

#[test]
fn block_face_on_with_pixel_centres_on_edges() {
    // View space = world space; cell boundaries pass exactly through pixel
    // centres; side faces are edge-on and front/back corners coincide.
    let cam = Camera {
        position: DVec3::ZERO,
        focal_point: DVec3::Z,
        up: DVec3::Y,
        right: DVec3::X,
        forward: DVec3::Z,
        view_angle: 30.0,
        parallel_scale: 1.0,
        ortho: true,
        width: 64,
        height: 64,
        near: 1e-9,
    };
    let mut rng = Rng(8);
    let m = DMat3::from_diagonal(DVec3::new(0.25, 0.25, 0.5));
    let t = DVec3::new(-0.5 + 1.0 / 64.0, -0.5 + 1.0 / 64.0, 2.0);
    let (pts, cells, s) = block([3, 3, 2], m, t, &mut rng);
    let (count, _) = coverage(&pts, &cells, &s, &cam);
    // The block's silhouette as two CCW triangles (pixel space).
    let corner = |x: f64, y: f64| {
        let (px, py, _) = cam.view_to_pixel(DVec3::new(x, y, 2.0)).unwrap();
        DVec2::new(px, py)
    };
    let (x0, x1) = (t.x, t.x + 0.75);
    let (y0, y1) = (t.y, t.y + 0.75);
    let (a, b, c, d) = (
        corner(x0, y1),
        corner(x1, y1),
        corner(x1, y0),
        corner(x0, y0),
    );
    let mut on_edges = 0;
    for j in 0..64usize {
        for i in 0..64usize {
            let q = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
            let inside = covers([a, b, c], q) || covers([a, c, d], q);
            let expect = if inside { 2 } else { 0 };
            assert_eq!(count[j * 64 + i], expect, "pixel ({i}, {j})");
            if (q.x - a.x) % 8.0 == 0.0 || (q.y - a.y) % 8.0 == 0.0 {
                on_edges += 1;
            }
        }
    }
    assert!(on_edges > 100, "pixel centres on cell edges: {on_edges}");
}
