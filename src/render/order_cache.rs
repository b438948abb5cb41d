//! The last visibility order a [`super::Renderer`] made, reused when the
//! next frame asks for the same one, and the last view's sort, reused when
//! only the values changed.
//!
//! An order is the geometry's order of the view ([`Sorter::base_order`]:
//! it depends on the camera, `--split all` and the sorter's options) with
//! the values spliced in ([`Sorter::splice`]: the mode's split points and,
//! through them, the point scalars, and what is dark). The cache keeps
//! both, each with its inputs as its key (the scalars by count and a 64-bit
//! hash of their bits, computed once per frame: about a millisecond per
//! million points):
//! - a frame whose whole key is equal takes the same order without sorting
//!   or splicing (a benchmark's repeats, new colours that keep the split
//!   points, new isosurface styles or drawing options; for a mode without
//!   split points, new values too, since the scalars then split nothing);
//! - a frame of the same view with new values or new split points (a time
//!   step, a new transfer function) keeps the sort and only splices, which
//!   is what `zoovr animate` saves on a series whose values change.
//!
//! New geometry clears both ([`super::Renderer::set_geometry`]).

use std::sync::Arc;

use crate::camera::Camera;
use crate::visibility::{NonConvex, Order, Sorter, SplitPolicy, VisibilityError};

/// What the geometry's order of a view was made from.
#[derive(Clone, Debug, PartialEq)]
struct BaseKey {
    camera: Camera,
    all: bool,
    nonconvex: NonConvex,
    plane_split: bool,
    frustum_margin: Option<f64>,
}

/// What an order was made from.
#[derive(Clone, Debug, PartialEq)]
struct Key {
    base: BaseKey,
    breakpoints: Vec<f64>,
    /// Count and hash of the point scalars, when the policy has them.
    scalars: Option<(usize, u64)>,
    /// What decides which cells are dark (not split).
    dark: Option<u64>,
}

/// What a frame took from the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reuse {
    /// Nothing: the view was sorted.
    None,
    /// The view's sort; the values were spliced in.
    Sort,
    /// The whole order.
    Order,
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
    base: Option<(BaseKey, Arc<Order>)>,
}

impl OrderCache {
    /// Forgets the last order and sort.
    pub fn clear(&mut self) {
        self.last = None;
        self.base = None;
    }

    /// The last order made or reused, if any.
    pub fn last(&self) -> Option<&Arc<Order>> {
        self.last.as_ref().map(|(_, o)| o)
    }

    /// The order of `sorter` for `camera` and `policy`: the last one when
    /// its key is equal, else the values spliced into the last sort of the
    /// view when that is the same, else a new sort; both kept for next
    /// time.
    pub fn order(
        &mut self,
        sorter: &mut Sorter,
        camera: &Camera,
        policy: &SplitPolicy,
    ) -> Result<(Arc<Order>, Reuse), VisibilityError> {
        let base_key = BaseKey {
            camera: *camera,
            all: policy.all,
            nonconvex: sorter.nonconvex,
            plane_split: sorter.plane_split,
            frustum_margin: sorter.frustum_margin,
        };
        let splits = policy.point_scalars.is_some() && !policy.breakpoints.is_empty();
        let key = Key {
            base: base_key.clone(),
            breakpoints: policy.breakpoints.to_vec(),
            // Without split points the scalars split nothing.
            scalars: policy
                .point_scalars
                .filter(|_| splits)
                .map(|s| (s.len(), hash_bits(s))),
            // Only where scalars decide splits.
            dark: policy.dark.filter(|_| splits).map(|d| d.key),
        };
        if let Some((k, order)) = &self.last {
            if *k == key {
                return Ok((order.clone(), Reuse::Order));
            }
        }
        self.last = None;
        let (base, reuse) = match &self.base {
            Some((k, base)) if *k == base_key => (base.clone(), Reuse::Sort),
            _ => {
                self.base = None;
                let base = Arc::new(sorter.base_order(camera, policy.all)?);
                self.base = Some((base_key, base.clone()));
                (base, Reuse::None)
            }
        };
        let order = if splits {
            Arc::new(sorter.splice(&base, camera, policy)?)
        } else {
            base
        };
        self.last = Some((key, order.clone()));
        Ok((order, reuse))
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
