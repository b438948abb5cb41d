//! Fuzz target for the VTK XML readers: any bytes, read as each XML dataset
//! format, must give a mesh or an error, never a panic, hang or huge
//! allocation. A mesh that is returned must be structurally valid.
//!
//! Run (time-capped, as CI does): `cargo fuzz run xml -- -max_total_time=60`.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use zoovr::io::{xml, Format};

fuzz_target!(|data: &[u8]| {
    for format in [
        Format::XmlUnstructured,
        Format::XmlStructured,
        Format::XmlImage,
    ] {
        if let Ok(m) = xml::read_bytes(Path::new("fuzz.vtu"), data, format) {
            for c in 0..m.cells.len() {
                assert!(m
                    .cells
                    .nodes(c)
                    .iter()
                    .all(|&p| (p as usize) < m.points.len()));
            }
            for a in &m.point_data {
                assert_eq!(a.tuples(), m.points.len());
            }
            for a in &m.cell_data {
                assert_eq!(a.tuples(), m.cells.len());
            }
        }
    }
});
