//! The CPU twin of the exact stage: rasteriser, `shaders/exact.wgsl` and
//! the blend unit, pixel by pixel.
//!
//! [`CpuFrame`] takes the same triangles as [`super::Frame`] and produces
//! the image the GPU would, without a GPU, so the comparison harness runs
//! everywhere and a wrong pixel can be taken apart ([`CpuFrame::covering`]
//! lists the fragments that coloured it). Stage by stage, as the hardware
//! does it:
//! 1. **Viewport.** Clip positions (`w = 1` in the exact mode; others are
//!    divided) become framebuffer coordinates in `f32`,
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
//! 3. **Interpolation.** Attributes are affine in screen space (the exact
//!    mode sends `w = 1`), from the barycentric weights of the snapped
//!    triangle.
//! 4. **Fragment** (`fs_main`): a fragment with a non-finite attribute is
//!    discarded; otherwise `alpha` comes from the exponential table
//!    ([`ExpTable::sample`], the twin of `alpha_of`) and the colour is
//!    `glow * alpha`. Its depth is its piece's key ([`piece_depth`]); the
//!    depth test (less, with write) lets each piece colour a pixel once.
//! 5. **Blend:** premultiplied "over" in `f32`, rounded to `f16` after
//!    each blend when the frame accumulates in `Rgba16Float`.
//!
//! Where the twin and the GPU can differ: the order of `f32` operations in
//! the viewport transform and the interpolation (a last-bit difference in
//! an attribute), and a device with other sub-pixel precision or another
//! tie rule (coverage of centres within 1/512 px of an edge). The GPU
//! coverage tests compare the twin's counts with the device's.

use half::f16;

use super::exptable::ExpTable;
use super::frame::DrawKind;
use super::vertex::{piece_depth, raster_side, ClipMapper, ExactVertex};
use super::{AccumFormat, GpuError};
use crate::image::Image;

/// Sub-pixel grid units per pixel.
const SUBPIXEL: i64 = super::vertex::SUBPIXEL as i64;

/// One fragment that coloured (or, counting, covered) a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fragment {
    /// Index of the triangle in the frame (in submission order).
    pub triangle: u64,
    pub piece: u32,
    pub thickness: f32,
    pub tau: f32,
    pub glow: [f32; 3],
    /// Premultiplied colour and opacity the fragment blended.
    pub rgba: [f32; 4],
}

/// A frame composited on the CPU; see the module docs.
pub struct CpuFrame {
    width: u32,
    height: u32,
    format: AccumFormat,
    draw: DrawKind,
    length_unit: f32,
    table: ExpTable,
    accum: Vec<[f32; 4]>,
    depth: Vec<f32>,
    triangles: u64,
    /// Pixel whose fragments are recorded, and the record.
    watch: Option<(u32, u32)>,
    watched: Vec<Fragment>,
}

impl CpuFrame {
    /// A cleared `width x height` frame (`format` F32 or F16; `Auto` means
    /// F32), drawing `draw`, with the shader's length unit (see
    /// [`super::FrameOptions::length_unit`]).
    pub fn new(
        width: u32,
        height: u32,
        format: AccumFormat,
        draw: DrawKind,
        length_unit: f32,
    ) -> Result<CpuFrame, GpuError> {
        if width == 0 || height == 0 || width > 1 << 14 || height > 1 << 14 {
            return Err(GpuError::BadSize {
                width,
                height,
                max: 1 << 14,
            });
        }
        if !(length_unit > 0.0 && length_unit.is_finite()) {
            return Err(GpuError::BadOption(
                "length_unit must be positive and finite",
            ));
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
            length_unit,
            table: ExpTable::new(super::exptable::TABLE_N),
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

    /// Draws triangles (`indices` into `vertices`, three per triangle) over
    /// everything drawn before.
    pub fn push_triangles(
        &mut self,
        vertices: &[ExactVertex],
        indices: &[u32],
    ) -> Result<(), GpuError> {
        if indices.len() % 3 != 0 {
            return Err(GpuError::NotTriangles(indices.len()));
        }
        if let Some(&index) = indices.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(GpuError::IndexOutOfRange {
                index,
                len: vertices.len(),
            });
        }
        if let Some(k) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(GpuError::NonFiniteVertex(k));
        }
        for t in indices.chunks_exact(3) {
            let tri = [0, 1, 2].map(|k| &vertices[t[k] as usize]);
            self.triangle(tri);
            self.triangles += 1;
        }
        Ok(())
    }

    fn snap(&self, v: &ExactVertex) -> Option<[i64; 2]> {
        let half = raster_side(self.width, self.height) as f32 * 0.5;
        let w = v.pos[3];
        let (nx, ny) = (v.pos[0] / w, v.pos[1] / w);
        let b = super::vertex::RASTER_BORDER as f32;
        let x = nx * half + half - b;
        let y = -ny * half + half - b;
        // Beyond 2^40 sub-pixels (4e9 px) the hardware clips; such
        // positions never reach here from the exact mode.
        Some([ClipMapper::snap(x as f64)?, ClipMapper::snap(y as f64)?])
    }

    fn triangle(&mut self, tri: [&ExactVertex; 3]) {
        let Some(p) = tri
            .iter()
            .map(|v| self.snap(v))
            .collect::<Option<Vec<[i64; 2]>>>()
        else {
            return;
        };
        let [a, b, c] = [p[0], p[1], p[2]].map(|q| [q[0] as i128, q[1] as i128]);
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
                    self.fragment(i as u32, j as u32, tri, bary);
                }
            }
        }
    }

    fn fragment(&mut self, i: u32, j: u32, tri: [&ExactVertex; 3], bary: [f64; 3]) {
        let lerp = |f: &dyn Fn(&ExactVertex) -> f32| -> f32 {
            (bary[0] * f(tri[0]) as f64 + bary[1] * f(tri[1]) as f64 + bary[2] * f(tri[2]) as f64)
                as f32
        };
        let piece = tri[0].piece;
        let l = lerp(&|v| v.thickness) / self.length_unit;
        let tau = lerp(&|v| v.tau) * self.length_unit;
        let glow = [0, 1, 2].map(|k| lerp(&|v| v.glow[k]));
        let at = (j as usize) * (self.width as usize) + i as usize;
        let watched = self.watch == Some((i, j));
        let mut record = Fragment {
            triangle: self.triangles,
            piece,
            thickness: l,
            tau,
            glow,
            rgba: [0.0; 4],
        };
        let src = match self.draw {
            DrawKind::Composite => {
                if !(l.is_finite() && tau.is_finite() && glow.iter().all(|g| g.is_finite())) {
                    if watched {
                        self.watched.push(record);
                    }
                    return;
                }
                let alpha = self.table.sample(l, tau);
                [glow[0] * alpha, glow[1] * alpha, glow[2] * alpha, alpha]
            }
            DrawKind::CountPieces | DrawKind::CountTriangles => [1.0, 0.0, 0.0, 0.0],
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
