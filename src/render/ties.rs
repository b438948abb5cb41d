//! Pixel centres next to a part's outline, decided on the exact geometry.
//!
//! The driver snaps every region corner to the rasteriser's sub-pixel grid
//! (1/256 pixel, [`crate::gpu::ClipMapper::ndc`]), which moves it by up to
//! `sqrt(2)/512` pixel. A pixel centre farther than that from every edge of
//! a part's outline is inside the snapped part exactly when it is inside
//! the exact one; a centre closer may change sides. Where the ray through
//! it crosses the piece for a length that is not small (a sliver seen
//! nearly edge-on, an opaque cell next to another), that is a visibly
//! wrong pixel: the piece's whole segment missing, or taken where the ray
//! caster's exact test says the ray misses the piece.
//!
//! So for each part the centres within [`TIE_BAND_PX`] of its outline
//! (edges of its triangles that are not shared by two drawn triangles) are
//! decided twice, exactly: inside the exact triangles (f64 positions,
//! exact orientation predicates, the top-left rule on an edge: the
//! convention of the rasteriser and the ray caster) and inside the snapped
//! triangles the GPU will draw (integer grid, the same rule). Where they
//! disagree, a pixel quad is drawn first in the part: with the exact
//! triangle's payload interpolated at the centre where the exact part
//! covers it, or transparent where it does not (a blocker, drawn at
//! [`BLOCKER_Z`], which counting draws do not count). Each piece colours a pixel
//! once (its depth key), so the quad decides the pixel and the triangles
//! drawn after it leave it alone.
//!
//! A centre exactly on an outline edge shared with a neighbouring piece is
//! given to one of the two by the top-left rule, on the exact positions,
//! so no pixel is covered twice or missed between pieces.

use glam::DVec2;

use crate::gpu::common::BLOCKER_Z;
use crate::gpu::{ClipMapper, GpuVertex, SUBPIXEL};
use crate::numeric::predicates::{orient2d, Side};
use crate::projection::Projected;

/// Centres within this distance (pixels) of an outline edge are decided
/// exactly: the largest move of a snapped corner is `sqrt(2)/512` = 2.8e-3
/// px; 1/256 leaves a margin.
pub const TIE_BAND_PX: f64 = 1.0 / 256.0;

/// Whether the exact triangle `p` (pixel coordinates) covers centre `c`
/// under the top-left rule: strictly inside, or on an edge that is a top
/// edge (horizontal, the triangle below) or a left edge (the triangle to
/// its right) — the rule of [`crate::gpu::cpu`], on exact positions.
pub fn covers_exact(p: [DVec2; 3], c: DVec2) -> bool {
    let s = match orient2d(p[0], p[1], p[2]) {
        Side::Positive => 1.0,
        Side::Negative => -1.0,
        Side::On => return false,
    };
    for (u, v) in [(p[1], p[2]), (p[2], p[0]), (p[0], p[1])] {
        match orient2d(u, v, c) {
            Side::On => {
                // dE/dx = -(v.y - u.y) s, dE/dy = (v.x - u.x) s: the signs
                // of exact differences of f64 values.
                let ex = -s * sign(v.y, u.y);
                let ey = s * sign(v.x, u.x);
                if !(ex > 0.0 || (ex == 0.0 && ey > 0.0)) {
                    return false;
                }
            }
            side => {
                let e = if side == Side::Positive { s } else { -s };
                if e < 0.0 {
                    return false;
                }
            }
        }
    }
    true
}

fn sign(a: f64, b: f64) -> f64 {
    if a > b {
        1.0
    } else if a < b {
        -1.0
    } else {
        0.0
    }
}

/// Whether the snapped triangle `g` (grid units) covers the centre `q`
/// (grid units): the rasteriser's test ([`crate::gpu::cpu`]).
pub fn covers_grid(g: [[i64; 2]; 3], q: [i64; 2]) -> bool {
    let [a, b, c] = g.map(|p| [p[0] as i128, p[1] as i128]);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0 {
        return false;
    }
    let s = area.signum();
    let q = [q[0] as i128, q[1] as i128];
    for (u, v) in [(b, c), (c, a), (a, b)] {
        let (dx, dy) = ((v[0] - u[0]) * s, (v[1] - u[1]) * s);
        let e = dx * (q[1] - u[1]) - dy * (q[0] - u[0]);
        let top_left = -dy > 0 || (-dy == 0 && dx > 0);
        if e < 0 || (e == 0 && !top_left) {
            return false;
        }
    }
    true
}

