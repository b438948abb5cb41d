// The exact mode with isosurfaces (zoovr): shaders/exptable.wgsl comes
// first (the uniform `Params`, the exponential table and `alpha_of`), and
// shaders/common.wgsl before it (`piece_depth`, `finite`, `count_of`).
//
// The mode slices pieces at the isovalues as at the TF's breakpoints, so a
// surface lies only on a piece's boundary: on the entry or exit face of a
// region (src/render/modes/exact_iso.rs decides which, per region, and gives
// the region's triangles their own vertices). Per vertex: the exact mode's
// values (thickness l, mean extinction tau, glow C / alpha), the piece
// number, and the region's surface: its straight colour and opacity (0:
// none), the field's view-space gradient at the surface point (the light),
// and whether it lies at the exit (the volume in front of it) or the entry.
// Per fragment: the volume as in shaders/exact.wgsl, the surface lit by the
// headlight, composited in their order along the ray (premultiplied, "over").
//
// Varyings use the default perspective-correct interpolation (every w is 1).

// Keep in sync with `ExactIsoParams` in src/render/modes/exact_iso.rs.
struct IsoLight {
    // 0: none, 1: flat, 2: smooth (the light is the same for both; the
    // gradients differ).
    lighting: u32,
    ambient: f32,
    diffuse: f32,
    _pad: u32,
}

@group(0) @binding(2) var<uniform> light: IsoLight;

// Keep in sync with `ExactIsoVertex` in src/render/modes/exact_iso.rs.
struct VertexIn {
    @location(0) pos: vec4<f32>,
    @location(1) thickness: f32,
    @location(2) tau: f32,
    @location(3) glow: vec3<f32>,
    @location(4) piece: u32,
    @location(5) surface: vec4<f32>,
    @location(6) grad: vec3<f32>,
    @location(7) at_back: f32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) thickness: f32,
    @location(1) tau: f32,
    @location(2) glow: vec3<f32>,
    @location(3) @interpolate(flat) piece: u32,
    @location(4) surface: vec4<f32>,
    @location(5) grad: vec3<f32>,
    @location(6) at_back: f32,
}

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
    out.surface = v.surface;
    out.grad = v.grad;
    out.at_back = v.at_back;
    return out;
}

// The headlight's factor for gradient g (view space: the light looks along
// +z): ambient + diffuse |cos|, 1 without light or gradient (twin:
// render::modes::exact_iso::exact_iso_light).
fn exact_iso_light(g: vec3<f32>) -> f32 {
    if light.lighting == 0u {
        return 1.0;
    }
    let n = length(g);
    if !(n > 0.0) || !finite(n) {
        return 1.0;
    }
    return light.ambient + light.diffuse * min(abs(g.z) / n, 1.0);
}

@fragment
fn fs_main(f: VertexOut) -> FragOut {
    // As in shaders/exact.wgsl: a fragment with garbage interpolants (a
    // sliver of almost zero area) is discarded.
    if !(finite(f.thickness) && finite(f.tau) && finite(f.glow.x) && finite(f.glow.y)
        && finite(f.glow.z) && finite(f.surface.x) && finite(f.surface.y)
        && finite(f.surface.z) && finite(f.surface.w) && finite(f.at_back)) {
        discard;
    }
    // Twin: render::modes::exact_iso::fs_main.
    let alpha = alpha_of(f.thickness, f.tau);
    let volume = vec4<f32>(f.glow * alpha, alpha);
    let a = clamp(f.surface.w, 0.0, 1.0);
    let i = exact_iso_light(f.grad) * a;
    let surface = vec4<f32>(f.surface.xyz * i, a);
    var out: FragOut;
    if f.at_back > 0.5 {
        out.color = volume + (1.0 - volume.a) * surface;
    } else {
        out.color = surface + (1.0 - surface.a) * volume;
    }
    out.depth = piece_depth(f.piece);
    return out;
}

// Coverage counting (tests and diagnostics), as in shaders/exact.wgsl.
@fragment
fn fs_count(f: VertexOut) -> FragOut {
    var out: FragOut;
    out.color = count_of(f.clip.z);
    out.depth = piece_depth(f.piece);
    return out;
}
