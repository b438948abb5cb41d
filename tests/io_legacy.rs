//! Legacy VTK reader: real files from `../shared/data` (their published
//! cell and point counts and ranges), a cross-check against `vtkio`, small
//! hand-written files for every section kind, the corrupt corpus in
//! `meshes/corrupt/`, and a seeded mutation test (no panic, bounded time).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use zoovr::field::{ArrayData, DataArray};
use zoovr::io::legacy::{read, read_bytes};
use zoovr::mesh::{CellKind, Mesh};
use zoovr::testdata::{shared_file, Rng};

fn load(rel: &str) -> Option<Mesh> {
    let p = shared_file(rel)?;
    Some(read(&p).unwrap_or_else(|e| panic!("{e}")))
}

fn arr<'a>(list: &'a [DataArray], name: &str) -> &'a DataArray {
    list.iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array {name}"))
}

fn by_type(m: &Mesh) -> Vec<(&str, usize)> {
    m.source
        .cells_by_type
        .iter()
        .map(|(k, v)| (k.as_str(), *v))
        .collect()
}

fn parse(text: &str) -> Mesh {
    read_bytes(Path::new("mem.vtk"), text.as_bytes()).unwrap_or_else(|e| panic!("{e}"))
}

fn parse_err(bytes: &[u8]) -> String {
    match read_bytes(Path::new("mem.vtk"), bytes) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

fn close(a: (f64, f64), b: (f64, f64), tol: f64) -> bool {
    (a.0 - b.0).abs() <= tol && (a.1 - b.1).abs() <= tol
}

// ---------------------------------------------------------------- real data

#[test]
fn bluntfin_legacy_binary_structured() {
    let Some(m) = load("bluntfin/bluntfin_converted_legacy42_binary.vtk") else {
        return;
    };
    assert_eq!(m.points.len(), 40_960);
    assert_eq!(by_type(&m), [("hexahedron", 37_479)]);
    let d = arr(&m.point_data, "Density");
    assert_eq!(d.vtk_type, "Float32");
    assert!(matches!(d.data, ArrayData::F32(_)));
    assert!(close(d.range(Some(0)).unwrap(), (0.19, 4.98), 0.005));
    assert_eq!(arr(&m.point_data, "Momentum").components, 3);
    assert_eq!(m.active_point_scalars.as_deref(), Some("Density"));
    // Node order of the first hex: (0,0,0) (1,0,0) (1,1,0) (0,1,0) + k.
    assert_eq!(m.cells.nodes(0), &[0, 1, 41, 40, 1280, 1281, 1321, 1320]);
}

#[test]
fn office_and_kitchen_structured_grids() {
    if let Some(m) = load("office_kitchen/office.binary.vtk") {
        assert_eq!(m.points.len(), 8_400);
        assert_eq!(by_type(&m), [("hexahedron", 7_220)]);
        assert_eq!(arr(&m.point_data, "vectors").components, 3);
    }
    if let Some(m) = load("office_kitchen/kitchen.vtk") {
        assert_eq!(m.points.len(), 28 * 24 * 17);
        assert_eq!(by_type(&m), [("hexahedron", 9_936)]);
        // `bit` arrays are read as 0/1 integers.
        let h = arr(&m.point_data, "hpor");
        assert_eq!(h.range(Some(0)), Some((0.0, 1.0)));
    }
}

#[test]
fn disk_out_ref_legacy51_offsets_connectivity() {
    let Some(m) = load("disk_out_ref/disk_out_ref_converted_legacy51_binary.vtk") else {
        return;
    };
    assert_eq!(m.points.len(), 8_499);
    assert_eq!(by_type(&m), [("hexahedron", 7_472)]);
    assert!(close(
        arr(&m.point_data, "Temp").range(Some(0)).unwrap(),
        (293.0, 913.0),
        0.5
    ));
    assert_eq!(arr(&m.cell_data, "ObjectId").tuples(), 7_472);
}

#[test]
fn notch_quadratic_cells_labelled_linear() {
    let Some(m) = load("notch/notch_stress.vtk") else {
        return;
    };
    assert_eq!(m.points.len(), 12_717);
    assert_eq!(by_type(&m), [("hexahedron", 2_188), ("wedge", 4)]);
    // Only corners are kept.
    assert!(m
        .cells
        .offsets
        .windows(2)
        .all(|w| w[1] - w[0] == 8 || w[1] - w[0] == 6));
    assert_eq!(m.active_point_scalars.as_deref(), Some("Nodal Stress-0"));
    assert_eq!(arr(&m.point_data, "Nodal Stress").components, 6);
    arr(&m.point_data, "Nodal Stress-normed");
}

#[test]
fn angular_sector_ascii_30() {
    let Some(m) = load("angular_sector/AngularSector.vtk") else {
        return;
    };
    assert_eq!(m.points.len(), 10_141);
    assert_eq!(by_type(&m), [("hexahedron", 7_632), ("pyramid", 144)]);
    assert!(!arr(&m.point_data, "PointId").data.is_float());
    assert_eq!(arr(&m.cell_data, "CellId").tuples(), 7_776);
}

#[test]
fn sphere_hybrid_ascii_42() {
    let Some(m) = load("su2_sphere_hybrid/sphere_hybrid_converted_legacy42_ascii.vtk") else {
        return;
    };
    assert_eq!(m.points.len(), 5_750);
    assert_eq!(
        by_type(&m),
        [("pyramid", 318), ("tetra", 312), ("wedge", 7_950)]
    );
    assert!(close(
        arr(&m.point_data, "Pressure").range(Some(0)).unwrap(),
        (-3.2, 4.0),
        0.05
    ));
    assert_eq!(arr(&m.point_data, "Velocity").components, 3);
}

#[test]
fn prisms_zoo() {
    if let Some(m) = load("prisms_zoo/PentaHexa.vtk") {
        assert_eq!(
            by_type(&m),
            [("hexagonal_prism", 150), ("pentagonal_prism", 60)]
        );
        assert_eq!(
            m.cells
                .kinds
                .iter()
                .filter(|&&k| k == CellKind::PentagonalPrism)
                .count(),
            60
        );
        assert_eq!(arr(&m.cell_data, "scalar1").vtk_type, "UInt64");
        arr(&m.point_data, "scalar2");
    }
    if let Some(m) = load("prisms_zoo/hexa.vtk") {
        assert_eq!(by_type(&m), [("hexahedron", 10_648)]);
    }
    if let Some(m) = load("prisms_zoo/uGridEx.vtk") {
        // 12 cells: 2 hex, 2 tet and 8 lower-dimensional cells (dropped).
        assert_eq!(m.cells.len() + m.source.ignored_cells, 12);
        assert!(m.source.ignored_cells > 0);
    }
}

#[test]
fn synthetic_mixed_binary() {
    let Some(m) = load("synthetic/mixed.vtk") else {
        return;
    };
    assert_eq!(
        by_type(&m),
        [
            ("hexahedron", 32_000),
            ("pyramid", 8_000),
            ("tetra", 80_000),
            ("wedge", 76_800)
        ]
    );
}

#[test]
fn tets_small() {
    if let Some(m) = load("tets_small/CylinderLinear.vtk") {
        assert_eq!(by_type(&m), [("tetra", 1_522)]);
        assert_eq!(m.points.len(), 465);
        arr(&m.point_data, "vel_norm");
    }
    if let Some(m) = load("tets_small/tetraMesh.vtk") {
        assert_eq!(m.cells.len(), 160);
        arr(&m.point_data, "scalars");
    }
}

/// Same points, cells and first point array as `vtkio` where it reads the file.
#[test]
fn agrees_with_vtkio() {
    use vtkio::model::{DataSet, Piece, VertexNumbers};
    for rel in [
        "angular_sector/AngularSector.vtk",
        "su2_sphere_hybrid/sphere_hybrid_converted_legacy42_ascii.vtk",
        "prisms_zoo/hexa.vtk",
        "tets_small/CylinderLinear.vtk",
        "disk_out_ref/disk_out_ref_converted_legacy51_binary.vtk",
        "synthetic/mixed.vtk",
    ] {
        let Some(p) = shared_file(rel) else { continue };
        let ours = read(&p).unwrap();
        let theirs = vtkio::Vtk::import(&p).unwrap_or_else(|e| panic!("vtkio {rel}: {e:?}"));
        let DataSet::UnstructuredGrid { pieces, .. } = theirs.data else {
            panic!("{rel}: not unstructured")
        };
        let Piece::Inline(piece) = &pieces[0] else {
            panic!()
        };
        let pts: Vec<f64> = piece.points.cast_into().unwrap();
        assert_eq!(pts.len(), 3 * ours.points.len(), "{rel}");
        for (i, p) in ours.points.iter().enumerate() {
            assert_eq!(
                [pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]],
                p.to_array(),
                "{rel}"
            );
        }
        // Cell node lists from either of vtkio's layouts (5.x offsets may
        // start with a leading zero).
        let lists: Vec<Vec<u64>> = match piece.cells.cell_verts.clone() {
            VertexNumbers::Legacy { vertices, .. } => {
                let mut v = Vec::new();
                let mut k = 0;
                while k < vertices.len() {
                    let n = vertices[k] as usize;
                    v.push(
                        vertices[k + 1..k + 1 + n]
                            .iter()
                            .map(|&x| x as u64)
                            .collect(),
                    );
                    k += 1 + n;
                }
                v
            }
            VertexNumbers::XML {
                connectivity,
                offsets,
            } => {
                let mut ends = offsets;
                if ends.len() == piece.cells.types.len() + 1 {
                    ends.remove(0);
                }
                let mut start = 0;
                ends.iter()
                    .map(|&e| {
                        let l = connectivity[start..e as usize].to_vec();
                        start = e as usize;
                        l
                    })
                    .collect()
            }
        };
        assert_eq!(lists.len(), piece.cells.types.len(), "{rel}");
        let mut c = 0;
        for (t, ids) in piece.cells.types.iter().zip(&lists) {
            if (*t as u8) < 10 {
                continue;
            }
            let ours_ids: Vec<u64> = ours.cells.nodes(c).iter().map(|&x| x as u64).collect();
            assert_eq!(ours_ids, ids[..ours_ids.len()], "{rel} cell {c}");
            c += 1;
        }
        assert_eq!(c, ours.cells.len());
        // Point arrays vtkio also exposes hold the same values.
        let mut theirs_arrays: Vec<(String, Vec<f64>)> = Vec::new();
        for a in &piece.data.point {
            match a {
                vtkio::model::Attribute::DataArray(d) => {
                    theirs_arrays.push((d.name.clone(), d.data.cast_into().unwrap()))
                }
                vtkio::model::Attribute::Field { data_array, .. } => {
                    for d in data_array {
                        theirs_arrays.push((d.name.clone(), d.data.cast_into().unwrap()));
                    }
                }
            }
        }
        let mut compared = 0;
        for (name, vals) in theirs_arrays {
            let Some(a) = ours.point_data.iter().find(|a| a.name == name) else {
                continue;
            };
            assert_eq!(a.data.len(), vals.len(), "{rel} {name}");
            assert!(
                (0..vals.len()).all(|i| a.data.get(i) == vals[i]),
                "{rel} {name}"
            );
            compared += 1;
        }
        assert!(compared > 0, "{rel}: no array compared");
    }
}

