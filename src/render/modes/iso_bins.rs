//! The bins that start the isosurface stages' search for the isovalues
//! between a segment's ends (`iso_bin`, `count_at_most` in
//! `shaders/iso.wgsl`): a binary search over a few surfaces instead of
//! all of them.

/// The bins that start `count_at_most`'s search: as many as there are
/// surfaces, of equal width between the first and the last value, so that
/// evenly spread values put one surface in each and the search takes two
/// steps however many there are (a binary search over all of them took
/// seven at 100 surfaces, each a gather on a software rasteriser).
///
/// Bin `k` of scalar `x` is `floor((x - origin) * scale)` clamped to
/// `0 ..= n - 1`, in `f32` (`iso_bin`), which is monotone in `x`: every
/// value in a lower bin than `x`'s is below `x`, every value in a higher
/// bin above it. The search for `x` in bin `k` runs over the surfaces of
/// bins `k - 1` to `k + 1` ([`IsoBins::window`]): the neighbours absorb a
/// GPU that rounds `x`'s bin differently by one. Bins narrower than
/// [`IsoBins::MIN_WIDTH`] of the values' magnitude (where that rounding
/// could be wider than a bin) are not made: one bin holds every surface,
/// a binary search over all of them.
#[derive(Clone, Debug, PartialEq)]
pub struct IsoBins {
    pub origin: f32,
    /// `0`: one bin.
    pub scale: f32,
    /// The number of bins: the number of surfaces.
    pub count: u32,
    /// For each bin `k` (of `n`), the first surface of bin `k - 1` and the
    /// end of the surfaces of bin `k + 1`.
    pub windows: Vec<[u32; 2]>,
}

impl IsoBins {
    /// The narrowest bin, relative to the largest magnitude of the first
    /// and last values (at least 1): many `f32` ulps, so that a scalar's
    /// bin can be off by one at most between GPU and CPU.
    pub const MIN_WIDTH: f32 = 1e-4;

    /// The bins of the sorted values `values` (normalised, `f32`).
    pub fn new(values: &[f32]) -> IsoBins {
        let n = values.len();
        let (Some(&first), Some(&last)) = (values.first(), values.last()) else {
            return IsoBins {
                origin: 0.0,
                scale: 0.0,
                count: 0,
                windows: Vec::new(),
            };
        };
        let width = (last - first) / n as f32;
        let magnitude = first.abs().max(last.abs()).max(1.0);
        let scale = if width.is_finite() && width > IsoBins::MIN_WIDTH * magnitude {
            1.0 / width
        } else {
            0.0
        };
        let mut bins = IsoBins {
            origin: first,
            scale,
            count: n as u32,
            windows: Vec::with_capacity(n),
        };
        // start[k]: the first surface of bin k (the values are sorted and
        // the bins monotone); start[n] = n.
        let mut start = vec![n as u32; n + 1];
        for (i, &v) in values.iter().enumerate().rev() {
            start[bins.bin(v) as usize] = i as u32;
        }
        for k in (0..n).rev() {
            start[k] = start[k].min(start[k + 1]);
        }
        bins.windows = (0..n)
            .map(|k| [start[k.saturating_sub(1)], start[(k + 2).min(n)]])
            .collect();
        bins
    }

    /// The bin of `x` (`iso_bin`).
    pub fn bin(&self, x: f32) -> u32 {
        iso_bin(self.origin, self.scale, self.count, x)
    }
}

