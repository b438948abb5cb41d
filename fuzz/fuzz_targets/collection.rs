//! Fuzz the time-series collection readers (`.pvd` XML and ParaView
//! `.series` JSON): any bytes give a list of time steps or an error, never a
//! panic, a hang or a huge allocation. Entries resolve next to the project's
//! `meshes/series/`, so the fuzzer can reach valid step files; a list that
//! comes back is non-empty, sorted by time and names existing files.
//!
//! The body is `zoovr::fuzzing::collection`, so crashes kept in
//! `fuzz/regressions/collection/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::collection(data));
