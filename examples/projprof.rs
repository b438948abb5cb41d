use criterion as _;
use glam::{DMat3, DVec3};
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::{CellKind, Cells};
use zoovr::projection::{Polyhedron, Projected, Projector};
include!("/tmp/common.rs");
fn main() {
    let ortho = std::env::args().nth(1).map_or(true, |a| a == "ortho");
    let iters: usize = std::env::args()
        .nth(2)
        .map_or(20000, |a| a.parse().unwrap());
    let set = pieces(CellKind::Hexahedron, ortho, 42);
    let mut pr = Projector::new();
    let mut out = Projected::default();
    let t = std::time::Instant::now();
    for k in 0..iters {
        let (p, cam) = &set[k % set.len()];
        pr.project(p, cam, &mut out).unwrap();
    }
    println!(
        "{:.3} us per hex",
        t.elapsed().as_secs_f64() * 1e6 / iters as f64
    );
}
