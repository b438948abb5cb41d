//! The parallel VTK XML files: `.pvtu`, `.pvts`, `.pvtr` and `.pvti`, whose
//! pieces are serial files. A structured lattice split into pieces that
//! share a layer of points reads as the same cells, values and face
//! adjacency (after merging coincident points) as the whole lattice in one
//! file; bad pieces are refused naming the parallel file and the piece.

mod xml_util;

use xml_util::{array, check_mesh, tmp, write, POLY};
use zoovr::io::{self, ReadOptions};
use zoovr::mesh::merge::merge_coincident_points;
use zoovr::mesh::topology::Topology;
use zoovr::mesh::Mesh;

/// The lattice: 4 x 3 x 3 points (3 x 2 x 2 cells), warped.
const N: [usize; 3] = [4, 3, 3];

fn point(i: usize, j: usize, k: usize) -> [f64; 3] {
    let (x, y, z) = (i as f64, j as f64, k as f64);
    [x + 0.1 * y * z, y + 0.05 * x * x, z - 0.1 * x * y]
}

/// `<Piece>` body of extent `[i0, i1] x [0, 2] x [0, 2]`: explicit points
/// (`.vts`), coordinate arrays (`.vtr`, unwarped) or nothing (`.vti`), a
/// point scalar `f` and a cell scalar `c` (the cell's lattice id).
fn piece(kind: &str, i0: usize, i1: usize) -> String {
    let mut f = Vec::new();
    let mut pts = Vec::new();
    for k in 0..N[2] {
        for j in 0..N[1] {
            for i in i0..=i1 {
                let p = if kind == "vts" {
                    point(i, j, k)
                } else {
                    [i as f64, j as f64, k as f64]
                };
                pts.extend(p.map(|v| v.to_string()));
                f.push((p[0] + 2.0 * p[1] + 3.0 * p[2]).to_string());
            }
        }
    }
    let mut c = Vec::new();
    for k in 0..N[2] - 1 {
        for j in 0..N[1] - 1 {
            for i in i0..i1 {
                c.push((i + (N[0] - 1) * (j + (N[1] - 1) * k)).to_string());
            }
        }
    }
    let geometry = match kind {
        "vts" => format!(
            r#"<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">{}</DataArray></Points>"#,
            pts.join(" ")
        ),
        "vtr" => {
            let axis = |a: Vec<usize>| {
                let v: Vec<String> = a.iter().map(|x| x.to_string()).collect();
                format!(
                    r#"<DataArray type="Float64" format="ascii">{}</DataArray>"#,
                    v.join(" ")
                )
            };
            format!(
                "<Coordinates>{}{}{}</Coordinates>",
                axis((i0..=i1).collect()),
                axis((0..N[1]).collect()),
                axis((0..N[2]).collect())
            )
        }
        _ => String::new(),
    };
    format!(
        r#"<Piece Extent="{i0} {i1} 0 2 0 2"><PointData Scalars="f"><DataArray type="Float64" Name="f" format="ascii">{}</DataArray></PointData><CellData><DataArray type="Int32" Name="c" format="ascii">{}</DataArray></CellData>{geometry}</Piece>"#,
        f.join(" "),
        c.join(" ")
    )
}

/// A serial file of `kind` holding `pieces` (`(i0, i1)` extents).
fn serial(kind: &str, pieces: &[(usize, usize)]) -> String {
    let grid = grid_name(kind);
    let attrs = if kind == "vti" {
        r#" Origin="0 0 0" Spacing="1 1 1""#
    } else {
        ""
    };
    let body: String = pieces.iter().map(|&(a, b)| piece(kind, a, b)).collect();
    format!(
        r#"<VTKFile type="{grid}"><{grid} WholeExtent="0 3 0 2 0 2"{attrs}>{body}</{grid}></VTKFile>"#
    )
}

fn grid_name(kind: &str) -> &'static str {
    match kind {
        "vts" => "StructuredGrid",
        "vtr" => "RectilinearGrid",
        _ => "ImageData",
    }
}

