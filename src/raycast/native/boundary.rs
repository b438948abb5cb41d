//! The ray's intervals inside one iso-parametric cell of the `native` field
//! model, bounded by the cell's true faces.
//!
//! The iso-parametric cell is the image of its reference
//! element; its faces are bilinear patches (quads) and planar triangles.
//! [`cell_intervals`] intersects the ray line with every face of a cell:
//! [`ray_bilinear`] solves the patch's quadratic in `u` with the stable root
//! pair and polishes each root by Newton on the 3D system; [`ray_triangle`]
//! is Möller-Trumbore. Each face is parameterised canonically by its global
//! point ids ([`canonical_quad`]; triangles by sorted ids), so the two cells
//! sharing a face compute bit-identical roots: the exit of one is the entry
//! of the other, with no gap and no double count. Between two consecutive
//! roots the ray is inside the cell iff the midpoint's inverted parametric
//! coordinates lie in the reference element ([`NATIVE_PARAM_TOL`] widened);
//! duplicated roots at edges give empty or zero-length intervals, and a
//! root missed at an edge by one face is found by the other (both accept
//! `NATIVE_PARAM_TOL` outside `[0, 1]`). Where the midpoint cannot be inverted the
//! root parity decides (counted in [`NativeStats::parity_classified`]).
//! Which cells are visited is described in the ray caster's module docs (the
//! walk's cells plus the neighbours across crossed bilinear faces).

use glam::{DMat3, DVec3};

use super::{in_reference, is_native_kind, IsoRay, NativeStats};
use crate::camera::Ray;
use crate::numeric::tolerance::{
    BILINEAR_DISC_REL, BILINEAR_LINEAR_REL, BILINEAR_ROOT_WINDOW, NATIVE_PARAM_TOL,
};
use crate::raycast::Scene;

/// Two unit vectors perpendicular to `d` and to each other.
fn ray_plane_axes(d: DVec3) -> (DVec3, DVec3) {
    let helper = if d.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
    let u = helper.cross(d).normalize();
    (u, d.cross(u))
}

