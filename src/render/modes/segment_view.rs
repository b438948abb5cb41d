//! The twin of `shaders/segment_view.wgsl`: what every segment stage
//! shares whatever its vertex (the view uniform [`SegmentView`], the
//! segment [`Seg`]) and [`segment_of`], which rebuilds a fragment's segment
//! from the interpolated front, back and thickness values of the segment
//! payload ([`super::segment`] says how the CPU fills them and why the
//! division makes them exact in perspective). Region vertices reach it
//! through [`super::segment::segment_at`]; exact-frag's whole-piece quads
//! ([`super::piece_quad`]) through their region fallback.

pub use super::segment::{Seg, SegmentView};

/// Twin of `segment_of` in `shaders/segment_view.wgsl`: the segment from
/// `front = (s_f q_f, q_f)`, `back = (s_b q_b, q_b)` and `thick = q_f -
/// q_b` (or `(s, 1)` and `l` in an orthographic view) at framebuffer
/// position `p`, in `f32` as the shader computes it.
pub fn segment_of(
    view: &SegmentView,
    front: [f32; 2],
    back: [f32; 2],
    thick: f32,
    p: [f32; 2],
) -> Seg {
    let s_f = front[0] / front[1];
    let s_b = back[0] / back[1];
    let mut l = if view.ortho == 1 {
        thick
    } else {
        let u = [
            p[0] * view.scale[0] + view.offset[0],
            p[1] * view.scale[1] + view.offset[1],
        ];
        thick / (front[1] * back[1]) * (1.0 + u[0] * u[0] + u[1] * u[1]).sqrt()
    };
    l = l.max(0.0);
    Seg {
        s_f,
        s_b,
        l,
        ok: s_f.is_finite() && s_b.is_finite() && l.is_finite(),
    }
}