// ------------------------------------------------------- hand-written files

const CUBE_PTS: &str = "POINTS 8 float\n0 0 0 1 0 0 1 1 0 0 1 0\n0 0 1 1 0 1 1 1 1 0 1 1\n";

#[test]
fn structured_points_become_vtk_ordered_hexes() {
    let m = parse(
        "# vtk DataFile Version 2.0\nimg\nASCII\nDATASET STRUCTURED_POINTS\n\
         DIMENSIONS 3 2 2\nORIGIN 1 2 3\nSPACING 0.5 1 2\n\
         POINT_DATA 12\nSCALARS v double\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7 8 9 10 11\n",
    );
    assert_eq!(m.points.len(), 12);
    assert_eq!(m.points[5].to_array(), [2.0, 3.0, 3.0]);
    assert_eq!(m.cells.len(), 2);
    assert_eq!(m.cells.nodes(1), &[1, 2, 5, 4, 7, 8, 11, 10]);
    assert_eq!(m.active_point_scalars.as_deref(), Some("v"));
}

#[test]
fn rectilinear_grid_and_2d_grids() {
    let m = parse(
        "# vtk DataFile Version 3.0\nr\nASCII\nDATASET RECTILINEAR_GRID\nDIMENSIONS 2 3 2\n\
         X_COORDINATES 2 float\n0 1\nY_COORDINATES 3 double\n0 1 5\nZ_COORDINATES 2 int\n-1 1\n\
         CELL_DATA 2\nSCALARS c int 1\nLOOKUP_TABLE default\n7 8\n",
    );
    assert_eq!(m.points.len(), 12);
    assert_eq!(m.points[11].to_array(), [1.0, 5.0, 1.0]);
    assert_eq!(m.cells.len(), 2);
    assert_eq!(arr(&m.cell_data, "c").data, ArrayData::Int(vec![7, 8]));
    // A 2D structured grid gives no 3D cells; its cell data is filtered away.
    let m = parse(
        "# vtk DataFile Version 3.0\ns\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 2 2 1\n\
         POINTS 4 float\n0 0 0 1 0 0 0 1 0 1 1 0\nCELL_DATA 1\nSCALARS c float\nLOOKUP_TABLE default\n3\n",
    );
    assert_eq!(m.cells.len(), 0);
    assert_eq!(m.source.ignored_cells, 1);
    assert_eq!(arr(&m.cell_data, "c").tuples(), 0);
}

