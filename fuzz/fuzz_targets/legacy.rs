//! Fuzz the legacy VTK reader: any bytes give a mesh or an error, never a
//! panic; a mesh that comes back only references existing points.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::path::Path::new("fuzz.vtk");
    if let Ok(mesh) = zoovr::io::legacy::read_bytes(path, data) {
        let n = mesh.points.len();
        assert!(mesh.cells.conn.iter().all(|&p| (p as usize) < n));
        let c = &mesh.cells;
        assert!(c.offsets.len() == c.len() + 1 || (c.is_empty() && c.offsets.is_empty()));
    }
});
