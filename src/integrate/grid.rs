//! Sample grids shared by the pre-integration tables: a uniform axis whose
//! samples sit exactly on texel centres, and the interpolation the GPU does.
//!
//! Axis `i` of a table with `n` samples over `[lo, hi]` holds the value at
//! `lo + i (hi - lo) / (n - 1)`. A GPU samples it with linear filtering and
//! clamp-to-edge at the normalised texture coordinate
//! `u = ((v - lo) / (hi - lo) (n - 1) + 0.5) / n`; the CPU `lookup`s
//! reproduce that: clamp to the range, then linear weights between the two
//! neighbouring samples (in f64; a GPU's filter weights are coarser).

use thiserror::Error;

/// Invalid table parameters.
#[derive(Debug, Error, PartialEq)]
pub enum TableError {
    #[error("table dimension {name} must be at least 2 (got {value})")]
    Dimension { name: &'static str, value: usize },
    #[error("table dimension {name} = {value} is too large")]
    TooLarge { name: &'static str, value: usize },
    #[error("table range {name} must be finite and non-empty (got {lo}..{hi})")]
    Range {
        name: &'static str,
        lo: f64,
        hi: f64,
    },
}

/// Largest table side accepted (a 4096^3 RGBA table would be 1 TiB).
const MAX_SIDE: usize = 4096;
/// Largest total texel count accepted (256 Mi texels = 4 GiB of f32 RGBA).
const MAX_TEXELS: usize = 1 << 28;

/// One uniform axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub n: usize,
}

impl Axis {
    pub(crate) fn new(name: &'static str, lo: f64, hi: f64, n: usize) -> Result<Self, TableError> {
        if n < 2 {
            return Err(TableError::Dimension { name, value: n });
        }
        if n > MAX_SIDE {
            return Err(TableError::TooLarge { name, value: n });
        }
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return Err(TableError::Range { name, lo, hi });
        }
        Ok(Self { lo, hi, n })
    }

    /// Value at sample `i`.
    #[inline]
    pub fn sample(&self, i: usize) -> f64 {
        if i + 1 >= self.n {
            self.hi
        } else {
            self.lo + (self.hi - self.lo) * (i as f64 / (self.n - 1) as f64)
        }
    }

    /// All sample values.
    pub fn samples(&self) -> Vec<f64> {
        (0..self.n).map(|i| self.sample(i)).collect()
    }

    /// Lower sample index and linear weight of the upper one, clamped.
    #[inline]
    pub fn locate(&self, v: f64) -> (usize, f64) {
        let x = (v - self.lo) / (self.hi - self.lo) * (self.n - 1) as f64;
        if x.is_nan() || x <= 0.0 {
            return (0, 0.0);
        }
        let top = (self.n - 2) as f64;
        if x >= top + 1.0 {
            return (self.n - 2, 1.0);
        }
        let i = x.floor().min(top);
        (i as usize, x - i)
    }

    /// Normalised GPU texture coordinate of value `v`.
    pub fn texcoord(&self, v: f64) -> f64 {
        let x = ((v - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0);
        (x * (self.n - 1) as f64 + 0.5) / self.n as f64
    }
}

pub(crate) fn check_total(name: &'static str, dims: &[usize]) -> Result<usize, TableError> {
    let mut total: usize = 1;
    for &d in dims {
        total = total.saturating_mul(d);
    }
    if total > MAX_TEXELS {
        return Err(TableError::TooLarge { name, value: total });
    }
    Ok(total)
}

/// Linear interpolation of two RGBA texels.
#[inline]
pub(crate) fn lerp4(a: [f64; 4], b: [f64; 4], w: f64) -> [f64; 4] {
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * w)
}

/// Reads texel `i` of an RGBA f32 array as f64.
#[inline]
pub(crate) fn texel(data: &[f32], i: usize) -> [f64; 4] {
    match data.get(4 * i..4 * i + 4) {
        Some(t) => [t[0] as f64, t[1] as f64, t[2] as f64, t[3] as f64],
        None => [0.0; 4],
    }
}

/// Bilinear lookup in an `nx x ny` RGBA layer starting at texel `base`.
#[inline]
pub(crate) fn bilinear(
    data: &[f32],
    base: usize,
    nx: usize,
    ix: (usize, f64),
    iy: (usize, f64),
) -> [f64; 4] {
    let row = |j: usize| {
        let a = texel(data, base + j * nx + ix.0);
        let b = texel(data, base + j * nx + ix.0 + 1);
        lerp4(a, b, ix.1)
    };
    lerp4(row(iy.0), row(iy.0 + 1), iy.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_locates_samples_and_clamps() {
        let a = Axis::new("x", 1.0, 3.0, 5).unwrap();
        assert_eq!(a.sample(2), 2.0);
        assert_eq!(a.locate(2.0), (2, 0.0));
        assert_eq!(a.locate(2.25), (2, 0.5));
        assert_eq!(a.locate(-7.0), (0, 0.0));
        assert_eq!(a.locate(3.0), (3, 1.0));
        assert_eq!(a.locate(f64::NAN), (0, 0.0));
        assert!((a.texcoord(1.0) - 0.1).abs() < 1e-15);
        assert!((a.texcoord(3.0) - 0.9).abs() < 1e-15);
        assert!(Axis::new("x", 1.0, 1.0, 5).is_err());
        assert!(Axis::new("x", 0.0, 1.0, 1).is_err());
    }
}