/// Scratch of [`fix_ties`], reused from part to part.
#[derive(Default)]
pub struct TieScratch {
    edges: Vec<(u32, u32)>,
    centres: Vec<(u32, u32)>,
}

/// What [`fix_ties`] needs of one part about to be drawn.
pub struct PartTriangles<'a> {
    pub proj: &'a Projected,
    /// Triangles the GPU draws (indices into `proj.vertices`), with their
    /// snapped grid positions.
    pub drawn: &'a [([u32; 3], [[i64; 2]; 3])],
    /// Every triangle of the exact part (after coverage culling, which
    /// leaves out only triangles holding no centre).
    pub exact: &'a [[u32; 3]],
    pub width: u32,
    pub height: u32,
}

/// Pixel quads deciding the centres near the part's outline (see the module
/// docs), appended to `vertices`/`indices` (to be drawn before the part's
/// triangles); `vertex(i)` is the part's vertex for `proj.vertices[i]`
/// (`None` when it was not emitted). Returns the number of quads.
pub fn fix_ties<V: GpuVertex>(
    part: &PartTriangles,
    mapper: &ClipMapper,
    vertex: impl Fn(u32) -> Option<V>,
    piece: u32,
    scratch: &mut TieScratch,
    vertices: &mut Vec<V>,
    indices: &mut Vec<u32>,
) -> usize {
    let pos = |i: u32| {
        let v = &part.proj.vertices[i as usize];
        DVec2::new(v.px, v.py)
    };
    // Outline candidates: edges of drawn triangles not shared by two of
    // them, and every edge of an exact triangle that is not drawn.
    let edges = &mut scratch.edges;
    edges.clear();
    let key = |a: u32, b: u32| if a < b { (a, b) } else { (b, a) };
    for (t, _) in part.drawn {
        for k in 0..3 {
            edges.push(key(t[k], t[(k + 1) % 3]));
        }
    }
    edges.sort_unstable();
    let mut outline: Vec<(u32, u32)> = Vec::new();
    let mut k = 0;
    while k < edges.len() {
        let mut n = 1;
        while k + n < edges.len() && edges[k + n] == edges[k] {
            n += 1;
        }
        if n != 2 {
            outline.push(edges[k]);
        }
        k += n;
    }
    if part.drawn.len() != part.exact.len() {
        for t in part.exact {
            if !part.drawn.iter().any(|(d, _)| d == t) {
                for k in 0..3 {
                    outline.push(key(t[k], t[(k + 1) % 3]));
                }
            }
        }
    }
    // Centres within the band of each outline edge.
    let centres = &mut scratch.centres;
    centres.clear();
    for &(ia, ib) in &outline {
        near_centres(pos(ia), pos(ib), part.width, part.height, centres);
    }
    if centres.is_empty() {
        return 0;
    }
    centres.sort_unstable();
    centres.dedup();
    let mut quads = 0;
    for &(i, j) in centres.iter() {
        let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
        let sub = SUBPIXEL as i64;
        let q = [i as i64 * sub + sub / 2, j as i64 * sub + sub / 2];
        let grid_in = part.drawn.iter().any(|(_, g)| covers_grid(*g, q));
        let exact_tri = part.exact.iter().find(|t| covers_exact(t.map(pos), c));
        let mut z = 0.5;
        let value = match (exact_tri, grid_in) {
            (Some(t), false) => {
                let p = t.map(pos);
                let Some(corners) = t.map(&vertex).into_iter().collect::<Option<Vec<V>>>() else {
                    continue;
                };
                let bary = barycentric(p, c);
                V::lerp3([&corners[0], &corners[1], &corners[2]], bary)
            }
            (None, true) => {
                // Transparent: any vertex of the part, emptied.
                let Some(v) = part.drawn.first().and_then(|(t, _)| vertex(t[0])) else {
                    continue;
                };
                z = BLOCKER_Z;
                v.transparent()
            }
            _ => continue,
        };
        let base = vertices.len() as u32;
        for (di, dj) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
            let Some((ndc, _)) = mapper.ndc((i + di) as f64, (j + dj) as f64) else {
                continue;
            };
            vertices.push(value.with_clip([ndc[0], ndc[1], z, 1.0]).with_piece(piece));
        }
        if vertices.len() as u32 == base + 4 {
            indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
            quads += 1;
        } else {
            vertices.truncate(base as usize);
        }
    }
    quads
}

