//! Exact predicates the visibility sort needs beyond
//! [`crate::numeric::predicates`]:
//!
//! - [`orient_dir`]: the exact sign of `((b - a) x (c - a)) . d`, the side of
//!   a triangle's plane an orthographic eye at infinity (direction `-d`) is on.
//!   `orient3d(a, b, c, a + d)` is not exact because `a + d` rounds, so this is
//!   computed with [`crate::numeric::expansion`] arithmetic, which represents
//!   every intermediate value exactly.
//! - [`ray_triangle`]: whether the line through two points `o, q` crosses a
//!   triangle, from the signs of the three tetrahedra `(o, q, edge)` (Plücker
//!   test) evaluated with exact `orient3d`. A crossing through an edge or a
//!   vertex, or a line in the triangle's plane, is reported as
//!   [`RayHit::Degenerate`]: the tie rule shared by the non-convex constraint
//!   rasteriser (which counts such rays as crossings, adding constraints on both
//!   sides) and the validator (which skips such rays) is documented in
//!   [`super`].
//!
//! The floating-point filter used in the per-view sweep lives in `sorter.rs`
//! and falls back to these functions (or `orient3d`) when it cannot decide.

use glam::DVec3;

use crate::numeric::expansion::Expansion;
use crate::numeric::predicates::{orient3d, Side};
use crate::numeric::tolerance::ORIENT_DIR_FILTER_EPS;

/// Exact sign of `((b - a) x (c - a)) . d`.
pub fn orient_dir(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Side {
    // Filter first: the float value with a conservative error bound.
    let u = b - a;
    let v = c - a;
    let det = u.cross(v).dot(d);
    let (ua, va, da) = (u.abs(), v.abs(), d.abs());
    let perm = (ua.y * va.z + ua.z * va.y) * da.x
        + (ua.z * va.x + ua.x * va.z) * da.y
        + (ua.x * va.y + ua.y * va.x) * da.z;
    let bound = ORIENT_DIR_FILTER_EPS * perm;
    if det > bound {
        return Side::Positive;
    }
    if -det > bound {
        return Side::Negative;
    }
    orient_dir_exact(a, b, c, d)
}

/// The expansion-arithmetic evaluation behind [`orient_dir`].
pub fn orient_dir_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Side {
    let u = [0, 1, 2].map(|k| Expansion::diff(b[k], a[k]));
    let v = [0, 1, 2].map(|k| Expansion::diff(c[k], a[k]));
    let w = [0, 1, 2].map(|k| Expansion::from_f64(d[k]));
    let mut total = Expansion::default();
    // det = sum over cyclic (i, j, k) of u_i (v_j w_k - v_k w_j).
    for (i, j, k) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
        let minor = v[j].mul(&w[k]).sub(&v[k].mul(&w[j]));
        total = total.add(&u[i].mul(&minor));
    }
    total.sign()
}

/// Outcome of an exact line-triangle crossing test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayHit {
    /// The line misses the closed triangle.
    Miss,
    /// The line crosses the open triangle transversally.
    Inside,
    /// The line meets the triangle's boundary (edge or vertex) or lies in its
    /// plane.
    Degenerate,
}

