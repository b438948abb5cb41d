//! Exact signs of small polynomials in `f64` coordinates, for the few
//! arrangement decisions that are not a single `orient2d` (the order of two
//! crossings along a piece when all three pieces cross each other).
//!
//! Values are [`Expansion`]s (exact sums of doubles, shared with the
//! visibility predicates); allocation only happens on this rare path.

use glam::DVec2;

use crate::numeric::expansion::Expansion;
use crate::numeric::predicates::Side;

/// An exact 2D vector: the difference of two points.
#[derive(Clone, Debug)]
pub(crate) struct ExactVec {
    x: Expansion,
    y: Expansion,
}

impl ExactVec {
    /// `b - a`, exactly.
    pub(crate) fn between(a: DVec2, b: DVec2) -> ExactVec {
        ExactVec {
            x: Expansion::diff(b.x, a.x),
            y: Expansion::diff(b.y, a.y),
        }
    }

    /// The cross product `self.x * o.y - self.y * o.x`, exactly.
    pub(crate) fn cross(&self, o: &ExactVec) -> Expansion {
        self.x.mul(&o.y).sub(&self.y.mul(&o.x))
    }
}

/// Exact side of the crossing point `Y` of the lines `q1a q1b` and `q2a q2b`
/// relative to the directed line `p0 -> p1`, times the sign of
/// `cross(q1b - q1a, q2b - q2a)`: the sign of
/// `cross(d, q1a - p0) cross(e1, e2) + cross(q2a - q1a, e2) cross(d, e1)`
/// with `d = p1 - p0`, `e_i = q_ib - q_ia` (`On` when the three lines meet in
/// one point or `q1, q2` are parallel).
pub(crate) fn crossing_side_times_turn(p: [DVec2; 2], q1: [DVec2; 2], q2: [DVec2; 2]) -> Side {
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
