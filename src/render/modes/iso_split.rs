//! Twin of `shaders/iso_split.wgsl`: `iso_segment` over the stage's
//! `volume` (a table lookup, or nothing for `--mode iso`), the segment split
//! at its crossings and each sub-segment's volume taken on its own. The
//! closed-form volume walks nodes and crossings together instead
//! ([`super::iso_walk`]).

use super::iso::{iso_crosses, iso_over, iso_surface, iso_window, IsoTwin};
use super::segment::Seg;

/// Twin of `iso_segment` in `shaders/iso_split.wgsl`.
pub fn iso_segment(
    stage: &IsoTwin,
    seg: &Seg,
    gf: [f32; 3],
    gb: [f32; 3],
    candidates: [f32; 2],
) -> [f32; 4] {
    let [a, b] = iso_window(stage, seg.s_f, seg.s_b, candidates);
    let rising = seg.s_f <= seg.s_b;
    let blend = stage.params.mix == 1;
    let d = seg.s_b - seg.s_f;
    let (mut acc, mut back) = ([0.0f32; 4], [0.0f32; 4]);
    let (mut u0, mut s0) = (0.0f32, seg.s_f);
    for i in a..=b {
        let (mut u, mut sv, mut k) = (1.0f32, seg.s_b, 0);
        if i < b {
            k = if rising { i } else { a + b - 1 - i };
            let v = stage.surfaces[k as usize].value[0];
            if !iso_crosses(v, seg) {
                continue;
            }
            u = if d != 0.0 {
                ((v - seg.s_f) / d).clamp(0.0, 1.0)
            } else {
                0.0
            };
            sv = v;
        }
        if !blend || i == b {
            let (from_u, from_s) = if blend { (0.0, seg.s_f) } else { (u0, s0) };
            acc = iso_over(acc, stage.volume.volume((u - from_u) * seg.l, from_s, sv));
        }
        if i < b {
            let g = std::array::from_fn(|c| gf[c] + (gb[c] - gf[c]) * u);
            if blend {
                acc = iso_over(acc, iso_surface(stage, k, rising, g, 1.0 - u));
                back = iso_over(back, iso_surface(stage, k, rising, g, u));
            } else {
                acc = iso_over(acc, iso_surface(stage, k, rising, g, 1.0));
                if acc[3] >= 1.0 {
                    break;
                }
            }
        }
        (u0, s0) = (u, sv);
    }
    iso_over(acc, back)
}
