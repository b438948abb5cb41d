//! Region geometry kept across frames whose values change and nothing else
//! ([`super::super::ProjectedOptions::keep_regions`]): the steps of a time
//! series with the same points and cells, under a fixed camera.
//!
//! A part's regions (steps 2-6 of the [`crate::projection::Projector`]:
//! pixel positions, facing, the winged-edge regions and their front and
//! back triangles, the fan triangles) depend on its points only; the
//! scalars enter through each region vertex's values, which
//! [`KeptRegions`] evaluates again from the new scalars, bit for bit as a
//! fresh projection would. The store keeps them per part that is a whole
//! cell or one of its consistent tets (slabs and cycle fragments follow the
//! values or are rare: they are projected afresh), keyed by the
//! geometry's cell id (so a visible subset that changes from step to step
//! keeps its cells' regions), and each lookup checks the part's points and
//! triangles against the kept ones ([`KeptRegions::holds`]): a key that
//! names another piece only costs a fresh projection.
//!
//! Everything after step 6 runs as always: the window clip, the
//! perspective refinement and the culling, the mode's payload (the exact
//! mode's vertex integrals and refinement), the tie, steep and thin
//! decisions, which all follow the values; dark and hidden pieces are
//! decided per frame too. The image is the one a fresh render gives
//! (`tests/keep_regions.rs`).
//!
//! The store is emptied when the camera, the culling or the geometry's
//! points change ([`super::super::Renderer::set_geometry`]), and holds at
//! most [`KEEP_REGIONS_MAX_BYTES`] (less where a quarter of the available
//! memory is less): parts met once it is full are projected every frame.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use crate::camera::Camera;
use crate::projection::{KeptRegions, Polyhedron};
use crate::visibility::Piece;

/// The most the kept regions may hold, bytes (1.5 to 2 KB per hex: 2^30
/// bytes keep about 600,000 hexes), and at most a quarter of the memory
/// available when the store is set up ([`budget`]).
pub const KEEP_REGIONS_MAX_BYTES: usize = 1 << 30;

/// The kept regions' budget: [`KEEP_REGIONS_MAX_BYTES`], or a quarter of
/// the memory the system says is available (Linux `MemAvailable`) where
/// that is less, so that keeping regions never pushes a machine into
/// swapping or out of memory.
fn budget() -> usize {
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemAvailable:"))?;
        let kib: usize = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib.saturating_mul(1024))
    });
    available.map_or(KEEP_REGIONS_MAX_BYTES, |a| {
        (a / 4).min(KEEP_REGIONS_MAX_BYTES)
    })
}

/// Which part of a cell a kept projection is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PartKey {
    Cell,
    /// One consistent tet (its global point ids).
    Tet([u32; 4]),
}

impl PartKey {
    /// The cell (in the drawn mesh) and part key of `piece`, for the
    /// pieces whose projection can be kept.
    pub(super) fn of(piece: &Piece) -> Option<(u32, PartKey)> {
        match *piece {
            Piece::Cell(c) => Some((c, PartKey::Cell)),
            Piece::Tet { cell, tet } => Some((cell, PartKey::Tet(tet))),
            Piece::Slab { .. } | Piece::Frag { .. } => None,
        }
    }
}

/// What the kept regions were made for besides the parts' own geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
struct StoreKey {
    camera: Camera,
    cull: bool,
}

type CellParts = Vec<(PartKey, Arc<KeptRegions>)>;

/// The kept regions of the renderer's geometry (module docs).
#[derive(Default)]
pub struct RegionStore {
    key: Option<StoreKey>,
    /// Per geometry cell, its parts' kept regions.
    cells: Vec<Mutex<CellParts>>,
    bytes: AtomicUsize,
    /// The most it may hold, bytes ([`budget`], set with the cells).
    budget: usize,
}

impl RegionStore {
    /// Forgets everything kept.
    pub fn clear(&mut self) {
        self.key = None;
        self.cells = Vec::new();
        self.bytes = AtomicUsize::new(0);
    }

    /// About how many bytes the kept regions hold.
    pub fn bytes(&self) -> usize {
        self.bytes.load(Ordering::Relaxed)
    }

    /// Readies the store for a frame with `camera` and culling `cull` over a
    /// geometry of `cells` cells (emptied when these changed), seen through
    /// `ids` (the geometry id of each drawn cell, for a visible subset).
    pub(super) fn frame<'a>(
        &'a mut self,
        camera: &Camera,
        cull: bool,
        cells: usize,
        ids: Option<&'a [u32]>,
    ) -> StoreFrame<'a> {
        let key = StoreKey {
            camera: *camera,
            cull,
        };
        if self.key != Some(key) || self.cells.len() != cells {
            self.clear();
            self.key = Some(key);
            self.cells = (0..cells).map(|_| Mutex::new(Vec::new())).collect();
            self.budget = budget();
        }
        StoreFrame { store: self, ids }
    }
}

/// The store during one frame: looked up and filled by the workers.
pub(super) struct StoreFrame<'a> {
    store: &'a RegionStore,
    ids: Option<&'a [u32]>,
}

