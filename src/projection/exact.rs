//! Exact signs of small polynomials in `f64` coordinates, for the few
//! arrangement decisions that are not a single `orient2d` (the order of two
//! crossings along a piece when all three pieces cross each other).
//!
//! Values are Shewchuk expansions: sums of nonoverlapping doubles in
//! increasing magnitude, built with error-free transformations (`two_sum`,
//! `two_product` via a fused multiply-add), so sums and products are exact
//! and the sign is that of the largest component. Exact as long as no
//! intermediate product underflows or overflows (the same assumption as the
//! `robust` predicates); allocation only happens on this rare path.

use glam::DVec2;

use crate::numeric::predicates::Side;

/// An exact sum of doubles (nonoverlapping, increasing magnitude, no zeros).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Expansion(Vec<f64>);

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    (x, a.mul_add(b, -x))
}

impl Expansion {
    /// The exact value of `a - b`.
    pub(crate) fn diff(a: f64, b: f64) -> Expansion {
        let mut e = Expansion::default();
        e.grow(a);
        e.grow(-b);
        e
    }

    /// Adds `b` exactly (Shewchuk's GROW-EXPANSION with zero elimination).
    fn grow(&mut self, b: f64) {
        if b == 0.0 {
            return;
        }
        let mut q = b;
        let mut k = 0;
        for i in 0..self.0.len() {
            let (x, h) = two_sum(q, self.0[i]);
            q = x;
            if h != 0.0 {
                self.0[k] = h;
                k += 1;
            }
        }
        self.0.truncate(k);
        if q != 0.0 {
            self.0.push(q);
        }
    }

    /// `self + other`, exactly.
    pub(crate) fn add(&self, other: &Expansion) -> Expansion {
        let mut s = self.clone();
        for &c in &other.0 {
            s.grow(c);
        }
        s
    }

    /// `self - other`, exactly.
    pub(crate) fn sub(&self, other: &Expansion) -> Expansion {
        let mut s = self.clone();
        for &c in &other.0 {
            s.grow(-c);
        }
        s
    }

    /// `self * other`, exactly.
    pub(crate) fn mul(&self, other: &Expansion) -> Expansion {
        let mut s = Expansion::default();
        for &a in &self.0 {
            for &b in &other.0 {
                let (x, y) = two_product(a, b);
                s.grow(y);
                s.grow(x);
            }
        }
        s
    }

    /// The exact sign: that of the largest component.
    pub(crate) fn sign(&self) -> Side {
        match self.0.iter().rev().find(|&&c| c != 0.0) {
            Some(&c) if c > 0.0 => Side::Positive,
            Some(_) => Side::Negative,
            None => Side::On,
        }
    }
}

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
    fn expansion_arithmetic_is_exact() {
        // (1 + 2^-60) - 1 = 2^-60, lost in plain f64 subtraction of a sum.
        let a = Expansion::diff(1.0, -(2f64).powi(-60));
        let b = a.sub(&Expansion::diff(1.0, 0.0));
        assert_eq!(b.0, vec![(2f64).powi(-60)]);
        // (1 + 2^-30)^2 - (1 + 2^-29) = 2^-60 > 0.
        let x = Expansion::diff(1.0, -(2f64).powi(-30));
        let y = x.mul(&x).sub(&Expansion::diff(1.0, -(2f64).powi(-29)));
        assert_eq!(y.sign(), Side::Positive);
        assert_eq!(y.0, vec![(2f64).powi(-60)]);
        assert_eq!(x.sub(&x).sign(), Side::On);
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
