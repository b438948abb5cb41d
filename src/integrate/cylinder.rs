//! The "cylindrical" 2D re-mapping of the 3D pre-integration table
//! (Röttger, Ertl 2002, section 4, equations 9 and 10; docs/math.md 8.5).
//!
//! In normalised coordinates (`S_f, S_b` = scalar mapped from the table range
//! onto [0, 1], `L = l / l_max`) every fragment of one projected tetrahedron
//! lies in one half-plane through the axis of zero-length segments
//! `{S_f = S_b, L = 0}`. The paper parameterises these half-planes by
//! `a in [0, 1]` and projects each onto the nearest of the planes
//! `a = 0, 1/2, 1`, which gives equally sized square 2D textures:
//!
//! ```text
//! f: (a, u, v) -> (S_f, S_b, L)                     (eq. 9)
//!   a in [0, 1/4]:   (v + u,               v, 4 a u)
//!   a in [1/4, 1/2]: (v + 4 (1/2 - a) u,   v, u)
//!   a in [1/2, 3/4]: (v - 4 (a - 1/2) u,   v, u)
//!   a in [3/4, 1]:   (v - u,               v, 4 (1 - a) u)
//! f^-1: (S_f, S_b, L) -> (a, u, v), d = S_f - S_b    (eq. 10)
//!   d >= 0, L <= d:  (L / (4 d),        d,  S_b)
//!   d >= 0, L >  d:  (1/2 - d / (4 L),  L,  S_b)
//!   d <  0, L >= -d: (1/2 - d / (4 L),  L,  S_b)
//!   d <  0, L < -d:  (1 + L / (4 d),   -d,  S_b)
//! ```
//!
//! (the paper's `s, t` are `u, v` here; its third and fourth cases are
//! written with `S_b - S_f`). `n_a` planes at `a_k = k / (n_a - 1)`, each
//! `ns x ns` over `u, v in [0, 1]`, are filled from the exact integrals
//! (`S_f` may leave [0, 1] there: those texels are the exact integral of the
//! constant extension and are only reached by interpolation). A lookup
//! blends the two nearest planes: trilinear in `(a, u, v)`. Layout: RGBA
//! `f32`, `u` fastest, then `v`, then the plane: a 2D array texture with one
//! layer per plane. The paper recommends `n_a = 4 ns` for an exact
//! reconstruction of the 3D table, and notes `ns` to `2 ns` are usually
//! enough.

use rayon::prelude::*;

use super::grid::{bilinear, check_total, lerp4, Axis, TableError};
use super::segment::segment;
use super::table3d::Table3d;
use crate::tf::TransferFunction;

/// The cylindrical table (see the module docs).
#[derive(Clone, Debug)]
pub struct CylinderTable {
    pub s_axis: Axis,
    pub l_max: f64,
    /// Number of planes `n_a`.
    pub planes: usize,
    /// RGBA f32, index `((p * ns + v) * ns + u) * 4`.
    pub data: Vec<f32>,
}

/// Equation 9: plane parameter and in-plane coordinates to normalised
/// `(S_f, S_b, L)`.
pub fn cyl_to_table(a: f64, u: f64, v: f64) -> (f64, f64, f64) {
    if a <= 0.25 {
        (v + u, v, 4.0 * a * u)
    } else if a <= 0.5 {
        (v + 4.0 * (0.5 - a) * u, v, u)
    } else if a <= 0.75 {
        (v - 4.0 * (a - 0.5) * u, v, u)
    } else {
        (v - u, v, 4.0 * (1.0 - a) * u)
    }
}

/// Equation 10: normalised `(S_f, S_b, L)` to `(a, u, v)`.
pub fn table_to_cyl(sf: f64, sb: f64, l: f64) -> (f64, f64, f64) {
    let d = sf - sb;
    if d >= 0.0 {
        if l <= d {
            if d > 0.0 {
                (l / (4.0 * d), d, sb)
            } else {
                (0.0, 0.0, sb) // zero-length segment on the axis
            }
        } else {
            (0.5 - d / (4.0 * l), l, sb)
        }
    } else if l >= -d {
        (0.5 - d / (4.0 * l), l, sb)
    } else {
        (1.0 + l / (4.0 * d), -d, sb)
    }
}

/// The exact segment integral as RGBA (premultiplied colour, opacity).
fn exact_rgba(tf: &TransferFunction, s_f: f64, s_b: f64, l: f64) -> [f64; 4] {
    let v = segment(tf, l, s_f, s_b);
    [v.color[0], v.color[1], v.color[2], v.alpha]
}

