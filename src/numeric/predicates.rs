//! Exact geometric predicates. Every side-of-line / side-of-plane decision in
//! zoovr goes through these and returns an enum, never a float compared to a
//! tolerance.
//!
//! - [`orient2d`], [`orient3d`]: Shewchuk's adaptive arithmetic via the
//!   `robust` crate; [`Plane3`] caches a plane for many [`orient3d`] tests
//!   behind a float filter.
//! - [`orient_dir`]: the exact sign of `((b - a) x (c - a)) . d`, the side of
//!   a triangle's plane an orthographic eye at infinity (direction `-d`) is
//!   on. `orient3d(a, b, c, a + d)` is not exact because `a + d` rounds, so
//!   this is computed with [`super::expansion`] arithmetic, which represents
//!   every intermediate value exactly.
//! - [`ray_triangle`]: whether the line through two points `o, q` crosses a
//!   triangle, from the signs of the three tetrahedra `(o, q, edge)`
//!   (Plücker test) evaluated with exact `orient3d`. A crossing through an
//!   edge or a vertex, or a line in the triangle's plane, is reported as
//!   [`RayHit::Degenerate`]: the tie rule shared by the visibility sort's
//!   non-convex constraint rasteriser (which counts such rays as crossings,
//!   adding constraints on both sides) and its validator (which skips such
//!   rays) is documented in [`crate::visibility`].
//! - [`crossing_side_times_turn`]: the order of two crossings along a
//!   projected piece in the planar arrangement of the projection, when all
//!   three pieces cross each other (a degree-4 polynomial sign, exact with
//!   [`super::expansion`]; allocation only happens on this rare path).
//!
//! Floating-point filters (in [`Plane3::side`], [`orient_dir`] and the
//! visibility sweep) only decide when their error bound proves the sign;
//! otherwise the exact evaluation does.

use glam::{DVec2, DVec3};

use super::expansion::Expansion;
use super::tolerance::{FILTER_UNDERFLOW_BOUND, ORIENT_DIR_FILTER_EPS, PLANE_FILTER_EPS};

/// The side of an oriented line or plane a point lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Counter-clockwise of the line (2D), or where the plane's normal by the
    /// right-hand rule points (3D).
    Positive,
    /// Clockwise / opposite side.
    Negative,
    /// Exactly on the line or plane.
    On,
}

impl Side {
    fn of(v: f64) -> Side {
        if v > 0.0 {
            Side::Positive
        } else if v < 0.0 {
            Side::Negative
        } else {
            Side::On
        }
    }
}

/// Exact sign of the 2D orientation of `c` relative to the line `a -> b`:
/// [`Side::Positive`] when `a, b, c` turn counter-clockwise.
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> Side {
    Side::of(robust::orient2d(
        robust::Coord { x: a.x, y: a.y },
        robust::Coord { x: b.x, y: b.y },
        robust::Coord { x: c.x, y: c.y },
    ))
}

/// Exact side of `d` relative to the plane through `a, b, c`:
/// [`Side::Positive`] when `d` is on the side the normal `(b-a) x (c-a)`
/// points to.
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Side {
    // robust::orient3d is positive when d lies *below* the plane (the side
    // opposite the right-hand normal of a, b, c).
    let v = robust::orient3d(
        robust::Coord3D {
            x: a.x,
            y: a.y,
            z: a.z,
        },
        robust::Coord3D {
            x: b.x,
            y: b.y,
            z: b.z,
        },
        robust::Coord3D {
            x: c.x,
            y: c.y,
            z: c.z,
        },
        robust::Coord3D {
            x: d.x,
            y: d.y,
            z: d.z,
        },
    );
    Side::of(-v)
}

/// A plane through `a, b, c` for many [`orient3d`] tests against it: the
/// normal is computed once and each test is one dot product, trusted when
/// it clears a float-filter bound ([`PLANE_FILTER_EPS`] times `|n|_inf`
/// bound times `|d - a|_inf`, a generous bound on the rounding of the 3x3
/// determinant); otherwise the exact [`orient3d`] decides. Same answers as
/// [`orient3d`]`(a, b, c, d)`, always.
#[derive(Clone, Copy, Debug)]
pub struct Plane3 {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    n: DVec3,
    /// `PLANE_FILTER_EPS * 2 |b - a|_inf |c - a|_inf`.
    scale: f64,
}

impl Plane3 {
    /// The plane through `a, b, c` (oriented by `(b - a) x (c - a)`).
    #[inline]
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Plane3 {
        let (u, w) = (b - a, c - a);
        Plane3 {
            a,
            b,
            c,
            n: u.cross(w),
            scale: PLANE_FILTER_EPS * 2.0 * u.abs().max_element() * w.abs().max_element(),
        }
    }

    /// Exact side of `d` (as [`orient3d`]).
    #[inline]
    pub fn side(&self, d: DVec3) -> Side {
        let x = d - self.a;
        let s = self.n.dot(x);
        let bound = self.scale * x.abs().max_element();
        // Far from underflow, a value beyond the bound has the exact sign.
        if bound > FILTER_UNDERFLOW_BOUND && s.abs() > bound {
            Side::of(s)
        } else {
            orient3d(self.a, self.b, self.c, d)
        }
    }
}

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

