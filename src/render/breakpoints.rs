//! The TF values at which pieces are sliced for a mode whose per-pixel
//! opacity is exact only where the extinction is linear along the ray
//! (the exact mode): every kink or jump of the extinction and every jump of
//! the colour.

use crate::numeric::tolerance::TF_SLOPE_REL;
use crate::tf::TransferFunction;

/// The scalar values at which pieces must be split for the per-pixel opacity
/// to be exact: every breakpoint of the extinction (a kink or a jump) and
/// every jump of the colour. Colour kinks alone are not split: vertex values
/// stay exact there and the interpolated `C/alpha` is bounded by the colour
/// refinement ([`crate::numeric::tolerance::COLOR_REFINE_TOL`]).
pub fn split_points(tf: &TransferFunction) -> Vec<f64> {
    let nodes = tf.nodes();
    let mut out: Vec<f64> = Vec::new();
    let slope = |a: &crate::tf::Node, b: &crate::tf::Node| -> Option<f64> {
        let ds = b.s - a.s;
        (ds > 0.0).then(|| (b.tau - a.tau) / ds)
    };
    for i in 0..nodes.len() {
        let n = &nodes[i];
        if i + 1 < nodes.len() && nodes[i + 1].s == n.s {
            // A jump: two nodes at one scalar.
            let m = &nodes[i + 1];
            let colour_jump =
                (0..3).any(|k| n.color[k] != m.color[k] || n.emission[k] != m.emission[k]);
            if n.tau != m.tau || colour_jump {
                out.push(n.s);
            }
            continue;
        }
        if i == 0 || i + 1 >= nodes.len() || nodes[i - 1].s == n.s {
            // Ends of the node range, or the right node of a jump (handled).
            if i > 0 && i + 1 < nodes.len() && nodes[i - 1].s == n.s {
                continue;
            }
            // The TF is constant outside the node range: a kink at each end
            // when the extinction slopes inside.
            let inner = if i == 0 {
                nodes.get(1)
            } else {
                nodes.get(i.wrapping_sub(1))
            };
            if let Some(m) = inner {
                if m.tau != n.tau {
                    out.push(n.s);
                }
            }
            continue;
        }
        let (l, r) = (slope(&nodes[i - 1], n), slope(n, &nodes[i + 1]));
        let kink = match (l, r) {
            (Some(l), Some(r)) => (l - r).abs() > TF_SLOPE_REL * l.abs().max(r.abs()),
            _ => true,
        };
        if kink {
            out.push(n.s);
        }
    }
    out.dedup();
    out
}
