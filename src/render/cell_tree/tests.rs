//! The tree's structure, and its classification against the per-cell
//! test, cell for cell.

use super::*;
use crate::generate::{scalar_f, warped_hex_grid, zoo_grid, Warp};
use crate::render::iso::IsoSet;
use crate::render::pieces::dark_range;
use crate::tf::{EmissionModel, Node as TfNode, TransferFunction};

fn tf(nodes: &[(f64, f64)]) -> TransferFunction {
    let nodes: Vec<TfNode> = nodes
        .iter()
        .map(|&(s, tau)| TfNode {
            s,
            tau,
            color: [tau.min(1.0), 0.5, 0.2],
            emission: [0.0; 3],
        })
        .collect();
    TransferFunction::from_nodes(&nodes, EmissionModel::Glow).unwrap()
}

fn meshes() -> Vec<Mesh> {
    vec![
        warped_hex_grid(12, &Warp::default()),
        zoo_grid(5, &Warp::default()),
        // One leaf only, and a level with an odd last node.
        warped_hex_grid(3, &Warp::default()),
        warped_hex_grid(7, &Warp::default()),
    ]
}

#[test]
fn every_cell_is_in_one_leaf_and_every_box_holds_its_cells() {
    for mesh in meshes() {
        let tree = CellTree::build(&mesh);
        let n = mesh.cells.len();
        let mut seen = vec![false; n];
        for &c in &tree.cells {
            assert!(!std::mem::replace(&mut seen[c as usize], true));
        }
        assert!(seen.iter().all(|&s| s));
        let root = tree.root().expect("a root");
        assert_eq!(tree.nodes[root].cells, 0..n as u32);
        assert_eq!(tree.parent[root], u32::MAX);
        for (i, node) in tree.nodes.iter().enumerate() {
            for k in node.cells.clone() {
                let c = tree.cells[k as usize] as usize;
                assert!(node.leaves.contains(&tree.leaf_of[c]));
                for &p in mesh.cells.nodes(c) {
                    let q = mesh.points[p as usize];
                    assert!(q.cmpge(node.lo).all() && q.cmple(node.hi).all());
                }
            }
            let kids: Vec<usize> = tree.children(i).collect();
            if i >= tree.levels[0].end {
                assert!(!kids.is_empty());
                let first = &tree.nodes[kids[0]];
                let last = &tree.nodes[*kids.last().unwrap()];
                assert_eq!(node.cells, first.cells.start..last.cells.end);
                for k in kids {
                    assert_eq!(tree.parent[k], i as u32);
                }
            } else {
                assert!(kids.is_empty());
                assert!(node.cells.len() <= LEAF_CELLS);
            }
        }
    }
}

/// Random transfer functions (narrow bands, jumps, dark outside), with and
/// without isovalues, over fields with NaN values: the tree's answer is
/// the per-cell test's for every cell, and a narrow band tests a small
/// part of the cells.
#[test]
fn classification_is_the_per_cell_test_cell_for_cell() {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for mesh in meshes() {
        let tree = CellTree::build(&mesh);
        for nan in [false, true] {
            let values: Vec<f64> = mesh
                .points
                .iter()
                .enumerate()
                .map(|(k, &p)| {
                    if nan && k % 97 == 5 {
                        f64::NAN
                    } else {
                        scalar_f(p, 0.0)
                    }
                })
                .collect();
            let (lo, hi) = value_range(values.iter().copied());
            let scalars = ScalarsRef::Point(&values);
            let ranges = CellRanges::build(&tree, &mesh, scalars);
            for trial in 0..12 {
                let a = lo + (hi - lo) * rnd();
                let w = (hi - lo) * [0.02, 0.1, 0.5][trial % 3];
                let nodes = match trial % 4 {
                    0 => vec![(a, 0.0), (a + w * 0.5, 3.0), (a + w, 0.0)],
                    1 => vec![(lo, 0.0), (a, 0.0), (a, 2.0), (a + w, 2.0), (a + w, 0.0)],
                    2 => vec![(a, 1.0), (a + w, 0.0)],
                    _ => vec![(lo, 0.0), (a, 0.0), (a + w, 5.0)],
                };
                let tf = tf(&nodes);
                let iso = (trial % 3 == 1).then(|| {
                    let v = lo + (hi - lo) * rnd();
                    IsoSet {
                        values: vec![v],
                        levels: vec![v],
                        ..Default::default()
                    }
                });
                for volume in [true, false] {
                    let test = |l: f64, h: f64| dark_range(&tf, iso.as_ref(), volume, l, h);
                    let (dark, stats) = tree.classify(&ranges, &test);
                    assert_eq!(dark.len(), mesh.cells.len());
                    for (c, &d) in dark.iter().enumerate() {
                        let (l, h) =
                            value_range(mesh.cells.nodes(c).iter().map(|&p| values[p as usize]));
                        assert_eq!(d, test(l, h), "cell {c} trial {trial} nan {nan}");
                    }
                    assert!(stats.cells_tested <= stats.cells);
                }
            }
        }
    }
}

