// The exact modes' exponential table (zoovr): the uniform `Params` and the
// 2D table of alpha = 1 - exp(-l tau) with its warped, bilinear lookup
// `alpha_of` (src/render/modes/exact/exptable.rs documents range, warp and
// clamping; its `ExpTable::alpha_of` is the CPU twin). Put in front of
// shaders/exact.wgsl.

// Keep in sync with `ExactParams` in src/render/modes/exact/mod.rs.
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
@group(0) @binding(1) var<storage, read> table: array<f32>;

// Texel (i, j), x (the length) fastest (src/gpu/table.rs).
fn texel(i: u32, j: u32) -> f32 {
    return table[j * params.n + i];
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
    let t00 = texel(i0, j0);
    let t10 = texel(i0 + 1u, j0);
    let t01 = texel(i0, j0 + 1u);
    let t11 = texel(i0 + 1u, j0 + 1u);
    let r0 = t00 * (1.0 - fu) + t10 * fu;
    let r1 = t01 * (1.0 - fu) + t11 * fu;
    return r0 * (1.0 - fv) + r1 * fv;
}