/// Each cell as its corner positions (in VTK order) and its `c` value,
/// sorted: equal for two meshes of the same cells however they number
/// points and cells.
fn cells_of(m: &Mesh) -> Vec<(Vec<[u64; 3]>, i64)> {
    let c = array(m, "c");
    let mut v: Vec<_> = (0..m.cells.len())
        .map(|i| {
            let corners = m
                .cells
                .nodes(i)
                .iter()
                .map(|&p| m.points[p as usize].to_array().map(f64::to_bits))
                .collect();
            (corners, c.data.get(i) as i64)
        })
        .collect();
    v.sort();
    v
}

/// The cells read from a copy of `file` named `.xml`: the format found by
/// content.
fn cells_read_by_content(file: &std::path::Path) -> usize {
    let copy = file.with_extension("copy.xml");
    std::fs::copy(file, &copy).unwrap();
    io::read(&copy, &ReadOptions::default())
        .unwrap()
        .cells
        .len()
}

/// Interior faces after merging coincident points.
fn interior_faces(m: &Mesh) -> usize {
    let mut m = m.clone();
    merge_coincident_points(&mut m);
    let t = Topology::build(&m.cells);
    (0..t.face_count()).filter(|&f| !t.is_boundary(f)).count()
}

#[test]
fn structured_pieces_read_as_the_whole_lattice() {
    let d = tmp();
    for kind in ["vts", "vtr", "vti"] {
        let whole = write(d.path(), &format!("whole.{kind}"), &serial(kind, &[(0, 3)]));
        let whole = io::read(&whole, &ReadOptions::default()).unwrap();
        // Two pieces sharing the points of the layer i = 1, one in a
        // subfolder (as ParaView writes them).
        std::fs::create_dir_all(d.path().join("parts")).unwrap();
        write(d.path(), &format!("a.{kind}"), &serial(kind, &[(0, 1)]));
        write(
            d.path(),
            &format!("parts/b.{kind}"),
            &serial(kind, &[(1, 3)]),
        );
        let grid = grid_name(kind);
        let ext = format!("pvt{}", &kind[2..]);
        let spacing = if kind == "vti" {
            r#" Origin="0 0 0" Spacing="1 1 1""#
        } else {
            ""
        };
        let p = write(
            d.path(),
            &format!("split.{ext}"),
            &format!(
                r#"<VTKFile type="P{grid}"><P{grid} WholeExtent="0 3 0 2 0 2" GhostLevel="0"{spacing}><PPointData Scalars="f"><PDataArray type="Float64" Name="f"/></PPointData><Piece Extent="0 1 0 2 0 2" Source="a.{kind}"/><Piece Extent="1 3 0 2 0 2" Source="parts/b.{kind}"/></P{grid}></VTKFile>"#
            ),
        );
        let split = io::read(&p, &ReadOptions::default()).unwrap_or_else(|e| panic!("{ext}: {e}"));
        check_mesh(&split);
        assert_eq!(split.cells.len(), 12, "{ext}");
        assert_eq!(split.points.len(), 2 * 9 + 3 * 9, "{ext}");
        assert_eq!(cells_of(&split), cells_of(&whole), "{ext}");
        assert_eq!(split.active_point_scalars.as_deref(), Some("f"), "{ext}");
        // The point values agree at every corner.
        let (fs, fw) = (array(&split, "f"), array(&whole, "f"));
        for (a, b) in [(&split, fs), (&whole, fw)] {
            for i in 0..a.cells.len() {
                for &q in a.cells.nodes(i) {
                    let p = a.points[q as usize];
                    assert_eq!(b.data.get(q as usize), p.x + 2.0 * p.y + 3.0 * p.z, "{ext}");
                }
            }
        }
        assert_eq!(interior_faces(&split), interior_faces(&whole), "{ext}");
        // Faces between cells: x-normal 2 * 2 * 2, y-normal 3 * 2, z-normal 3 * 2.
        assert_eq!(interior_faces(&whole), 8 + 6 + 6);
        assert_eq!(cells_read_by_content(&p), 12, "{ext}");
    }
}

