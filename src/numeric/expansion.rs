//! Shewchuk expansion arithmetic: a value is an exact sum of nonoverlapping
//! doubles in increasing magnitude, built with error-free transformations
//! (`two_sum`, `two_product` via a fused multiply-add), so sums and products
//! are exact and the sign is that of the largest component. Exact as long as
//! no intermediate product underflows or overflows (the same assumption as
//! the `robust` predicates). Used by the predicates that are not a single
//! `orient2d`/`orient3d`: [`super::predicates::orient_dir`] and the
//! crossing order of the projection's arrangement. These are rare fallbacks
//! behind float filters, so the simple allocating form is enough.

use super::predicates::Side;

/// An exact sum of doubles (nonoverlapping, increasing magnitude, no zeros).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expansion(Vec<f64>);

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
    /// The exact value of `a`.
    pub fn from_f64(a: f64) -> Expansion {
        let mut e = Expansion::default();
        e.grow(a);
        e
    }

    /// The exact value of `a - b`.
    pub fn diff(a: f64, b: f64) -> Expansion {
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
    pub fn add(&self, other: &Expansion) -> Expansion {
        let mut s = self.clone();
        for &c in &other.0 {
            s.grow(c);
        }
        s
    }

    /// `self - other`, exactly.
    pub fn sub(&self, other: &Expansion) -> Expansion {
        let mut s = self.clone();
        for &c in &other.0 {
            s.grow(-c);
        }
        s
    }

    /// `self * other`, exactly.
    pub fn mul(&self, other: &Expansion) -> Expansion {
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
    pub fn sign(&self) -> Side {
        match self.0.iter().rev().find(|&&c| c != 0.0) {
            Some(&c) if c > 0.0 => Side::Positive,
            Some(_) => Side::Negative,
            None => Side::On,
        }
    }
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
}
