//! Fuzz the PLOT3D reader: the input is split into a grid and a q file at a
//! position given by its first byte; any bytes give a mesh or an error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&cut, rest)) = data.split_first() else {
        return;
    };
    let path = std::path::Path::new("fuzz.xyz");
    let _ = zoovr::io::plot3d::looks_like_grid(rest);
    let (grid, q) = if cut == 0 {
        (rest, None)
    } else {
        let at = (cut as usize * rest.len()) / 255;
        let (g, q) = rest.split_at(at.min(rest.len()));
        (g, Some((std::path::Path::new("fuzz.q"), q)))
    };
    if let Ok(mesh) = zoovr::io::plot3d::read_bytes(path, grid, q) {
        let n = mesh.points.len();
        assert!(mesh.cells.conn.iter().all(|&p| (p as usize) < n));
    }
});
