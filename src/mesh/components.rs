//! Connected components of the cells through shared faces.
//!
//! Union-find (union by size, path halving) over the interior faces of a
//! [`Topology`]; cells that only touch at an edge or a point are separate
//! components. Labels are renumbered `0..count` in order of each
//! component's smallest cell.

use super::topology::Topology;
use super::NONE;

/// Component label of every cell and the number of components.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Components {
    /// Label of each cell, `0..count`, ordered by each component's first cell.
    pub labels: Vec<u32>,
    /// Number of components.
    pub count: usize,
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[parent[x as usize] as usize];
        parent[x as usize] = p;
        x = p;
    }
    x
}

/// Connected components of the cells of `topo` through shared faces.
pub fn connected_components(topo: &Topology) -> Components {
    let n = topo.cell_count();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let mut size = vec![1u32; n];
    for &[a, b] in &topo.face_cells {
        if b == NONE || a as usize >= n || b as usize >= n {
            continue;
        }
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra == rb {
            continue;
        }
        let (big, small) = if size[ra as usize] >= size[rb as usize] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        parent[small as usize] = big;
        size[big as usize] += size[small as usize];
    }
    drop(size);
    let mut label_of_root = vec![NONE; n];
    let mut labels = vec![0u32; n];
    let mut count = 0u32;
    for c in 0..n as u32 {
        let r = find(&mut parent, c) as usize;
        if label_of_root[r] == NONE {
            label_of_root[r] = count;
            count += 1;
        }
        labels[c as usize] = label_of_root[r];
    }
    Components {
        labels,
        count: count as usize,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{CellKind, Cells};

    #[test]
    fn edge_contact_does_not_connect() {
        let mut cells = Cells::default();
        cells.push(CellKind::Tetra, &[0, 1, 2, 3]);
        cells.push(CellKind::Tetra, &[0, 2, 1, 4]); // shares face 0 1 2
        cells.push(CellKind::Tetra, &[0, 1, 5, 6]); // shares edge 0 1 only
        cells.push(CellKind::Tetra, &[7, 8, 9, 10]);
        cells.push(CellKind::Tetra, &[0, 1, 6, 11]); // shares face 0 1 6 with cell 2
        let t = Topology::build(&cells);
        let comp = connected_components(&t);
        assert_eq!(comp.count, 3);
        assert_eq!(comp.labels, vec![0, 0, 1, 2, 1]);
    }
}
