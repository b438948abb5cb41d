//! Exact Williams-Max segment integrals and pre-integration tables.
//!
//! The interface every renderer uses is [`RayMaterial`]: the exact integral
//! of one segment over which the scalar is linear, the transfer function's
//! breakpoints, and the material at one scalar value. Segments composite
//! front to back with [`RayAccumulator`].
//!
//! Submodules: [`weights`](mod@weights) (basis integrals of one linear piece, the ported
//! closed form), `segment` (slicing at breakpoints, whole segments and
//! rays, per-vertex values for the exact GPU mode), [`table3d`], [`table2d`]
//! and [`cylinder`] (pre-integration tables filled from the exact integrals),
//! [`fast`] (integral functions for approximate fills and local updates).

pub mod cylinder;
pub mod fast;
pub mod grid;
mod segment;
pub mod table2d;
pub mod table3d;
pub(crate) mod tables_sf;
pub mod weights;

pub use grid::TableError;
pub use segment::{ray, segment, vertex_values, VertexValues};
pub use weights::{weights, Regime, Weights};

/// Colour and opacity of one ray segment: premultiplied colour `C` (the
/// segment's own light at its front), opacity `alpha = 1 - exp(-depth)` and
/// optical depth `depth`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentValue {
    pub color: [f64; 3],
    pub alpha: f64,
    pub depth: f64,
}

/// Extinction `tau` (per unit length) and source term `g` (radiance per unit
/// length: `tau * colour` for glow, `E` for independent emission) at a scalar.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Material {
    pub tau: f64,
    pub source: [f64; 3],
}

/// What a renderer needs from a transfer function.
pub trait RayMaterial: Sync {
    /// Exact integral over a segment of length `l` on which the scalar goes
    /// linearly from `s_f` (front) to `s_b` (back), sliced at breakpoints.
    fn segment(&self, l: f64, s_f: f64, s_b: f64) -> SegmentValue;
    /// Sorted scalar values where the transfer function's pieces meet.
    fn breakpoints(&self) -> &[f64];
    /// Material at scalar `s` (right-continuous at jumps).
    fn material(&self, s: f64) -> Material;
}

/// Front-to-back compositing of segments along one ray. Accumulates optical
/// depth (not transmittance) so thin rays keep full precision.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayAccumulator {
    pub color: [f64; 3],
    pub depth: f64,
}

impl RayAccumulator {
    /// Adds a segment behind everything accumulated so far.
    #[inline]
    pub fn add(&mut self, s: &SegmentValue) {
        let t = (-self.depth).exp();
        for k in 0..3 {
            self.color[k] += t * s.color[k];
        }
        self.depth += s.depth;
    }

    /// Opacity of the accumulated ray.
    #[inline]
    pub fn alpha(&self) -> f64 {
        -(-self.depth).exp_m1()
    }

    /// Premultiplied RGBA.
    pub fn rgba(&self) -> [f32; 4] {
        [
            self.color[0] as f32,
            self.color[1] as f32,
            self.color[2] as f32,
            self.alpha() as f32,
        ]
    }
}
