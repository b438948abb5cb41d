//! The bins that start the isosurface stages' search for the isovalues
//! between a segment's ends (`iso_bin`, `count_at_most` in
//! `shaders/iso.wgsl`): a binary search over a few surfaces instead of
//! all of them.

/// The bins that start `count_at_most`'s search: as many as there are
/// surfaces, of equal width between the first and the last value, so that
/// evenly spread values put about one surface in each and the search takes
/// one or two steps however many there are (a binary search over all of
/// them took seven at 100 surfaces, each a gather on a software
/// rasteriser).
///
/// Bin `k` of scalar `x` is `floor((x - origin) * scale)` clamped to
/// `0 ..= n - 1`, in `f32` (`iso_bin`): `x` lies between the bin's edges
/// `origin + k / scale` and `origin + (k + 1) / scale` up to the rounding
/// of those two operations. The search for `x` in bin `k` runs over the
/// surfaces whose values lie between the edges widened by
/// [`IsoBins::margin`], far more than that rounding (on any GPU: IEEE
/// subtraction and multiplication, a few ulps at most): every value below
/// the window is below `x`, every value above it above `x`. Bins narrower
/// than [`IsoBins::MIN_WIDTH`] of the values' magnitude are not made: one
/// bin holds every surface, a binary search over all of them.
#[derive(Clone, Debug, PartialEq)]
pub struct IsoBins {
    pub origin: f32,
    /// `0`: one bin.
    pub scale: f32,
    /// The number of bins: the number of surfaces.
    pub count: u32,
    /// For each bin `k` (of `n`), the surfaces its search runs over:
    /// `windows[k][0] .. windows[k][1]`.
    pub windows: Vec<[u32; 2]>,
}

impl IsoBins {
    /// The narrowest bin, relative to the largest magnitude of the first
    /// and last values (at least 1): many `f32` ulps.
    pub const MIN_WIDTH: f32 = 1e-4;

    /// How far beyond its edges a bin's window reaches: `1e-3` of the bin
    /// plus `4e-6` of it per bin (the rounding of `(x - origin) * scale`,
    /// relative to `t` up to `n`, in units of `x`), plus 16 ulps of the
    /// values' magnitude (the rounding of `x` and of the edges).
    pub fn margin(width: f64, n: usize, magnitude: f64) -> f64 {
        width * (1e-3 + 4e-6 * n as f64) + 16.0 * f32::EPSILON as f64 * magnitude
    }

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
        let windows = if scale > 0.0 {
            let w = 1.0 / scale as f64;
            let margin = IsoBins::margin(w, n, magnitude as f64);
            let edge = |k: usize| first as f64 + k as f64 * w;
            (0..n)
                .map(|k| {
                    let lo = if k == 0 {
                        0
                    } else {
                        values.partition_point(|&v| (v as f64) < edge(k) - margin)
                    };
                    let hi = if k + 1 == n {
                        n
                    } else {
                        values.partition_point(|&v| v as f64 <= edge(k + 1) + margin)
                    };
                    [lo as u32, hi.max(lo) as u32]
                })
                .collect()
        } else {
            vec![[0, n as u32]; n]
        };
        IsoBins {
            origin: first,
            scale,
            count: n as u32,
            windows,
        }
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
            // Values on a bin's edge and an ulp below the next (bins of
            // 0.25): a scalar rounded into the neighbouring bin must still
            // find them.
            vec![0.0, 0.25, 0.5f32.next_down(), 0.75f32.next_up(), 1.0],
            vec![0.0, 0.5f32.next_down(), 0.75, 1.0],
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
                // The bin, and where the scalar lies at an edge (within
                // far more than a GPU's rounding of `t`) the bins on both
                // sides of it.
                let mut ks = vec![bins.bin(x)];
                let t = (x - bins.origin) * bins.scale;
                if bins.scale > 0.0 && (t - t.round()).abs() <= 5e-4 {
                    let m = t.round() as i64;
                    ks.extend([m - 1, m].map(|k| k.clamp(0, n as i64 - 1) as u32));
                }
                for k in ks {
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

    /// Evenly spread values get at most one surface per bin (the search's
    /// one step); sets too narrow for bins get one window over all.
    #[test]
    fn even_values_fill_one_bin_each() {
        let values: Vec<f32> = (1..=100).map(|k| k as f32 / 101.0).collect();
        let bins = IsoBins::new(&values);
        assert!(bins.scale > 0.0);
        for (k, w) in bins.windows.iter().enumerate() {
            assert!(w[1] - w[0] <= 1, "bin {k}: {w:?}");
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
