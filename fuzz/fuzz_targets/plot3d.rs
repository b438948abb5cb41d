//! Fuzz the PLOT3D reader: the input is split into a grid and a q file at a
//! position given by its first byte; any bytes give a mesh or an error.
//!
//! The body is `zoovr::fuzzing::plot3d`, so crashes kept in
//! `fuzz/regressions/plot3d/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::plot3d(data));
