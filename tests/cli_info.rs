//! `zoovr info` run as a real binary on the project's own meshes.
//!
//! The files in `meshes/` are written by `examples/gen_mesh.rs --meshes
//! meshes` from `zoovr::generate`; every expected value here is computed
//! independently in memory from the same generator (or by hand for the
//! degenerate cells), so these tests check the readers and `info` together.
//! They need the legacy and XML readers.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;
use zoovr::field::ArrayData;
use zoovr::generate::{
    ghost_grid, ghost_grid_flags, ring_grid, single_cell, warped_hex_grid, zoo_grid, Warp,
};
use zoovr::io::writer::{write_vtu, Compression};
use zoovr::mesh::report::MeshReport;
use zoovr::mesh::{CellKind, Mesh};
use zoovr::testdata::mesh_file;

/// serde_json parses floats to within an ulp (no `float_roundtrip`).
fn close(got: &Value, want: f64) -> bool {
    got.as_f64()
        .is_some_and(|g| (g - want).abs() <= 1e-14 * want.abs().max(1e-300))
}

fn zoovr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_zoovr"))
        .args(args)
        .output()
        .expect("run zoovr")
}

fn info_json(file: &Path) -> Value {
    let out = zoovr(&["info", file.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

/// Asserts the JSON of `file` agrees with the in-memory `mesh`.
fn assert_agrees(file: &str, mesh: &Mesh) {
    let v = info_json(&mesh_file(file));
    let r = MeshReport::compute(mesh);
    assert_eq!(v["cells3d"], mesh.cells.len(), "{file}");
    assert_eq!(v["points"], mesh.points.len(), "{file}");
    let b = mesh.bounds();
    for k in 0..6 {
        assert!(close(&v["bounds"][k], b[k]), "{file} bounds[{k}]");
    }
    for (key, want) in [
        ("boundary_faces", r.boundary_faces),
        ("components", r.components),
        ("inverted_cells", r.inverted_cells),
        ("degenerate_cells", r.degenerate_cells),
        ("nonplanar_faces", r.nonplanar_faces),
        ("inverted_tets", r.inverted_tets),
        ("nonmanifold_faces", r.nonmanifold_faces),
        ("ignored_cells", 0),
    ] {
        assert_eq!(v[key], want, "{file}: {key}");
    }
    match r.convexity {
        Some(c) => {
            let got = v["convexity"].as_f64().unwrap();
            assert!((got - c).abs() < 1e-9, "{file}: convexity {got} vs {c}");
        }
        None => assert!(v["convexity"].is_null()),
    }
    assert_eq!(v["timesteps"], 1, "{file}");
    let f = v["arrays"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == "f")
        .unwrap_or_else(|| panic!("{file}: no array f"));
    assert_eq!(f["association"], "point");
    assert_eq!(f["components"], 1);
    assert_eq!(f["type"], "Float32");
    let range = mesh.point_data[0].range(Some(0)).unwrap();
    assert!(close(&f["range"][0], range.0), "{file}: {}", f["range"]);
    assert!(close(&f["range"][1], range.1), "{file}: {}", f["range"]);
}

#[test]
fn one_file_per_cell_kind() {
    for (name, kind) in [
        ("tetra", CellKind::Tetra),
        ("pyramid", CellKind::Pyramid),
        ("wedge", CellKind::Wedge),
        ("hexahedron", CellKind::Hexahedron),
        ("pentagonal_prism", CellKind::PentagonalPrism),
        ("hexagonal_prism", CellKind::HexagonalPrism),
        ("polyhedron", CellKind::Polyhedron),
    ] {
        let mesh = single_cell(kind);
        for ext in ["vtk", "vtu"] {
            let file = format!("{name}.{ext}");
            assert_agrees(&file, &mesh);
            let v = info_json(&mesh_file(&file));
            assert_eq!(v["cells_by_type"][name], 1, "{file}");
            assert_eq!(
                v["convexity"].as_f64().map(|c| (c - 1.0).abs() < 1e-12),
                Some(true)
            );
        }
    }
}

#[test]
fn voxel_is_read_in_voxel_order() {
    let v = info_json(&mesh_file("voxel.vtk"));
    assert_eq!(v["cells3d"], 1);
    assert_eq!(v["cells_by_type"]["voxel"], 1);
    // as a hexahedron with the voxel order converted: a positive unit cube
    assert_eq!(v["inverted_cells"], 0);
    assert_eq!(v["degenerate_cells"], 0);
    assert_eq!(v["boundary_faces"], 6);
    assert!((v["convexity"].as_f64().unwrap() - 1.0).abs() < 1e-12);
}

#[test]
fn grids_ring_and_zoo() {
    let w = Warp::default();
    let curv = warped_hex_grid(4, &w);
    assert_agrees("curvilinear_4x4x4.vtk", &curv);
    assert_agrees("curvilinear_4x4x4.vtu", &curv);
    let v = info_json(&mesh_file("curvilinear_4x4x4.vtu"));
    assert_eq!(v["boundary_faces"], 96);
    assert!(v["nonplanar_faces"].as_u64().unwrap() > 0);
    let ring = ring_grid(6, &w);
    assert_agrees("ring_hole.vtk", &ring);
    assert_agrees("ring_hole.vtu", &ring);
    let v = info_json(&mesh_file("ring_hole.vtu"));
    assert!(v["convexity"].as_f64().unwrap() < 0.95);
    assert_eq!(v["components"], 1);
    let zoo = zoo_grid(3, &w);
    assert_agrees("zoo_3x3x3.vtu", &zoo);
}

#[test]
fn degenerate_cells_are_counted() {
    for file in ["degenerate.vtk", "degenerate.vtu"] {
        let v = info_json(&mesh_file(file));
        assert_eq!(v["cells3d"], 5, "{file}");
        assert_eq!(v["cells_by_type"]["hexahedron"], 3);
        assert_eq!(v["cells_by_type"]["wedge"], 1);
        assert_eq!(v["cells_by_type"]["tetra"], 1);
        assert_eq!(v["inverted_cells"], 2, "{file}");
        assert_eq!(v["degenerate_cells"], 2, "{file}");
        assert_eq!(v["repeated_index_cells"], 1, "{file}");
        assert_eq!(v["inverted_tets"], 0, "{file}");
        assert_eq!(v["components"], 5, "{file}");
    }
}

#[test]
fn time_series_collections() {
    for file in ["series/series.pvd", "series/series.vtu.series"] {
        let v = info_json(&mesh_file(file));
        assert_eq!(v["timesteps"], 3, "{file}");
        assert_eq!(v["cells3d"], 27, "{file}");
    }
}

#[test]
fn text_output_shows_the_same_facts() {
    let out = zoovr(&["info", mesh_file("degenerate.vtk").to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("2 inverted, 2 degenerate, 1 with a repeated point"),
        "{text}"
    );
    assert!(text.contains("components:  5"), "{text}");
}

#[test]
fn errors_name_the_file_and_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no_such_mesh.vtk");
    let bad = dir.path().join("truncated_mesh.vtu");
    std::fs::write(
        &bad,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"8\"",
    )
    .unwrap();
    for f in [&missing, &bad] {
        let out = zoovr(&["info", f.to_str().unwrap(), "--json"]);
        assert_eq!(out.status.code(), Some(1), "{}", f.display());
        let err = String::from_utf8_lossy(&out.stderr);
        let name = f.file_name().unwrap().to_str().unwrap();
        assert!(err.contains(name), "{err}");
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(zoovr(&["info"]).status.code(), Some(2));
    assert_eq!(zoovr(&["info", "x.vtk", "--bogus"]).status.code(), Some(2));
}

#[test]
fn q_solution_on_a_non_plot3d_grid_is_an_error() {
    let f = mesh_file("tetra.vtk");
    let out = zoovr(&["info", f.to_str().unwrap(), "--q", "solution.q"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("tetra.vtk") && err.contains("solution.q") && err.contains("PLOT3D"),
        "{err}"
    );
}

/// `hidden_cells` / `duplicate_cells` count the flags of a `vtkGhostType`
/// cell array (0 without one); the text output has a line for them only
/// when the array exists. Every cell is still counted in `cells3d`.
#[test]
fn ghost_cells_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("ghost.vtu");
    write_vtu(&file, &ghost_grid(4, &Warp::default()), Compression::Zlib).unwrap();
    let (mut hidden, mut duplicate) = (0, 0);
    for k in 0..4 {
        for j in 0..4 {
            for i in 0..4 {
                let g = ghost_grid_flags(4, i, j, k);
                hidden += usize::from(g & 32 != 0);
                duplicate += usize::from(g & 1 != 0);
            }
        }
    }
    assert_eq!((hidden, duplicate), (13, 4));
    let v = info_json(&file);
    assert_eq!(v["hidden_cells"], hidden);
    assert_eq!(v["duplicate_cells"], duplicate);
    assert_eq!(v["cells3d"], 64);
    let out = zoovr(&["info", file.to_str().unwrap()]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("ghost cells: 13 hidden, 4 duplicate"),
        "{text}"
    );

    let plain = mesh_file("hexahedron.vtk");
    let v = info_json(&plain);
    assert_eq!(
        (&v["hidden_cells"], &v["duplicate_cells"]),
        (&0.into(), &0.into())
    );
    let out = zoovr(&["info", plain.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&out.stdout).contains("ghost cells:"));
}

/// A ghost array that is not one flag per cell is an error naming the file
/// and the array, exit 1.
#[test]
fn malformed_ghost_arrays_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (name, components, len) in [("two_comp.vtu", 2, 128), ("short.vtu", 1, 10)] {
        let mut m = ghost_grid(4, &Warp::default());
        m.cell_data[0].components = components;
        m.cell_data[0].data = ArrayData::Int(vec![0; len]);
        let file = dir.path().join(name);
        write_vtu(&file, &m, Compression::None).unwrap();
        for json in [true, false] {
            let mut args = vec!["info", file.to_str().unwrap()];
            if json {
                args.push("--json");
            }
            let out = zoovr(&args);
            assert_eq!(out.status.code(), Some(1), "{name}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(
                err.contains(name) && err.contains("vtkGhostType"),
                "{name}: {err}"
            );
            assert!(out.stdout.is_empty());
        }
    }
}

/// What a reader repaired or left out reaches the user: `info` lists the
/// notes (`notes` in `--json`), `render` says them on stderr. Here a
/// multiblock file whose second block lacks the first block's array.
#[test]
fn reader_notes_are_shown() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut a = warped_hex_grid(2, &Warp::default());
    let mut b = a.clone();
    for p in &mut b.points {
        p.x += 10.0;
    }
    b.point_data.clear();
    a.active_point_scalars = a.point_data.first().map(|x| x.name.clone());
    write_vtu(&d.join("a.vtu"), &a, Compression::None).unwrap();
    write_vtu(&d.join("b.vtu"), &b, Compression::None).unwrap();
    let vtm = d.join("m.vtm");
    std::fs::write(
        &vtm,
        r#"<VTKFile type="vtkMultiBlockDataSet"><vtkMultiBlockDataSet><DataSet index="0" file="a.vtu"/><DataSet index="1" file="b.vtu"/></vtkMultiBlockDataSet></VTKFile>"#,
    )
    .unwrap();
    let v = info_json(&vtm);
    assert_eq!(v["cells3d"], 16);
    let notes = v["notes"].as_array().expect("notes");
    assert!(
        notes
            .iter()
            .any(|n| n.as_str().unwrap().contains("missing from some pieces")),
        "{notes:?}"
    );
    let text = String::from_utf8(zoovr(&["info", vtm.to_str().unwrap()]).stdout).unwrap();
    assert!(text.contains("notes:"), "{text}");
    let png = d.join("m.png");
    let o = zoovr(&[
        "render",
        vtm.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--size",
        "32x32",
        "--mode",
        "raycast",
    ]);
    assert!(o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("zoovr: note:") && e.contains("m.vtm"), "{e}");
    // Files without notes: an empty list.
    assert_eq!(
        info_json(&mesh_file("tetra.vtk"))["notes"],
        serde_json::json!([])
    );
}
