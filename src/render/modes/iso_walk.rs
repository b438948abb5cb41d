//! Twin of `shaders/iso_walk.wgsl`: `iso_segment` with the closed-form
//! volume, one walk front to back over the transfer function's nodes
//! between the segment's ends and its crossings, merged in order; each
//! event ends a linear piece of the volume, a crossing then adds its lit
//! surface. The shader's comments say why (a crossing costs one piece, not
//! a second integral) and how the material at a crossing is found.

use super::exact_frag::ExactFragTwin;
use super::integral::{neg_expm1, Composite, Material, MAX_SCALAR, MAX_THICKNESS};
use super::iso::{count_at_most, iso_over, iso_surface, IsoTwin};
use super::segment::Seg;

/// Twin of `iso_segment` in `shaders/iso_walk.wgsl`, with `vol`'s transfer
/// function, constants and rule.
pub fn iso_segment(
    stage: &IsoTwin,
    vol: &ExactFragTwin,
    seg: &Seg,
    gf: [f32; 3],
    gb: [f32; 3],
    candidates: [f32; 2],
) -> [f32; 4] {
    let (tf, consts, rule) = vol.integral();
    let ok = !seg.s_f.is_nan() && !seg.s_b.is_nan();
    let l = if ok && seg.l > 0.0 {
        seg.l.min(MAX_THICKNESS)
    } else {
        0.0
    };
    let clamped = |s: f32| {
        if ok {
            s.clamp(-MAX_SCALAR, MAX_SCALAR)
        } else {
            0.0
        }
    };
    let (s_f, s_b) = (clamped(seg.s_f), clamped(seg.s_b));
    let rising = s_f <= s_b;
    let (lo, hi) = (s_f.min(s_b), s_f.max(s_b));
    let (first, end) = (candidates[0] as u32, candidates[1] as u32);
    let value = |k: u32| stage.surfaces[k as usize].value[0];
    let c = count_at_most(stage, s_f, first, end);
    let (mut k, mut more) = if rising {
        (c, c < end)
    } else {
        (c.max(1) - 1, c > first)
    };
    let blend = stage.params.mix == 1;
    let d = s_b - s_f;
    let inv = if d != 0.0 { 1.0 / d } else { 0.0 };
    let sp = tf.segment_spans(s_f, s_b);
    let mut acc = Composite {
        tr: 1.0,
        ..Composite::default()
    };
    let mut surf_t = 1.0f32;
    let (mut front, mut back) = ([0.0f32; 4], [0.0f32; 4]);
    let (mut x_prev, mut m_prev) = (0.0f32, sp.m_first);
    let (mut x_s0, mut m_s0) = (0.0f32, sp.m_first);
    let (mut e_m, mut e_x) = tf.span_end(&sp, 0, s_f);
    let mut n = 0u32;
    loop {
        let mut xi = 2.0f32;
        if more {
            let v = value(k);
            if v > lo && v <= hi {
                xi = ((v - s_f) * inv).clamp(0.0, 1.0);
            }
        }
        let at_iso = xi <= e_x;
        let span = e_x - x_s0;
        let f = if span > 0.0 { (xi - x_s0) / span } else { 1.0 };
        let m_iso = Material {
            tau: m_s0.tau + (e_m.tau - m_s0.tau) * f,
            col: std::array::from_fn(|c| m_s0.col[c] + (e_m.col[c] - m_s0.col[c]) * f),
        };
        let (x, m) = if at_iso { (xi, m_iso) } else { (e_x, e_m) };
        if x > x_prev {
            tf.add_piece(consts, rule, &mut acc, l * (x - x_prev), m_prev, m);
        }
        (x_prev, m_prev) = (x, m);
        if at_iso {
            let g = std::array::from_fn(|c| gf[c] + (gb[c] - gf[c]) * xi);
            if blend {
                front = iso_over(front, iso_surface(stage, k, rising, g, 1.0 - xi));
                back = iso_over(back, iso_surface(stage, k, rising, g, xi));
            } else {
                let c = iso_surface(stage, k, rising, g, 1.0);
                for (a, c) in acc.color.iter_mut().zip(c) {
                    *a += acc.tr * c;
                }
                acc.tr *= 1.0 - c[3];
                surf_t *= 1.0 - c[3];
                if acc.tr <= 0.0 {
                    break;
                }
            }
            (k, more) = if rising {
                (k + 1, k + 1 < end)
            } else {
                (k.max(1) - 1, k > first)
            };
        } else {
            n += 1;
            if n > sp.count {
                break;
            }
            (x_s0, m_s0) = (e_x, e_m);
            (e_m, e_x) = tf.span_end(&sp, n, s_f);
        }
    }
    let mut alpha = if acc.pieces != 1 {
        neg_expm1(acc.depth)
    } else {
        acc.alpha
    };
    alpha += (1.0 - alpha) * (1.0 - surf_t);
    let c = acc.color.map(|v| v.min(MAX_THICKNESS));
    iso_over(iso_over(front, [c[0], c[1], c[2], alpha]), back)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::camera::{Camera, CameraParams};
    use crate::render::iso::{IsoMix, IsoOptions, IsoSet, IsoSpec, Lighting, SideStyle};
    use crate::render::modes::iso::iso_window;
    use crate::render::modes::iso::VolumeTwin;
    use crate::render::modes::iso_split;
    use crate::render::modes::segment::ScalarMap;
    use crate::testdata::Rng;
    use crate::tf::{EmissionModel, Node, TransferFunction};

    /// A transfer function of 2 to 7 nodes on [0, 1], some at one scalar (a
    /// jump), some extinctions 0; extinction up to `tau_max`.
    fn random_tf(rng: &mut Rng, model: EmissionModel, tau_max: f64) -> TransferFunction {
        let n = 2 + rng.below(6);
        let mut s: Vec<f64> = (0..n).map(|_| rng.f64()).collect();
        s.sort_by(f64::total_cmp);
        (s[0], s[n - 1]) = (0.0, 1.0);
        if n > 3 && rng.below(2) == 0 {
            s[2] = s[1];
        }
        let nodes: Vec<Node> = s
            .iter()
            .map(|&s| Node {
                s,
                tau: if rng.below(5) == 0 {
                    0.0
                } else {
                    rng.range(0.0, tau_max)
                },
                color: [rng.f64(), rng.f64(), rng.f64()],
                emission: [rng.range(0.0, 3.0), rng.f64(), rng.range(0.0, 2.0)],
            })
            .collect();
        TransferFunction::from_nodes(&nodes, model).unwrap()
    }

    /// `n` surfaces on [-0.1, 1.1], opacities 0, 1 or between, colours
    /// given or the transfer function's.
    fn random_set(rng: &mut Rng, tf: &TransferFunction, n: usize, mix: IsoMix) -> IsoSet {
        let side = |rng: &mut Rng| SideStyle {
            color: (rng.below(2) == 0).then(|| [rng.f64(), rng.f64(), rng.f64()]),
            opacity: match rng.below(4) {
                0 => 0.0,
                1 => 1.0,
                _ => rng.f64(),
            },
        };
        let surfaces = (0..n)
            .map(|_| IsoSpec {
                value: rng.range(-0.1, 1.1),
                front: side(rng),
                back: side(rng),
            })
            .collect();
        let opts = IsoOptions {
            surfaces,
            lighting: Lighting::Smooth,
            alone: false,
            mix,
        };
        IsoSet::new(&opts, tf)
    }

    fn camera() -> Camera {
        Camera::fit([0.0, 1.0, 0.0, 1.0, 0.0, 1.0], &CameraParams::default())
    }

    /// A scalar for a segment end: random, or exactly a node's or a
    /// surface's (normalised, as the stage holds them).
    fn end(rng: &mut Rng, twin: &IsoTwin, vol: &ExactFragTwin) -> f32 {
        let (tf, _, _) = vol.integral();
        match rng.below(4) {
            0 => tf.node_s(rng.below(tf.count() as usize) as u32),
            1 => twin.surfaces[rng.below(twin.surfaces.len())].value[0],
            _ => rng.range(-0.2, 1.2) as f32,
        }
    }

    fn close(a: [f32; 4], b: [f32; 4], tol: f32) -> bool {
        a.iter()
            .zip(b)
            .all(|(&x, y)| (x - y).abs() <= tol * x.abs().max(y.abs()).max(1.0))
    }

    /// The walk gives what splitting the segment at its crossings and
    /// integrating each part gives (the split is the table modes' path,
    /// and was this one's): glow and emission, exact and blend mixing,
    /// 1 to 100 surfaces, ends at nodes and at isovalues, thickness from 0
    /// to opaque.
    #[test]
    fn walk_matches_the_split_segment() {
        let mut rng = Rng(0x5eed_1502);
        let mut worst = 0.0f32;
        let mut crossings = 0;
        for case in 0..240 {
            let model = [EmissionModel::Glow, EmissionModel::Independent][case % 2];
            let mix = [IsoMix::Exact, IsoMix::Blend][(case / 2) % 2];
            let tf = random_tf(&mut rng, model, [0.5, 5.0, 200.0][case % 3]);
            let n = [1, 2, 10, 100][(case / 4) % 4];
            let set = random_set(&mut rng, &tf, n, mix);
            let vol = ExactFragTwin::new(&tf, &camera());
            let twin = IsoTwin::new(&set, &ScalarMap::of(&tf), &camera(), VolumeTwin::None);
            for _ in 0..40 {
                let seg = Seg {
                    s_f: end(&mut rng, &twin, &vol),
                    s_b: end(&mut rng, &twin, &vol),
                    l: [0.0, 1e-6, rng.f64() as f32, rng.range(0.0, 4.0) as f32][rng.below(4)],
                    ok: true,
                };
                let g = |rng: &mut Rng| [rng.range(-1.0, 1.0) as f32, rng.f64() as f32, 0.5];
                let (gf, gb) = (g(&mut rng), g(&mut rng));
                let range = [0.0, twin.params.count as f32];
                let walk = iso_segment(&twin, &vol, &seg, gf, gb, range);
                let split_twin = IsoTwin::new(
                    &set,
                    &ScalarMap::of(&tf),
                    &camera(),
                    VolumeTwin::Integral(ExactFragTwin::new(&tf, &camera())),
                );
                let split = iso_split::iso_segment(&split_twin, &seg, gf, gb, range);
                let [a, b] = iso_window(&twin, seg.s_f, seg.s_b, range);
                crossings += (b - a) as usize;
                assert!(
                    close(walk, split, 5e-6),
                    "case {case}: {seg:?}: walk {walk:?}, split {split:?}"
                );
                let d = walk
                    .iter()
                    .zip(split)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f32::max);
                worst = worst.max(d);
            }
        }
        assert!(crossings > 5000, "{crossings} crossings");
        eprintln!("worst {worst:e} over {crossings} crossings");
    }

    /// Against the `f64` reference ([`IsoSet::composite`] over
    /// [`crate::integrate::segment`]), unlit, with the stage's own levels
    /// and segment ends (the `f32` levels lie [`ISO_LEVEL_F32`] below the
    /// reference's: a model difference, not the walk's) and ends away from
    /// every level (where the two may decide a crossing differently).
    ///
    /// [`ISO_LEVEL_F32`]: crate::numeric::tolerance::ISO_LEVEL_F32
    #[test]
    fn walk_matches_the_f64_reference() {
        let mut rng = Rng(0x1503_0f64);
        let mut worst = 0.0f64;
        for case in 0..120 {
            let model = [EmissionModel::Glow, EmissionModel::Independent][case % 2];
            let mix = [IsoMix::Exact, IsoMix::Blend][(case / 2) % 2];
            let tf = random_tf(&mut rng, model, [0.5, 5.0, 200.0][case % 3]);
            let mut set = random_set(&mut rng, &tf, [1, 3, 10, 100][(case / 4) % 4], mix);
            set.lighting = Lighting::None;
            let map = ScalarMap::of(&tf);
            let vol = ExactFragTwin::new(&tf, &camera());
            let twin = IsoTwin::new(&set, &map, &camera(), VolumeTwin::None);
            let raw = |s: f32| s as f64 / map.scale + map.offset;
            for (level, s) in set.levels.iter_mut().zip(&twin.surfaces) {
                *level = raw(s.value[0]);
            }
            let mut tried = 0;
            while tried < 30 {
                let ends = [0; 2].map(|_| map.apply(rng.range(-0.2, 1.2)) as f32);
                let near = |s: f32| twin.surfaces.iter().any(|v| (v.value[0] - s).abs() < 1e-4);
                if ends.iter().any(|&s| near(s)) {
                    continue;
                }
                tried += 1;
                let seg = Seg {
                    s_f: ends[0],
                    s_b: ends[1],
                    l: rng.range(0.0, 2.0) as f32,
                    ok: true,
                };
                let range = [0.0, twin.params.count as f32];
                let got = iso_segment(&twin, &vol, &seg, [0.0; 3], [0.0; 3], range);
                let (l, s_f, s_b) = (seg.l as f64, raw(seg.s_f), raw(seg.s_b));
                let want = set.composite(l, s_f, s_b, [DVec3::Z; 2], DVec3::Z, |l, a, b| {
                    crate::integrate::segment(&tf, l, a, b)
                });
                let want = [want.color[0], want.color[1], want.color[2], want.alpha];
                for (g, w) in got.iter().zip(want) {
                    let d = (*g as f64 - w).abs() / w.abs().max(1.0);
                    worst = worst.max(d);
                    assert!(
                        d < 5e-6,
                        "case {case}: l {l} s {s_f}..{s_b}: {got:?} against {want:?}"
                    );
                }
            }
        }
        eprintln!("worst {worst:e}");
    }
}
