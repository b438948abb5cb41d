//! The default-field rule of docs/conventions.md (Conventions), `--field` selection and
//! `--cell-to-point` averaging, on small hand-built meshes and real data.

use zoovr::field::{
    cell_to_point, select_field, ArrayData, Association, DataArray, FieldError, FieldSpec,
};
use zoovr::generate::warped_hex_grid;
use zoovr::generate::Warp;
use zoovr::mesh::Mesh;

fn arr(name: &str, components: usize, data: ArrayData) -> DataArray {
    DataArray {
        name: name.into(),
        components,
        vtk_type: match &data {
            ArrayData::F32(_) => "Float32",
            ArrayData::F64(_) => "Float64",
            ArrayData::Int(_) => "Int32",
        }
        .into(),
        data,
    }
}

/// A 2 x 2 x 2 hex grid (27 points, 8 cells) with no arrays.
fn grid() -> Mesh {
    let mut m = warped_hex_grid(2, &Warp::default());
    m.point_data.clear();
    m.cell_data.clear();
    m.active_point_scalars = None;
    m
}

fn pf(n: usize, c: usize, f: impl Fn(usize) -> f64) -> ArrayData {
    ArrayData::F64((0..n * c).map(f).collect())
}

fn pick(m: &Mesh) -> Option<(String, Association)> {
    select_field(m, None)
        .unwrap()
        .map(|f| (f.name, f.association))
}

#[test]
fn default_rule_in_order() {
    let np = 27;
    let nc = 8;
    let mut m = grid();
    // (7) nothing: constant scalar.
    assert_eq!(pick(&m), None);
    // (6) integers, cell after point.
    m.cell_data
        .push(arr("cid", 1, ArrayData::Int((0..nc as i64).collect())));
    assert_eq!(pick(&m), Some(("cid".into(), Association::Cell)));
    m.point_data
        .push(arr("pid", 1, ArrayData::Int((0..np as i64).collect())));
    assert_eq!(pick(&m), Some(("pid".into(), Association::Point)));
    // (5) a float cell vector beats integers, as magnitude.
    m.cell_data.push(arr("cvec", 3, pf(nc, 3, |i| i as f64)));
    assert_eq!(pick(&m), Some(("cvec:mag".into(), Association::Cell)));
    // (4) a float point vector beats cell vectors.
    m.point_data.push(arr("pvec", 3, pf(np, 3, |i| i as f64)));
    assert_eq!(pick(&m), Some(("pvec:mag".into(), Association::Point)));
    // (3) a 1-component float cell array beats vectors.
    m.cell_data.push(arr("cs", 1, pf(nc, 1, |i| i as f64)));
    assert_eq!(pick(&m), Some(("cs".into(), Association::Cell)));
    // (2) the first 1-component float point array beats cell scalars.
    m.point_data.push(arr("ps", 1, pf(np, 1, |i| -(i as f64))));
    m.point_data.push(arr("ps2", 1, pf(np, 1, |i| i as f64)));
    let f = select_field(&m, None).unwrap().unwrap();
    assert_eq!((f.name.as_str(), f.association), ("ps", Association::Point));
    assert_eq!(f.range, (-26.0, 0.0));
    // (1) the active point scalars, when 1-component, beat everything.
    m.active_point_scalars = Some("ps2".into());
    assert_eq!(pick(&m), Some(("ps2".into(), Association::Point)));
    // An active array with several components falls back to the rule.
    m.active_point_scalars = Some("pvec".into());
    assert_eq!(pick(&m), Some(("ps".into(), Association::Point)));
}

/// VTK's bookkeeping arrays (ghost flags, original ids) are passed over by
/// the default rule while any other array exists, and taken (in the usual
/// order) when nothing else is there; `--field` names them as any array.
#[test]
fn default_rule_skips_vtk_bookkeeping_arrays() {
    let np = 27;
    let nc = 8;
    let ghost = |m: &mut Mesh| {
        let mut a = arr("vtkGhostType", 1, ArrayData::Int(vec![0; nc]));
        a.vtk_type = "UInt8".into();
        m.cell_data.push(a);
    };
    let mut m = grid();
    ghost(&mut m);
    assert_eq!(
        pick(&m),
        Some(("vtkGhostType".into(), Association::Cell)),
        "only the ghost array: taken"
    );
    m.cell_data.push(arr(
        "vtkOriginalCellIds",
        1,
        ArrayData::Int((0..nc as i64).collect()),
    ));
    assert_eq!(pick(&m), Some(("vtkGhostType".into(), Association::Cell)));
    // a point id array wins over cell ones when only bookkeeping is there
    m.point_data.push(arr(
        "vtkOriginalPointIds",
        1,
        ArrayData::Int((0..np as i64).collect()),
    ));
    assert_eq!(
        pick(&m),
        Some(("vtkOriginalPointIds".into(), Association::Point))
    );
    // any other array is preferred, even an integer cell array after them
    m.cell_data.push(arr(
        "layer",
        1,
        ArrayData::Int(vec![1, 1, 1, 1, 2, 2, 2, 2]),
    ));
    assert_eq!(pick(&m), Some(("layer".into(), Association::Cell)));
    // ids stored as floats (rule 2/3 would take them first) are skipped too
    m.point_data
        .insert(0, arr("vtkOriginalPointIds", 1, pf(np, 1, |i| i as f64)));
    m.cell_data
        .insert(0, arr("vtkOriginalCellIds", 1, pf(nc, 1, |i| i as f64)));
    assert_eq!(pick(&m), Some(("layer".into(), Association::Cell)));
    // ... as are active point scalars that are ids
    m.active_point_scalars = Some("vtkOriginalPointIds".into());
    assert_eq!(pick(&m), Some(("layer".into(), Association::Cell)));
    m.cell_data
        .push(arr("poro", 1, pf(nc, 1, |i| i as f64 / 10.0)));
    assert_eq!(pick(&m), Some(("poro".into(), Association::Cell)));
    // named explicitly, they are used
    let f = select_field(&m, Some(&FieldSpec::parse("vtkGhostType").unwrap()))
        .unwrap()
        .unwrap();
    assert_eq!(
        (f.name.as_str(), f.association),
        ("vtkGhostType", Association::Cell)
    );
}

