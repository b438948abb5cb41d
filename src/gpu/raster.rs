//! The rasteriser's geometry, common to every stage: the pixel ->
//! clip-space mapping, the sub-pixel grid, and the [`GpuVertex`] trait
//! every stage's vertex implements (the piece keys are in
//! [`super::common`]).
//!
//! [`ClipMapper`] builds clip-space positions from continuous pixel
//! coordinates `(px, py)` (row 0 at the top, pixel centres at `i + 0.5`, as in
//! [`crate::camera::Camera::view_to_pixel`]) and the view depth `z`: the
//! position is snapped to the rasteriser's sub-pixel grid ([`SUBPIXEL`]) and
//! mapped to `ndc = (2 px / S - 1, 1 - 2 py / S)` for the square viewport
//! of side `S` ([`raster_side`], a power of two), which makes the mapping
//! exact in `f32` both ways; wgpu's viewport maps NDC x = -1 to the
//! left edge of column 0 and y = +1 to the top edge of row 0, and the
//! rasteriser samples pixel centres, so the pixel whose centre is at `(px, py)`
//! samples exactly that point. Perspective: `w = z` (and `x, y` scaled by
//! `z`), so the hardware's perspective-correct interpolation makes every
//! varying affine in view space on the triangle; orthographic: `w = 1`, i.e.
//! affine in screen space. Clip z is `w / 2`: always inside the clip volume
//! (the depth test compares the piece key the fragment writes).

use bytemuck::Pod;

use crate::camera::Camera;

/// A vertex a stage draws: the Rust mirror of a shader's `VertexIn`
/// (`#[repr(C)]`, [`Pod`]), with what the frame and the CPU twin need to
/// know of every vertex type.
pub trait GpuVertex: Pod + Send + Sync {
    /// Clip-space position (x, y, z, w); see [`ClipMapper`].
    fn clip(&self) -> [f32; 4];
    /// The piece this vertex's triangles belong to, numbered in drawing
    /// order ([`super::common::piece_depth`]).
    fn piece(&self) -> u32;
    /// This vertex in piece `piece`.
    fn with_piece(self, piece: u32) -> Self;
    /// Whether every value the shader reads is finite.
    fn is_finite(&self) -> bool;
    /// This vertex at clip position `clip`.
    fn with_clip(self, clip: [f32; 4]) -> Self;
    /// The attributes at barycentric weights `bary` of `tri`, interpolated
    /// as the rasteriser does (linearly: the projected-cell modes send
    /// `w = 1`); position and piece of `tri[0]`.
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self;
    /// This vertex with attributes that make the stage draw nothing
    /// (premultiplied colour and opacity 0) but still pass the depth test.
    fn transparent(self) -> Self;
}

/// Sub-pixel grid of the rasteriser: positions are snapped to 1/`SUBPIXEL`
/// pixel (8 bits, what lavapipe, llvmpipe and the desktop drivers use).
pub const SUBPIXEL: f64 = 256.0;

/// Pixels between the image and the viewport's edges on every side: more
/// than the margin to which the projection clips regions
/// ([`crate::numeric::tolerance::IMAGE_CLIP_MARGIN_PX`]), so the GPU never
/// clips a triangle (clipping would make corners off the sub-pixel grid).
pub const RASTER_BORDER: u32 = 8;

/// The side of the square viewport (and render target) for a `width x
/// height` image: the next power of two of the larger side plus a border
/// of [`RASTER_BORDER`] on each side. With it, a position on the sub-pixel
/// grid has an exact `f32` NDC value, and the rasteriser's viewport
/// transform (`ndc * side/2 + side/2`, in `f32`) gives back exactly that
/// position: the GPU draws the triangles the CPU decided on, so no
/// snapping moves a corner, and a covered pixel centre is inside the very
/// triangle whose corners the attributes are interpolated from (no
/// extrapolation on slivers). The image is the `width x height` rectangle
/// at `(RASTER_BORDER, RASTER_BORDER)` of the viewport, which the frame
/// places that far up and left of its `width x height` target (viewports
/// may extend past the attachment), so the target holds just the image.
pub fn raster_side(width: u32, height: u32) -> u32 {
    (width.max(height).max(1) + 2 * RASTER_BORDER).next_power_of_two()
}

/// Maps continuous pixel coordinates and view depth to clip space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipMapper {
    pub width: u32,
    pub height: u32,
    pub ortho: bool,
    /// [`raster_side`] of the image.
    pub side: u32,
}

impl ClipMapper {
    /// For an image of `width x height`; `ortho` selects w = 1.
    pub fn new(width: u32, height: u32, ortho: bool) -> ClipMapper {
        ClipMapper {
            width,
            height,
            ortho,
            side: raster_side(width, height),
        }
    }

    /// For the image and projection of `camera`.
    pub fn for_camera(camera: &Camera) -> ClipMapper {
        ClipMapper::new(camera.width, camera.height, camera.ortho)
    }

    /// A pixel coordinate snapped to the sub-pixel grid, in grid units
    /// (`None` when not finite or beyond 2^40 units, ~4e9 pixels).
    #[inline]
    pub fn snap(p: f64) -> Option<i64> {
        let v = (p * SUBPIXEL).round();
        (v.abs() < (1u64 << 40) as f64).then_some(v as i64)
    }