/// Roots `(t, u, v)` of the ray line `o + t d` (unit `d`, `e1`, `e2` its
/// perpendicular axes) with the bilinear patch
/// `P(u, v) = (1-u)(1-v) q0 + u(1-v) q1 + u v q2 + (1-u) v q3`, with `u`,
/// `v` in `[0, 1]` (widened by `NATIVE_PARAM_TOL`).
///
/// Projected onto the two planes through the ray, `P(u, v) = o` is two
/// bilinear equations `A_k + B_k u + C_k v + D_k u v = 0`; eliminating `v`
/// gives a quadratic in `u`, solved with the cancellation-free pair
/// `q = -(b + sgn(b) sqrt(b^2 - 4ac)) / 2`, `u = q / a`, `u = c / q`; `v` then
/// from the equation with the larger denominator `|C_k + D_k u|`. Each
/// root is polished by two Newton steps on the 3D system
/// `P(u, v) - o - t d = 0` (Ramsey, Potter and Hansen 2004 solve the same
/// system; this is the standard stable form).
pub fn ray_bilinear(
    o: DVec3,
    d: DVec3,
    axes: (DVec3, DVec3),
    q: [DVec3; 4],
    out: &mut Vec<(f64, f64, f64)>,
) {
    let (e1, e2) = axes;
    let r = q.map(|p| p - o);
    let proj = |e: DVec3| {
        let p = r.map(|x| x.dot(e));
        (p[0], p[1] - p[0], p[3] - p[0], p[0] - p[1] + p[2] - p[3])
    };
    let (a1, b1, c1, d1) = proj(e1);
    let (a2, b2, c2, d2) = proj(e2);
    let qa = b1 * d2 - b2 * d1;
    let qb = a1 * d2 - a2 * d1 + b1 * c2 - b2 * c1;
    let qc = a1 * c2 - a2 * c1;
    let scale = qa.abs().max(qb.abs()).max(qc.abs());
    if scale == 0.0 || !scale.is_finite() {
        return;
    }
    let mut us = [f64::NAN; 2];
    if qa.abs() <= BILINEAR_LINEAR_REL * scale {
        if qb != 0.0 {
            us[0] = -qc / qb;
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        let disc = if disc < 0.0 {
            if disc > -BILINEAR_DISC_REL * qb * qb {
                0.0
            } else {
                return;
            }
        } else {
            disc
        };
        let sq = disc.sqrt();
        let qq = -0.5 * (qb + if qb >= 0.0 { sq } else { -sq });
        us[0] = qq / qa;
        if qq != 0.0 {
            us[1] = qc / qq;
        }
    }
    let eval = |u: f64, v: f64| {
        let p = q[0] * ((1.0 - u) * (1.0 - v))
            + q[1] * (u * (1.0 - v))
            + q[2] * (u * v)
            + q[3] * ((1.0 - u) * v);
        let pu = (q[1] - q[0]) * (1.0 - v) + (q[2] - q[3]) * v;
        let pv = (q[3] - q[0]) * (1.0 - u) + (q[2] - q[1]) * u;
        (p, pu, pv)
    };
    let in01 = |x: f64| (-NATIVE_PARAM_TOL..=1.0 + NATIVE_PARAM_TOL).contains(&x);
    for (k, &u) in us.iter().enumerate() {
        if !u.is_finite() || (k == 1 && (us[0] - u).abs() == 0.0) {
            continue;
        }
        if !(-BILINEAR_ROOT_WINDOW..=1.0 + BILINEAR_ROOT_WINDOW).contains(&u) {
            continue;
        }
        let den1 = c1 + d1 * u;
        let den2 = c2 + d2 * u;
        let v = if den1.abs() >= den2.abs() {
            if den1 == 0.0 {
                continue;
            }
            -(a1 + b1 * u) / den1
        } else {
            -(a2 + b2 * u) / den2
        };
        if !v.is_finite() || !(-BILINEAR_ROOT_WINDOW..=1.0 + BILINEAR_ROOT_WINDOW).contains(&v) {
            continue;
        }
        let (mut u, mut v) = (u, v);
        let mut t = (eval(u, v).0 - o).dot(d);
        for _ in 0..2 {
            let (p, pu, pv) = eval(u, v);
            let f = p - o - d * t;
            let j = DMat3::from_cols(pu, pv, -d);
            let det = j.determinant();
            if det == 0.0 || !det.is_finite() {
                break;
            }
            let step = j.inverse() * f;
            if !step.is_finite() {
                break;
            }
            u -= step.x;
            v -= step.y;
            t -= step.z;
        }
        if in01(u) && in01(v) && t.is_finite() {
            out.push((t, u, v));
        }
    }
}

/// The root `(t, b1, b2)` of the ray line with triangle `p` (barycentric
/// weights of `p[1]`, `p[2]`, widened by `NATIVE_PARAM_TOL`), Möller-Trumbore.
pub fn ray_triangle(o: DVec3, d: DVec3, p: [DVec3; 3]) -> Option<(f64, f64, f64)> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - p[0];
    let b1 = tv.dot(pv) * inv;
    let qv = tv.cross(e1);
    let b2 = d.dot(qv) * inv;
    let t = e2.dot(qv) * inv;
    let ok =
        b1 >= -NATIVE_PARAM_TOL && b2 >= -NATIVE_PARAM_TOL && b1 + b2 <= 1.0 + NATIVE_PARAM_TOL;
    (ok && t.is_finite()).then_some((t, b1, b2))
}

/// One cell's part of a ray in the native model: between two roots of the
/// ray with the cell's true (bilinear / planar) boundary, with the exact
/// boundary scalars at both ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub cell: u32,
    pub t_a: f64,
    pub t_b: f64,
    pub s_a: f64,
    pub s_b: f64,
}

/// A root of the ray with a face of the cell: depth, exact scalar there,
/// the global face.
#[derive(Clone, Copy, Debug)]
struct Root {
    t: f64,
    s: f64,
    face: u32,
}

/// The canonical cyclic order of a quad face's global ids: from the
/// smallest, towards the smaller of its two neighbours. Both cells sharing
/// the face see the same patch parameterisation, hence bit-identical roots.
fn canonical_quad(g: [u32; 4]) -> [usize; 4] {
    let k0 = (0..4).min_by_key(|&i| g[i]).unwrap_or(0);
    let fwd = g[(k0 + 1) % 4] < g[(k0 + 3) % 4];
    std::array::from_fn(|i| if fwd { (k0 + i) % 4 } else { (k0 + 4 - i) % 4 })
}

