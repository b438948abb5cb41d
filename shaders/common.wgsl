// Functions every stage of zoovr shares; src/gpu/stage.rs puts this file in
// front of each stage's own file. Twin: gpu::common, function for function
// (src/render/modes/twins.rs lists every twin).

// The depth key of piece number `piece` in drawing order (twin:
// gpu::common::piece_depth): the f32 just below 1.0 for piece 0, and one
// representable value lower for each later piece, so later pieces pass a
// strict less-than test against earlier ones while a second fragment of the
// same piece at the same pixel fails it. Flat and written per fragment, the
// key is exact (an interpolated position z need not be).
fn piece_depth(piece: u32) -> f32 {
    return bitcast<f32>(0x3F7FFFFFu - piece);
}

// Whether a value is finite: false for NaN (every comparison with NaN is
// false) and for infinities.
fn finite(x: f32) -> bool {
    return abs(x) <= 3.4028235e38;
}

// Clip z of the corners of a blocker quad (src/render/ties.rs: a pixel the
// snapped triangles of a piece would take but its exact outline does not;
// twin: gpu::common::BLOCKER_Z). Other geometry is drawn at z = 0.5.
const BLOCKER_Z: f32 = 0.25;

// What a counting fragment adds (fs_count): 1 to red, except for a blocker
// quad, which only takes the pixel for its piece. `z` is the fragment's
// @builtin(position).z.
fn count_of(z: f32) -> vec4<f32> {
    if z < 0.375 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(1.0, 0.0, 0.0, 0.0);
}
