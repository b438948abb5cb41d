//! The reference for isosurfaces: the ray caster's segments, each split
//! at the isovalues it crosses and composited with its volume exactly as
//! [`crate::render::iso`] defines it. On the `faces` and `tets` fields the
//! scalar is linear along each segment, so the crossing is at
//! `u = (V - s_in) / (s_out - s_in)`; the gradient is the piece's
//! least-squares gradient (flat: for `tets` the tet's exact gradient) or
//! the points' gradients interpolated at the entry and exit points with
//! the barycentric weights of the crossed triangles and linearly between
//! (smooth), the same definitions the projected modes use
//! ([`crate::render::gradients`]). The light's direction is the camera's
//! view direction.
//!
//! [`IsoReference`] follows the walk ([`Raycaster`]): with the `native`
//! model it takes the native intervals instead and finds the crossings of
//! the iso-parametric field inside each ([`super::native::iso`]; cells
//! without a native field keep their walk segments, as the volume does).
//! [`BruteIsoReference`] follows the brute-force traversal
//! ([`super::brute`], `faces` and `tets`).

use glam::DVec3;

use crate::camera::Ray;
use crate::integrate::{RayAccumulator, RayMaterial, SegmentValue};
use crate::render::gradients::fit_gradient;
use crate::render::iso::{IsoSet, Lighting};

use super::brute::{Brute, BruteScratch};
use super::native::iso::{interval_iso, IsoShading};
use super::native::{self, NativeStats};
use super::walk::{RawSegment, Scratch};
use super::{stop_depth, FieldModel, RayTracer, RaycastOptions, Raycaster, Segment};

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

/// Flat light: the least-squares gradient of each of `n` cells or pieces
/// (their nodes by `nodes`), or nothing when the light is not flat.
fn flat_gradients<'n>(
    set: &IsoSet,
    n: usize,
    nodes: impl Fn(usize) -> &'n [u32],
    pts: &[DVec3],
    scalars: &[f64],
) -> Vec<DVec3> {
    if set.lighting != Lighting::Flat {
        return Vec::new();
    }
    (0..n)
        .map(|c| {
            fit_gradient(
                nodes(c)
                    .iter()
                    .filter_map(|&n| Some((*pts.get(n as usize)?, *scalars.get(n as usize)?))),
            )
        })
        .collect()
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
        let flat = flat_gradients(set, cells.len(), |c| cells.nodes(c), pts, scalars);
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

impl IsoReference<'_, '_> {
    /// The gradients at the ends of walk segment `s` (cut from `raw`).
    fn walk_gradients(&self, s: &Segment, raw: &RawSegment) -> [DVec3; 2] {
        match self.set.lighting {
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
        }
    }

    /// The `native` model: its intervals, each with its surfaces
    /// ([`interval_iso`]; cells without a native field as walk segments);
    /// `None` without point scalars.
    fn trace_native<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        stop: f64,
        scratch: &mut Scratch,
    ) -> Option<RayAccumulator> {
        let rc = self.rc;
        let vals = native::point_values(&rc.scene)?;
        let mut stats = NativeStats::default();
        let mut raws = Vec::new();
        let ivs = rc.native_intervals_with(ray, t_near, scratch, &mut stats, Some(&mut raws))?;
        let cells = &rc.scene.mesh.cells;
        let sh = IsoShading {
            set: self.set,
            forward: self.forward,
            points: self.points,
        };
        let mut acc = RayAccumulator::default();
        let mut next = 0;
        for iv in &ivs {
            let c = iv.cell as usize;
            let flat = self.flat.get(c).copied().unwrap_or_default();
            let v = if native::is_native_kind(cells.kinds[c]) {
                interval_iso(
                    &rc.scene, vals, material, ray, iv, t_near, &sh, flat, &mut stats,
                )
            } else {
                let mut s = Segment {
                    cell: iv.cell,
                    t_in: iv.t_a,
                    t_out: iv.t_b,
                    s_in: iv.s_a,
                    s_out: iv.s_b,
                };
                if s.t_in < t_near {
                    s.s_in += (t_near - s.t_in) / (s.t_out - s.t_in) * (s.s_out - s.s_in);
                    s.t_in = t_near;
                }
                // Its walk segment: the raws are in depth order too, so
                // the search goes on from the last one found.
                let same = |r: &RawSegment| r.cell == iv.cell && r.t_in == iv.t_a;
                let found = raws[next..]
                    .iter()
                    .position(same)
                    .map(|k| next + k)
                    .or_else(|| raws.iter().position(same));
                let g = match found {
                    Some(k) => {
                        next = k + 1;
                        self.walk_gradients(&s, &raws[k])
                    }
                    None => [flat; 2],
                };
                self.segment(material, &s, g)
            };
            acc.add(&v);
            if acc.depth >= stop {
                break;
            }
        }
        rc.record_native(&stats);
        Some(acc)
    }

    /// Linear segment `s` with end gradients `g`, split at its surfaces.
    fn segment<M: RayMaterial>(&self, material: &M, s: &Segment, g: [DVec3; 2]) -> SegmentValue {
        self.set.composite(
            s.t_out - s.t_in,
            s.s_in,
            s.s_out,
            g,
            self.forward,
            |l, a, b| material.segment(l, a, b),
        )
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
        if self.rc.model == FieldModel::Native {
            if let Some(acc) = self.trace_native(material, ray, t_near, stop, scratch) {
                return acc;
            }
        }
        let acc = RayAccumulator::default();
        self.rc
            .composite(ray, t_near, stop, scratch, acc, |s, raw| {
                self.segment(material, s, self.walk_gradients(s, raw))
            })
    }
}

