//! Consistent tetrahedralisation by the smallest-vertex rule (MWS section IV,
//! Dompierre et al.).
//!
//! Every face is split the same way from both of its cells, because the split
//! depends only on global point ids:
//! - a quad face is two triangles split by the diagonal from its smallest
//!   vertex; an n-gon face (n > 4) is a fan from its smallest vertex;
//! - a cell is the cone from its smallest vertex `v0` over the triangles of
//!   the faces that do not contain `v0`. This gives pyramid 2, wedge 3,
//!   hexahedron 6, pentagonal prism 8 (if v0 is on a cap)...
//! - exception (Dompierre's hexahedron rule): when none of the three face
//!   diagonals of the faces opposite `v0` passes through `v6` (the vertex
//!   opposite `v0`), the hexahedron is the five tetrahedra that avoid the
//!   interior diagonal `v0-v6`.
//!
//! Tets are emitted with the orientation inherited from the face order
//! (positive volume for a positively oriented convex cell); distorted cells
//! can yield inverted or flat tets, which callers must accept.

use std::collections::HashMap;

use thiserror::Error;

use super::topology::Topology;
use super::{CellKind, Cells, NONE};

/// A broken invariant of a tetrahedralisation, found by
/// [`check_tetrahedralisation`].
#[derive(Debug, Error, PartialEq, Eq)]
#[error("tetrahedralisation invariant broken: {0}")]
pub struct TetError(pub String);

/// The consistent tetrahedra of all cells, with `offsets[c]..offsets[c + 1]`
/// indexing the tets of cell `c`.
pub fn tetrahedralize(cells: &Cells) -> (Vec<[u32; 4]>, Vec<u32>) {
    let mut tets = Vec::with_capacity(cells.len() * 5);
    let mut offsets = Vec::with_capacity(cells.len() + 1);
    offsets.push(0);
    for c in 0..cells.len() {
        tetrahedralize_cell(cells, c, &mut tets);
        offsets.push(tets.len() as u32);
    }
    (tets, offsets)
}