#[test]
fn mixed_cells_voxel_quadratic_and_filtered_cell_data() {
    // 0: voxel, 1: triangle (dropped), 2: quadratic tet (10 nodes), 3: vertex (dropped),
    // 4: tet; cell data must keep tuples 0, 2 and 4.
    let text = format!(
        "# vtk DataFile Version 4.2\nm\nASCII\n\n\nDATASET UNSTRUCTURED_GRID\n\
         FIELD FieldData 2\nTIME 1 1 double\n2.5\nCYCLE 1 1 int\n7\n{CUBE_PTS}\n\
         CELLS 5 31\n8 0 1 3 2 4 5 7 6\n3 0 1 2\n10 0 1 3 4 0 1 3 4 0 1\n1 5\n4 0 1 2 4\n\
         CELL_TYPES 5\n11 5 24 1 10\n\
         CELL_DATA 5\nSCALARS id%20no int\nLOOKUP_TABLE default\n10 11 12 13 14\n\
         TENSORS t float\n{}\nFIELD f 1\nw 2 5 double\n0 1 2 3 4 5 6 7 8 9\n\
         POINT_DATA 8\nVECTORS vel float\n{}\nNORMALS n double\n{}\n\
         METADATA\nINFORMATION 0\n\n\
         SCALARS two float 2\nLOOKUP_TABLE default\n{}\n\
         COLOR_SCALARS rgb 3\n{}\nLOOKUP_TABLE my 2\n0 0 0 1 1 1 1 1\n",
        (0..45).map(|i| i.to_string()).collect::<Vec<_>>().join(" "),
        (0..24).map(|i| i.to_string()).collect::<Vec<_>>().join(" "),
        (0..24).map(|i| i.to_string()).collect::<Vec<_>>().join(" "),
        (0..16).map(|i| i.to_string()).collect::<Vec<_>>().join(" "),
        (0..24).map(|_| "0.5").collect::<Vec<_>>().join(" "),
    );
    let m = parse(&text);
    // The dataset's TIME is the step's time; CYCLE is dropped with a note.
    assert_eq!(m.source.time_value, Some(2.5));
    assert!(
        m.source
            .notes
            .iter()
            .any(|n| n.contains("CYCLE") && !n.contains("TIME")),
        "{:?}",
        m.source.notes
    );
    assert_eq!(m.cells.len(), 3);
    assert_eq!(m.source.ignored_cells, 2);
    assert_eq!(
        by_type(&m),
        [("quadratic_tetra", 1), ("tetra", 1), ("voxel", 1)]
    );
    // Voxel 0 1 3 2 4 5 7 6 becomes hexahedron 0 1 2 3 4 5 6 7.
    assert_eq!(m.cells.kinds[0], CellKind::Hexahedron);
    assert_eq!(m.cells.nodes(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(m.cells.nodes(1), &[0, 1, 3, 4]);
    assert_eq!(m.cells.nodes(2), &[0, 1, 2, 4]);
    assert_eq!(
        arr(&m.cell_data, "id no").data,
        ArrayData::Int(vec![10, 12, 14])
    );
    let t = arr(&m.cell_data, "t");
    assert_eq!(t.components, 9);
    assert_eq!(t.component(1, 0), 18.0);
    let w = arr(&m.cell_data, "w");
    assert_eq!(w.data, ArrayData::F64(vec![0.0, 1.0, 4.0, 5.0, 8.0, 9.0]));
    assert_eq!(m.active_cell_scalars.as_deref(), Some("id no"));
    assert_eq!(m.active_point_scalars.as_deref(), Some("two"));
    assert_eq!(arr(&m.point_data, "two").components, 2);
    assert_eq!(arr(&m.point_data, "rgb").components, 3);
    assert!(m.source.notes.iter().any(|n| n.contains("CYCLE")));
}

#[test]
fn polyhedron_face_stream() {
    let m = parse(&format!(
        "# vtk DataFile Version 4.2\np\nASCII\nDATASET UNSTRUCTURED_GRID\n{CUBE_PTS}\
         CELLS 1 32\n31 6 4 0 3 2 1 4 4 5 6 7 4 0 1 5 4 4 1 2 6 5 4 2 3 7 6 4 3 0 4 7\n\
         CELL_TYPES 1\n42\n"
    ));
    assert_eq!(m.cells.kinds, [CellKind::Polyhedron]);
    assert_eq!(m.cells.nodes(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(m.cells.face_count(0), 6);
    assert_eq!(by_type(&m), [("polyhedron", 1)]);
}

/// Minimal big-endian binary file writer for the tests.
fn binary_51(int_type: &str, width: usize, extra: &[u8]) -> Vec<u8> {
    let mut b =
        b"# vtk DataFile Version 5.1\nvtk output\nBINARY\nDATASET UNSTRUCTURED_GRID\n".to_vec();
    b.extend_from_slice(b"POINTS 5 double\n");
    for v in [
        0.0f64, 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.,
    ] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.extend_from_slice(
        b"\nMETADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\nDATA 2 0 1.7\n\n",
    );
    let put = |b: &mut Vec<u8>, v: i64| b.extend_from_slice(&v.to_be_bytes()[8 - width..]);
    b.extend_from_slice(format!("CELLS 3 7\nOFFSETS {int_type}\n").as_bytes());
    for v in [0, 4, 7] {
        put(&mut b, v);
    }
    b.extend_from_slice(format!("\nCONNECTIVITY {int_type}\n").as_bytes());
    for v in [0, 1, 2, 3, 1, 2, 4] {
        put(&mut b, v);
    }
    b.extend_from_slice(b"\nCELL_TYPES 2\n");
    for t in [10i32, 5] {
        b.extend_from_slice(&t.to_be_bytes());
    }
    b.extend_from_slice(b"\nCELL_DATA 2\nFIELD FieldData 1\nf 1 2 float\n");
    for v in [1.5f32, 2.5] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.extend_from_slice(b"\nMETADATA\nINFORMATION 0\n\nPOINT_DATA 5\nSCALARS s unsigned_short\nLOOKUP_TABLE default\n");
    for v in [10u16, 11, 12, 10, 32] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.extend_from_slice(extra);
    b
}

#[test]
fn binary_51_any_integer_width() {
    for (ty, w) in [
        ("vtktypeint64", 8),
        ("vtktypeint32", 4),
        ("short", 2),
        ("unsigned_char", 1),
    ] {
        let m = read_bytes(Path::new("b.vtk"), &binary_51(ty, w, b"\n")).unwrap();
        assert_eq!(m.cells.len(), 1, "{ty}");
        assert_eq!(m.cells.nodes(0), &[0, 1, 2, 3]);
        assert_eq!(m.source.ignored_cells, 1);
        assert_eq!(arr(&m.cell_data, "f").data, ArrayData::F32(vec![1.5]));
        assert_eq!(
            arr(&m.point_data, "s").data,
            ArrayData::Int(vec![10, 11, 12, 10, 32])
        );
        assert_eq!(arr(&m.point_data, "s").vtk_type, "UInt16");
        assert_eq!(m.points[4].to_array(), [1.0, 1.0, 1.0]);
    }
}

#[test]
fn f32_values_are_bit_exact() {
    let vals = [0.1f32, f32::MIN_POSITIVE, 3.4e38, -1.0e-7, 0.3];
    let mut b =
        b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\nPOINTS 1 float\n".to_vec();
    for v in [0f32, 0., 0.] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.extend_from_slice(b"\nPOINT_DATA 1\nSCALARS s float 5\nLOOKUP_TABLE default\n");
    for v in vals {
        b.extend_from_slice(&v.to_be_bytes());
    }
    let m = read_bytes(Path::new("f.vtk"), &b).unwrap();
    assert_eq!(arr(&m.point_data, "s").data, ArrayData::F32(vals.to_vec()));
    // ASCII float text is parsed straight to f32 as VTK does.
    let m = parse("# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 1 float\n0 0 0\nVERTICES 1 2\n1 0\nPOINT_DATA 1\nSCALARS s float\nLOOKUP_TABLE default\n0.1\n");
    assert_eq!(arr(&m.point_data, "s").data, ArrayData::F32(vec![0.1f32]));
    assert_eq!(m.source.ignored_cells, 1);
}

// ----------------------------------------------------------- hostile input

#[test]
fn huge_counts_are_refused_before_allocating() {
    let t = Instant::now();
    let e = parse_err(b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1000000000000 float\n0 0 0\n");
    assert!(e.contains("line 5"), "{e}");
    let mut b = b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 3000000000 double\n".to_vec();
    b.extend_from_slice(&[0u8; 64]);
    let e = parse_err(&b);
    assert!(e.contains("byte"), "{e}");
    assert!(t.elapsed() < Duration::from_secs(1));
}

#[test]
fn errors_name_line_or_byte_of_the_bad_value() {
    let e = parse_err(
        format!("# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n{CUBE_PTS}CELLS 2 10\n4 0 1 2 3\n4 0 1 9 3\nCELL_TYPES 2\n10 10\n")
            .as_bytes(),
    );
    assert!(e.contains("line 10") && e.contains("point id 9"), "{e}");
    let e = parse_err(b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n0 0 0\n\n1 inf 0\n");
    assert!(e.contains("line 8") && e.contains("non-finite"), "{e}");
    // Binary: byte offset of the offending id (the last connectivity value).
    let mut b = binary_51("vtktypeint64", 8, b"\n");
    let pos = find(&b, b"CONNECTIVITY vtktypeint64\n") + 26 + 2 * 8;
    b[pos + 7] = 99;
    let e = parse_err(&b);
    assert!(
        e.contains(&format!("byte {pos}")),
        "{e} (expected byte {pos})"
    );
}

fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).position(|w| w == needle).unwrap()
}

fn corrupt_files() -> Vec<PathBuf> {
    let dir = zoovr::testdata::mesh_file("corrupt");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            n.starts_with("legacy_") || n.starts_with("plot3d_")
        })
        .collect();
    v.sort();
    v
}

/// A valid 2x2x2 big-endian PLOT3D grid, to pair with the corrupt q files.
fn unit_grid() -> Vec<u8> {
    let mut b = Vec::new();
    for d in [2i32, 2, 2] {
        b.extend_from_slice(&d.to_be_bytes());
    }
    for c in 0..3 {
        for p in 0..8 {
            b.extend_from_slice(&(((p >> c) & 1) as f32).to_be_bytes());
        }
    }
    b
}

#[test]
fn corrupt_corpus_fails_with_file_and_location() {
    let files = corrupt_files();
    assert!(files.len() >= 10, "only {} corrupt files", files.len());
    let loc = regex_like_location;
    for p in files {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let res = if name.starts_with("legacy_") {
            zoovr::io::legacy::read(&p)
        } else if name.ends_with(".q") {
            let q = std::fs::read(&p).unwrap();
            zoovr::io::plot3d::read_bytes(Path::new("grid.xyz"), &unit_grid(), Some((&p, &q)))
        } else {
            zoovr::io::plot3d::read(&p, None)
        };
        let msg = match res {
            Ok(_) => panic!("{name}: read without error"),
            Err(e) => e.to_string(),
        };
        assert!(
            msg.contains(&name),
            "{name}: message does not name the file: {msg}"
        );
        assert!(loc(&msg), "{name}: message has no line/byte: {msg}");
    }
}

/// Whether a message contains `line N` or `byte N`.
fn regex_like_location(msg: &str) -> bool {
    ["line ", "byte "].iter().any(|k| {
        msg.match_indices(k)
            .any(|(i, _)| msg[i + k.len()..].starts_with(|c: char| c.is_ascii_digit()))
    })
}

fn mutate(rng: &mut Rng, base: &[u8]) -> Vec<u8> {
    let mut b = base.to_vec();
    match rng.below(4) {
        0 => b.truncate(rng.below(b.len())),
        1 => {
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                b[i] = rng.next_u64() as u8;
            }
        }
        2 => {
            // Replace a digit by a large or negative number.
            let digits: Vec<usize> = (0..b.len()).filter(|&i| b[i].is_ascii_digit()).collect();
            if !digits.is_empty() {
                let i = digits[rng.below(digits.len())];
                let rep: &[u8] = [&b"99999999999"[..], b"-1", b"0", b"4294967296"][rng.below(4)];
                b.splice(i..i + 1, rep.iter().copied());
            }
        }
        _ => {
            let i = rng.below(b.len());
            let j = (i + rng.below(64)).min(b.len());
            b.drain(i..j);
        }
    }
    b
}

/// Applies `per_base` seeded mutations to each base file; returns the count.
fn run_mutations(per_base: usize, seed: u64) -> usize {
    let mut bases: Vec<Vec<u8>> = vec![
        binary_51("vtktypeint64", 8, b"\n"),
        binary_51("int", 4, b"\n"),
        format!("# vtk DataFile Version 4.2\np\nASCII\nDATASET UNSTRUCTURED_GRID\n{CUBE_PTS}CELLS 3 23\n8 0 1 2 3 4 5 6 7\n4 0 1 2 4\n8 0 1 3 2 4 5 7 6\nCELL_TYPES 3\n12 10 11\nCELL_DATA 3\nSCALARS c int\nLOOKUP_TABLE default\n1 2 3\nPOINT_DATA 8\nVECTORS v float\n{}\n", (0..24).map(|i| i.to_string()).collect::<Vec<_>>().join(" ")).into_bytes(),
        b"# vtk DataFile Version 2.0\ni\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 3 3\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 27\nSCALARS s float\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26\n".to_vec(),
    ];
    if let Some(p) = shared_file("prisms_zoo/uGridEx.vtk") {
        bases.push(std::fs::read(p).unwrap());
    }
    let mut rng = Rng(seed);
    let t = Instant::now();
    let mut errors = 0;
    let mut n = 0;
    for base in &bases {
        for _ in 0..per_base {
            let input = mutate(&mut rng, base);
            let r = std::panic::catch_unwind(|| read_bytes(Path::new("mut.vtk"), &input));
            match r {
                Err(_) => panic!(
                    "panic on mutated input: {:?}",
                    String::from_utf8_lossy(&input)
                ),
                Ok(Err(e)) => {
                    let m = e.to_string();
                    assert!(m.contains("mut.vtk") && regex_like_location(&m), "{m}");
                    errors += 1;
                }
                Ok(Ok(mesh)) => {
                    // Whatever was read is consistent.
                    for &id in &mesh.cells.conn {
                        assert!((id as usize) < mesh.points.len());
                    }
                }
            }
            n += 1;
        }
    }
    assert!(errors > n / 4, "only {errors} of {n} mutations rejected");
    eprintln!("{n} mutations in {:?}", t.elapsed());
    n
}

#[test]
fn seeded_mutations_never_panic() {
    let t = Instant::now();
    assert!(run_mutations(800, 0x005e_ed1e_9ac7) >= 3200);
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
}

/// A longer run for local fuzzing: `cargo test --test io_legacy -- --ignored`.
#[test]
#[ignore]
fn many_seeded_mutations_never_panic() {
    for seed in 1..=20u64 {
        run_mutations(5_000, seed.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    }
}
