//! Random convex polyhedra (affine images of the zoo cells, or breakpoint
//! slabs of a tet) under random views: projection must not panic, and a
//! successful projection leaves a subdivision that passes `sanity_check`
//! after every insertion, with regions tiling the silhouette.
//!
//! The body is `zoovr::fuzzing::projection`, so crashes kept in
//! `fuzz/regressions/projection/` are replayed by `cargo test`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| zoovr::fuzzing::projection(data));
