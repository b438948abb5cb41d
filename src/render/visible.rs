//! Dark cells left out of the sort: the visible subset of a geometry.
//!
//! A transfer function that maps most of the field to zero extinction (and
//! zero emission, with no isosurface in range) leaves most cells *dark*:
//! nothing of them is drawn ([`super::pieces::dark_range`]). The driver
//! skips their pieces, but sorting them still costs what sorting a visible
//! cell does. When at least [`DARK_SUBSET_MIN`] of the cells are dark, the
//! renderer sorts and draws the **visible subset** instead: a mesh of the
//! other cells only, over *every* point of the geometry (point ids, point
//! scalars and the points' gradients stay as they are; only cell ids
//! change, and [`VisibleSubset::cells`] maps them back), with its own
//! topology, sorter and order cache. It is built once per (geometry,
//! field, darkness) and kept while those hold: a turntable or a change of
//! colours or of the extinction's scale reuses it.
//!
//! **Why the image is the same.** The subset's order is an exact
//! visibility order of its pieces at the pixel centres (the sorter takes
//! any mesh: the subset's boundary, convex or not, gets the pixel-ray
//! constraints of non-convex meshes). Along every pixel-centre ray the
//! kept pieces therefore come back to front, and the dark pieces left out
//! between them would have composited as the identity (zero extinction,
//! zero emission). The pieces themselves are the same: a face between a
//! kept and a dark cell is a boundary face of the subset, and the subset's
//! sorter is told it was interior ([`Sorter::for_subset`]), so a problem
//! face there splits the kept cell as in the whole mesh; the tie decisions
//! use the whole mesh's bounding sphere, as the reference does. Only a
//! visibility cycle through dark cells differs: the whole mesh's sort
//! splits some of its kept cells into tets to break it, the subset's has
//! no cycle there and draws them whole (the `faces` field rather than the
//! `tets` field in those cells, a model difference, not an error).
//!
//! What it saves: the sort of the dark cells (face classification,
//! splits, the topological sort) and, where the renderer has not made the
//! whole mesh's sorter yet, building it (per geometry). Building the
//! subset costs its topology and its sorter's planes, for the kept cells
//! only, and finding the dark cells: a walk of the geometry's min/max tree
//! ([`super::cell_tree`], built once per geometry, its ranges once per
//! field), which tests the cells of the leaves near the visible part of
//! the range only, so a transfer function covering a narrow band costs
//! about what that band holds. The tree is kept here for the occlusion
//! pass too ([`VisibleCache::tree`]).

use std::sync::Arc;
use std::time::Instant;

use crate::field::{Association, ScalarField};
use crate::mesh::subset::cells_subset;
use crate::mesh::topology::Topology;
use crate::mesh::Mesh;
use crate::visibility::{Order, Piece, Sorter};

use super::cell_tree::{CellRanges, CellTree, ClassifyStats};
use super::iso::IsoSet;
use super::order_cache::OrderCache;
use super::pieces::{dark_key, dark_range};
use super::scene::Scene;

/// The smallest fraction of dark cells for which the renderer sorts the
/// visible subset: below it, building the subset's topology and sorter
/// (per kept cell, about what sorting a cell costs on the generated
/// 1M-hex grid) would cost more than the sort of the dark cells saves.
pub const DARK_SUBSET_MIN: f64 = 0.5;

/// The kept cells of a geometry with what sorts them.
pub struct VisibleSubset {
    /// Every point of the geometry, the kept cells.
    pub mesh: Arc<Mesh>,
    pub topology: Arc<Topology>,
    /// The geometry's id of each kept cell.
    pub cells: Vec<u32>,
    /// The kept cells' values of a cell field.
    cell_field: Option<Arc<ScalarField>>,
    pub sorter: Sorter,
    pub orders: OrderCache,
}

