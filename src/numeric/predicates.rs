//! Exact geometric predicates (Shewchuk's adaptive arithmetic via the
//! `robust` crate). Every side-of-line / side-of-plane decision in zoovr goes
//! through these and returns an enum, never a float compared to a tolerance.

use glam::{DVec2, DVec3};

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

#[cfg(test)]
mod tests {
    use super::*;

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
