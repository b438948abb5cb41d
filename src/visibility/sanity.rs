//! [`Sorter::sanity_check`]: the invariants of the split-cell pool, run by
//! the tests and the fuzz target after every view.

use super::Sorter;
use crate::mesh::NONE;

impl Sorter {
    /// Verifies the split bookkeeping: every active cell has a slot holding
    /// its own tets, slots are not shared, free slots are not in use, every
    /// face triangle of a split cell has an owning tet that contains it.
    pub fn sanity_check(&self) -> Result<(), String> {
        let n = self.mesh.cells.len();
        let mut used = vec![false; self.pool.slots.len()];
        let mut prev: Option<u32> = None;
        for &c in &self.pool.active {
            if prev.is_some_and(|p| p >= c) {
                return Err(format!("active list not increasing at cell {c}"));
            }
            prev = Some(c);
            let s = *self
                .pool
                .slot_of
                .get(c as usize)
                .ok_or("active cell out of range")?;
            if s == NONE {
                return Err(format!("active cell {c} has no slot"));
            }
            let su = s as usize;
            if su >= used.len() || used[su] {
                return Err(format!("slot {s} of cell {c} invalid or shared"));
            }
            used[su] = true;
            let sc = &self.pool.slots[su];
            if sc.cell != c {
                return Err(format!("slot {s} holds cell {} not {c}", sc.cell));
            }
            let mut want = Vec::new();
            crate::mesh::tetra::tetrahedralize_cell(&self.mesh.cells, c as usize, &mut want);
            if want != sc.tets {
                return Err(format!(
                    "cell {c}: stored tets differ from its consistent tets"
                ));
            }
            for (li, &f) in self.topo.faces_of(c as usize).iter().enumerate() {
                let mut k = 0;
                let mut err = None;
                crate::mesh::tetra::triangulate_face(self.topo.face(f as usize), |t| {
                    let o = sc.owner(li, k) as usize;
                    let ok = sc
                        .tets
                        .get(o)
                        .is_some_and(|tet| t.iter().all(|v| tet.contains(v)));
                    if !ok && sc.unmatched == 0 {
                        err = Some(format!(
                            "cell {c} face {f} triangle {k}: owner tet misses it"
                        ));
                    }
                    k += 1;
                });
                if let Some(e) = err {
                    return Err(e);
                }
            }
        }
        for &s in &self.pool.free {
            if used.get(s as usize).copied().unwrap_or(true) {
                return Err(format!("free slot {s} is in use or out of range"));
            }
        }
        let split = self.pool.slot_of.iter().filter(|&&s| s != NONE).count();
        if split != self.pool.active.len()
            || self.pool.slot_of.len() != n && n > 0 && self.invalid.is_none()
        {
            return Err(format!(
                "{split} cells have slots but {} are active",
                self.pool.active.len()
            ));
        }
        Ok(())
    }
}