impl VisibleSubset {
    /// The frame's scene on the subset: `scene`'s shading (its transfer
    /// function, range and unit, which may change while the subset
    /// holds), the field's values for the kept cells.
    pub fn scene_of(&self, scene: &Scene) -> Scene {
        let field = match &scene.field {
            Some(f) if f.association == Association::Cell => self.cell_field.clone(),
            other => other.clone(),
        };
        Scene {
            mesh: self.mesh.clone(),
            topology: self.topology.clone(),
            field,
            range: scene.range,
            tf: scene.tf.clone(),
            unit_distance: scene.unit_distance,
            merged_points: scene.merged_points,
            ghost_cells: scene.ghost_cells,
        }
    }

    /// `order` (one of the subset's) with the geometry's cell ids.
    pub fn whole_order(&self, order: &Order) -> Order {
        let map = |c: u32| self.cells.get(c as usize).copied().unwrap_or(c);
        let mut out = order.clone();
        for p in &mut out.pieces {
            match p {
                Piece::Cell(c) => *c = map(*c),
                Piece::Tet { cell, .. } | Piece::Slab { cell, .. } | Piece::Frag { cell, .. } => {
                    *cell = map(*cell)
                }
            }
        }
        out
    }
}

/// What the subset was built for: the geometry and the field (held, so
/// that their allocations cannot be reused by others while the key is
/// compared by address) and the darkness of the transfer function.
struct Key {
    mesh: Arc<Mesh>,
    field: Option<Arc<ScalarField>>,
    dark: u64,
}

impl Key {
    fn matches(&self, scene: &Scene, dark: u64) -> bool {
        let field = match (&self.field, &scene.field) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        Arc::ptr_eq(&self.mesh, &scene.mesh) && field && self.dark == dark
    }
}

/// The renderer's visible subset, rebuilt when its key changes.
#[derive(Default)]
pub struct VisibleCache {
    key: Option<Key>,
    /// `None` when fewer than [`DARK_SUBSET_MIN`] of the cells are dark.
    subset: Option<VisibleSubset>,
    /// Dark cells of the last key.
    dark_cells: usize,
    /// The geometry's min/max tree, and the ranges of the field they were
    /// built for (the field held, compared by address).
    tree: Option<(Arc<Mesh>, Arc<CellTree>)>,
    ranges: Option<(Option<Arc<ScalarField>>, Arc<CellRanges>)>,
}

impl VisibleCache {
    /// The subset of the last key, if it has one.
    pub fn current(&self) -> Option<&VisibleSubset> {
        self.subset.as_ref()
    }

    /// Forgets the subset and the tree (a new geometry).
    pub fn clear(&mut self) {
        *self = VisibleCache::default();
    }

    /// The min/max tree over `mesh`'s cells ([`super::cell_tree`]), built
    /// on first use and kept while the geometry is the same, with the
    /// seconds spent building it (0 when kept).
    pub fn tree(&mut self, mesh: &Arc<Mesh>) -> (Arc<CellTree>, f64) {
        let t0 = Instant::now();
        if let Some((m, t)) = &self.tree {
            if Arc::ptr_eq(m, mesh) {
                return (t.clone(), 0.0);
            }
        }
        let tree = Arc::new(CellTree::build(mesh));
        self.tree = Some((mesh.clone(), tree.clone()));
        self.ranges = None;
        (tree, t0.elapsed().as_secs_f64())
    }