#[test]
fn bad_structured_pieces_name_the_file_and_the_piece() {
    let d = tmp();
    write(d.path(), "a.vts", &serial("vts", &[(0, 1)]));
    let p = write(
        d.path(),
        "s.pvts",
        r#"<VTKFile type="PStructuredGrid"><PStructuredGrid WholeExtent="0 3 0 2 0 2"><Piece Extent="0 1 0 2 0 2" Source="a.vts"/><Piece Extent="1 3 0 2 0 2" Source="gone.vts"/></PStructuredGrid></VTKFile>"#,
    );
    let e = io::read(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.pvts") && e.contains("piece 1") && e.contains("gone.vts"),
        "{e}"
    );
    // A piece that is itself a parallel file.
    let q = write(
        d.path(),
        "t.pvts",
        r#"<VTKFile type="PStructuredGrid"><PStructuredGrid WholeExtent="0 3 0 2 0 2"><Piece Extent="0 3 0 2 0 2" Source="s.pvts"/></PStructuredGrid></VTKFile>"#,
    );
    let e = io::read(&q, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.pvts") && e.contains("parallel"), "{e}");
}

/// A `.pvtu` step's time is its pieces' `TimeValue`; pieces that disagree
/// leave it unset with a note.
#[test]
fn pvtu_time_value_from_its_pieces() {
    let d = tmp();
    let timed = |t: f64| {
        POLY.replace(
            "<UnstructuredGrid><Piece",
            &format!(
                "<UnstructuredGrid><FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" \
                 NumberOfTuples=\"1\" format=\"ascii\">{t}</DataArray></FieldData><Piece"
            ),
        )
    };
    write(d.path(), "a.vtu", &timed(1.5));
    write(d.path(), "b.vtu", &timed(1.5));
    write(d.path(), "c.vtu", &timed(2.0));
    let pvtu = |name: &str, pieces: &[&str]| {
        let body: String = pieces
            .iter()
            .map(|p| format!("<Piece Source=\"{p}\"/>"))
            .collect();
        write(
            d.path(),
            name,
            &format!(
                "<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid>{body}</PUnstructuredGrid></VTKFile>"
            ),
        )
    };
    let same = io::read(
        &pvtu("s.pvtu", &["a.vtu", "b.vtu"]),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(same.source.time_value, Some(1.5));
    let differ = io::read(
        &pvtu("d.pvtu", &["a.vtu", "c.vtu"]),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(differ.source.time_value, None);
    assert!(
        differ.source.notes.iter().any(|n| n.contains("TimeValue")),
        "{:?}",
        differ.source.notes
    );
    let single = io::read(&d.path().join("c.vtu"), &ReadOptions::default()).unwrap();
    assert_eq!(single.source.time_value, Some(2.0));
}

#[test]
fn pvtu_missing_and_self_pieces() {
    let d = tmp();
    let p = write(
        d.path(),
        "p.pvtu",
        r#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid><Piece Source="p.pvtu"/></PUnstructuredGrid></VTKFile>"#,
    );
    let e = io::read(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("p.pvtu") && e.contains("itself"), "{e}");
    let q = write(
        d.path(),
        "q.pvtu",
        r#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid><Piece Source="a.vtu"/><Piece Source="gone.vtu"/></PUnstructuredGrid></VTKFile>"#,
    );
    write(d.path(), "a.vtu", POLY);
    let e = io::read(&q, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("q.pvtu") && e.contains("piece 1") && e.contains("gone.vtu"),
        "{e}"
    );
    // A piece that is itself a .pvtu pointing back.
    let r = write(
        d.path(),
        "r.pvtu",
        r#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid><Piece Source="p.pvtu"/></PUnstructuredGrid></VTKFile>"#,
    );
    assert!(io::read(&r, &ReadOptions::default()).is_err());
}

/// A `.vtm` tree: an unstructured block, a nested structured block split
/// into a parallel file, an empty leaf, a polygonal patch and a surface
/// block: the blocks with 3D cells are merged, the others named in a note.
#[test]
fn multiblock_merges_its_volume_blocks() {
    let d = tmp();
    std::fs::create_dir_all(d.path().join("case/zone2")).unwrap();
    write(d.path(), "case/poly.vtu", POLY);
    write(d.path(), "case/zone2/a.vts", &serial("vts", &[(0, 1)]));
    write(d.path(), "case/zone2/b.vts", &serial("vts", &[(1, 3)]));
    write(
        d.path(),
        "case/zone2.pvts",
        r#"<VTKFile type="PStructuredGrid"><PStructuredGrid WholeExtent="0 3 0 2 0 2"><Piece Extent="0 1 0 2 0 2" Source="zone2/a.vts"/><Piece Extent="1 3 0 2 0 2" Source="zone2/b.vts"/></PStructuredGrid></VTKFile>"#,
    );
    write(d.path(), "case/inlet.vtp", "<VTKFile type=\"PolyData\"/>");
    // Only a triangle: no 3D cells.
    write(
        d.path(),
        "case/wall.vtu",
        r#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="3" NumberOfCells="1">
        <Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0</DataArray></Points>
        <Cells><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">3</DataArray><DataArray type="UInt8" Name="types" format="ascii">5</DataArray></Cells>
        </Piece></UnstructuredGrid></VTKFile>"#,
    );
    let vtm = write(
        d.path(),
        "case.vtm",
        r#"<?xml version="1.0"?>
<VTKFile type="vtkMultiBlockDataSet" version="1.0" byte_order="LittleEndian">
  <vtkMultiBlockDataSet>
    <Block index="0" name="internal">
      <DataSet index="0" name="poly" file="case/poly.vtu"/>
      <Block index="1" name="zones"><Piece index="0"><DataSet index="0" file="case/zone2.pvts"/></Piece></Block>
      <DataSet index="2" name="nothing"/>
    </Block>
    <Block index="1" name="boundary">
      <DataSet index="0" name="inlet" file="case/inlet.vtp"/>
      <DataSet index="1" name="wall" file="case/wall.vtu"/>
    </Block>
  </vtkMultiBlockDataSet>
</VTKFile>"#,
    );
    let m = io::read(&vtm, &ReadOptions::default()).unwrap();
    check_mesh(&m);
    assert_eq!(m.cells.len(), 2 + 12);
    let notes = m.source.notes.join(" | ");
    assert!(
        notes.contains("boundary/inlet") && notes.contains("polygonal"),
        "{notes}"
    );
    assert!(
        notes.contains("boundary/wall") && notes.contains("no 3D cells"),
        "{notes}"
    );
    assert_eq!(cells_read_by_content(&vtm), 14);
}

#[test]
fn bad_multiblocks_name_the_file_and_the_block() {
    let d = tmp();
    write(d.path(), "poly.vtu", POLY);
    let vtm = |name: &str, leaves: &str| {
        write(
            d.path(),
            name,
            &format!(
                r#"<VTKFile type="vtkMultiBlockDataSet"><vtkMultiBlockDataSet>{leaves}</vtkMultiBlockDataSet></VTKFile>"#
            ),
        )
    };
    let read = |p: &std::path::Path| {
        io::read(p, &ReadOptions::default())
            .unwrap_err()
            .to_string()
    };
    let e = read(&vtm(
        "a.vtm",
        r#"<DataSet index="0" name="ok" file="poly.vtu"/><Block name="zones"><DataSet index="0" name="gone" file="gone.vtu"/></Block>"#,
    ));
    assert!(
        e.contains("a.vtm") && e.contains("zones/gone") && e.contains("gone.vtu"),
        "{e}"
    );
    let e = read(&vtm("b.vtm", r#"<DataSet index="0" file="b.vtm"/>"#));
    assert!(e.contains("b.vtm") && e.contains("itself"), "{e}");
    let e = read(&vtm("c.vtm", r#"<DataSet index="0" file="a.vtm"/>"#));
    assert!(e.contains("c.vtm") && e.contains("multiblock"), "{e}");
    let e = read(&vtm(
        "e.vtm",
        r#"<Block name="x"><DataSet index="0"/></Block>"#,
    ));
    assert!(e.contains("e.vtm") && e.contains("no block files"), "{e}");
    write(d.path(), "s.vtp", "<VTKFile type=\"PolyData\"/>");
    let e = read(&vtm(
        "f.vtm",
        r#"<DataSet index="0" name="skin" file="s.vtp"/>"#,
    ));
    assert!(
        e.contains("f.vtm") && e.contains("no block holds 3D cells"),
        "{e}"
    );
}
