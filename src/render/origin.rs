//! Scalars far from zero next to their span, moved to an origin in their
//! middle before any renderer reads them.
//!
//! A field spanning 1e-12 around 1 has only about 4500 `f64` values in its
//! range: one ulp of its values is 2.2e-4 of the range. Every renderer
//! interpolates scalars (the ray caster along its segments, the projected
//! modes' tie and seam decisions at pixel centres, the exact mode's slices
//! at the transfer function's breakpoints), and interpolating the raw
//! values rounds each result to those ulps: surfaces and breakpoints moved
//! by a few thousandths of the range, enough to put the isosurfaces of
//! such a field up to 38 pixels per view away from where the projected
//! modes drew them, and to open single-pixel holes in the projected modes'
//! surfaces where their exact decisions at shared faces read the rounded
//! values.
//!
//! So a frame of such a field is rendered from the field, the transfer
//! function and the isovalues all moved by one origin, the middle of the
//! field's finite values ([`scalar_origin`]): each moved scalar is exact
//! (Sterbenz) wherever it lies within a factor two of the origin, and
//! every quantity of the image (the transfer function's pieces, the
//! surfaces' places, colours and gradients) is the same function of the
//! moved scalar, so the image is that of the field itself, resolved to the
//! rounding of its offsets instead of its values. Only the renderers see
//! the moved values: the range printed, the legend and the warnings about
//! isovalues outside the range keep the field's own units.
//!
//! The move applies where the rounding of the raw values exceeds the
//! margin of the isosurface levels relative to the span
//! ([`ISO_LEVEL_ULPS`] ulps of the middle above [`ISO_LEVEL_F64`] of the
//! span: a field more than about 1100 times as far from zero as it is
//! wide); elsewhere the field is rendered as it is, bit for bit. The moved
//! field is kept between frames ([`MovedField`]), so that the caches keyed
//! by the field (the visible subset, the kept projection) hold across
//! frames of one field.

use std::sync::Arc;

use crate::field::ScalarField;
use crate::numeric::tolerance::{ISO_LEVEL_F64, ISO_LEVEL_ULPS};

use super::scene::Shading;
use super::RenderOptions;

/// The origin a field with finite values from `lo` to `hi` is moved by
/// (module docs): their middle, where [`ISO_LEVEL_ULPS`] ulps of it exceed
/// [`ISO_LEVEL_F64`] of the span; `None` elsewhere and where the span is
/// empty (a constant field) or not finite.
pub fn scalar_origin((lo, hi): (f64, f64)) -> Option<f64> {
    let (span, mid) = (hi - lo, 0.5 * lo + 0.5 * hi);
    (span > 0.0
        && span.is_finite()
        && ISO_LEVEL_ULPS * f64::EPSILON * mid.abs() > ISO_LEVEL_F64 * span)
        .then_some(mid)
}

/// The last field moved, kept for the next frame.
#[derive(Default)]
pub struct MovedField {
    last: Option<(Arc<ScalarField>, Arc<ScalarField>, f64)>,
}

impl MovedField {
    /// The frame's shading and options with the field, the transfer
    /// function, its range and the isovalues moved by the field's origin
    /// ([`scalar_origin`]), or `None` where the field is rendered as it is
    /// (no field, a field near zero next to its span, or a transfer function
    /// whose nodes the move would merge, [`crate::tf::TransferFunction::shifted`]).
    pub fn frame(
        &mut self,
        shading: &Shading,
        opts: &RenderOptions,
    ) -> Option<(Shading, RenderOptions)> {
        let field = shading.field.as_ref()?;
        let origin = scalar_origin(field.range)?;
        let tf = shading.tf.shifted(origin)?;
        let moved = match &self.last {
            Some((was, moved, o)) if Arc::ptr_eq(was, field) && *o == origin => moved.clone(),
            _ => {
                let values = field.values.iter().map(|&v| v - origin).collect();
                let moved = Arc::new(ScalarField::new(
                    field.name.clone(),
                    field.association,
                    values,
                ));
                self.last = Some((field.clone(), moved.clone(), origin));
                moved
            }
        };
        let mut opts = opts.clone();
        for s in &mut opts.iso.surfaces {
            s.value -= origin;
        }
        let (lo, hi) = shading.range;
        Some((
            Shading {
                field: Some(moved),
                range: (lo - origin, hi - origin),
                tf,
                unit_distance: shading.unit_distance,
            },
            opts,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::Association;
    use crate::render::iso::IsoSpec;
    use crate::tf::TransferFunction;

    #[test]
    fn only_fields_far_from_zero_next_to_their_span_are_moved() {
        let o = scalar_origin((1.0, 1.0 + 1e-12)).unwrap();
        assert!((o - (1.0 + 0.5e-12)).abs() <= 2.0 * f64::EPSILON);
        // Every value of the range moves exactly (within a factor two).
        for k in 0..=10 {
            let v = 1.0 + 1e-13 * k as f64;
            assert_eq!((v - o) + o, v, "{k}");
        }
        // 1e3 times as far as wide: the span margin still holds.
        assert_eq!(scalar_origin((1e3, 1e3 + 1.0)), None);
        assert!(scalar_origin((-1e4, -1e4 + 1.0)).is_some());
        for unmoved in [(0.0, 1.0), (-5.0, 7.0), (3.0, 3.0), (0.0, f64::INFINITY)] {
            assert_eq!(scalar_origin(unmoved), None, "{unmoved:?}");
        }
    }

    #[test]
    fn a_frame_moves_field_function_range_and_values_together_and_keeps_the_field() {
        let values: Vec<f64> = (0..=4).map(|k| 1.0 + 0.25e-12 * k as f64).collect();
        let field = Arc::new(ScalarField::new("f".into(), Association::Point, values));
        let tf = TransferFunction::from_channels(
            &[(1.0, [0.0]), (1.0 + 1e-12, [5.0])],
            &[(1.0, [0.1, 0.2, 0.9]), (1.0 + 1e-12, [1.0, 0.5, 0.1])],
            None,
            crate::tf::EmissionModel::Glow,
        )
        .unwrap();
        let shading = Shading {
            field: Some(field.clone()),
            range: (1.0, 1.0 + 1e-12),
            tf: tf.clone(),
            unit_distance: 1.0,
        };
        let mut opts = RenderOptions::default();
        opts.iso
            .surfaces
            .push("1.0000000000005".parse::<IsoSpec>().unwrap());
        let mut moved = MovedField::default();
        let (s, o) = moved.frame(&shading, &opts).unwrap();
        let origin = 1.0 + 0.5e-12;
        let f = s.field.as_ref().unwrap();
        for (m, v) in f.values.iter().zip(&field.values) {
            assert_eq!(*m, v - origin);
        }
        assert_eq!(o.iso.surfaces[0].value, 1.0000000000005 - origin);
        assert_eq!(s.range, (1.0 - origin, 1e-12 + 1.0 - origin));
        for v in &field.values {
            assert_eq!(s.tf.tau_at(v - origin), tf.tau_at(*v));
            assert_eq!(s.tf.color_at(v - origin), tf.color_at(*v));
        }
        // The next frame of the same field reads the same moved field.
        let (again, _) = moved.frame(&shading, &opts).unwrap();
        assert!(Arc::ptr_eq(again.field.as_ref().unwrap(), f));
        // A field near zero is rendered as it is.
        let near = Shading {
            field: Some(Arc::new(ScalarField::new(
                "g".into(),
                Association::Point,
                vec![0.0, 1.0],
            ))),
            ..shading
        };
        assert!(moved.frame(&near, &opts).is_none());
    }
}