/// Exact crossing test of the line through `o, q` with triangle `a, b, c`.
pub fn ray_triangle(o: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> RayHit {
    let s = [
        orient3d(o, q, a, b),
        orient3d(o, q, b, c),
        orient3d(o, q, c, a),
    ];
    classify_signs(s)
}

/// Combines the three edge signs of a Plücker test.
pub fn classify_signs(s: [Side; 3]) -> RayHit {
    let pos = s.iter().filter(|&&x| x == Side::Positive).count();
    let neg = s.iter().filter(|&&x| x == Side::Negative).count();
    if pos > 0 && neg > 0 {
        RayHit::Miss
    } else if pos == 3 || neg == 3 {
        RayHit::Inside
    } else {
        RayHit::Degenerate
    }
}

/// Parameter `t` (in units of `q - o`) where the line `o + t (q - o)` meets
/// the plane of `a, b, c`. The vertices are sorted first so the result does
/// not depend on their order (coincident triangles give identical `t`).
/// Returns `None` for a line parallel to the plane.
pub fn line_plane_t(o: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let mut p = [a, b, c];
    p.sort_by(|x, y| {
        x.x.total_cmp(&y.x)
            .then(x.y.total_cmp(&y.y))
            .then(x.z.total_cmp(&y.z))
    });
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let den = n.dot(q - o);
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    Some(n.dot(p[0] - o) / den)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn det_i128(a: [i64; 3], b: [i64; 3], c: [i64; 3], d: [i64; 3]) -> i128 {
        let u: Vec<i128> = (0..3).map(|i| (b[i] - a[i]) as i128).collect();
        let v: Vec<i128> = (0..3).map(|i| (c[i] - a[i]) as i128).collect();
        let w: Vec<i128> = d.iter().map(|&x| x as i128).collect();
        u[0] * (v[1] * w[2] - v[2] * w[1])
            + u[1] * (v[2] * w[0] - v[0] * w[2])
            + u[2] * (v[0] * w[1] - v[1] * w[0])
    }

    fn side_of(x: i128) -> Side {
        match x.cmp(&0) {
            std::cmp::Ordering::Greater => Side::Positive,
            std::cmp::Ordering::Less => Side::Negative,
            std::cmp::Ordering::Equal => Side::On,
        }
    }

    #[test]
    fn orient_dir_matches_integer_determinant() {
        // Large integers (up to 2^30): products of three exceed 2^53, so plain
        // floating point loses bits; the expansion result must still be exact.
        let mut x: u64 = 0x9E3779B97F4A7C15;
        let mut next = |m: i64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % (2 * m as u64 + 1)) as i64 - m
        };
        let m = 1i64 << 30;
        for k in 0..3000 {
            let a = [next(m), next(m), next(m)];
            let b = [next(m), next(m), next(m)];
            let mut c = [next(m), next(m), next(m)];
            let d = [next(1 << 20), next(1 << 20), next(1 << 20)];
            if k % 3 == 0 {
                // Make d exactly parallel to the plane: d = (b - a) * s.
                c = [a[0] + 2 * (b[0] - a[0]) / 3, c[1], c[2]];
            }
            let f = |p: [i64; 3]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            let want = side_of(det_i128(a, b, c, d));
            assert_eq!(orient_dir(f(a), f(b), f(c), f(d)), want);
            assert_eq!(orient_dir_exact(f(a), f(b), f(c), f(d)), want);
        }
        // An exactly degenerate case: d in the plane spanned by b - a, c - a.
        let a = DVec3::new(0.1, 0.7, 1.3);
        let b = a + DVec3::new(1.0, 0.0, 0.0);
        let c = a + DVec3::new(0.0, 1.0, 0.0);
        assert_eq!(
            orient_dir(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.9, 0.0)),
            Side::On
        );
        assert_eq!(
            orient_dir(a, b, c, DVec3::Z),
            orient3d(a, b, c, a + DVec3::Z)
        );
    }

    #[test]
    fn ray_triangle_cases() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 0.0, 0.0);
        let c = DVec3::new(0.0, 1.0, 0.0);
        let o = DVec3::new(0.25, 0.25, 5.0);
        assert_eq!(ray_triangle(o, o - DVec3::Z, a, b, c), RayHit::Inside);
        let o2 = DVec3::new(0.5, 0.5, 5.0); // on the hypotenuse
        assert_eq!(ray_triangle(o2, o2 - DVec3::Z, a, b, c), RayHit::Degenerate);
        let o3 = DVec3::new(0.8, 0.8, 5.0);
        assert_eq!(ray_triangle(o3, o3 - DVec3::Z, a, b, c), RayHit::Miss);
        let t = line_plane_t(o, o - DVec3::Z, a, b, c).unwrap();
        assert!((t - 5.0).abs() < 1e-15);
        assert_eq!(line_plane_t(o, o + DVec3::X, a, b, c), None);
    }
}
