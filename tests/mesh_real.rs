//! `MeshReport` on the shared real datasets (`../shared/data`) against
//! their published figures (cells, "neg" = inverted cells in VTK node
//! order, "vol/hull" to 0.01), stated with each case below. Skips cleanly when the data is absent; needs
//! the legacy and XML readers. can_crush's distorted hexahedra give
//! inverted consistent tets: counted, never a failure.

use zoovr::io::{read, ReadOptions};
use zoovr::mesh::report::MeshReport;
use zoovr::mesh::topology::Topology;
use zoovr::testdata::shared_file;

/// (file, 3D cells, inverted cells, vol/hull, nonplanar quad faces)
///
/// can_crush's "np faces" (24,569) is that of the last step of its series;
/// `can.vtu` is another state of the crush whose count is 24,570 (its
/// 24,570th face is 1.3e-6 over the threshold, seen from both its cells).
const README: &[(&str, usize, usize, f64, usize)] = &[
    ("bluntfin/bluntfin_converted.vts", 37_479, 0, 0.98, 2),
    ("office_kitchen/office.binary.vtk", 7_220, 0, 1.00, 0),
    ("fire_room/fire_ug.vtu", 10_462, 10_462, 0.99, 0),
    ("can_crush/can.vtu", 4_800, 0, 0.22, 24_570),
    (
        "can_crush/series/can_t2_converted.vtu",
        4_800,
        0,
        0.22,
        24_569,
    ),
    (
        "disk_out_ref/disk_out_ref_converted.vtu",
        7_472,
        0,
        0.78,
        2_316,
    ),
    ("notch/notch_stress.vtk", 2_192, 4, 0.96, 0),
    ("angular_sector/AngularSector.vtk", 7_776, 0, 1.00, 0),
    (
        "su2_sphere_hybrid/sphere_hybrid_converted.vtu",
        8_580,
        7_950,
        1.00,
        0,
    ),
    (
        "blood_vessels_pvtu/blood_vessels/T0000000500.pvtu",
        39_353,
        0,
        0.33,
        0,
    ),
    ("tets_small/CylinderLinear.vtk", 1_522, 0, 0.98, 0),
    ("prisms_zoo/PentaHexa.vtk", 210, 150, 1.00, 0),
];

#[test]
fn shared_datasets_match_the_readme() {
    for &(file, cells, inverted, convexity, nonplanar) in README {
        let Some(path) = shared_file(file) else {
            continue;
        };
        let mesh = read(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        mesh.sanity_check()
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let topo = Topology::build(&mesh.cells);
        topo.sanity_check(&mesh.cells).unwrap();
        let r = MeshReport::compute_with(&mesh, &topo);
        assert_eq!(r.cells, cells, "{file}");
        assert_eq!(r.inverted_cells, inverted, "{file}");
        let c = r.convexity.unwrap();
        assert!((c - convexity).abs() <= 0.01, "{file}: vol/hull {c}");
        assert_eq!(r.degenerate_cells, 0, "{file}");
        assert_eq!(r.nonplanar_faces, nonplanar, "{file}: nonplanar quad faces");
        if file.starts_with("can_crush") {
            assert!(r.inverted_tets > 0, "can_crush has distorted cells");
        } else {
            assert_eq!(r.inverted_tets, 0, "{file}");
        }
    }
}
