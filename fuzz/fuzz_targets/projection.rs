//! Random convex polyhedra (affine images of the zoo cells, or breakpoint
//! slabs of a tet) under random views: projection must not panic, and a
//! successful projection leaves a subdivision that passes `sanity_check`
//! after every insertion, with regions tiling the silhouette.
#![no_main]

use glam::{DMat3, DVec3};
use libfuzzer_sys::fuzz_target;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::{CellKind, Cells};
use zoovr::projection::{slice_tet, Polyhedron, Projected, Projector};

fn f(data: &[u8], i: usize) -> f64 {
    // Quantised to 1/16 so exact degeneracies (coincident and collinear
    // projections, edge-on faces) are frequent.
    let b = data.get(i).copied().unwrap_or(0) as i8;
    b as f64 / 16.0
}

fuzz_target!(|data: &[u8]| {
    if data.len() < 20 {
        return;
    }
    let kinds = [
        CellKind::Tetra,
        CellKind::Pyramid,
        CellKind::Wedge,
        CellKind::Hexahedron,
        CellKind::PentagonalPrism,
        CellKind::HexagonalPrism,
    ];
    let kind = kinds[data[0] as usize % kinds.len()];
    let m = DMat3::from_cols_array(&std::array::from_fn(|k| f(data, 1 + k)));
    let params = CameraParams {
        width: 64,
        height: 48,
        azimuth: f(data, 10) * 11.25,
        elevation: f(data, 11) * 11.25,
        roll: f(data, 12) * 11.25,
        ortho: data[13] & 1 == 0,
        ..Default::default()
    };
    let reference: Vec<DVec3> = match kind {
        CellKind::Tetra => vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        CellKind::Pyramid => vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1., 1., 0.),
            DVec3::Y,
            DVec3::new(0.5, 0.5, 1.),
        ],
        CellKind::Wedge => vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1., 0., 1.),
            DVec3::new(0., 1., 1.),
        ],
        CellKind::Hexahedron => vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1., 1., 0.),
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1., 0., 1.),
            DVec3::new(1., 1., 1.),
            DVec3::new(0., 1., 1.),
        ],
        _ => {
            let n = if kind == CellKind::PentagonalPrism {
                5
            } else {
                6
            };
            (0..2 * n)
                .map(|i| {
                    let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
                    DVec3::new(a.cos(), a.sin(), (i / n) as f64)
                })
                .collect()
        }
    };
    let pts: Vec<DVec3> = reference.iter().map(|&p| m * p).collect();
    if m.determinant().abs() < 1e-3 {
        return;
    }
    let mut cells = Cells::default();
    cells.push(kind, &(0..pts.len() as u32).collect::<Vec<_>>());
    let cam = Camera::fit([-8.0, 8.0, -8.0, 8.0, -8.0, 8.0], &params);
    let s: Vec<f64> = (0..pts.len()).map(|i| f(data, 14 + i % 6)).collect();
    let Ok(poly) = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam) else {
        return;
    };
    let mut pieces = vec![poly];
    if kind == CellKind::Tetra {
        let v: [DVec3; 4] = std::array::from_fn(|i| pieces[0].points[i]);
        let sc: [f64; 4] = std::array::from_fn(|i| pieces[0].scalars[i]);
        pieces = slice_tet(v, sc, &[0.0, 0.5], &cam);
    }
    let mut pr = Projector::new();
    pr.check_each_insertion = true;
    let mut out = Projected::default();
    for p in &pieces {
        if pr.project(p, &cam, &mut out).is_ok() {
            pr.arrangement().sanity_check().expect("sanity_check");
            assert!(out.region_area() >= 0.0);
        }
    }
});
