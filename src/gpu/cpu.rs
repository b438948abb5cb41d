//! The CPU twin of a frame: rasteriser, fragment stage and blend unit,
//! pixel by pixel.
//!
//! [`CpuFrame`] takes the same triangles as [`super::Frame`], each stage's
//! fragment shader replaced by its CPU twin ([`CpuStage`], which every
//! stage has, with the name of the shader function it mirrors), and
//! produces
//! the image the GPU would, without a GPU, so the comparison harness runs
//! everywhere and a wrong pixel can be taken apart ([`CpuFrame::covering`]
//! lists the fragments that coloured it). Stage by stage, as the hardware
//! does it:
//! 1. **Viewport.** Clip positions (divided by `w`) become framebuffer coordinates in `f32`,
//!    `x = ndc_x * S/2 + S/2`, `y = -ndc_y * S/2 + S/2` (row 0 at the top;
//!    `S` the square viewport's side, [`raster_side`]; the image starts
//!    [`super::vertex::RASTER_BORDER`] pixels in), then are snapped to
//!    a grid of 1/[`super::vertex::SUBPIXEL`] pixel (8 bits of sub-pixel
//!    precision, as lavapipe, llvmpipe and the desktop drivers have),
//!    rounding to nearest. Positions from [`ClipMapper`] are on that grid
//!    already and come through unchanged.
//! 2. **Coverage.** A triangle of zero snapped area covers nothing. Pixel
//!    centres `(i + 0.5, j + 0.5)` are tested against the three edge
//!    functions in exact integer arithmetic; a centre exactly on an edge
//!    belongs to the triangle for which the edge is a *top* edge
//!    (horizontal, the triangle below it) or a *left* edge (the triangle
//!    to its right): the top-left rule, which is the sample point moved by
//!    `(+e, +e^2)`. Triangles of either winding are drawn (no culling).
//! 3. **Interpolation.** The barycentric weights of the snapped triangle
//!    (affine in screen space: the projected-cell modes send `w = 1`) go to
//!    the stage's twin, which interpolates its own attributes.
//! 4. **Fragment** ([`CpuStage::shade`], the twin of `fs_main`): the
//!    premultiplied colour, or `None` to discard. Its depth is its piece's
//!    key ([`piece_depth`]); the depth test (less, with write) lets each
//!    piece colour a pixel once. Counting draws ([`DrawKind`]) add 1 to red
//!    instead, as `fs_count` does.
//! 5. **Blend:** premultiplied "over" in `f32`, rounded to `f16` after
//!    each blend when the frame accumulates in `Rgba16Float`.
//!
//! Where the twin and the GPU can differ: the order of `f32` operations in
//! the viewport transform and the interpolation (a last-bit difference in
//! an attribute), and a device with other sub-pixel precision or another
//! tie rule (coverage of centres within 1/512 px of an edge). The GPU
//! coverage tests compare the twin's counts with the device's.

use half::f16;

use super::common::{count_of, piece_depth};
use super::frame::{validate, DrawKind};
use super::raster::{raster_side, ClipMapper, GpuVertex};
use super::{AccumFormat, GpuError};
use crate::image::Image;

/// Sub-pixel grid units per pixel.
const SUBPIXEL: i64 = super::raster::SUBPIXEL as i64;

