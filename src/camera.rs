//! The camera, identical to vtkCamera + vtkRenderer::ResetCamera.
//!
//! Construction follows VTK exactly (the contract in docs/conventions.md, Conventions):
//! 1. start looking down -Z with +Y up;
//! 2. ResetCamera: focal point = bounds centre, radius = half the bounds
//!    diagonal, distance = radius / sin(view_angle / 2) (view angle vertical,
//!    30 degrees; narrowed for images taller than wide, as VTK does), parallel
//!    scale = radius (divided by the aspect for tall images);
//! 3. `azimuth` rotates the position about the view-up through the focal point;
//! 4. `elevation` rotates position about the negated right axis (VTK's
//!    `Elevation`), then the view-up is orthogonalised;
//! 5. `roll` rotates the view-up about the direction of projection;
//! 6. `zoom` divides the view angle (perspective) or parallel scale (`ortho`).
//!
//! Pixel `(i, j)` samples its centre `(i + 0.5, j + 0.5)`, row 0 at the top.
//! All maths is `f64`; [`Camera::to_view`] gives camera-relative coordinates
//! (x right, y up, z = distance along the view direction) before any `f32`
//! conversion.

use crate::numeric::tolerance::{CAMERA_NEAR_REL, CAMERA_UP_PARALLEL_SQ};
use glam::{DMat3, DVec3};

/// User-facing camera parameters (the CLI flags).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraParams {
    pub width: u32,
    pub height: u32,
    pub azimuth: f64,
    pub elevation: f64,
    pub roll: f64,
    pub zoom: f64,
    pub ortho: bool,
    /// Vertical view angle in degrees before zoom.
    pub view_angle: f64,
}

impl Default for CameraParams {
    fn default() -> Self {
        CameraParams {
            width: 512,
            height: 512,
            azimuth: 0.0,
            elevation: 0.0,
            roll: 0.0,
            zoom: 1.0,
            ortho: false,
            view_angle: 30.0,
        }
    }
}

/// A ray in world space: `origin + t * dir`, `dir` unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
    /// The image's right direction for a pixel ray (zero when the ray has
    /// no image), for breaking ties by the rasteriser's top-left rule
    /// ([`crate::raycast::geometry::tie_basis`]).
    pub right: DVec3,
}

impl Ray {
    /// A ray with no image (ties broken in an arbitrary fixed direction).
    pub fn new(origin: DVec3, dir: DVec3) -> Ray {
        Ray {
            origin,
            dir,
            right: DVec3::ZERO,
        }
    }
}

/// A fitted camera for one image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: DVec3,
    pub focal_point: DVec3,
    /// Unit view-up, orthogonal to the view direction.
    pub up: DVec3,
    /// Unit right vector.
    pub right: DVec3,
    /// Unit direction of projection (from the eye towards the focal point).
    pub forward: DVec3,
    /// Vertical view angle in degrees (after zoom).
    pub view_angle: f64,
    /// Half the image height in world units (orthographic; after zoom).
    pub parallel_scale: f64,
    pub ortho: bool,
    pub width: u32,
    pub height: u32,
    /// Distance from the eye to the near plane (perspective). Cells in front
    /// of it are clipped; it is tiny so that rays effectively start at the eye.
    pub near: f64,
}

fn rotate(v: DVec3, axis: DVec3, degrees: f64) -> DVec3 {
    if degrees == 0.0 || axis.length_squared() == 0.0 {
        return v;
    }
    DMat3::from_axis_angle(axis.normalize(), degrees.to_radians()) * v
}

impl Camera {
    /// Fits a camera to `bounds` (`[xmin, xmax, ymin, ymax, zmin, zmax]`) and
    /// applies the parameters, in VTK's order.
    pub fn fit(bounds: [f64; 6], p: &CameraParams) -> Camera {
        let center = DVec3::new(
            0.5 * (bounds[0] + bounds[1]),
            0.5 * (bounds[2] + bounds[3]),
            0.5 * (bounds[4] + bounds[5]),
        );
        let diag = DVec3::new(
            bounds[1] - bounds[0],
            bounds[3] - bounds[2],
            bounds[5] - bounds[4],
        );
        let mut radius = 0.5 * diag.length();
        if radius.is_nan() || radius <= 0.0 || !radius.is_finite() {
            radius = 0.5;
        }
        let aspect = p.width.max(1) as f64 / p.height.max(1) as f64;
        let mut angle = p.view_angle.to_radians();
        let mut parallel_scale = radius;
        if aspect < 1.0 {
            angle = 2.0 * ((angle * 0.5).tan() * aspect).atan();
            parallel_scale /= aspect;
        }
        let distance = radius / (angle * 0.5).sin();
        let focal = center;
        let mut position = focal + DVec3::Z * distance;
        let mut up = DVec3::Y;

        // Azimuth: rotate the position about the view-up through the focal point.
        position = focal + rotate(position - focal, up, p.azimuth);
        // Elevation: about -right (row 0 of the view matrix), view-up kept, then
        // orthogonalised.
        let forward = (focal - position).normalize();
        let right = forward.cross(up).normalize();
        position = focal + rotate(position - focal, -right, p.elevation);
        let forward = (focal - position).normalize();
        up = orthogonalise(up, forward, right);
        // Roll: rotate the view-up about the direction of projection.
        up = rotate(up, forward, p.roll);
        let right = forward.cross(up).normalize();
        let up = right.cross(forward).normalize();

        let zoom = if p.zoom > 0.0 && p.zoom.is_finite() {
            p.zoom
        } else {
            1.0
        };
        Camera {
            position,
            focal_point: focal,
            up,
            right,
            forward,
            view_angle: p.view_angle / zoom,
            parallel_scale: parallel_scale / zoom,
            ortho: p.ortho,
            width: p.width,
            height: p.height,
            near: distance * CAMERA_NEAR_REL,
        }
    }