impl StoreFrame<'_> {
    fn cell(&self, cell: u32) -> Option<&Mutex<CellParts>> {
        let id = match self.ids {
            Some(ids) => *ids.get(cell as usize)?,
            None => cell,
        };
        self.store.cells.get(id as usize)
    }

    /// The kept regions of part `key` of drawn cell `cell`, if they hold
    /// `part`.
    pub(super) fn get(
        &self,
        cell: u32,
        key: PartKey,
        part: &Polyhedron,
    ) -> Option<Arc<KeptRegions>> {
        let parts = self.cell(cell)?.lock().ok()?;
        parts
            .iter()
            .find(|(k, kept)| *k == key && kept.holds(part))
            .map(|(_, kept)| kept.clone())
    }

    /// Whether there is room for more.
    pub(super) fn has_room(&self) -> bool {
        self.store.bytes() < self.store.budget
    }

    /// About how many bytes the kept regions hold.
    pub(super) fn bytes(&self) -> usize {
        self.store.bytes()
    }

    /// Keeps `kept` as part `key` of drawn cell `cell`, in place of what
    /// was kept for it.
    pub(super) fn put(&self, cell: u32, key: PartKey, kept: KeptRegions) {
        let Some(Ok(mut parts)) = self.cell(cell).map(|m| m.lock()) else {
            return;
        };
        let bytes = kept.bytes();
        let kept = Arc::new(kept);
        let bytes_of = &self.store.bytes;
        match parts.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => {
                bytes_of.fetch_sub(slot.1.bytes(), Ordering::Relaxed);
                slot.1 = kept;
            }
            None => parts.push((key, kept)),
        }
        bytes_of.fetch_add(bytes, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraParams;
    use crate::projection::Projector;
    use glam::DVec3;

    /// A tet's polyhedron and its kept regions for `camera`.
    fn kept_tet(camera: &Camera, s: f64) -> (Polyhedron, KeptRegions) {
        let p =
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.2, 0.3, 1.0)].map(|w| camera.to_view(w));
        let mut poly = Polyhedron::default();
        poly.set_tet(p, [0.0, s, 1.0, 0.5]);
        let mut pr = Projector::new();
        pr.clip_to_image = true;
        pr.cull_to_pixels = true;
        let kept = pr
            .project_with(&poly, camera, None, true, &mut Default::default())
            .unwrap()
            .expect("regions");
        (poly, kept)
    }

    #[test]
    fn parts_are_found_by_key_and_geometry_within_the_budget() {
        let params = CameraParams {
            width: 64,
            height: 64,
            ..Default::default()
        };
        let camera = Camera::fit([0.0, 1.0, 0.0, 1.0, 0.0, 1.0], &params);
        let mut store = RegionStore::default();
        let (poly, kept) = kept_tet(&camera, 0.25);
        let bytes = kept.bytes();
        {
            let frame = store.frame(&camera, true, 3, None);
            assert!(frame.has_room());
            frame.put(1, PartKey::Cell, kept);
            assert!(frame.get(1, PartKey::Cell, &poly).is_some());
            assert!(frame.get(0, PartKey::Cell, &poly).is_none(), "another cell");
            assert!(frame.get(1, PartKey::Tet([0, 1, 2, 3]), &poly).is_none());
            let mut moved = poly.clone();
            moved.points[0].x += 1e-9;
            assert!(
                frame.get(1, PartKey::Cell, &moved).is_none(),
                "other points"
            );
            // Put again in place: counted once.
            frame.put(1, PartKey::Cell, kept_tet(&camera, 0.5).1);
            assert_eq!(frame.bytes(), bytes);
            // Cells beyond the store, or a subset's ids out of range.
            frame.put(7, PartKey::Cell, kept_tet(&camera, 0.5).1);
            assert_eq!(frame.bytes(), bytes);
        }
        let ids = [2u32, 1, 9];
        {
            let frame = store.frame(&camera, true, 3, Some(&ids));
            assert!(
                frame.get(1, PartKey::Cell, &poly).is_some(),
                "geometry id 1"
            );
            assert!(frame.get(0, PartKey::Cell, &poly).is_none());
            assert!(frame.get(2, PartKey::Cell, &poly).is_none(), "id 9: none");
        }
        // Full: nothing more is kept.
        store.budget = bytes;
        assert!(!store.frame(&camera, true, 3, None).has_room());
        // Another camera or culling empties the store.
        let other = Camera::fit([0.0, 2.0, 0.0, 1.0, 0.0, 1.0], &params);
        assert_eq!(store.frame(&other, true, 3, None).bytes(), 0);
        store
            .frame(&camera, true, 3, None)
            .put(0, PartKey::Cell, kept_tet(&camera, 0.1).1);
        assert!(store.bytes() > 0);
        assert_eq!(store.frame(&camera, false, 3, None).bytes(), 0);
        assert!(budget() > 0 && budget() <= KEEP_REGIONS_MAX_BYTES);
    }
}
