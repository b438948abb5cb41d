//! Fuzzes the plane cuts of visibility cycles (`zoovr::visibility::bsp`):
//! random tets on a coarse lattice and an eye; an order that comes back must
//! consist of closed fragments inside their tets that fill them.
//!
//! The body is `zoovr::fuzzing::cycles`, so crashes kept in
//! `fuzz/regressions/cycles/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::cycles(data));
