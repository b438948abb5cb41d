//! Fuzz target for the VTK XML readers: any bytes, read as each XML dataset
//! format, must give a mesh or an error, never a panic, hang or huge
//! allocation. A mesh that is returned must be structurally valid.
//!
//! Run (time-capped, as CI does in `.ci/fuzz`): `cargo fuzz run -s none xml -- -max_total_time=60`.
//!
//! The body is `zoovr::fuzzing::xml`, so crashes kept in
//! `fuzz/regressions/xml/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::xml(data));
