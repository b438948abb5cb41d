//! Isosurfaces in the `native` field model: the reference of `--mode
//! raycast --model native --iso ...`.
//!
//! Inside a native cell interval `s(t)` is not linear, so the crossings of
//! an isovalue are roots of `s(t) = V`, found with the machinery that finds
//! the transfer function's breakpoints ([`super::monotone_nodes`] splits
//! the interval into monotone pieces, [`super::piece_root`] brackets and
//! bisects): on each monotone piece from `s_a` to `s_b` the surfaces
//! crossed are those [`IsoSet::crossed`] gives for a segment from `s_a` to
//! `s_b` (`min < level <= max`, the levels being the values less
//! [`crate::numeric::tolerance::ISO_LEVEL_F64`]), visited in the piece's
//! direction, so the half-open rule of the linear fields holds piece by
//! piece: a piece that ends exactly at a level crosses it, the next one,
//! leaving the level, does not unless it turns back below it (a ray
//! touching the surface at an extremum of `s` crosses it twice, front then
//! back, as two linear segments meeting there would). The first and last
//! node take the interval's exact boundary scalars (bit-identical for the
//! two cells sharing a face), so a surface on a shared face is drawn once.
//! A crossing is *rising* when its piece rises.
//!
//! **Compositing** ([`IsoMix::Exact`]): the native integral of the volume
//! from the interval's start to the first crossing (cut at the transfer
//! function's breakpoints in between, as [`super::integrate`] cuts), the
//! surface ([`IsoSet::surface`]), the volume to the next crossing, ..., to
//! the interval's end. With [`IsoMix::Blend`] the interval is one segment
//! of RKE's blend ([`IsoSet::composite`]'s blend branch): the whole
//! interval's native volume between the front layer of its surfaces
//! (opacity times `1 - u`) and the back layer (times `u`), `u` the
//! crossing's fraction of the interval's length.
//!
//! **Light**: flat, the cell's least-squares gradient (as
//! [`crate::raycast::iso::IsoReference`] on the walk); smooth, the points'
//! gradients interpolated with the cell's iso-parametric shape functions
//! at the crossing's parametric point ([`IsoRay::locate`]; the flat
//! gradient where it cannot be located).
//!
//! Where the map cannot be inverted inside the interval it falls back, as
//! the volume does ([`super::interval_value`]), to the linear segment
//! between the exact boundary scalars ([`IsoSet::composite`] with the
//! flat gradient at both ends), counted in
//! [`NativeStats::fallback_intervals`].

use glam::DVec3;

use super::{
    integrate_cuts, monotone_nodes, node_crossings, piece_root, shape, ClippedInterval, Interval,
    IsoRay, NativeStats,
};
use crate::camera::Ray;
use crate::integrate::{RayMaterial, SegmentValue};
use crate::raycast::Scene;
use crate::render::iso::{over, IsoMix, IsoSet, Lighting};

/// What the surfaces of one render need: the set, the light and the
/// points' gradients.
#[derive(Clone, Copy)]
pub struct IsoShading<'a> {
    pub set: &'a IsoSet,
    /// Unit view direction (world): the light.
    pub forward: DVec3,
    /// Smooth light: the gradient of each point.
    pub points: Option<&'a [DVec3]>,
}

/// A surface crossed inside an interval: depth, surface, side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoHit {
    pub t: f64,
    pub k: usize,
    pub rising: bool,
}

/// The crossings of `set`'s levels along the monotone pieces `nodes`, in
/// depth order (see the module docs).
fn level_crossings(
    field: &mut IsoRay,
    nodes: &[(f64, f64)],
    set: &IsoSet,
    out: &mut Vec<IsoHit>,
) -> Option<()> {
    for w in nodes.windows(2) {
        let (a, b) = (w[0], w[1]);
        let range = set.crossed(a.1, b.1);
        let rising = a.1 < b.1;
        for i in 0..range.len() {
            let k = if rising {
                range.start + i
            } else {
                range.end - 1 - i
            };
            let mut t = piece_root(field, a, b, set.levels[k])?;
            // Roots of one monotone piece come in depth order; keep it so
            // through the bisection's last bits.
            if let Some(prev) = out.last() {
                t = t.max(prev.t);
            }
            out.push(IsoHit { t, k, rising });
        }
    }
    Some(())
}

/// The ends of an interval's monotone pieces: depth and scalar.
type Nodes = Vec<(f64, f64)>;

/// The surfaces the native field of one cell crosses along `[t_a, t_b]`
/// (the ends' scalars replaced by `s_a` where given and `s_b`), in depth
/// order, with the monotone pieces' nodes; `None` when the map cannot be
/// inverted.
fn interval_crossings(
    field: &mut IsoRay,
    set: &IsoSet,
    (t_a, s_a): (f64, Option<f64>),
    (t_b, s_b): (f64, f64),
    stats: &mut NativeStats,
) -> Option<(Vec<IsoHit>, Nodes)> {
    let nodes = monotone_nodes(field, t_a, t_b, stats)?;
    let mut classed = nodes.clone();
    if let Some(s) = s_a {
        classed[0].1 = s;
    }
    if let Some(last) = classed.last_mut() {
        last.1 = s_b;
    }
    let mut hits = Vec::new();
    level_crossings(field, &classed, set, &mut hits)?;
    Some((hits, nodes))
}

