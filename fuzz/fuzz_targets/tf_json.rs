//! Fuzz target: arbitrary bytes as a transfer-function file. Loading must
//! never panic; a loaded transfer function must integrate to finite values.
//!
//! The body is `zoovr::fuzzing::tf_json`, so crashes kept in
//! `fuzz/regressions/tf_json/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::tf_json(data));