/// The CPU twin of a stage's fragment shader (`fs_main`).
pub trait CpuStage<V>: Sync {
    /// The premultiplied RGBA the fragment blends at barycentric weights
    /// `bary` of triangle `tri` (weights of the snapped triangle, in `f64`),
    /// or `None` where the shader discards.
    fn shade(&self, tri: [&V; 3], bary: [f64; 3]) -> Option<[f32; 4]>;
    /// Whether the fragment at `bary` of `tri` is drawn at all (what a
    /// counting draw counts): true unless the stage's `fs_count` discards
    /// some fragments, as a stage drawing a piece's bounding quad does
    /// where the pixel's ray misses the piece.
    fn covers(&self, _tri: [&V; 3], _bary: [f64; 3]) -> bool {
        true
    }
    /// The interpolated values the shader works from, named, for
    /// diagnostics ([`CpuFrame::covering`]).
    fn describe(&self, tri: [&V; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)>;
}

/// The value of attribute `f` at barycentric weights `bary`, interpolated
/// in `f64` and rounded to `f32`.
pub fn lerp<V>(tri: [&V; 3], bary: [f64; 3], f: impl Fn(&V) -> f32) -> f32 {
    (bary[0] * f(tri[0]) as f64 + bary[1] * f(tri[1]) as f64 + bary[2] * f(tri[2]) as f64) as f32
}

/// One fragment that coloured (or, counting, covered) a pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Fragment {
    /// Index of the triangle in the frame (in submission order).
    pub triangle: u64,
    pub piece: u32,
    /// The interpolated values the stage worked from ([`CpuStage::describe`]).
    pub values: Vec<(&'static str, f32)>,
    /// Premultiplied colour and opacity the fragment blended.
    pub rgba: [f32; 4],
}

/// A frame composited on the CPU; see the module docs.
pub struct CpuFrame {
    width: u32,
    height: u32,
    format: AccumFormat,
    draw: DrawKind,
    accum: Vec<[f32; 4]>,
    depth: Vec<f32>,
    triangles: u64,
    /// Pixel whose fragments are recorded, and the record.
    watch: Option<(u32, u32)>,
    watched: Vec<Fragment>,
}

impl CpuFrame {
    /// A cleared `width x height` frame (`format` F32 or F16; `Auto` means
    /// F32), drawing `draw`.
    pub fn new(
        width: u32,
        height: u32,
        format: AccumFormat,
        draw: DrawKind,
    ) -> Result<CpuFrame, GpuError> {
        if width == 0 || height == 0 || width > 1 << 14 || height > 1 << 14 {
            return Err(GpuError::BadSize {
                width,
                height,
                max: 1 << 14,
            });
        }
        let n = (width as usize) * (height as usize);
        Ok(CpuFrame {
            width,
            height,
            format: match format {
                AccumFormat::F16 => AccumFormat::F16,
                _ => AccumFormat::F32,
            },
            draw,
            accum: vec![[0.0; 4]; n],
            depth: vec![1.0; n],
            triangles: 0,
            watch: None,
            watched: Vec::new(),
        })
    }

    /// Records every fragment drawn at pixel `(i, j)` from now on
    /// ([`Self::covering`]).
    pub fn watch(&mut self, i: u32, j: u32) {
        self.watch = Some((i, j));
        self.watched.clear();
    }

    /// The fragments drawn at the watched pixel, in drawing order; a
    /// fragment that failed the depth test is listed with `rgba` zero.
    pub fn covering(&self) -> &[Fragment] {
        &self.watched
    }

    /// Triangles drawn so far.
    pub fn triangles(&self) -> u64 {
        self.triangles
    }

    /// Draws triangles of a stage (`indices` into `vertices`, three per
    /// triangle; `stage` the twin of its fragment shader) over everything
    /// drawn before.
    pub fn push_triangles<V: GpuVertex>(
        &mut self,
        stage: &dyn CpuStage<V>,
        vertices: &[V],
        indices: &[u32],
    ) -> Result<(), GpuError> {
        validate(vertices, indices)?;
        for t in indices.chunks_exact(3) {
            let tri = [0, 1, 2].map(|k| &vertices[t[k] as usize]);
            self.triangle(stage, tri);
            self.triangles += 1;
        }
        Ok(())
    }

    fn snap<V: GpuVertex>(&self, v: &V) -> Option<[i64; 2]> {
        let half = raster_side(self.width, self.height) as f32 * 0.5;
        let pos = v.clip();
        let w = pos[3];
        let (nx, ny) = (pos[0] / w, pos[1] / w);
        let b = super::raster::RASTER_BORDER as f32;
        let x = nx * half + half - b;
        let y = -ny * half + half - b;
        // Beyond 2^40 sub-pixels (4e9 px) the hardware clips; such
        // positions never reach here from the projected-cell modes.
        Some([ClipMapper::snap(x as f64)?, ClipMapper::snap(y as f64)?])
    }