/// The light's gradient at depth `t` of the cell whose nodes are `nodes`.
fn gradient(field: &mut IsoRay, sh: &IsoShading, nodes: &[u32], flat: DVec3, t: f64) -> DVec3 {
    match sh.set.lighting {
        Lighting::None => DVec3::ZERO,
        Lighting::Flat => flat,
        Lighting::Smooth => {
            let (Some(points), Some(xi)) = (sh.points, field.locate(t)) else {
                return flat;
            };
            let mut n = [0.0; 8];
            let mut dn = [DVec3::ZERO; 8];
            let cnt = shape(field.kind, xi, &mut n, &mut dn);
            (0..cnt.min(nodes.len()))
                .map(|i| points.get(nodes[i] as usize).copied().unwrap_or_default() * n[i])
                .sum()
        }
    }
}

/// The interval `[t_a, t_b]` of the cell with `nodes` through its
/// iso-parametric field, surfaces and volume composited (module docs);
/// `None` when the map cannot be inverted.
#[allow(clippy::too_many_arguments)]
fn composite<M: RayMaterial>(
    field: &mut IsoRay,
    material: &M,
    sh: &IsoShading,
    nodes: &[u32],
    flat: DVec3,
    a: (f64, Option<f64>),
    b: (f64, f64),
    stats: &mut NativeStats,
) -> Option<SegmentValue> {
    let (t_a, t_b) = (a.0, b.0);
    let (hits, monotone) = interval_crossings(field, sh.set, a, b, stats)?;
    let breaks = node_crossings(field, &monotone, material.breakpoints())?;
    // The volume from t0 to t1, cut at the breakpoints between.
    let volume = |field: &mut IsoRay, t0: f64, t1: f64| {
        let mut cuts = vec![t0];
        cuts.extend(breaks.iter().copied().filter(|&t| t > t0 && t < t1));
        cuts.push(t1);
        integrate_cuts(field, material, &cuts)
    };
    let set = sh.set;
    if hits.is_empty() {
        return volume(field, t_a, t_b);
    }
    if set.mix == IsoMix::Blend {
        let l = t_b - t_a;
        let (mut front, mut back) = (SegmentValue::default(), SegmentValue::default());
        for h in &hits {
            let u = ((h.t - t_a) / l).clamp(0.0, 1.0);
            let g = gradient(field, sh, nodes, flat, h.t);
            front = over(
                front,
                set.surface_weighted(h.k, h.rising, g, sh.forward, 1.0 - u),
            );
            back = over(back, set.surface_weighted(h.k, h.rising, g, sh.forward, u));
        }
        return Some(over(over(front, volume(field, t_a, t_b)?), back));
    }
    let mut acc = SegmentValue::default();
    let mut t0 = t_a;
    for h in &hits {
        acc = over(acc, volume(field, t0, h.t)?);
        let g = gradient(field, sh, nodes, flat, h.t);
        acc = over(acc, set.surface(h.k, h.rising, g, sh.forward));
        t0 = h.t;
    }
    Some(over(acc, volume(field, t0, t_b)?))
}

/// [`super::interval_value`] with the isosurfaces of `sh`: one native
/// interval (clipped to `t >= t_near`) with its surfaces, `flat` the
/// cell's least-squares gradient; the linear segment between the exact
/// boundary scalars where the map cannot be inverted (counted).
#[allow(clippy::too_many_arguments)]
pub fn interval_iso<M: RayMaterial>(
    scene: &Scene,
    vals: &[f64],
    material: &M,
    ray: &Ray,
    iv: &Interval,
    t_near: f64,
    sh: &IsoShading,
    flat: DVec3,
    stats: &mut NativeStats,
) -> SegmentValue {
    let Some(cut) = ClippedInterval::new(scene, vals, iv, t_near, stats) else {
        return SegmentValue::default();
    };
    let (l, sa) = (iv.t_b - cut.ta, cut.sa);
    let a = (cut.ta, (!cut.clipped).then_some(iv.s_a));
    let value = IsoRay::new(cut.kind, &cut.x, &cut.s, ray).and_then(|mut f| {
        let r = composite(
            &mut f,
            material,
            sh,
            cut.nodes,
            flat,
            a,
            (iv.t_b, iv.s_b),
            stats,
        );
        stats.newton_failures += f.failures;
        r
    });
    value.unwrap_or_else(|| {
        stats.fallback_intervals += 1;
        let g = if sh.set.lighting == Lighting::None {
            DVec3::ZERO
        } else {
            flat
        };
        sh.set
            .composite(l, sa, iv.s_b, [g; 2], sh.forward, |l, a, b| {
                material.segment(l, a, b)
            })
    })
}
