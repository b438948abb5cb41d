//! Cells a `vtkGhostType` cell array flags hidden (32) or duplicate (1) are
//! left out of every render, as ParaView does: the render of
//! `generate::ghost_grid` equals the render of the same grid with those
//! cells removed by hand here (ray caster and, with an adapter, the exact
//! mode), and differs from `show_hidden`. Also: the default range is over
//! the cells and points drawn, the ghost array survives the writers and
//! readers, and malformed ghost arrays are errors that name the array.

mod render_util;
use render_util::gpu_available;

use zoovr::camera::CameraParams;
use zoovr::field::{ArrayData, Association, DataArray};
use zoovr::generate::{ghost_grid, ghost_grid_flags, Warp, GHOST_GRID_HIDDEN_VALUE};
use zoovr::image::Image;
use zoovr::io::writer::{write_legacy_ascii, write_vtu, Compression};
use zoovr::io::{self, ReadOptions};
use zoovr::mesh::ghost::{GhostCounts, GhostError};
use zoovr::mesh::{Cells, Mesh};
use zoovr::raycast::FieldModel;
use zoovr::render::{
    Mode, ReferenceOptions, RenderError, RenderOptions, Renderer, Scene, SceneSpec,
};

const N: usize = 4;

/// Whether cell `c` of the `N`-grid is drawn (flag computed from its grid
/// position, not read from the array).
fn drawn(c: usize) -> bool {
    let (i, j, k) = (c % N, (c / N) % N, c / (N * N));
    ghost_grid_flags(N, i, j, k) & (1 | 32) == 0
}

/// The ghost grid with its hidden and duplicate cells removed by hand: the
/// other cells pushed one by one, the cell arrays' tuples picked alongside;
/// every point kept.
fn removed_by_hand(full: &Mesh) -> Mesh {
    let mut cells = Cells::default();
    let mut keep = Vec::new();
    for c in 0..full.cells.len() {
        if drawn(c) {
            cells.push(full.cells.kinds[c], full.cells.nodes(c));
            keep.push(c);
        }
    }
    let cell_data = full
        .cell_data
        .iter()
        .map(|a| {
            let data = match &a.data {
                ArrayData::Int(v) => ArrayData::Int(keep.iter().map(|&c| v[c]).collect()),
                ArrayData::F32(v) => ArrayData::F32(keep.iter().map(|&c| v[c]).collect()),
                ArrayData::F64(v) => ArrayData::F64(keep.iter().map(|&c| v[c]).collect()),
            };
            DataArray { data, ..a.clone() }
        })
        .collect();
    Mesh {
        cells,
        cell_data,
        ..full.clone()
    }
}

fn render(scene: &Scene, mode: Mode) -> Image {
    let opts = RenderOptions {
        camera: CameraParams {
            width: 64,
            height: 64,
            azimuth: 30.0,
            elevation: 25.0,
            ..Default::default()
        },
        mode,
        reference: ReferenceOptions {
            model: FieldModel::Faces,
            ..Default::default()
        },
        ..Default::default()
    };
    let (img, _) = Renderer::new(scene.geometry())
        .render(&scene.shading(), &opts, |_, _| {})
        .unwrap();
    assert_eq!(img.count_non_finite(), 0);
    img
}

fn max_diff(a: &Image, b: &Image) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f32::max)
}

fn scenes() -> (Scene, Scene, Scene) {
    let full = ghost_grid(N, &Warp::default());
    let hand = removed_by_hand(&full);
    let shown = SceneSpec {
        show_hidden: true,
        ..Default::default()
    };
    (
        Scene::build(full.clone(), &SceneSpec::default()).unwrap(),
        Scene::build(hand, &SceneSpec::default()).unwrap(),
        Scene::build(full, &shown).unwrap(),
    )
}

#[test]
fn scene_leaves_out_flagged_cells_and_their_range() {
    let (ghost, hand, shown) = scenes();
    let left_out = (0..N * N * N).filter(|&c| !drawn(c)).count();
    assert!(left_out > 0);
    assert_eq!(ghost.ghost_cells, left_out);
    assert_eq!(ghost.mesh.cells.len(), N * N * N - left_out);
    assert_eq!(shown.ghost_cells, 0);
    assert_eq!(shown.mesh.cells.len(), N * N * N);
    // the default field is the float cell array, aligned with the cells left
    let f = ghost.field.as_ref().unwrap();
    assert_eq!(
        (f.name.as_str(), f.association),
        ("value", Association::Cell)
    );
    assert_eq!(f.values, hand.field.as_ref().unwrap().values);
    assert_eq!(ghost.topology.face_count(), hand.topology.face_count());
    // range over the cells drawn: neither the hidden marker nor the
    // duplicates' 2 take part
    assert_eq!(ghost.range, hand.range);
    assert!(
        ghost.range.0 >= 0.0 && ghost.range.1 <= 1.0,
        "{:?}",
        ghost.range
    );
    assert_eq!(
        shown.range,
        (GHOST_GRID_HIDDEN_VALUE as f64, 2.0),
        "--show-hidden takes every cell"
    );
}

