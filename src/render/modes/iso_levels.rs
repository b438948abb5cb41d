//! The levels the isosurface stages compare with, and the ends of a tie
//! quad put on the reference's side of them.
//!
//! The reference crosses isovalue `V` where one end of a segment is below
//! its `f64` level ([`IsoSet::levels`]: `V` less a margin of the span) and
//! the other not. The `f32` stages compare with [`gpu_level`], `V` less
//! [`ISO_LEVEL_F32`] of itself, so that a face whose corners all hold `V`
//! (interpolated to within a few ulps of it) is crossed once, not twice or
//! never. Within that margin the two can disagree; [`decided_end`] moves
//! the ends of a tie triangle (the exact segment at one pixel centre) across the
//! `f32` level to where the reference puts them.

use crate::numeric::tolerance::{ISO_DECIDE_FLOOR, ISO_DECIDE_ULPS, ISO_LEVEL_F32};
use crate::render::iso::IsoSet;

use super::segment::ScalarMap;

/// The level the stage compares with for normalised isovalue `v`: `v` in
/// `f32` less [`ISO_LEVEL_F32`] of itself (see [`IsoSet::levels`]): exact at 0.
pub fn gpu_level(v: f64) -> f32 {
    let v32 = v as f32;
    (v32 as f64 - ISO_LEVEL_F32 * v.abs()) as f32
}

/// A vertex's end `(s q, q)` in `f32` (or `(s, 1)` orthographic) for the
/// exact raw scalar `s`, moved where the stage would read it on the other
/// side of a level than the reference puts `s`: the stage crosses a
/// surface where one end is below [`gpu_level`] of the normalised value and
/// the other not, the reference ([`IsoSet::crossed`]) where one end is
/// below the `f64` level. Within [`ISO_LEVEL_F32`] of a value the two can
/// disagree: a ray caster's segment ending `3e-7` below a value crosses
/// it, the same segment read in `f32` against the level `1e-6` below the
/// value does not, and the surface is missing or drawn at the next
/// crossing. The value read is put [`ISO_DECIDE_ULPS`] beyond the level on
/// the reference's side (a move of at most `ISO_LEVEL_F32` of the value
/// and those ulps). For a tie triangle's ends only: it carries the exact
/// segment over its one pixel, and so decides the pixel as the ray caster
/// does. Levels closer together than the move are not told apart.
pub fn decided_end(set: &IsoSet, map: &ScalarMap, s: f64, end: [f32; 2]) -> [f32; 2] {
    let q = end[1];
    let read = end[0] / q;
    if !(s.is_finite() && read.is_finite() && q != 0.0) {
        return end;
    }
    // Levels at or below `s` (it is at or above them), then those above.
    let k = set.levels.partition_point(|&l| l <= s);
    let level = |i: usize| gpu_level(map.apply(set.values[i]));
    let away =
        |g: f32| (ISO_DECIDE_ULPS * f32::EPSILON as f64 * g.abs() as f64).max(ISO_DECIDE_FLOOR);
    let mut target = None;
    if k > 0 {
        let g = level(k - 1);
        let want = g as f64 + away(g);
        if (read as f64) < want {
            target = Some(want);
        }
    }
    if k < set.levels.len() {
        let g = level(k);
        let want = g as f64 - away(g);
        if (read as f64) > want {
            target = Some(want);
        }
    }
    match target {
        Some(t) => [(t * q as f64) as f32, q],
        None => end,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::iso::{parse_list, IsoOptions};
    use crate::tf::TransferFunction;

    /// A tie triangle's ends are read by the stage (in `f32`, against the GPU
    /// levels) on the side of every level that the reference puts the exact
    /// scalar (in `f64`, against [`IsoSet::levels`]), in both projections
    /// and with a few ulps of interpolation rounding, including next to
    /// 0, where the `f64` margin is of the span and the `f32` one none. The
    /// ends as stored before the move disagree for some of these scalars
    /// (the test would pass without the move otherwise).
    #[test]
    fn tie_ends_fall_on_the_references_side_of_each_level() {
        let tf = TransferFunction::default_for((0.0, 2.0), 1.0);
        let map = ScalarMap::of(&tf);
        let opts = IsoOptions {
            surfaces: parse_list("0,0.6,1.3,2").unwrap(),
            ..Default::default()
        };
        let set = IsoSet::new(&opts, &tf);
        let gpu: Vec<f32> = set
            .values
            .iter()
            .map(|&v| gpu_level(map.apply(v)))
            .collect();
        let side = |read: f32| gpu.iter().map(|&g| read < g).collect::<Vec<_>>();
        let (mut raw_wrong, mut cases) = (0, 0);
        for &v in &set.values {
            for rel in [
                -1e-4, -2e-6, -1e-6, -9e-7, -3e-7, -1e-9, -1e-12, -1e-13, 0.0, 1e-13, 1e-12, 1e-9,
                3e-7, 2e-6,
            ] {
                let s = v + rel * v.abs().max(1.0);
                let want: Vec<bool> = set.levels.iter().map(|&l| s < l).collect();
                for q in [1.0f64, 3.7, 0.013] {
                    let n = map.apply(s);
                    let end = [(n * q) as f32, q as f32];
                    raw_wrong += (side(end[0] / end[1]) != want) as usize;
                    let got = decided_end(&set, &map, s, end);
                    for wobble in [-4.0f32, 0.0, 4.0] {
                        let read = got[0] / got[1] * (1.0 + wobble * f32::EPSILON);
                        assert_eq!(side(read), want, "v {v} s {s:e} q {q} read {read:e}");
                    }
                    let moved = (got[0] / got[1]) as f64 - n;
                    assert!(
                        moved.abs() <= 2.0 * ISO_LEVEL_F32 * v.abs() + 1e-11,
                        "{moved:e}"
                    );
                    cases += 1;
                }
            }
        }
        assert!(raw_wrong > 0 && raw_wrong < cases, "{raw_wrong} of {cases}");
    }
}