    fn triangle<V: GpuVertex>(&mut self, stage: &dyn CpuStage<V>, tri: [&V; 3]) {
        let (Some(p0), Some(p1), Some(p2)) =
            (self.snap(tri[0]), self.snap(tri[1]), self.snap(tri[2]))
        else {
            return;
        };
        let [a, b, c] = [p0, p1, p2].map(|q| [q[0] as i128, q[1] as i128]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area == 0 {
            return;
        }
        let s = area.signum();
        // Edge k is opposite vertex k; its function is positive inside.
        let corners = [a, b, c];
        let edges = [(b, c), (c, a), (a, b)].map(|(u, v)| {
            // E(p) = s * ((v - u) x (p - u)).
            let (dx, dy) = (v[0] - u[0], v[1] - u[1]);
            let (ex, ey) = (-dy * s, dx * s); // dE/dx, dE/dy
            let top_left = ex > 0 || (ex == 0 && ey > 0);
            (u, dx * s, dy * s, top_left)
        });
        let sub = SUBPIXEL as i128;
        let lo = |k: usize| corners.iter().map(|q| q[k]).min().unwrap_or(0);
        let hi = |k: usize| corners.iter().map(|q| q[k]).max().unwrap_or(0);
        // Pixel centres (i + 0.5) * SUBPIXEL within the box, clamped.
        let first = |v: i128| ((v - sub / 2 + sub - 1).div_euclid(sub)).max(0);
        let last = |v: i128, n: u32| ((v - sub / 2).div_euclid(sub)).min(n as i128 - 1);
        let (i0, i1) = (first(lo(0)), last(hi(0), self.width));
        let (j0, j1) = (first(lo(1)), last(hi(1), self.height));
        let area_abs = (area * s) as f64;
        for j in j0..=j1 {
            for i in i0..=i1 {
                let q = [i * sub + sub / 2, j * sub + sub / 2];
                let mut w = [0i128; 3];
                let mut inside = true;
                for (k, &(u, dx, dy, top_left)) in edges.iter().enumerate() {
                    let e = dx * (q[1] - u[1]) - dy * (q[0] - u[0]);
                    if e < 0 || (e == 0 && !top_left) {
                        inside = false;
                        break;
                    }
                    w[k] = e;
                }
                if inside {
                    let bary = w.map(|e| e as f64 / area_abs);
                    self.fragment(stage, i as u32, j as u32, tri, bary);
                }
            }
        }
    }

    fn fragment<V: GpuVertex>(
        &mut self,
        stage: &dyn CpuStage<V>,
        i: u32,
        j: u32,
        tri: [&V; 3],
        bary: [f64; 3],
    ) {
        let piece = tri[0].piece();
        let at = (j as usize) * (self.width as usize) + i as usize;
        let watched = self.watch == Some((i, j));
        let mut record = Fragment {
            triangle: self.triangles,
            piece,
            values: if watched {
                stage.describe(tri, bary)
            } else {
                Vec::new()
            },
            rgba: [0.0; 4],
        };
        let src = match self.draw {
            DrawKind::Composite => match stage.shade(tri, bary) {
                Some(rgba) => rgba,
                None => {
                    if watched {
                        self.watched.push(record);
                    }
                    return;
                }
            },
            DrawKind::CountPieces | DrawKind::CountTriangles => {
                if !stage.covers(tri, bary) {
                    return;
                }
                let clip = tri[0].clip();
                count_of(clip[2] / clip[3])
            }
        };
        let key = piece_depth(piece);
        let passes = self.draw == DrawKind::CountTriangles || key < self.depth[at];
        if passes {
            if self.draw != DrawKind::CountTriangles {
                self.depth[at] = key;
            }
            let dst = self.accum[at];
            let blended: [f32; 4] = if self.draw == DrawKind::Composite {
                [0, 1, 2, 3].map(|k| src[k] + (1.0 - src[3]) * dst[k])
            } else {
                [0, 1, 2, 3].map(|k| src[k] + dst[k])
            };
            self.accum[at] = match self.format {
                AccumFormat::F16 => blended.map(|v| f16::from_f32(v).to_f32()),
                _ => blended,
            };
            record.rgba = src;
        }
        if watched {
            self.watched.push(record);
        }
    }

    /// The image (linear premultiplied RGBA, row 0 at the top).
    pub fn finish(self) -> Image {
        let mut img = Image::new(self.width, self.height);
        for j in 0..self.height {
            for i in 0..self.width {
                let v = self.accum[(j as usize) * (self.width as usize) + i as usize];
                img.set(i, j, v);
            }
        }
        img
    }
}