fn sorted3(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

/// Checks that `tets` (from [`tetrahedralize`]) is a conforming
/// tetrahedralisation of the faces in `topo`: every triangle of a tet is
/// used by at most two tets; triangles used once are exactly the triangles
/// of the boundary faces split by [`triangulate_face`]; every triangle of an
/// interior face is used by exactly two tets (so shared quads got the same
/// diagonal from both sides); no tet repeats a vertex.
pub fn check_tetrahedralisation(topo: &Topology, tets: &[[u32; 4]]) -> Result<(), TetError> {
    let mut uses: HashMap<[u32; 3], u32> = HashMap::with_capacity(tets.len() * 2);
    for (i, t) in tets.iter().enumerate() {
        let mut s = *t;
        s.sort_unstable();
        if s.windows(2).any(|w| w[0] == w[1]) {
            return Err(TetError(format!("tet {i} {t:?} repeats a vertex")));
        }
        for tri in [
            [t[0], t[1], t[2]],
            [t[0], t[1], t[3]],
            [t[0], t[2], t[3]],
            [t[1], t[2], t[3]],
        ] {
            *uses.entry(sorted3(tri)).or_insert(0) += 1;
        }
    }
    let mut boundary = 0usize;
    for f in 0..topo.face_count() {
        let interior = topo.face_cells[f][1] != NONE;
        let mut bad = None;
        triangulate_face(topo.face(f), |tri| {
            let n = uses.get(&sorted3(tri)).copied().unwrap_or(0);
            let want = if interior { 2 } else { 1 };
            if n != want && bad.is_none() {
                bad = Some(format!(
                    "face {f} triangle {tri:?} used by {n} tets, want {want}"
                ));
            }
            boundary += (!interior) as usize;
        });
        if let Some(b) = bad {
            return Err(TetError(b));
        }
    }
    for (tri, &n) in &uses {
        if n > 2 {
            return Err(TetError(format!("triangle {tri:?} used by {n} tets")));
        }
    }
    let once = uses.values().filter(|&&n| n == 1).count();
    if once != boundary {
        return Err(TetError(format!(
            "{once} triangles used once but the boundary has {boundary}"
        )));
    }
    Ok(())
}

/// Splits a face into triangles by the smallest-vertex rule, calling `f` with
/// each triangle (same winding as the face).
pub fn triangulate_face(face: &[u32], mut f: impl FnMut([u32; 3])) {
    let n = face.len();
    if n < 3 {
        return;
    }
    let k = (0..n).min_by_key(|&i| face[i]).unwrap_or(0);
    for i in 1..n - 1 {
        f([face[k], face[(k + i) % n], face[(k + i + 1) % n]]);
    }
}

/// Appends the consistent tetrahedra of cell `c` to `out`.
pub fn tetrahedralize_cell(cells: &Cells, c: usize, out: &mut Vec<[u32; 4]>) {
    let nodes = cells.nodes(c);
    let kind = cells.kinds[c];
    if kind == CellKind::Tetra {
        out.push([nodes[0], nodes[1], nodes[2], nodes[3]]);
        return;
    }
    if kind == CellKind::Hexahedron {
        if let Some(five) = hex_five(nodes) {
            out.extend_from_slice(&five);
            return;
        }
    }
    let v0 = match nodes.iter().min() {
        Some(&v) => v,
        None => return,
    };
    cells.for_each_face(c, |_, face| {
        if face.contains(&v0) {
            return;
        }
        triangulate_face(face, |t| {
            // Face winding is outward; the cone apex is inside, so the tet
            // (apex, t[0], t[1], t[2]) is positively oriented.
            out.push([v0, t[0], t[1], t[2]]);
        });
    });
}

/// The five-tet split of a hexahedron when it applies (see module docs).
fn hex_five(n: &[u32]) -> Option<[[u32; 4]; 5]> {
    // Relabel so that local 0 is the smallest vertex: use the symmetry of the
    // hexahedron that maps the smallest corner to corner 0.
    let k = (0..8).min_by_key(|&i| n[i])?;
    let p = HEX_SYMMETRY[k];
    let m: [u32; 8] = std::array::from_fn(|i| n[p[i] as usize]);
    // Faces opposite v0: (1,2,6,5), (2,3,7,6), (4,5,6,7). Their diagonals avoid
    // v6 iff the smallest vertex of each face is not 6 and not the one
    // opposite 6 in that face... a diagonal passes through v6 iff the face's
    // smallest vertex is v6 or the vertex diagonally opposite v6.
    let through6 = |a: usize, b: usize, c: usize, d: usize| {
        // face (a,b,c,d) in cyclic order with c == 6 at position 2.
        let s = [m[a], m[b], m[c], m[d]];
        let min = s.iter().copied().min().unwrap();
        min == m[c] || min == m[a]
    };
    if through6(1, 2, 6, 5) || through6(3, 7, 6, 2) || through6(4, 5, 6, 7) {
        return None;
    }
    // Diagonals 2-5, 2-7, 5-7: central tet (0,2,5,7) and four corner tets.
    // Orientation: for the unit cube numbering, (0,1,3,4) is positive.
    Some([
        [m[0], m[1], m[2], m[5]],
        [m[0], m[2], m[3], m[7]],
        [m[0], m[5], m[7], m[4]],
        [m[2], m[7], m[5], m[6]],
        [m[0], m[2], m[7], m[5]],
    ])
}

/// For each corner k, a permutation of the hexahedron's local nodes (an
/// orientation-preserving symmetry) that maps local 0 to k:
/// `relabelled[i] = original[HEX_SYMMETRY[k][i]]`.
const HEX_SYMMETRY: [[u8; 8]; 8] = [
    [0, 1, 2, 3, 4, 5, 6, 7],
    [1, 2, 3, 0, 5, 6, 7, 4],
    [2, 3, 0, 1, 6, 7, 4, 5],
    [3, 0, 1, 2, 7, 4, 5, 6],
    [4, 7, 6, 5, 0, 3, 2, 1],
    [5, 4, 7, 6, 1, 0, 3, 2],
    [6, 5, 4, 7, 2, 1, 0, 3],
    [7, 6, 5, 4, 3, 2, 1, 0],
];

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn vol(p: &[DVec3], t: [u32; 4]) -> f64 {
        let [a, b, c, d] = t.map(|i| p[i as usize]);
        (b - a).cross(c - a).dot(d - a) / 6.0
    }

    fn unit_hex() -> Vec<DVec3> {
        vec![
            DVec3::new(0., 0., 0.),
            DVec3::new(1., 0., 0.),
            DVec3::new(1., 1., 0.),
            DVec3::new(0., 1., 0.),
            DVec3::new(0., 0., 1.),
            DVec3::new(1., 0., 1.),
            DVec3::new(1., 1., 1.),
            DVec3::new(0., 1., 1.),
        ]
    }

    #[test]
    fn hex_splits_sum_to_volume_for_every_labelling() {
        let base = unit_hex();
        // Try many relabellings of the global ids (which changes the diagonals).
        let mut perm: Vec<u32> = (0..8).collect();
        let mut seen5 = 0;
        let mut seen6 = 0;
        for s in 0..400u32 {
            // simple deterministic shuffle
            let mut x = s.wrapping_mul(2654435761).wrapping_add(12345);
            for i in (1..8).rev() {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                perm.swap(i, (x % (i as u32 + 1)) as usize);
            }
            let mut pts = vec![DVec3::ZERO; 8];
            for i in 0..8 {
                pts[perm[i] as usize] = base[i];
            }
            let mut cells = Cells::default();
            let nodes: Vec<u32> = (0..8).map(|i| perm[i]).collect();
            cells.push(CellKind::Hexahedron, &nodes);
            let mut tets = Vec::new();
            tetrahedralize_cell(&cells, 0, &mut tets);
            match tets.len() {
                5 => seen5 += 1,
                6 => seen6 += 1,
                n => panic!("{n} tets"),
            }
            let total: f64 = tets.iter().map(|&t| vol(&pts, t)).sum();
            assert!((total - 1.0).abs() < 1e-12, "total {total}");
            for &t in &tets {
                assert!(vol(&pts, t) > 0.0, "inverted tet {t:?} for {perm:?}");
            }
        }
        assert!(seen5 > 0 && seen6 > 0);
    }
}
