//! Fuzz target: arbitrary bytes as a transfer-function file. Loading must
//! never panic; a loaded transfer function must integrate to finite values.
#![no_main]

use libfuzzer_sys::fuzz_target;
use zoovr::integrate::{self, RayMaterial};
use zoovr::tf::TransferFunction;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(tf) = TransferFunction::from_json_str(text, 0.5) else { return };
    let (lo, hi) = tf.scalar_range();
    let mid = 0.5 * (lo + hi);
    for (l, sf, sb) in [(1.0, lo, hi), (1e-9, mid, mid), (1e6, hi, lo), (0.5, lo - 1.0, hi + 1.0)] {
        let v = tf.segment(l, sf, sb);
        assert!(v.alpha.is_finite() && (0.0..=1.0).contains(&v.alpha));
        assert!(v.color.iter().all(|c| c.is_finite()));
        let vv = integrate::vertex_values(&tf, l, sf, sb);
        assert!(vv.glow.iter().all(|c| c.is_finite()));
    }
    // Round trip through the project format.
    let again = TransferFunction::from_json_str(&tf.to_json(), 0.5).expect("own output loads");
    assert_eq!(again.nodes(), tf.nodes());
});
