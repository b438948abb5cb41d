// Exact (Max-Williams-Silva) compositing stage of zoovr.
//
// Per vertex: clip position, thickness l, mean extinction tau, glow C / alpha,
// and the number of the piece (convex polyhedron) the triangle belongs to.
// (`piece_depth` and `finite` come from shaders/common.wgsl.)
// Per fragment: alpha = 1 - exp(-l tau) from the 2D exponential table
// (src/render/modes/exact/exptable.rs documents range, warp and clamping;
// its `ExpTable::alpha_of` is the CPU twin of `alpha_of` below), colour = glow * alpha, premultiplied. The
// pipeline blends with src + (1 - src.a) * dst on all channels, and tests
// depth (less, write) against the piece's key: a pixel centre that two
// triangles of one piece both cover (a sliver folded over by the rounding of
// its corners to f32 and to the rasteriser's sub-pixel grid) is coloured
// once, by the first.
//
// Varyings use the default perspective-correct interpolation; never
// @interpolate(linear) (Mesa gives NaN with it on triangles crossing the
// viewport edge whose vertices have different w).

// Keep in sync with `ExactParams` in src/render/modes/exact.rs.
struct Params {
    // 1 / length unit: l' = l * inv_unit.
    inv_unit: f32,
    // Length unit: tau' = tau * unit.
    unit: f32,
    // Warp scale X (AXIS_MAX) and 1 / ln(1 + X^2).
    scale: f32,
    inv_log_range: f32,
    // Texels per table axis.
    n: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var table: texture_2d<f32>;

// Keep in sync with `ExactVertex` in src/render/modes/exact.rs.
struct VertexIn {
    @location(0) pos: vec4<f32>,
    @location(1) thickness: f32,
    @location(2) tau: f32,
    @location(3) glow: vec3<f32>,
    @location(4) piece: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) thickness: f32,
    @location(1) tau: f32,
    @location(2) glow: vec3<f32>,
    @location(3) @interpolate(flat) piece: u32,
}

// What a fragment writes: its colour, and as its depth the piece's key (see
// `piece_depth`), so that the depth test (less, with write) lets each piece
// colour a pixel at most once.
struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = v.pos;
    out.thickness = v.thickness * params.inv_unit;
    out.tau = v.tau * params.unit;
    out.glow = v.glow;
    out.piece = v.piece;
    return out;
}

// ln(1 + z) keeping relative accuracy for tiny z (twin: exact::exptable::log1p_).
fn log1p_(z: f32) -> f32 {
    if z < 1e-3 {
        return z * (1.0 - z * (0.5 - z * (1.0 / 3.0)));
    }
    return log(1.0 + z);
}

// Continuous texel coordinate in [0, n - 1] (twin: exact::exptable::coord).
// Negative and NaN inputs map to 0; beyond the axis range clamps.
fn coord(x: f32) -> f32 {
    let xs = select(0.0, x, x > 0.0);
    let s = log1p_(xs * params.scale) * params.inv_log_range;
    return min(s, 1.0) * f32(params.n - 1u);
}

// Bilinear lookup with f32 weights (twin: ExpTable::alpha_of).
fn alpha_of(l: f32, tau: f32) -> f32 {
    let u = coord(l);
    let v = coord(tau);
    let i0 = min(u32(u), params.n - 2u);
    let j0 = min(u32(v), params.n - 2u);
    let fu = u - f32(i0);
    let fv = v - f32(j0);
    let t00 = textureLoad(table, vec2<u32>(i0, j0), 0).r;
    let t10 = textureLoad(table, vec2<u32>(i0 + 1u, j0), 0).r;
    let t01 = textureLoad(table, vec2<u32>(i0, j0 + 1u), 0).r;
    let t11 = textureLoad(table, vec2<u32>(i0 + 1u, j0 + 1u), 0).r;
    let r0 = t00 * (1.0 - fu) + t10 * fu;
    let r1 = t01 * (1.0 - fu) + t11 * fu;
    return r0 * (1.0 - fv) + r1 * fv;
}

@fragment
fn fs_main(f: VertexOut) -> FragOut {
    // Every vertex the CPU sends is finite, but a rasteriser may still
    // interpolate garbage on a sliver of almost zero area (its attribute
    // planes divide by the area: Mesa gives NaN). Such a fragment has no
    // meaningful value; it is discarded rather than poisoning every layer
    // blended over it, and (writing no depth) leaves the pixel to the
    // piece's other triangle there.
    if !(finite(f.thickness) && finite(f.tau) && finite(f.glow.x) && finite(f.glow.y)
        && finite(f.glow.z)) {
        discard;
    }
    // Twin: render::modes::exact::fs_main.
    let alpha = alpha_of(f.thickness, f.tau);
    var out: FragOut;
    out.color = vec4<f32>(f.glow * alpha, alpha);
    out.depth = piece_depth(f.piece);
    return out;
}

// Coverage counting (tests and diagnostics): every fragment adds 1 to red.
// With the depth test on, red counts the pieces covering a pixel centre;
// without it, their triangles.
@fragment
fn fs_count(f: VertexOut) -> FragOut {
    var out: FragOut;
    out.color = count_of(f.clip.z);
    out.depth = piece_depth(f.piece);
    return out;
}
