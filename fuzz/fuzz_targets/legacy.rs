//! Fuzz the legacy VTK reader: any bytes give a mesh or an error, never a
//! panic; a mesh that comes back only references existing points.
//!
//! The body is `zoovr::fuzzing::legacy`, so crashes kept in
//! `fuzz/regressions/legacy/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::legacy(data));
