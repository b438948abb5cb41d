//! Optional merge of coincident points.
//!
//! Points with exactly equal coordinates (`-0.0` equals `0.0`; NaN never
//! merges) form a group; every cell reference to a point of a group is
//! replaced by the group's smallest original index (the vertex-order
//! convention of `docs/conventions.md`). Points are not removed, so point arrays stay
//! aligned; the merged-away points simply become unused. Cells that shared
//! positions but not indices become face neighbours once the topology is
//! rebuilt. Groups are found by sorting point indices by coordinates.

use rayon::prelude::*;

use super::Mesh;

fn key(p: glam::DVec3) -> [u64; 3] {
    // +0.0 for -0.0 so both sort together; bit order is only used for equality
    // grouping, so any total order on the bits works.
    [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits)
}

/// For every point, the smallest index of the points with exactly the same
/// coordinates (itself when unique or not finite).
pub fn coincident_representatives(points: &[glam::DVec3]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.par_sort_unstable_by_key(|&i| (key(points[i as usize]), i));
    let mut rep: Vec<u32> = (0..points.len() as u32).collect();
    let mut i = 0;
    while i < order.len() {
        let first = order[i];
        let k = key(points[first as usize]);
        let finite = points[first as usize].is_finite();
        let mut j = i + 1;
        while j < order.len() && key(points[order[j] as usize]) == k {
            if finite {
                rep[order[j] as usize] = first; // sorted by index within a run
            }
            j += 1;
        }
        i = j;
    }
    rep
}

/// Replaces every cell reference to a coincident point by its group's
/// smallest index; returns the number of points merged away.
pub fn merge_coincident_points(mesh: &mut Mesh) -> usize {
    let rep = coincident_representatives(&mesh.points);
    let merged = rep
        .iter()
        .enumerate()
        .filter(|(i, &r)| *i != r as usize)
        .count();
    if merged == 0 {
        return 0;
    }
    let map = |i: &mut u32| {
        if let Some(&r) = rep.get(*i as usize) {
            *i = r;
        }
    };
    mesh.cells.conn.par_iter_mut().for_each(map);
    for faces in mesh.cells.poly_faces.values_mut() {
        faces.iter_mut().flatten().for_each(map);
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::topology::Topology;
    use crate::mesh::{CellKind, Mesh};
    use glam::DVec3;

    #[test]
    fn duplicated_face_points_become_neighbours() {
        let mut m = Mesh::default();
        let quad = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)];
        for z in [0.0, 1.0] {
            for (x, y) in quad {
                m.points.push(DVec3::new(x, y, z));
            }
        }
        // second hex above, with its own copies of the shared face's points
        for z in [1.0, 2.0] {
            for (x, y) in quad {
                m.points.push(DVec3::new(x, y, z));
            }
        }
        m.points.push(DVec3::new(-0.0, 0.0, 1.0)); // 16: same as 4 via -0.0
        m.cells
            .push(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
        m.cells
            .push(CellKind::Hexahedron, &[16, 9, 10, 11, 12, 13, 14, 15]);
        assert_eq!(Topology::build(&m.cells).boundary_face_count(), 12);
        assert_eq!(merge_coincident_points(&mut m), 5);
        assert_eq!(m.cells.nodes(1), &[4, 5, 6, 7, 12, 13, 14, 15]);
        let t = Topology::build(&m.cells);
        assert_eq!(t.boundary_face_count(), 10);
        t.sanity_check(&m.cells).unwrap();
    }

    #[test]
    fn nan_points_never_merge() {
        let p = vec![DVec3::splat(f64::NAN), DVec3::splat(f64::NAN)];
        assert_eq!(coincident_representatives(&p), vec![0, 1]);
    }
}