/// An exact 2D vector: the difference of two points.
#[derive(Clone, Debug)]
struct ExactVec {
    x: Expansion,
    y: Expansion,
}

impl ExactVec {
    /// `b - a`, exactly.
    fn between(a: DVec2, b: DVec2) -> ExactVec {
        ExactVec {
            x: Expansion::diff(b.x, a.x),
            y: Expansion::diff(b.y, a.y),
        }
    }

    /// The cross product `self.x * o.y - self.y * o.x`, exactly.
    fn cross(&self, o: &ExactVec) -> Expansion {
        self.x.mul(&o.y).sub(&self.y.mul(&o.x))
    }
}

/// Exact side of the crossing point `Y` of the lines `q1a q1b` and `q2a q2b`
/// relative to the directed line `p0 -> p1`, times the sign of
/// `cross(q1b - q1a, q2b - q2a)`: the sign of
/// `cross(d, q1a - p0) cross(e1, e2) + cross(q2a - q1a, e2) cross(d, e1)`
/// with `d = p1 - p0`, `e_i = q_ib - q_ia` (`On` when the three lines meet in
/// one point or `q1, q2` are parallel).
pub fn crossing_side_times_turn(p: [DVec2; 2], q1: [DVec2; 2], q2: [DVec2; 2]) -> Side {
    let d = ExactVec::between(p[0], p[1]);
    let e1 = ExactVec::between(q1[0], q1[1]);
    let e2 = ExactVec::between(q2[0], q2[1]);
    let a = d.cross(&ExactVec::between(p[0], q1[0])).mul(&e1.cross(&e2));
    let b = ExactVec::between(q1[0], q2[0])
        .cross(&e2)
        .mul(&d.cross(&e1));
    a.add(&b).sign()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane3_agrees_with_orient3d() {
        let mut rng = crate::testdata::Rng(99);
        let mut f = || rng.range(-1.0, 1.0);
        let mut exact_calls = 0;
        for i in 0..20000 {
            let a = DVec3::new(f(), f(), f()) * 100.0;
            let b = a + DVec3::new(f(), f(), f());
            let c = a + DVec3::new(f(), f(), f());
            // Points on, near and off the plane.
            let t = (f(), f());
            let on = a + (b - a) * t.0 + (c - a) * t.1;
            let n = (b - a).cross(c - a);
            let d = match i % 3 {
                0 => on,
                1 => on + n * (f() * 1e-15),
                _ => on + n * f(),
            };
            let p = Plane3::new(a, b, c);
            assert_eq!(p.side(d), orient3d(a, b, c, d), "{a} {b} {c} {d}");
            exact_calls += (i % 3 != 2) as usize;
        }
        assert!(exact_calls > 0);
        // Exactly on: grid points.
        let p = Plane3::new(DVec3::ZERO, DVec3::X, DVec3::Y);
        assert_eq!(p.side(DVec3::new(3.0, -7.0, 0.0)), Side::On);
        assert_eq!(p.side(DVec3::new(3.0, -7.0, 1e-300)), Side::Positive);
    }

    #[test]
    fn signs() {
        let o = DVec2::ZERO;
        assert_eq!(orient2d(o, DVec2::X, DVec2::Y), Side::Positive);
        assert_eq!(orient2d(o, DVec2::Y, DVec2::X), Side::Negative);
        assert_eq!(orient2d(o, DVec2::X, DVec2::X * 3.0), Side::On);
        let z = DVec3::ZERO;
        assert_eq!(orient3d(z, DVec3::X, DVec3::Y, DVec3::Z), Side::Positive);
        assert_eq!(orient3d(z, DVec3::X, DVec3::Y, -DVec3::Z), Side::Negative);
        // Exact: a point on the plane up to the last bit.
        let a = DVec3::new(0.1, 0.2, 0.3);
        assert_eq!(
            orient3d(
                a,
                a + DVec3::X,
                a + DVec3::Y,
                a + DVec3::new(0.5, 0.25, 0.0)
            ),
            Side::On
        );
    }

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
    }

    #[test]
    fn crossing_side() {
        // p: the x axis; q1, q2 meet at (0, 1), above it.
        let v = DVec2::new;
        let p = [v(-5.0, 0.0), v(5.0, 0.0)];
        let q1 = [v(1.0, 2.0), v(-2.0, -1.0)];
        let q2 = [v(-1.0, 2.0), v(2.0, -1.0)];
        // cross(e1, e2) > 0 and Y on the left of p.
        assert_eq!(crossing_side_times_turn(p, q1, q2), Side::Positive);
        assert_eq!(crossing_side_times_turn(p, q2, q1), Side::Negative);
        let p = [v(-5.0, 1.0), v(5.0, 1.0)];
        assert_eq!(crossing_side_times_turn(p, q1, q2), Side::On);
    }
}
