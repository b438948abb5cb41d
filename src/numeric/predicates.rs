//! Exact geometric predicates (Shewchuk's adaptive arithmetic via the
//! `robust` crate). Every side-of-line / side-of-plane decision in zoovr goes
//! through these and returns an enum, never a float compared to a tolerance.

use glam::{DVec2, DVec3};

use super::tolerance::{FILTER_UNDERFLOW_BOUND, PLANE_FILTER_EPS};

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
}