#[test]
fn named_fields_components_and_errors() {
    let np = 27;
    let mut m = grid();
    m.point_data
        .push(arr("v", 3, pf(np, 3, |i| (i % 3) as f64 + 1.0)));
    m.cell_data.push(arr("v", 1, pf(8, 1, |i| i as f64)));
    let get = |s: &str| {
        select_field(&m, Some(&FieldSpec::parse(s).unwrap()))
            .unwrap()
            .unwrap()
    };
    // A name on both associations: point first; `cell:` picks the other.
    assert_eq!(get("v").association, Association::Point);
    assert_eq!(get("cell:v").association, Association::Cell);
    assert_eq!(get("cell:v").range, (0.0, 7.0));
    // Component 2 of (1, 2, 3) is 3 everywhere; magnitude is sqrt(14).
    assert_eq!(get("v:2").range, (3.0, 3.0));
    let mag = get("v:mag").range.0;
    assert!((mag - 14f64.sqrt()).abs() < 1e-12);
    let err = select_field(&m, Some(&FieldSpec::parse("v:3").unwrap())).unwrap_err();
    assert!(matches!(err, FieldError::BadComponent { .. }), "{err}");
    let err = select_field(&m, Some(&FieldSpec::parse("nope").unwrap())).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("nope") && msg.contains("point:v") && msg.contains("cell:v"),
        "{msg}"
    );
}

#[test]
fn cell_to_point_averages_the_cells_of_each_point() {
    let mut m = grid();
    // Cell c carries c; a corner point belongs to one cell, the centre point
    // (index 13 of the 3 x 3 x 3 lattice) to all eight.
    m.cell_data.push(arr("c", 1, pf(8, 1, |i| i as f64)));
    let f = select_field(&m, None).unwrap().unwrap();
    assert_eq!(f.association, Association::Cell);
    let p = cell_to_point(&m, &f);
    assert_eq!(p.association, Association::Point);
    assert_eq!(p.values.len(), 27);
    for (i, &v) in p.values.iter().enumerate() {
        let mut sum = 0.0;
        let mut n = 0;
        for c in 0..m.cells.len() {
            if m.cells.nodes(c).contains(&(i as u32)) {
                sum += c as f64;
                n += 1;
            }
        }
        assert!(n > 0);
        assert_eq!(v, sum / n as f64, "point {i}");
    }
    assert_eq!(p.values[13], 3.5);
    assert_eq!(p.range, (0.0, 7.0));
    // A point field is returned as it is.
    let q = cell_to_point(&m, &p);
    assert_eq!(q.values, p.values);
}

/// The default field of the shared datasets named in their README.
#[test]
fn shared_data_default_fields() {
    for (rel, name, assoc) in [
        (
            "bluntfin/bluntfin_converted.vts",
            "Density",
            Association::Point,
        ),
        ("fire_room/fire_ug.vtu", "t", Association::Point),
        (
            "disk_out_ref/disk_out_ref_converted.vtu",
            "Temp",
            Association::Point,
        ),
        (
            "fea_bracket_qtet/kiefer_bracket.vtu",
            "Equivalent (von-Mises) Stress (psi)",
            Association::Cell,
        ),
        ("can_crush/can.vtu", "EQPS", Association::Cell),
    ] {
        let Some(path) = zoovr::testdata::shared_file(rel) else {
            continue;
        };
        let mesh = zoovr::io::read(&path, &Default::default()).unwrap();
        let f = select_field(&mesh, None).unwrap().unwrap();
        assert_eq!((f.name.as_str(), f.association), (name, assoc), "{rel}");
    }
}
