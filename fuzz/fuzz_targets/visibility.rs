//! Fuzzes the visibility sort: a jittered (optionally holed) grid and a camera
//! from the input bytes; the split bookkeeping must pass `sanity_check` and
//! the order must pass the brute-force validator at every pixel centre.
//!
//! The body is `zoovr::fuzzing::visibility`, so crashes kept in
//! `fuzz/regressions/visibility/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::visibility(data));
