//! The reference for isosurfaces: the walk's segments ([`Raycaster`]),
//! each split at the isovalues it crosses and composited with its volume
//! exactly as [`crate::render::iso`] defines it. On the `faces` and `tets`
//! fields the scalar is linear along each segment, so the crossing is at
//! `u = (V - s_in) / (s_out - s_in)`; the gradient is the walk cell's
//! least-squares gradient (flat: for `tets` the tet's exact gradient) or
//! the points' gradients interpolated at the entry and exit points with
//! the walk's barycentric weights and linearly between (smooth), the same
//! definitions the projected modes use ([`crate::render::gradients`]).
//! The light's direction is the camera's view direction.

use glam::DVec3;

use crate::camera::Ray;
use crate::integrate::{RayAccumulator, RayMaterial};
use crate::render::gradients::fit_gradient;
use crate::render::iso::{IsoSet, Lighting};

use super::walk::Scratch;
use super::{stop_depth, RayTracer, RaycastOptions, Raycaster};

/// The ray caster with isosurfaces.
pub struct IsoReference<'a, 'm> {
    rc: &'a Raycaster<'m>,
    set: &'a IsoSet,
    /// Unit view direction (world).
    forward: DVec3,
    /// Flat light: the gradient of each walk cell.
    flat: Vec<DVec3>,
    /// Smooth light: the gradient of each point.
    points: Option<&'a [DVec3]>,
}

impl<'a, 'm> IsoReference<'a, 'm> {
    /// Isosurfaces `set` on the walk of `rc`, lit along `forward`;
    /// `points` are the points' gradients (smooth light).
    pub fn new(
        rc: &'a Raycaster<'m>,
        set: &'a IsoSet,
        forward: DVec3,
        points: Option<&'a [DVec3]>,
        scalars: &[f64],
    ) -> IsoReference<'a, 'm> {
        let cells = &rc.walker.cells;
        let pts = rc.walker.points;
        let flat =
            if set.lighting == Lighting::Flat {
                (0..cells.len())
                    .map(|c| {
                        let nodes = cells.nodes(c);
                        fit_gradient(nodes.iter().filter_map(|&n| {
                            Some((*pts.get(n as usize)?, *scalars.get(n as usize)?))
                        }))
                    })
                    .collect()
            } else {
                Vec::new()
            };
        IsoReference {
            rc,
            set,
            forward,
            flat,
            points,
        }
    }

    fn point_gradient(&self, v: [u32; 3], w: [f64; 3]) -> DVec3 {
        let g = |i: u32| {
            self.points
                .and_then(|p| p.get(i as usize).copied())
                .unwrap_or(DVec3::ZERO)
        };
        g(v[0]) * w[0] + g(v[1]) * w[1] + g(v[2]) * w[2]
    }
}

impl RayTracer for IsoReference<'_, '_> {
    type Scratch = Scratch;

    fn integrate<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut Scratch,
    ) -> RayAccumulator {
        let stop = stop_depth(opts);
        let acc = RayAccumulator::default();
        self.rc
            .composite(ray, t_near, stop, scratch, acc, |s, raw| {
                let grads = || match self.set.lighting {
                    Lighting::None => [DVec3::ZERO; 2],
                    Lighting::Flat => {
                        [self.flat
                            .get(raw.cell as usize)
                            .copied()
                            .unwrap_or_default(); 2]
                    }
                    Lighting::Smooth => {
                        let gi = self.point_gradient(raw.v_in, raw.w_in);
                        let go = self.point_gradient(raw.v_out, raw.w_out);
                        // The segment may start later than the walk's (clipped
                        // at the near plane).
                        let span = raw.t_out - raw.t_in;
                        let x = if span > 0.0 {
                            ((s.t_in - raw.t_in) / span).clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        [gi.lerp(go, x), go]
                    }
                };
                let l = s.t_out - s.t_in;
                self.set
                    .composite(l, s.s_in, s.s_out, grads(), self.forward, |l, a, b| {
                        material.segment(l, a, b)
                    })
            })
    }
}

/// A material that is empty everywhere (isosurfaces alone).
pub struct Empty;

impl RayMaterial for Empty {
    fn segment(&self, _l: f64, _s_f: f64, _s_b: f64) -> crate::integrate::SegmentValue {
        crate::integrate::SegmentValue::default()
    }
    fn breakpoints(&self) -> &[f64] {
        &[]
    }
    fn material(&self, _s: f64) -> crate::integrate::Material {
        crate::integrate::Material::default()
    }
}