/// Barycentric weights of `c` in triangle `p`.
fn barycentric(p: [DVec2; 3], c: DVec2) -> [f64; 3] {
    let cross = |a: DVec2, b: DVec2, q: DVec2| (b - a).perp_dot(q - a);
    let area = cross(p[0], p[1], p[2]);
    if area == 0.0 {
        return [1.0 / 3.0; 3];
    }
    [
        cross(p[1], p[2], c) / area,
        cross(p[2], p[0], c) / area,
        cross(p[0], p[1], c) / area,
    ]
}

/// Appends the image's pixel centres within [`TIE_BAND_PX`] of segment `a b`
/// (a superset: the band is walked along the segment's major axis).
fn near_centres(a: DVec2, b: DVec2, width: u32, height: u32, out: &mut Vec<(u32, u32)>) {
    let band = TIE_BAND_PX;
    let d = b - a;
    if !(a.is_finite() && b.is_finite()) {
        return;
    }
    let (major_x, len) = if d.x.abs() >= d.y.abs() {
        (true, d.x.abs())
    } else {
        (false, d.y.abs())
    };
    // Along the major axis, the centres' coordinates k + 0.5 within the
    // segment's extent grown by the band; across it, the segment's
    // coordinate there (clamped to the segment) +- band * sqrt(2).
    let (a_m, b_m, a_n, b_n, n_major, n_minor) = if major_x {
        (a.x, b.x, a.y, b.y, width, height)
    } else {
        (a.y, b.y, a.x, b.x, height, width)
    };
    let lo = a_m.min(b_m) - band;
    let hi = a_m.max(b_m) + band;
    let k0 = ((lo - 0.5).ceil().max(0.0)) as i64;
    let k1 = ((hi - 0.5).floor().min(n_major as f64 - 1.0)) as i64;
    let reach = band * std::f64::consts::SQRT_2;
    for k in k0..=k1 {
        let m = k as f64 + 0.5;
        let t = if len > 0.0 {
            ((m - a_m) / (b_m - a_m)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let n = a_n + (b_n - a_n) * t;
        let l0 = ((n - reach - 0.5).ceil().max(0.0)) as i64;
        let l1 = ((n + reach - 0.5).floor().min(n_minor as f64 - 1.0)) as i64;
        for l in l0..=l1 {
            let (i, j) = if major_x { (k, l) } else { (l, k) };
            out.push((i as u32, j as u32));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact and the grid test agree on grid positions, including
    /// centres on edges (the top-left rule) and both windings.
    #[test]
    fn exact_and_grid_rules_agree_on_the_grid() {
        let sub = SUBPIXEL;
        let tris = [
            [[0.5, 0.5], [4.5, 0.5], [0.5, 4.5]],
            [[0.5, 0.5], [0.5, 4.5], [4.5, 0.5]],
            [[1.0, 1.0], [3.5, 2.5], [2.5, 5.5]],
            [[0.0, 2.5], [5.0, 2.5], [2.5, 0.0]],
            [[0.0, 2.5], [2.5, 5.0], [5.0, 2.5]],
        ];
        for t in tris {
            let p = t.map(|q| DVec2::new(q[0], q[1]));
            let g = t.map(|q| [(q[0] * sub) as i64, (q[1] * sub) as i64]);
            for j in 0..6 {
                for i in 0..6 {
                    let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                    let q = [(c.x * sub) as i64, (c.y * sub) as i64];
                    assert_eq!(covers_exact(p, c), covers_grid(g, q), "{t:?} {i} {j}");
                }
            }
        }
    }

    /// Two triangles sharing an edge through centres: each centre on it
    /// belongs to exactly one.
    #[test]
    fn shared_edges_give_each_centre_once() {
        let a = DVec2::new(0.5, 0.5);
        let b = DVec2::new(3.5, 3.5);
        let l = DVec2::new(0.5, 3.5);
        let r = DVec2::new(3.5, 0.5);
        for k in 0..4 {
            let c = DVec2::new(k as f64 + 0.5, k as f64 + 0.5);
            let n = [covers_exact([a, b, l], c), covers_exact([a, r, b], c)]
                .iter()
                .filter(|&&x| x)
                .count();
            assert!(n <= 1, "{k}");
        }
        let c = DVec2::new(1.5, 1.5);
        assert_eq!(
            [covers_exact([a, b, l], c), covers_exact([a, r, b], c)]
                .iter()
                .filter(|&&x| x)
                .count(),
            1
        );
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
}