impl CylinderTable {
    /// Exact fill: `planes` planes of `ns x ns` texels for scalars in
    /// `s_range` and lengths in `[0, l_max]`.
    pub fn new(
        tf: &TransferFunction,
        ns: usize,
        planes: usize,
        s_range: (f64, f64),
        l_max: f64,
    ) -> Result<Self, TableError> {
        let s_axis = Axis::new("scalar", s_range.0, s_range.1, ns)?;
        Axis::new("length", 0.0, l_max, 2)?;
        Axis::new("planes", 0.0, 1.0, planes)?;
        let total = check_total("cylindrical table", &[ns, ns, planes])?;
        let mut t = Self {
            s_axis,
            l_max,
            planes,
            data: vec![0.0f32; 4 * total],
        };
        t.fill(|sf, sb, l| Some(exact_rgba(tf, sf, sb, l)));
        Ok(t)
    }

    /// The re-mapping of a 3D table (RE section 4): every texel is the 3D
    /// table's trilinear lookup at its equation-9 coordinates, so the result
    /// carries the 3D table's values in `planes` 2D layers. Scalars and
    /// length are those of the 3D table.
    pub fn from_table3d(t3: &Table3d, planes: usize) -> Result<Self, TableError> {
        let ns = t3.s_axis.n;
        Axis::new("planes", 0.0, 1.0, planes)?;
        let total = check_total("cylindrical table", &[ns, ns, planes])?;
        let mut t = Self {
            s_axis: t3.s_axis,
            l_max: t3.l_axis.hi,
            planes,
            data: vec![0.0f32; 4 * total],
        };
        t.fill(|sf, sb, l| Some(t3.lookup(sf, sb, l)));
        Ok(t)
    }

    /// Local update after a transfer-function change confined to the scalar
    /// interval `[a, b]` (either order): only texels whose segment's scalar
    /// interval meets it are recomputed from the exact integral of `tf`.
    pub fn update(&mut self, tf: &TransferFunction, a: f64, b: f64) {
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.fill(|sf, sb, l| {
            (sf.min(sb) <= b && sf.max(sb) >= a).then(|| exact_rgba(tf, sf, sb, l))
        });
    }

    /// Sets every texel for which `value(s_f, s_b, l)` (absolute scalars and
    /// length at the texel's equation-9 coordinates) gives `Some`.
    fn fill(&mut self, value: impl Fn(f64, f64, f64) -> Option<[f64; 4]> + Sync) {
        let ns = self.s_axis.n;
        let planes = self.planes;
        let (lo, w) = (self.s_axis.lo, self.s_axis.hi - self.s_axis.lo);
        let l_max = self.l_max;
        let step = 1.0 / (ns - 1) as f64;
        self.data
            .par_chunks_mut(4 * ns)
            .enumerate()
            .for_each(|(row, out)| {
                let p = row / ns;
                let v = (row % ns) as f64 * step;
                let a = p as f64 / (planes - 1) as f64;
                for iu in 0..ns {
                    let u = iu as f64 * step;
                    let (sf, sb, l) = cyl_to_table(a, u, v);
                    if let Some(t) = value(lo + sf * w, lo + sb * w, l * l_max) {
                        out[4 * iu..4 * iu + 4].copy_from_slice(&t.map(|x| x as f32));
                    }
                }
            });
    }

    /// Lookup of a segment: equation 10, then bilinear in each of the two
    /// nearest planes and linear between them.
    pub fn lookup(&self, s_f: f64, s_b: f64, l: f64) -> [f64; 4] {
        let w = self.s_axis.hi - self.s_axis.lo;
        let sf = ((s_f - self.s_axis.lo) / w).clamp(0.0, 1.0);
        let sb = ((s_b - self.s_axis.lo) / w).clamp(0.0, 1.0);
        let l = (l / self.l_max).clamp(0.0, 1.0);
        let (a, u, v) = table_to_cyl(sf, sb, l);
        let unit = |n: usize| Axis {
            lo: 0.0,
            hi: 1.0,
            n,
        };
        let ns = self.s_axis.n;
        let (iu, iv) = (unit(ns).locate(u), unit(ns).locate(v));
        let (p, wp) = unit(self.planes).locate(a);
        let layer = |p: usize| bilinear(&self.data, p * ns * ns, ns, iu, iv);
        lerp4(layer(p), layer(p + 1), wp)
    }

    /// The texel data as bytes, for a texture upload.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equations_9_and_10_are_inverse() {
        for &(sf, sb, l) in &[
            (0.7, 0.2, 0.1),
            (0.7, 0.2, 0.9),
            (0.2, 0.7, 0.9),
            (0.2, 0.7, 0.1),
            (0.4, 0.4, 0.3),
            (0.5, 0.1, 0.4),
        ] {
            let (a, u, v) = table_to_cyl(sf, sb, l);
            assert!((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&u));
            let (x, y, z) = cyl_to_table(a, u, v);
            assert!((x - sf).abs() < 1e-14 && (y - sb).abs() < 1e-14 && (z - l).abs() < 1e-14);
        }
        assert_eq!(table_to_cyl(0.3, 0.3, 0.0), (0.0, 0.0, 0.3));
    }
}
