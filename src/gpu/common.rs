//! The CPU twin of `shaders/common.wgsl`, the functions every stage shares
//! (`gpu::stage` puts that file in front of each stage's own): the piece
//! keys written as depth ([`piece_depth`]), the finiteness test
//! ([`finite`]) and what a counting fragment adds ([`count_of`], with the
//! blocker quads' depth [`BLOCKER_Z`]).

/// The depth key of piece number `piece` in drawing order (twin of
/// `piece_depth`): the `f32` just below 1 for piece 0 and one
/// representable value lower for each later piece, so that a strict
/// less-than depth test passes later pieces and stops a second fragment of
/// the same piece at a pixel. Keys stay in `(0, 1)` for pieces below
/// [`MAX_PIECES`].
pub fn piece_depth(piece: u32) -> f32 {
    f32::from_bits(0x3F7F_FFFF - piece.min(MAX_PIECES - 1))
}

/// Pieces one frame can number ([`piece_depth`] stays positive); the frame
/// refuses more.
pub const MAX_PIECES: u32 = 0x3F7F_FFFF;

/// Twin of `finite`: false for NaN and the infinities.
pub fn finite(x: f32) -> bool {
    x.is_finite()
}

/// Clip z of the corners of a blocker ([`crate::render::ties`]): a
/// pixel's triangle that takes a pixel for its piece without colouring or
/// counting it ([`count_of`]). Everything else is drawn at z = 0.5.
pub const BLOCKER_Z: f32 = 0.25;

/// Twin of `count_of`: what a counting fragment (`fs_count`) at depth `z`
/// (clip z over clip w) adds, 1 to red, except for a blocker quad
/// ([`BLOCKER_Z`]), which only takes the pixel for its piece.
pub fn count_of(z: f32) -> [f32; 4] {
    if z < 0.375 {
        [0.0; 4]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blockers_count_nothing() {
        assert_eq!(count_of(BLOCKER_Z), [0.0; 4]);
        assert_eq!(count_of(0.5), [1.0, 0.0, 0.0, 0.0]);
        assert!(piece_depth(1) < piece_depth(0));
        assert!(!finite(f32::NAN) && !finite(f32::INFINITY) && finite(f32::MAX));
    }
}
