//! The last visibility order a [`super::Renderer`] made, reused when the
//! next frame asks for the same one.
//!
//! An order depends on the camera, the split policy (`--split all`, the
//! mode's split points, and through them the point scalars: cells whose
//! range holds a split point are split) and the sorter's own options. The
//! cache keeps the last order with those inputs as its key (the scalars by
//! count and a 64-bit hash of their bits, computed once per frame: about a
//! millisecond per million points); a frame whose key is equal takes the
//! same order without sorting again (the order is shared, not copied). This
//! is what a repeated frame (a benchmark's repeats), a change of colours
//! that keeps the split points, or of isosurface styles, or of the mode's
//! drawing options, saves; for a mode without split points (`exact-frag`
//! with no `--split all`) new values alone keep the order too, since the
//! scalars then split nothing. New geometry clears it
//! ([`super::Renderer::set_geometry`]).

use std::sync::Arc;

use crate::camera::Camera;
use crate::visibility::{NonConvex, Order, Sorter, SplitPolicy, VisibilityError};

/// What an order was made from.
#[derive(Clone, Debug, PartialEq)]
struct Key {
    camera: Camera,
    all: bool,
    breakpoints: Vec<f64>,
    /// Count and hash of the point scalars, when the policy has them.
    scalars: Option<(usize, u64)>,
    nonconvex: NonConvex,
    plane_split: bool,
    frustum_margin: Option<f64>,
    /// What decides which cells are dark (not split).
    dark: Option<u64>,
}

/// A 64-bit hash of the bits of `v` (FxHash-style mixing; equal slices hash
/// equal, and a changed value changes it but for a 2^-64 chance).
fn hash_bits(v: &[f64]) -> u64 {
    const K: u64 = 0x517c_c1b7_2722_0a95;
    let mut h = v.len() as u64;
    for x in v {
        h = (h.rotate_left(5) ^ x.to_bits()).wrapping_mul(K);
    }
    h
}

/// The last order and its key.
#[derive(Default)]
pub struct OrderCache {
    last: Option<(Key, Arc<Order>)>,
}

impl OrderCache {
    /// Forgets the last order.
    pub fn clear(&mut self) {
        self.last = None;
    }

    /// The last order made or reused, if any.
    pub fn last(&self) -> Option<&Arc<Order>> {
        self.last.as_ref().map(|(_, o)| o)
    }

    /// The order of `sorter` for `camera` and `policy`: the last one when
    /// its key is equal (`true`), else a new sort (`false`), kept for next
    /// time.
    pub fn order(
        &mut self,
        sorter: &mut Sorter,
        camera: &Camera,
        policy: &SplitPolicy,
    ) -> Result<(Arc<Order>, bool), VisibilityError> {
        let key = Key {
            camera: *camera,
            all: policy.all,
            breakpoints: policy.breakpoints.to_vec(),
            // Without split points the scalars split nothing.
            scalars: policy
                .point_scalars
                .filter(|_| !policy.breakpoints.is_empty())
                .map(|s| (s.len(), hash_bits(s))),
            nonconvex: sorter.nonconvex,
            plane_split: sorter.plane_split,
            frustum_margin: sorter.frustum_margin,
            // Only where scalars decide splits.
            dark: policy
                .dark
                .filter(|_| policy.point_scalars.is_some() && !policy.breakpoints.is_empty())
                .map(|d| d.key),
        };
        if let Some((k, order)) = &self.last {
            if *k == key {
                return Ok((order.clone(), true));
            }
        }
        self.last = None;
        let order = Arc::new(sorter.order(camera, policy)?);
        self.last = Some((key, order.clone()));
        Ok((order, false))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_tell_values_apart() {
        let a = [0.0, 1.0, 2.0];
        assert_eq!(hash_bits(&a), hash_bits(&[0.0, 1.0, 2.0]));
        assert_ne!(hash_bits(&a), hash_bits(&[0.0, 1.0, 2.0000000001]));
        assert_ne!(hash_bits(&a), hash_bits(&[1.0, 0.0, 2.0]));
        assert_ne!(hash_bits(&a), hash_bits(&[0.0, 1.0]));
        assert_ne!(hash_bits(&[0.0]), hash_bits(&[-0.0]));
    }
}
