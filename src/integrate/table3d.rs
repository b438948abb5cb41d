//! The 3D pre-integration table over `(s_f, s_b, l)` (Röttger, Kraus, Ertl
//! 2000, section 3), filled from the exact integrals.
//!
//! Texel `(i, j, k)` holds the exact premultiplied colour and opacity of a
//! segment of length `l_k` over which the scalar goes linearly from `s_i` to
//! `s_j` (axes as in [`super::grid`]: samples on texel centres, `l_0 = 0`).
//! Storage is RGBA `f32`, `s_f` fastest, then `s_b`, then `l`: exactly the
//! layout of a `width = ns, height = ns, depth = nl` 3D texture
//! (`Rgba32Float`). [`Table3d::lookup`] does the GPU's trilinear filtering
//! on the CPU.
//!
//! Fills are parallel over `l` slices (rayon). [`Table3d::fast`] fills from
//! the integral functions of [`super::fast`] instead (EKE 3.5, approximate
//! colour, exact opacity). [`Table3d::update`] recomputes only the texels
//! whose scalar interval meets `[a, b]`, which is all a transfer-function
//! edit confined to `[a, b]` can change (a segment's integral depends only
//! on the transfer function between its two scalars).

use rayon::prelude::*;

use super::fast::{approx_rgba, point_source, FastColour, IntegralFunctions};
use super::grid::{check_total, lerp4, texel, Axis, TableError};
use super::segment::segment;
use crate::numeric::tolerance::INTEGRAL_FUNCTION_MIN_DS_REL;
use crate::tf::TransferFunction;

/// How a table's texels were computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Exact segment integrals.
    Exact,
    /// Integral functions with the given colour rule.
    Fast(FastColour),
}

/// A 3D pre-integration table (see the module docs).
#[derive(Clone, Debug)]
pub struct Table3d {
    pub s_axis: Axis,
    pub l_axis: Axis,
    pub fill: Fill,
    /// RGBA f32, index `((k * ns + j) * ns + i) * 4`.
    pub data: Vec<f32>,
}

impl Table3d {
    /// Exact fill: `ns x ns x nl` texels over `s in s_range`, `l in [0, l_max]`.
    pub fn exact(
        tf: &TransferFunction,
        ns: usize,
        nl: usize,
        s_range: (f64, f64),
        l_max: f64,
    ) -> Result<Self, TableError> {
        let mut t = Self::empty(ns, nl, s_range, l_max, Fill::Exact)?;
        t.refill(tf, f64::NEG_INFINITY, f64::INFINITY);
        Ok(t)
    }

    /// Approximate fill from the integral functions (EKE section 3.5).
    pub fn fast(
        tf: &TransferFunction,
        ns: usize,
        nl: usize,
        s_range: (f64, f64),
        l_max: f64,
        rule: FastColour,
    ) -> Result<Self, TableError> {
        let mut t = Self::empty(ns, nl, s_range, l_max, Fill::Fast(rule))?;
        t.refill(tf, f64::NEG_INFINITY, f64::INFINITY);
        Ok(t)
    }

    fn empty(
        ns: usize,
        nl: usize,
        s_range: (f64, f64),
        l_max: f64,
        fill: Fill,
    ) -> Result<Self, TableError> {
        let s_axis = Axis::new("scalar", s_range.0, s_range.1, ns)?;
        let l_axis = Axis::new("length", 0.0, l_max, nl)?;
        let total = check_total("3D table", &[ns, ns, nl])?;
        Ok(Self {
            s_axis,
            l_axis,
            fill,
            data: vec![0.0; 4 * total],
        })
    }

    /// Recomputes the texels whose scalar interval meets `[a, b]` after the
    /// transfer function changed only there (same fill method as before).
    pub fn update(&mut self, tf: &TransferFunction, a: f64, b: f64) {
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.refill(tf, a, b);
    }

    fn refill(&mut self, tf: &TransferFunction, a: f64, b: f64) {
        let ns = self.s_axis.n;
        let s = self.s_axis.samples();
        let ls = self.l_axis.samples();
        let touched = |i: usize, j: usize| s[i].min(s[j]) <= b && s[i].max(s[j]) >= a;
        match self.fill {
            Fill::Exact => {
                self.data
                    .par_chunks_mut(4 * ns * ns)
                    .zip(ls.par_iter())
                    .for_each(|(slice, &l)| {
                        for j in 0..ns {
                            for i in 0..ns {
                                if !touched(i, j) {
                                    continue;
                                }
                                let v = segment(tf, l, s[i], s[j]);
                                let o = 4 * (j * ns + i);
                                slice[o..o + 4].copy_from_slice(&[
                                    v.color[0] as f32,
                                    v.color[1] as f32,
                                    v.color[2] as f32,
                                    v.alpha as f32,
                                ]);
                            }
                        }
                    });
            }
            Fill::Fast(rule) => {
                let f = IntegralFunctions::new(tf);
                let ends: Vec<_> = s.iter().map(|&x| f.eval(x)).collect();
                let min_ds = INTEGRAL_FUNCTION_MIN_DS_REL * (self.s_axis.hi - self.s_axis.lo);
                self.data
                    .par_chunks_mut(4 * ns * ns)
                    .zip(ls.par_iter())
                    .for_each(|(slice, &l)| {
                        for j in 0..ns {
                            for i in 0..ns {
                                if !touched(i, j) {
                                    continue;
                                }
                                let v = approx_rgba(
                                    l,
                                    s[j] - s[i],
                                    (ends[i], ends[j]),
                                    || point_source(tf, 0.5 * (s[i] + s[j])),
                                    min_ds,
                                    rule,
                                );
                                let o = 4 * (j * ns + i);
                                slice[o..o + 4].copy_from_slice(&v.map(|x| x as f32));
                            }
                        }
                    });
            }
        }
    }

    /// Texel `(i, j, k)` as f64 RGBA (zero outside the table).
    pub fn texel(&self, i: usize, j: usize, k: usize) -> [f64; 4] {
        let ns = self.s_axis.n;
        if i >= ns || j >= ns || k >= self.l_axis.n {
            return [0.0; 4];
        }
        texel(&self.data, (k * ns + j) * ns + i)
    }

    /// Trilinear lookup (clamped), as the GPU filters the texture:
    /// `[r, g, b, alpha]`, premultiplied.
    pub fn lookup(&self, s_f: f64, s_b: f64, l: f64) -> [f64; 4] {
        let (i, wi) = self.s_axis.locate(s_f);
        let (j, wj) = self.s_axis.locate(s_b);
        let (k, wk) = self.l_axis.locate(l);
        let plane = |k: usize| {
            let r0 = lerp4(self.texel(i, j, k), self.texel(i + 1, j, k), wi);
            let r1 = lerp4(self.texel(i, j + 1, k), self.texel(i + 1, j + 1, k), wi);
            lerp4(r0, r1, wj)
        };
        lerp4(plane(k), plane(k + 1), wk)
    }

    /// The texel data as bytes, for a texture upload.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.data)
    }

    /// `(width, height, depth)` of the 3D texture.
    pub fn extent(&self) -> (u32, u32, u32) {
        (
            self.s_axis.n as u32,
            self.s_axis.n as u32,
            self.l_axis.n as u32,
        )
    }
}
