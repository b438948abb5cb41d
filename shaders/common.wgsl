// Functions every stage of zoovr shares; src/gpu/stage.rs puts this file in
// front of each stage's own file.

// The depth key of piece number `piece` in drawing order (twin:
// gpu::raster::piece_depth): the f32 just below 1.0 for piece 0, and one
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
