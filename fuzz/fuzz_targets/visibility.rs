//! Fuzzes the visibility sort: a jittered (optionally holed) grid and a camera
//! from the input bytes; the split bookkeeping must pass `sanity_check` and
//! the order must pass the brute-force validator at every pixel centre.
#![no_main]

use libfuzzer_sys::fuzz_target;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::visibility::synth::{grid, holed_grid, GridSpec};
use zoovr::visibility::{sample_pixels, validate, Sorter, SplitPolicy};

fuzz_target!(|data: &[u8]| {
    if data.len() < 12 {
        return;
    }
    let b = |i: usize| data[i] as f64 / 255.0;
    let spec = GridSpec {
        dims: [
            2 + data[0] as usize % 4,
            2 + data[1] as usize % 4,
            2 + data[2] as usize % 3,
        ],
        jitter: 0.24 * b(3),
        seed: u64::from_le_bytes([data[4], data[5], data[6], data[7], 1, 2, 3, 4]),
        planar_boundary: data[8] & 1 == 0,
    };
    let mesh = if data[8] & 2 != 0 {
        holed_grid(&spec)
    } else {
        grid(&spec, |_, _, _| true)
    };
    if mesh.cells.is_empty() {
        return;
    }
    let topo = Topology::build(&mesh.cells);
    let mut sorter = Sorter::new(&mesh, &topo);
    let policy = SplitPolicy {
        all: data[8] & 4 != 0,
        ..Default::default()
    };
    for view in data[9..].chunks(3).take(3) {
        if view.len() < 3 {
            break;
        }
        let p = CameraParams {
            width: 24,
            height: 24,
            azimuth: view[0] as f64 * 360.0 / 255.0,
            elevation: view[1] as f64 * 178.0 / 255.0 - 89.0,
            ortho: view[2] & 1 != 0,
            zoom: 1.0 + (view[2] >> 1) as f64 / 64.0,
            ..Default::default()
        };
        let cam = Camera::fit(mesh.bounds(), &p);
        let order = sorter.order(&cam, &policy).expect("valid input must sort");
        sorter.sanity_check().expect("sanity");
        let v = validate(&mesh, &order, &cam, &sample_pixels(&cam, usize::MAX, 0));
        assert!(v.ok(), "{} violations: {:?}", v.count, v.examples.first());
    }
});