/// The intervals of `ray` inside native cell `c` (bounded by its bilinear
/// quad faces and planar triangles), appended to `out`; the global faces
/// through which the ray crosses the cell's boundary are appended to
/// `crossed` (so a caller can add neighbours the walk missed).
///
/// All roots of the ray line with the cell's faces are sorted; the ray is
/// inside the cell between two consecutive roots iff the midpoint's
/// inverted parametric coordinates lie in the reference element (the
/// definition of the iso-parametric cell, robust to roots duplicated or
/// missed at edges). Where the midpoint cannot be inverted the parity of
/// the root index decides (counted). Returns `None` for cells without a
/// native field.
#[allow(clippy::too_many_arguments)]
pub fn cell_intervals(
    scene: &Scene,
    vals: &[f64],
    c: usize,
    ray: &Ray,
    axes: (DVec3, DVec3),
    out: &mut Vec<Interval>,
    crossed: &mut Vec<u32>,
    stats: &mut NativeStats,
) -> Option<()> {
    let cells = &scene.mesh.cells;
    let kind = cells.kinds[c];
    if !is_native_kind(kind) {
        return None;
    }
    let nodes = cells.nodes(c);
    let pts = &scene.mesh.points;
    let x: Vec<DVec3> = nodes.iter().map(|&n| pts[n as usize]).collect();
    let s: Vec<f64> = nodes.iter().map(|&n| vals[n as usize]).collect();
    let mut field = IsoRay::new(kind, &x, &s, ray)?;
    let faces = scene.topology.faces_of(c);
    let (o, d) = (ray.origin, ray.dir);
    let mut roots: Vec<Root> = Vec::with_capacity(12);
    let mut hits = Vec::with_capacity(2);
    for (fi, lf) in kind.faces().iter().enumerate() {
        let face = faces.get(fi).copied().unwrap_or(u32::MAX);
        match lf.len() {
            4 => {
                let g: [u32; 4] = std::array::from_fn(|i| nodes[lf[i] as usize]);
                let ord = canonical_quad(g);
                let q = ord.map(|i| pts[g[i] as usize]);
                let sv = ord.map(|i| vals[g[i] as usize]);
                hits.clear();
                ray_bilinear(o, d, axes, q, &mut hits);
                for &(t, u, v) in &hits {
                    let s = sv[0] * ((1.0 - u) * (1.0 - v))
                        + sv[1] * (u * (1.0 - v))
                        + sv[2] * (u * v)
                        + sv[3] * ((1.0 - u) * v);
                    roots.push(Root { t, s, face });
                }
            }
            3 => {
                let mut g: [u32; 3] = std::array::from_fn(|i| nodes[lf[i] as usize]);
                g.sort_unstable();
                let p = g.map(|i| pts[i as usize]);
                if let Some((t, b1, b2)) = ray_triangle(o, d, p) {
                    let sv = g.map(|i| vals[i as usize]);
                    let s = sv[0] * (1.0 - b1 - b2) + sv[1] * b1 + sv[2] * b2;
                    roots.push(Root { t, s, face });
                }
            }
            _ => {}
        }
    }
    roots.sort_by(|a, b| a.t.total_cmp(&b.t));
    for r in &roots {
        crossed.push(r.face);
    }
    for (k, w) in roots.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        if b.t <= a.t {
            continue;
        }
        let tm = 0.5 * (a.t + b.t);
        let inside = match field.locate(tm) {
            Some(xi) => in_reference(kind, xi),
            None => {
                stats.parity_classified += 1;
                k % 2 == 0
            }
        };
        if inside {
            out.push(Interval {
                cell: c as u32,
                t_a: a.t,
                t_b: b.t,
                s_a: a.s,
                s_b: b.s,
            });
        }
    }
    stats.newton_failures += field.failures;
    Some(())
}

/// The ray line's perpendicular axes, for [`cell_intervals`].
pub fn axes_of(ray: &Ray) -> (DVec3, DVec3) {
    ray_plane_axes(ray.dir)
}
