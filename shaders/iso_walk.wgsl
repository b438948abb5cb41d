// `iso_segment` with the closed-form volume (exact-frag, and the exact
// mode with surfaces): one walk front to back over the events of the
// segment, the transfer function's nodes strictly between its ends
// (`segment_spans`, `span_end` of shaders/integral.wgsl) and its crossings
// (the surfaces `iso_window` of shaders/iso.wgsl gives, found with one
// search and stepped through), merged in order. Each event ends a
// linear piece of the volume (`add_piece`); a crossing then adds its lit
// surface. So a crossing costs one piece and one surface, not a second
// integral with its own node search and end evaluations (as splitting the
// segment at it and integrating both halves would): a software rasteriser
// runs a loop's body as often as the longest lane of its group needs,
// which made every crossing cost the volume's whole integral again.
//
// The material at a crossing is the transfer function's, linear over the
// node span holding it (from the span's front event to its back one).
// RKE's blend (iso.mix 1) composites the walk's volume without the
// surfaces, between their front-face layers (opacity times 1 - u) and
// their back-face layers (times u).
//
// Twin: render::modes::iso_walk.

fn iso_segment(seg: Seg, gf: vec3<f32>, gb: vec3<f32>, candidates: vec2<f32>) -> vec4<f32> {
    // As `integrate_segment` takes a segment: no volume where the length is
    // not positive, nothing at all where a scalar is NaN.
    let ok = seg.s_f == seg.s_f && seg.s_b == seg.s_b;
    let l = select(0.0, min(seg.l, MAX_THICKNESS), ok && seg.l > 0.0);
    let s_f = select(0.0, clamp(seg.s_f, -MAX_SCALAR, MAX_SCALAR), ok);
    let s_b = select(0.0, clamp(seg.s_b, -MAX_SCALAR, MAX_SCALAR), ok);
    // The crossings, front to back: the values in (lo, hi] among the
    // part's candidates (the window of `iso_window`), ascending from the
    // first above s_f (= lo) where the scalar rises, descending from the
    // last at or below s_f (= hi) where it falls. One search at s_f finds
    // the first (no branch on the direction: a SIMD group would run both
    // sides' searches); the walk steps from it.
    let rising = s_f <= s_b;
    let lo = min(s_f, s_b);
    let hi = max(s_f, s_b);
    let first = u32(candidates.x);
    let end = u32(candidates.y);
    let c = count_at_most(s_f, first, end);
    var k = select(max(c, 1u) - 1u, c, rising);
    var more = select(c > first, c < end, rising);
    let blend = iso.mix == 1u;
    let d = s_b - s_f;
    var inv = 0.0;
    if d != 0.0 {
        inv = 1.0 / d;
    }
    let sp = segment_spans(s_f, s_b);
    var acc = Composite(vec3<f32>(0.0), 0.0, 0.0, 0u, 1.0);
    // The product of 1 - opacity of the surfaces mixed into `acc`.
    var surf_t = 1.0;
    var front = vec4<f32>(0.0);
    var back = vec4<f32>(0.0);
    // The last event, and the node span the walk is in: from its front
    // (x_s0, m_s0) to the next node event `e`.
    var x_prev = 0.0;
    var m_prev = sp.m_first;
    var x_s0 = 0.0;
    var m_s0 = sp.m_first;
    var e = span_end(sp, 0u, s_f);
    var n = 0u;
    loop {
        // The next crossing's fraction (2: none left, after every node).
        var xi = 2.0;
        if more {
            let v = surfaces[k].value.x;
            if v > lo && v <= hi {
                xi = clamp((v - s_f) * inv, 0.0, 1.0);
            }
        }
        // A crossing at a node comes first (either order gives the same
        // pieces; this one takes the node's front material at a jump).
        let at_iso = xi <= e.x;
        let span = e.x - x_s0;
        let f = select(1.0, (xi - x_s0) / span, span > 0.0);
        let m_iso = Material(
            m_s0.tau + (e.m.tau - m_s0.tau) * f,
            m_s0.col + (e.m.col - m_s0.col) * f,
        );
        let x = select(e.x, xi, at_iso);
        let m = Material(select(e.m.tau, m_iso.tau, at_iso), select(e.m.col, m_iso.col, at_iso));
        if x > x_prev {
            add_piece(&acc, l * (x - x_prev), m_prev, m);
        }
        x_prev = x;
        m_prev = m;
        if at_iso {
            let g = mix(gf, gb, xi);
            if blend {
                front = iso_over(front, iso_surface(k, rising, g, 1.0 - xi));
                back = iso_over(back, iso_surface(k, rising, g, xi));
            } else {
                let c = iso_surface(k, rising, g, 1.0);
                acc.color += acc.tr * c.xyz;
                acc.tr *= 1.0 - c.w;
                surf_t *= 1.0 - c.w;
                // Opaque now: nothing behind shows, so the cost is one
                // surface's, however many the segment crosses.
                if acc.tr <= 0.0 {
                    break;
                }
            }
            more = select(k > first, k + 1u < end, rising);
            k = select(max(k, 1u) - 1u, k + 1u, rising);
        } else {
            n++;
            if n > sp.count {
                break;
            }
            x_s0 = e.x;
            m_s0 = e.m;
            e = span_end(sp, n, s_f);
        }
    }
    var alpha = acc.alpha;
    if acc.pieces != 1u {
        alpha = neg_expm1(acc.depth);
    }
    // The surfaces' opacity over the volume's (exactly the volume's where
    // the segment crosses none).
    alpha += (1.0 - alpha) * (1.0 - surf_t);
    let vol = vec4<f32>(min(acc.color, vec3<f32>(MAX_THICKNESS)), alpha);
    return iso_over(iso_over(front, vol), back);
}