    /// Tangent of half the vertical view angle.
    pub fn tan_half(&self) -> f64 {
        (self.view_angle.to_radians() * 0.5).tan()
    }

    /// Aspect ratio width / height.
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    /// Half extents of the image plane at unit distance (perspective) or in
    /// world units (orthographic): `(half_width, half_height)`.
    pub fn half_extent(&self) -> (f64, f64) {
        let h = if self.ortho {
            self.parallel_scale
        } else {
            self.tan_half()
        };
        (h * self.aspect(), h)
    }

    /// The ray through continuous pixel position `(px, py)` (pixel centres at
    /// `i + 0.5`; `py` grows downwards).
    pub fn ray_at(&self, px: f64, py: f64) -> Ray {
        let (hw, hh) = self.half_extent();
        let x = (2.0 * px / self.width as f64 - 1.0) * hw;
        let y = (1.0 - 2.0 * py / self.height as f64) * hh;
        if self.ortho {
            Ray {
                origin: self.position + self.right * x + self.up * y,
                dir: self.forward,
                right: self.right,
            }
        } else {
            Ray {
                origin: self.position,
                dir: (self.forward + self.right * x + self.up * y).normalize(),
                right: self.right,
            }
        }
    }

    /// The ray through the centre of pixel `(i, j)`.
    pub fn pixel_ray(&self, i: u32, j: u32) -> Ray {
        self.ray_at(i as f64 + 0.5, j as f64 + 0.5)
    }

    /// Camera-relative coordinates of world point `p`: x right, y up,
    /// z = depth along the view direction (positive in front of the eye).
    #[inline]
    pub fn to_view(&self, p: DVec3) -> DVec3 {
        let d = p - self.position;
        DVec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// Continuous pixel coordinates `(px, py)` of a view-space point and its
    /// depth; `None` when a perspective point is not in front of the near plane.
    #[inline]
    pub fn view_to_pixel(&self, v: DVec3) -> Option<(f64, f64, f64)> {
        self.view_to_pixel_with(v, self.half_extent())
    }

    /// [`Self::view_to_pixel`] with [`Self::half_extent`] given (computed
    /// once for many points: the same operations, bit-identical results).
    #[inline]
    pub fn view_to_pixel_with(&self, v: DVec3, (hw, hh): (f64, f64)) -> Option<(f64, f64, f64)> {
        let (x, y) = if self.ortho {
            (v.x, v.y)
        } else {
            if v.z <= self.near {
                return None;
            }
            (v.x / v.z, v.y / v.z)
        };
        let px = (x / hw + 1.0) * 0.5 * self.width as f64;
        let py = (1.0 - y / hh) * 0.5 * self.height as f64;
        Some((px, py, v.z))
    }

    /// Pixel coordinates and depth of world point `p` (see [`Self::view_to_pixel`]).
    pub fn project(&self, p: DVec3) -> Option<(f64, f64, f64)> {
        self.view_to_pixel(self.to_view(p))
    }
}

fn orthogonalise(up: DVec3, forward: DVec3, right_hint: DVec3) -> DVec3 {
    let u = up - forward * up.dot(forward);
    if u.length_squared() > CAMERA_UP_PARALLEL_SQ {
        u.normalize()
    } else {
        // View-up parallel to the view direction: fall back to the old right axis.
        right_hint.cross(forward).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn reset_camera_matches_vtk() {
        let cam = Camera::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], &CameraParams::default());
        let r = 3f64.sqrt();
        let d = r / (15f64.to_radians()).sin();
        assert_relative_eq!(cam.position.z, d, epsilon = 1e-12);
        assert_relative_eq!(cam.forward.z, -1.0);
        // The centre pixel ray goes through the focal point.
        let ray = cam.ray_at(256.0, 256.0);
        assert_relative_eq!(ray.dir.z, -1.0);
    }

    #[test]
    fn azimuth_moves_right_elevation_moves_up() {
        let p = CameraParams {
            azimuth: 90.0,
            ..Default::default()
        };
        let cam = Camera::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], &p);
        assert!(cam.position.x > 1.0 && cam.position.z.abs() < 1e-9);
        let p = CameraParams {
            elevation: 45.0,
            ..Default::default()
        };
        let cam = Camera::fit([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0], &p);
        assert!(cam.position.y > 1.0);
        assert!(cam.up.dot(cam.forward).abs() < 1e-12);
    }

    #[test]
    fn project_inverts_ray() {
        for ortho in [false, true] {
            let p = CameraParams {
                azimuth: 20.0,
                elevation: 35.0,
                zoom: 1.25,
                ortho,
                width: 300,
                height: 200,
                ..Default::default()
            };
            let cam = Camera::fit([0.0, 2.0, -1.0, 1.0, 0.0, 3.0], &p);
            let ray = cam.ray_at(37.25, 150.5);
            let q = ray.origin + ray.dir * 4.0;
            let (px, py, _) = cam.project(q).unwrap();
            assert_relative_eq!(px, 37.25, epsilon = 1e-9);
            assert_relative_eq!(py, 150.5, epsilon = 1e-9);
        }
    }
}