/// A cell whose values are all NaN has no range: it is never dark, and
/// neither is any node above it, whatever the test says of infinite
/// ranges.
#[test]
fn a_cell_without_values_is_never_dark() {
    let mesh = warped_hex_grid(4, &Warp::default());
    let tree = CellTree::build(&mesh);
    let mut values: Vec<f64> = mesh.points.iter().map(|&p| scalar_f(p, 0.0)).collect();
    for &p in mesh.cells.nodes(7) {
        values[p as usize] = f64::NAN;
    }
    let ranges = CellRanges::build(&tree, &mesh, ScalarsRef::Point(&values));
    let mut up = tree.leaf_of[7] as usize;
    loop {
        assert_eq!(ranges.node[up], (f64::NEG_INFINITY, f64::INFINITY));
        match tree.parent[up] {
            u32::MAX => break,
            p => up = p as usize,
        }
    }
    // A test that calls every range dark, infinite ones too, still tests
    // the cell itself (NaN range: not dark by `dark_range`'s rule).
    let tf = tf(&[(0.0, 0.0), (1.0, 0.0)]);
    let test = |l: f64, h: f64| dark_range(&tf, None, true, l, h);
    let (dark, _) = tree.classify(&ranges, &test);
    assert!(!dark[7]);
    assert!(dark.iter().enumerate().all(|(c, &d)| d || c == 7));
}

/// On a smooth field over a larger grid, a transfer function covering a
/// narrow band of the range tests the cells of the leaves near the band
/// only: a small part of the cells, from a small part of the nodes.
#[test]
fn a_narrow_band_tests_few_cells() {
    let mesh = warped_hex_grid(40, &Warp::default());
    let tree = CellTree::build(&mesh);
    let values: Vec<f64> = mesh.points.iter().map(|&p| scalar_f(p, 0.0)).collect();
    let (lo, hi) = value_range(values.iter().copied());
    let ranges = CellRanges::build(&tree, &mesh, ScalarsRef::Point(&values));
    // The tests made (nodes and cells) against the cells, at most: the
    // 5 % band holds 15 % of the cells here.
    for (frac, most) in [(0.05, 0.4), (0.5, 1.0)] {
        let a = lo + (hi - lo) * 0.4;
        let tf = tf(&[
            (a, 0.0),
            (a + (hi - lo) * frac * 0.5, 3.0),
            (a + (hi - lo) * frac, 0.0),
        ]);
        let test = |l: f64, h: f64| dark_range(&tf, None, true, l, h);
        let (dark, stats) = tree.classify(&ranges, &test);
        let visible = dark.iter().filter(|&&d| !d).count();
        eprintln!("band {frac}: {visible} visible, {stats:?}");
        assert!(stats.cells_tested >= visible);
        let tests = stats.nodes_visited + stats.cells_tested;
        assert!(
            (tests as f64) <= most * stats.cells as f64,
            "{frac}: {stats:?}"
        );
    }
}