#[test]
fn point_field_range_is_over_the_points_drawn() {
    let mut full = ghost_grid(N, &Warp::default());
    // a point field whose maximum sits on a point that only hidden cells use
    let mut used_by_drawn = vec![false; full.points.len()];
    for c in (0..full.cells.len()).filter(|&c| drawn(c)) {
        for &p in full.cells.nodes(c) {
            used_by_drawn[p as usize] = true;
        }
    }
    let only_hidden = used_by_drawn
        .iter()
        .position(|u| !u)
        .expect("a point of hidden cells only");
    let mut v: Vec<f64> = (0..full.points.len()).map(|p| p as f64 / 100.0).collect();
    v[only_hidden] = 50.0;
    let drawn_values = || (0..v.len()).filter(|&p| used_by_drawn[p]).map(|p| v[p]);
    let want = (
        drawn_values().fold(f64::INFINITY, f64::min),
        drawn_values().fold(f64::NEG_INFINITY, f64::max),
    );
    assert!(want.1 < 50.0 && want.0 > 0.0, "{want:?}");
    full.point_data.push(DataArray {
        name: "p".into(),
        components: 1,
        data: ArrayData::F64(v.clone()),
        vtk_type: "Float64".into(),
    });
    let scene = Scene::build(full.clone(), &SceneSpec::default()).unwrap();
    assert_eq!(scene.field.as_ref().unwrap().name, "p");
    assert_eq!(scene.range, want);
    assert_eq!(
        scene.mesh.points.len(),
        used_by_drawn.iter().filter(|&&u| u).count()
    );
    let shown = SceneSpec {
        show_hidden: true,
        ..Default::default()
    };
    let all = (v.iter().copied().fold(f64::INFINITY, f64::min), 50.0);
    assert_eq!(Scene::build(full, &shown).unwrap().range, all);
}

#[test]
fn raycast_equals_the_mesh_without_those_cells() {
    let (ghost, hand, shown) = scenes();
    let a = render(&ghost, Mode::Raycast);
    let b = render(&hand, Mode::Raycast);
    let c = render(&shown, Mode::Raycast);
    assert!(a.pixels.iter().any(|p| p[3] > 0.05), "nothing drawn");
    assert_eq!(max_diff(&a, &b), 0.0, "raycast: ghost vs removed by hand");
    let d = max_diff(&a, &c);
    assert!(
        d > 0.05,
        "raycast: --show-hidden should differ, max diff {d}"
    );
}

#[test]
fn exact_mode_equals_the_mesh_without_those_cells() {
    if !gpu_available() {
        return;
    }
    let (ghost, hand, shown) = scenes();
    let a = render(&ghost, Mode::Exact);
    let b = render(&hand, Mode::Exact);
    let c = render(&shown, Mode::Exact);
    assert!(a.pixels.iter().any(|p| p[3] > 0.05), "nothing drawn");
    assert_eq!(max_diff(&a, &b), 0.0, "exact: ghost vs removed by hand");
    let d = max_diff(&a, &c);
    assert!(d > 0.05, "exact: --show-hidden should differ, max diff {d}");
}

#[test]
fn ghost_array_round_trips_through_the_writers() {
    let mesh = ghost_grid(N, &Warp::default());
    let want = GhostCounts::of(&mesh).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for name in ["g.vtu", "g.vtk"] {
        let path = dir.path().join(name);
        if name.ends_with(".vtu") {
            write_vtu(&path, &mesh, Compression::Zlib).unwrap();
        } else {
            write_legacy_ascii(&path, &mesh, "ghost grid").unwrap();
        }
        let back = io::read(&path, &ReadOptions::default()).unwrap();
        back.sanity_check().unwrap();
        let a = back
            .cell_data
            .iter()
            .find(|a| a.name == "vtkGhostType")
            .unwrap_or_else(|| panic!("{name}: no vtkGhostType"));
        assert_eq!(a.vtk_type, "UInt8", "{name}");
        assert_eq!(a.data, mesh.cell_data[0].data, "{name}");
        assert_eq!(GhostCounts::of(&back).unwrap(), want, "{name}");
    }
}

#[test]
fn malformed_ghost_arrays_are_errors_naming_the_array() {
    let mut short = ghost_grid(N, &Warp::default());
    short.cell_data[0].data = ArrayData::Int(vec![0; 10]);
    match Scene::build(short, &SceneSpec::default()) {
        Err(e @ RenderError::Ghost(GhostError::WrongLength { got: 10, want: 64 })) => {
            let msg = e.to_string();
            assert!(msg.contains("vtkGhostType"), "{msg}");
        }
        other => panic!("{other:?}"),
    }
    let mut bad = ghost_grid(N, &Warp::default());
    bad.cell_data[0].data = ArrayData::F32(vec![0.5; 64]);
    assert!(matches!(
        Scene::build(bad.clone(), &SceneSpec::default()),
        Err(RenderError::Ghost(GhostError::BadValue { cell: 0, .. }))
    ));
    // --show-hidden does not read the flags at all
    let shown = SceneSpec {
        show_hidden: true,
        ..Default::default()
    };
    assert!(Scene::build(bad, &shown).is_ok());
    let mut all = ghost_grid(N, &Warp::default());
    all.cell_data[0].data = ArrayData::Int(vec![32; 64]);
    let e = Scene::build(all, &SceneSpec::default()).unwrap_err();
    assert!(matches!(e, RenderError::AllCellsHidden(64)), "{e:?}");
    assert!(e.to_string().contains("--show-hidden"), "{e}");
}
