// Exact (Max-Williams-Silva) compositing stage of zoovr.
//
// Per vertex: clip position, thickness l, mean extinction tau, glow C / alpha,
// and the number of the piece (convex polyhedron) the triangle belongs to.
// (`piece_depth` and `finite` come from shaders/common.wgsl.)
// Per fragment: alpha = 1 - exp(-l tau) from the 2D exponential table
// (`alpha_of`, shaders/exptable.wgsl, which comes first), colour = glow *
// alpha, premultiplied. The
// pipeline blends with src + (1 - src.a) * dst on all channels, and tests
// depth (less, write) against the piece's key: a pixel centre that two
// triangles of one piece both cover (a sliver folded over by the rounding of
// its corners to f32 and to the rasteriser's sub-pixel grid) is coloured
// once, by the first.
//
// Varyings use the default perspective-correct interpolation; never
// @interpolate(linear) (Mesa gives NaN with it on triangles crossing the
// viewport edge whose vertices have different w).

// Keep in sync with `ExactVertex` in src/render/modes/exact/mod.rs.
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