/// Twin of `iso_bin`: the bin of `x` among `count` (`IsoParams`).
pub fn iso_bin(origin: f32, scale: f32, count: u32, x: f32) -> u32 {
    let t = (x - origin) * scale;
    // `clamp` as WGSL's `min(max(t, 0), n - 1)`: 0 for NaN.
    t.floor().max(0.0).min(count.saturating_sub(1) as f32) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testdata::Rng;

    /// The number of values `<= x`, as `count_at_most` searches it: among
    /// the window of bin `k`.
    fn count_in(values: &[f32], bins: &IsoBins, k: u32, x: f32) -> u32 {
        let [mut lo, mut hi] = bins.windows[k as usize];
        while lo < hi {
            let mid = (lo + hi) / 2;
            if values[mid as usize] <= x {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Sorted value sets: even, random, clustered, repeated, one value,
    /// a range too narrow for bins, huge magnitudes.
    fn value_sets(rng: &mut Rng) -> Vec<Vec<f32>> {
        let mut sets = vec![
            (1..=100).map(|k| k as f32 / 101.0).collect(),
            vec![0.5],
            vec![0.25, 0.25, 0.25, 0.75],
            vec![0.3, 0.3 + 1e-7, 0.3 + 2e-7],
            vec![-1e30, 0.0, 1e30],
            vec![1e6, 1e6 + 0.125, 1e6 + 0.25],
        ];
        // 99 values in a cluster, one far away: bins of 1/100 of the range
        // put the cluster in one.
        let mut clustered: Vec<f32> = (0..99).map(|k| 0.2 + k as f32 * 1e-5).collect();
        clustered.push(0.9);
        sets.push(clustered);
        for n in [2, 7, 64, 300, 1024] {
            let mut v: Vec<f32> = (0..n).map(|_| rng.range(-0.5, 1.5) as f32).collect();
            v.sort_by(f32::total_cmp);
            sets.push(v);
        }
        sets
    }

    /// `count_at_most` through the bins is the number of values `<= x`
    /// for every set and every scalar tried (values themselves, their
    /// neighbouring floats, bin edges, random, infinities), also where
    /// the GPU rounds a scalar into the next bin on either side.
    #[test]
    fn bins_count_every_value_at_most_x() {
        let mut rng = Rng(0xb1b5);
        for values in value_sets(&mut rng) {
            let bins = IsoBins::new(&values);
            let n = values.len() as u32;
            assert_eq!(bins.windows.len(), values.len());
            let mut xs = vec![f32::NEG_INFINITY, f32::INFINITY, f32::MIN, f32::MAX, 0.0];
            for &v in &values {
                xs.extend([v, v.next_down(), v.next_up()]);
            }
            if bins.scale > 0.0 {
                for k in 0..=n {
                    let edge = bins.origin + k as f32 / bins.scale;
                    xs.extend([edge, edge.next_down(), edge.next_up()]);
                }
            }
            xs.extend((0..200).map(|_| rng.range(-1.0, 2.0) as f32));
            for x in xs {
                let want = values.iter().filter(|&&v| v <= x).count() as u32;
                let k = bins.bin(x);
                for k in [k.saturating_sub(1), k, (k + 1).min(n - 1)] {
                    // A bin one off is absorbed only where the scalar lies
                    // at its edge: check the rounding the window allows.
                    if k != bins.bin(x) && bins.scale > 0.0 {
                        let t = (x - bins.origin) * bins.scale;
                        if (t - t.round()).abs() > 1e-3 {
                            continue;
                        }
                    }
                    assert_eq!(
                        count_in(&values, &bins, k, x),
                        want,
                        "{} values, x {x}, bin {k}",
                        values.len()
                    );
                }
            }
        }
    }

    /// Evenly spread values get one surface per bin (the search's two
    /// steps); sets too narrow for bins get one window over all.
    #[test]
    fn even_values_fill_one_bin_each() {
        let values: Vec<f32> = (1..=100).map(|k| k as f32 / 101.0).collect();
        let bins = IsoBins::new(&values);
        assert!(bins.scale > 0.0);
        for (k, w) in bins.windows.iter().enumerate() {
            assert!(w[1] - w[0] <= 4, "bin {k}: {w:?}");
        }
        let narrow = IsoBins::new(&[0.3, 0.3 + 1e-7, 0.3 + 2e-7]);
        assert_eq!(narrow.scale, 0.0);
        assert_eq!(narrow.windows[0], [0, 3]);
        assert!([-1.0, 0.3, 0.5, f32::INFINITY]
            .iter()
            .all(|&x| narrow.bin(x) == 0));
        assert_eq!(IsoBins::new(&[]).windows, Vec::<[u32; 2]>::new());
    }
}