/// The brute-force traversal with isosurfaces: each composited part of a
/// piece's segment split at its surfaces, lit by the piece's gradient
/// (flat) or the points' gradients at the part's ends (smooth).
pub struct BruteIsoReference<'a, 'm> {
    brute: &'a Brute<'m>,
    set: &'a IsoSet,
    /// Unit view direction (world).
    forward: DVec3,
    /// Flat light: the gradient of each piece (cell or tet).
    flat: Vec<DVec3>,
    /// Smooth light: the gradient of each point.
    points: Option<&'a [DVec3]>,
}

impl<'a, 'm> BruteIsoReference<'a, 'm> {
    /// Isosurfaces `set` on the pieces of `brute`, lit along `forward`;
    /// `points` are the points' gradients (smooth light).
    pub fn new(
        brute: &'a Brute<'m>,
        set: &'a IsoSet,
        forward: DVec3,
        points: Option<&'a [DVec3]>,
        scalars: &[f64],
    ) -> BruteIsoReference<'a, 'm> {
        let pts = &brute.scene.mesh.points;
        let pieces = match brute.model() {
            FieldModel::Tets => brute.piece_count(),
            _ => brute.scene.mesh.cells.len(),
        };
        let flat = flat_gradients(
            set,
            pieces,
            |p| brute.piece_nodes(p as u32).unwrap_or(&[]),
            pts,
            scalars,
        );
        BruteIsoReference {
            brute,
            set,
            forward,
            flat,
            points,
        }
    }
}

impl RayTracer for BruteIsoReference<'_, '_> {
    type Scratch = BruteScratch;

    fn integrate<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut BruteScratch,
    ) -> RayAccumulator {
        let grads = match self.set.lighting {
            Lighting::Smooth => Some(self.points.unwrap_or(&[])),
            _ => None,
        };
        self.brute
            .trace_with(ray, t_near, opts, scratch, grads, |p| {
                let g = match self.set.lighting {
                    Lighting::Smooth => p.g,
                    Lighting::Flat => {
                        [self.flat.get(p.piece as usize).copied().unwrap_or_default(); 2]
                    }
                    Lighting::None => [DVec3::ZERO; 2],
                };
                self.set
                    .composite(p.l, p.s[0], p.s[1], g, self.forward, |l, a, b| {
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
