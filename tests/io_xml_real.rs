//! VTK XML readers on real files from `../shared/data` (each test skips
//! when its file is absent): their published cell and point counts, and every
//! array's range checked against the `RangeMin`/`RangeMax` that VTK wrote
//! into the file (an independent oracle: magnitude range for vectors, value
//! range for scalars). The encodings, hand-written files, collections and
//! corrupt files are `tests/io_xml.rs`.

mod xml_util;

use std::path::Path;

use xml_util::{array, by_type, check_mesh};
use zoovr::field::ArrayData;
use zoovr::io::{self, ReadOptions};
use zoovr::mesh::{CellKind, Mesh};
use zoovr::testdata::shared_file;

// ---------------------------------------------------------------- helpers

fn load(rel: &str) -> Option<Mesh> {
    let p = shared_file(rel)?;
    let m = io::read(&p, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    check_mesh(&m);
    Some(m)
}

/// `(name, components, RangeMin, RangeMax)` of the DataArrays in a VTK file's
/// header, found by plain text search (not by the reader under test).
fn file_ranges(path: &Path) -> Vec<(String, usize, f64, f64)> {
    let bytes = std::fs::read(path).unwrap();
    let end = find(&bytes, b"<AppendedData").unwrap_or(bytes.len());
    let text = String::from_utf8_lossy(&bytes[..end]);
    let attr = |tag: &str, key: &str| -> Option<String> {
        let k = format!(" {key}=\"");
        let i = tag.find(&k)? + k.len();
        Some(tag[i..i + tag[i..].find('"')?].to_string())
    };
    let mut out = Vec::new();
    for part in text.split("<DataArray").skip(1) {
        let tag = &part[..part.find('>').unwrap_or(part.len())];
        let (Some(name), Some(lo), Some(hi)) = (
            attr(tag, "Name"),
            attr(tag, "RangeMin"),
            attr(tag, "RangeMax"),
        ) else {
            continue;
        };
        let (Ok(lo), Ok(hi)) = (lo.parse(), hi.parse()) else {
            continue;
        };
        let nc = attr(tag, "NumberOfComponents")
            .and_then(|s| s.parse().ok())
            .unwrap_or(1);
        out.push((name, nc, lo, hi));
    }
    out
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Every array with a recorded range matches it (scalars: values; vectors:
/// magnitudes, as VTK records them). Returns how many were checked.
fn check_ranges(m: &Mesh, path: &Path) -> usize {
    let mut checked = 0;
    for (name, nc, lo, hi) in file_ranges(path) {
        let Some(a) = m
            .point_data
            .iter()
            .chain(&m.cell_data)
            .find(|a| a.name == name)
        else {
            continue;
        };
        if a.components != nc
            || (lo == 0.0 && hi == 0.0 && a.range(None).is_some_and(|r| r.1 != 0.0))
        {
            continue;
        }
        let (l, h) = a.range(if nc == 1 { Some(0) } else { None }).unwrap();
        let tol = 1e-6 * (hi.abs().max(lo.abs()).max(1e-30));
        assert!(
            (l - lo).abs() <= tol && (h - hi).abs() <= tol,
            "{}: {name} range {l}..{h}, file says {lo}..{hi}",
            path.display()
        );
        checked += 1;
    }
    checked
}

// ---------------------------------------------------------------- real data

#[test]
fn bluntfin_vts_appended_raw() {
    let Some(m) = load("bluntfin/bluntfin_converted.vts") else {
        return;
    };
    assert_eq!(m.cells.len(), 37_479);
    assert_eq!(m.points.len(), 40_960);
    assert_eq!(by_type(&m, "hexahedron"), 37_479);
    let d = array(&m, "Density");
    assert_eq!(d.vtk_type, "Float32");
    let (lo, hi) = d.range(Some(0)).unwrap();
    assert!(
        (0.19..0.2).contains(&lo) && (4.97..4.98).contains(&hi),
        "{lo} {hi}"
    );
    assert_eq!(m.active_point_scalars.as_deref(), Some("Density"));
    assert!(check_ranges(&m, &shared_file("bluntfin/bluntfin_converted.vts").unwrap()) >= 7);
    // Node order: cell 0 is (0,0,0)-(1,1,1) of a 40 x 32 x 32 lattice.
    assert_eq!(m.cells.nodes(0), &[0, 1, 41, 40, 1280, 1281, 1321, 1320]);
}

#[test]
fn fire_room_appended_base64_zlib() {
    let Some(m) = load("fire_room/fire_ug.vtu") else {
        return;
    };
    assert_eq!((m.cells.len(), m.points.len()), (10_462, 12_323));
    assert_eq!(by_type(&m, "hexahedron"), 10_462);
    let (lo, hi) = array(&m, "t").range(Some(0)).unwrap();
    assert!(
        (297.0..299.0).contains(&lo) && (691.0..693.0).contains(&hi),
        "{lo} {hi}"
    );
    assert_eq!(array(&m, "uvw").components, 3);
    assert_eq!(m.active_point_scalars.as_deref(), Some("t"));
}

#[test]
fn can_crush_appended_raw_and_series() {
    let Some(m) = load("can_crush/can.vtu") else {
        return;
    };
    assert_eq!((m.cells.len(), m.points.len()), (4_800, 6_724));
    assert_eq!(array(&m, "EQPS").tuples(), 4_800);
    assert_eq!(array(&m, "DISPL").components, 3);
    let g = array(&m, "GlobalNodeId");
    assert!(matches!(g.data, ArrayData::Int(_)) && g.vtk_type == "Int64");
    let p = shared_file("can_crush/can.vtu").unwrap();
    assert!(check_ranges(&m, &p) >= 4);

    let pvd = shared_file("can_crush/series/can_series.pvd").unwrap();
    let steps = io::read_series(&pvd).unwrap();
    assert_eq!(steps.len(), 3);
    assert!(steps.windows(2).all(|w| w[0].time < w[1].time));
    assert!((steps[1].time - 0.00209992984).abs() < 1e-15);
    let mut moved = Vec::new();
    for s in &steps {
        let m = io::read(&s.path, &ReadOptions::default()).unwrap();
        check_mesh(&m);
        assert_eq!(m.cells.len(), 4_800);
        check_ranges(&m, &s.path);
        moved.push(m.points[0]);
    }
    assert_ne!(moved[0], moved[2], "the can deforms over time");
}

#[test]
fn disk_out_ref_inline_zlib() {
    let Some(m) = load("disk_out_ref/disk_out_ref_converted.vtu") else {
        return;
    };
    assert_eq!((m.cells.len(), m.points.len()), (7_472, 8_499));
    let (lo, hi) = array(&m, "Temp").range(Some(0)).unwrap();
    assert!((293.0..293.2).contains(&lo) && (913.0..913.2).contains(&hi));
    assert!(
        check_ranges(
            &m,
            &shared_file("disk_out_ref/disk_out_ref_converted.vtu").unwrap()
        ) >= 7
    );
}

#[test]
fn notch_quadratic_cells_keep_corners() {
    let Some(m) = load("notch/notch_disp.vtu") else {
        return;
    };
    assert_eq!(m.cells.len(), 2_192);
    assert_eq!(m.points.len(), 12_717);
    let hex = m
        .cells
        .kinds
        .iter()
        .filter(|k| **k == CellKind::Hexahedron)
        .count();
    let wedge = m
        .cells
        .kinds
        .iter()
        .filter(|k| **k == CellKind::Wedge)
        .count();
    assert_eq!((hex, wedge), (2_188, 4));
    let a = array(&m, "Nodal Displacement");
    assert_eq!(a.components, 3);
    assert_eq!(
        m.active_point_scalars.as_deref(),
        Some("Nodal Displacement")
    );
}

#[test]
fn fea_bracket_quadratic_tets_cell_data_only() {
    let Some(m) = load("fea_bracket_qtet/kiefer_bracket.vtu") else {
        return;
    };
    assert_eq!(m.cells.len(), 56_786);
    assert_eq!(by_type(&m, "quadratic_tetra"), 56_786);
    assert_eq!(m.points.len(), 102_578);
    assert!(m.point_data.is_empty());
    let s = array(&m, "Equivalent (von-Mises) Stress (psi)");
    assert_eq!(s.tuples(), 56_786);
    assert_eq!(
        m.active_cell_scalars.as_deref(),
        Some("Equivalent (von-Mises) Stress (psi)")
    );
    assert_eq!(
        check_ranges(
            &m,
            &shared_file("fea_bracket_qtet/kiefer_bracket.vtu").unwrap()
        ),
        1
    );
}

#[test]
fn su2_sphere_hybrid_mixed_cells() {
    let Some(m) = load("su2_sphere_hybrid/sphere_hybrid_converted.vtu") else {
        return;
    };
    assert_eq!(by_type(&m, "tetra"), 312);
    assert_eq!(by_type(&m, "wedge"), 7_950);
    assert_eq!(by_type(&m, "pyramid"), 318);
    assert_eq!(m.points.len(), 5_750);
    let (lo, hi) = array(&m, "Pressure").range(Some(0)).unwrap();
    assert!(
        (-3.3..-3.1).contains(&lo) && (3.9..4.1).contains(&hi),
        "{lo} {hi}"
    );
    assert_eq!(m.active_point_scalars.as_deref(), Some("Pressure"));
    assert!(
        check_ranges(
            &m,
            &shared_file("su2_sphere_hybrid/sphere_hybrid_converted.vtu").unwrap()
        ) >= 10
    );
}

#[test]
fn blood_vessels_pvtu_voxels_int8_types() {
    let Some(m) = load("blood_vessels_pvtu/blood_vessels/T0000000500.pvtu") else {
        return;
    };
    assert_eq!(m.cells.len(), 39_353);
    assert_eq!(by_type(&m, "voxel"), 39_353);
    assert_eq!(m.points.len(), 48_823);
    assert!(m.cells.kinds.iter().all(|k| *k == CellKind::Hexahedron));
    for name in ["node_value", "simerr_type"] {
        assert!(m
            .point_data
            .iter()
            .any(|a| a.name == name && a.vtk_type == "Int32"));
    }
    for name in ["density", "velocity", "shearstress"] {
        assert!(m.cell_data.iter().any(|a| a.name == name));
    }
    // Voxels reordered to hexahedron order: the quad 0-1-2-3 is a cycle, so
    // nodes 0 and 2 are diagonal opposites (differ in two coordinates).
    let n = m.cells.nodes(0);
    let (p0, p1, p2) = (
        m.points[n[0] as usize],
        m.points[n[1] as usize],
        m.points[n[2] as usize],
    );
    let diff = |a: glam::DVec3, b: glam::DVec3| {
        [(a.x != b.x), (a.y != b.y), (a.z != b.z)]
            .iter()
            .filter(|&&d| d)
            .count()
    };
    assert_eq!((diff(p0, p1), diff(p0, p2)), (1, 2));
}

#[test]
fn hex_shell_synthetic_zlib() {
    let Some(m) = load("synthetic/hex_shell_zlib.vtu") else {
        return;
    };
    assert_eq!((m.cells.len(), m.points.len()), (250_047, 262_144));
    let (lo, hi) = array(&m, "f").range(Some(0)).unwrap();
    assert!(lo >= 0.0 && hi <= 1.0 && hi - lo > 0.99, "{lo} {hi}");
}