    /// NDC of continuous pixel `(px, py)` snapped to the sub-pixel grid
    /// (exact in `f32` within `±2^24 / SUBPIXEL` pixels of the image; see
    /// [`raster_side`]), with the snapped grid position; `None` for
    /// non-finite or absurdly distant input.
    #[inline]
    pub fn ndc(&self, px: f64, py: f64) -> Option<([f32; 2], [i64; 2])> {
        let (gx, gy) = (Self::snap(px)?, Self::snap(py)?);
        let scale = 2.0 / (SUBPIXEL * self.side as f64);
        let b = RASTER_BORDER as f64 * SUBPIXEL;
        let nx = (gx as f64 + b) * scale - 1.0;
        let ny = 1.0 - (gy as f64 + b) * scale;
        Some(([nx as f32, ny as f32], [gx, gy]))
    }

    /// Clip position of continuous pixel `(px, py)` at view depth `z`
    /// (ignored for orthographic). `None` for a perspective point not in front
    /// of the eye (`z <= 0`; clip such pieces at the near plane first), for
    /// non-finite input or an empty image.
    pub fn clip(&self, px: f64, py: f64, z: f64) -> Option<[f32; 4]> {
        if self.width == 0 || self.height == 0 {
            return None;
        }
        let ([nx, ny], _) = self.ndc(px, py)?;
        let w = if self.ortho {
            1.0
        } else if z > 0.0 && z.is_finite() {
            z
        } else {
            return None;
        };
        let out = [
            (nx as f64 * w) as f32,
            (ny as f64 * w) as f32,
            (0.5 * w) as f32,
            w as f32,
        ];
        out.iter().all(|v| v.is_finite()).then_some(out)
    }

    /// Clip position of a camera-relative point (see
    /// [`Camera::to_view`]); `None` behind the near plane.
    pub fn clip_view(&self, camera: &Camera, view: glam::DVec3) -> Option<[f32; 4]> {
        let (px, py, z) = camera.view_to_pixel(view)?;
        self.clip(px, py, z)
    }

    /// Inverse of [`Self::clip`]: continuous pixel coordinates of a clip
    /// position (after the perspective divide, as the rasteriser sees it).
    pub fn pixel_of(&self, pos: [f32; 4]) -> (f64, f64) {
        let w = pos[3] as f64;
        let nx = pos[0] as f64 / w;
        let ny = pos[1] as f64 / w;
        let b = RASTER_BORDER as f64;
        (
            (nx + 1.0) * 0.5 * self.side as f64 - b,
            (1.0 - ny) * 0.5 * self.side as f64 - b,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraParams;

    #[test]
    fn pixel_centres_round_trip() {
        for ortho in [false, true] {
            let m = ClipMapper::new(300, 200, ortho);
            let p = m.clip(10.5, 199.5, 7.25).unwrap();
            let (px, py) = m.pixel_of(p);
            assert!((px - 10.5).abs() < 1e-4 && (py - 199.5).abs() < 1e-4);
            assert_eq!(p[3], if ortho { 1.0 } else { 7.25 });
            assert!(p[2] > 0.0 && p[2] < p[3]);
        }
        // The viewport (32 wide) has the image 8 pixels in from its edges.
        let m = ClipMapper::new(4, 4, false);
        assert_eq!(m.side, 32);
        assert_eq!(m.clip(0.0, 0.0, 1.0), Some([-0.5, 0.5, 0.5, 1.0]));
        let wide = ClipMapper::new(300, 200, true);
        assert_eq!(wide.side, 512);
        assert_eq!(wide.clip(248.0, -8.0, 1.0), Some([0.0, 1.0, 0.5, 1.0]));
        assert!(m.clip(1.0, 1.0, 0.0).is_none());
        assert!(m.clip(f64::NAN, 1.0, 1.0).is_none());
    }

    /// Positions on the sub-pixel grid survive the trip to NDC and back
    /// through the rasteriser's `f32` viewport transform bit for bit.
    #[test]
    fn grid_positions_are_exact_in_f32() {
        for (w, h) in [(300, 200), (512, 512), (1000, 7), (1, 1), (4097, 3)] {
            let m = ClipMapper::new(w, h, true);
            let half = m.side as f32 * 0.5;
            for k in [-70_000i64, -1, 0, 1, 127, 128, 129, 76_543, 1_048_575] {
                let p = k as f64 / SUBPIXEL;
                let ([nx, ny], g) = m.ndc(p, p).unwrap();
                assert_eq!(g, [k, k]);
                let x = nx * half + half;
                let y = -ny * half + half;
                let b = RASTER_BORDER as f64;
                assert_eq!((x as f64 - b, y as f64 - b), (p, p), "{w}x{h} k={k}");
            }
        }
    }

    #[test]
    fn matches_camera_projection() {
        let p = CameraParams {
            width: 64,
            height: 48,
            azimuth: 30.0,
            ..Default::default()
        };
        let cam = Camera::fit([0.0, 1.0, 0.0, 2.0, 0.0, 3.0], &p);
        let m = ClipMapper::for_camera(&cam);
        // The ray through the centre of pixel (5, 7) hits a point projecting
        // back to (5.5, 7.5).
        let ray = cam.pixel_ray(5, 7);
        let (px, py, z) = cam.project(ray.origin + ray.dir * 4.0).unwrap();
        let (qx, qy) = m.pixel_of(m.clip(px, py, z).unwrap());
        assert!((qx - 5.5).abs() < 3e-3 && (qy - 7.5).abs() < 3e-3);
        let v = cam.to_view(ray.origin + ray.dir * 4.0);
        assert_eq!(m.clip_view(&cam, v), m.clip(px, py, z));
    }
}