    /// The tree's ranges of `scene`'s field, built once per field.
    fn ranges(&mut self, scene: &Scene, tree: &CellTree) -> Arc<CellRanges> {
        if let Some((f, r)) = &self.ranges {
            let same = match (f, &scene.field) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            };
            if same {
                return r.clone();
            }
        }
        let r = Arc::new(CellRanges::build(tree, &scene.mesh, scene.scalars()));
        self.ranges = Some((scene.field.clone(), r.clone()));
        r
    }

    /// The visible subset of `scene` for a mode drawing surfaces `iso` and
    /// the volume when `volume`, built if its key changed (see the module
    /// docs), with the number of dark cells it leaves out, the seconds
    /// spent building it (0 when reused) and what finding the dark cells
    /// looked at (zeros when reused); `None` when too few are dark.
    pub fn prepare(
        &mut self,
        scene: &Scene,
        iso: Option<&IsoSet>,
        volume: bool,
    ) -> (Option<&mut VisibleSubset>, usize, f64, ClassifyStats) {
        let t0 = Instant::now();
        let dark = dark_key(&scene.tf, iso, volume);
        let mut classified = ClassifyStats::default();
        if !self.key.as_ref().is_some_and(|k| k.matches(scene, dark)) {
            let (tree, _) = self.tree(&scene.mesh);
            let ranges = self.ranges(scene, &tree);
            let test = |lo: f64, hi: f64| dark_range(&scene.tf, iso, volume, lo, hi);
            let (dark_flags, stats) = tree.classify(&ranges, &test);
            classified = stats;
            let (subset, dark_cells) = build(scene, &dark_flags);
            self.key = Some(Key {
                mesh: scene.mesh.clone(),
                field: scene.field.clone(),
                dark,
            });
            self.subset = subset;
            self.dark_cells = dark_cells;
        }
        let built = t0.elapsed().as_secs_f64();
        let dark_cells = self.dark_cells;
        match self.subset.as_mut() {
            Some(s) => (Some(s), dark_cells, built, classified),
            None => (None, 0, built, classified),
        }
    }
}

/// The subset of `scene`'s cells not flagged in `dark` (by cell id), when
/// at least [`DARK_SUBSET_MIN`] of them are dark, and the number of dark
/// cells.
fn build(scene: &Scene, dark: &[bool]) -> (Option<VisibleSubset>, usize) {
    let mesh = &scene.mesh;
    let cells = &mesh.cells;
    let n = cells.len();
    let count = dark.iter().filter(|&&d| d).count();
    if n == 0 || (count as f64) < DARK_SUBSET_MIN * n as f64 {
        return (None, count);
    }
    let (sub_cells, old_id) = cells_subset(cells, |c| !dark[c]);
    let topology = Topology::build(&sub_cells);
    // The subset's boundary faces that were interior in the geometry.
    let whole = &scene.topology;
    let mut cut = vec![false; topology.face_count()];
    for (k, &c) in old_id.iter().enumerate() {
        let Some(old_faces) = whole.faces_of_checked(c as usize) else {
            continue;
        };
        for (&f, &g) in topology.faces_of(k).iter().zip(old_faces) {
            if topology.is_boundary(f as usize) && !whole.is_boundary(g as usize) {
                cut[f as usize] = true;
            }
        }
    }
    let cell_field = match &scene.field {
        Some(f) if f.association == Association::Cell => Some(Arc::new(ScalarField {
            name: f.name.clone(),
            association: Association::Cell,
            values: old_id
                .iter()
                .map(|&c| f.values.get(c as usize).copied().unwrap_or(f64::NAN))
                .collect(),
            // The whole field's: the subset's values are some of its
            // values, so a span holding all of them holds the subset's.
            range: f.range,
            all_finite: f.all_finite && old_id.iter().all(|&c| (c as usize) < f.values.len()),
        })),
        _ => None,
    };
    let sub_mesh = Arc::new(Mesh {
        points: mesh.points.clone(),
        cells: sub_cells,
        point_data: Vec::new(),
        cell_data: Vec::new(),
        active_point_scalars: None,
        active_cell_scalars: None,
        source: mesh.source.clone(),
    });
    let topology = Arc::new(topology);
    let sorter = Sorter::for_subset(sub_mesh.clone(), topology.clone(), &cut);
    (
        Some(VisibleSubset {
            mesh: sub_mesh,
            topology,
            cells: old_id,
            cell_field,
            sorter,
            orders: OrderCache::default(),
        }),
        count,
    )
}
