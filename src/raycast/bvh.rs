//! A bounding volume hierarchy over the mesh's boundary triangles, used to
//! find every place a ray line enters the mesh from outside.
//!
//! Built once per scene (camera independent): median split on the longest
//! axis of the triangle centroids, leaves of at most [`LEAF_SIZE`]
//! triangles. Boxes are padded by a tiny fraction of the scene size so that
//! the floating-point slab test never rejects a triangle that the exact
//! crossing predicate would accept; the box test only prunes, every
//! candidate is then decided exactly.

use glam::DVec3;

const LEAF_SIZE: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first item; inner: index of the right child (left is next).
    index: u32,
    /// Number of items in a leaf; 0 for inner nodes.
    count: u32,
}

/// The hierarchy: items are indices `0..n` of the caller's triangles.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    items: Vec<u32>,
}

impl Bvh {
    /// Builds over items with the given boxes (`lo`, `hi`), padded by `pad`.
    pub fn build(boxes: &[(DVec3, DVec3)], pad: f64) -> Bvh {
        let mut items: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1);
        if !boxes.is_empty() {
            build_rec(boxes, pad, &mut items, 0, boxes.len(), &mut nodes);
        }
        Bvh { nodes, items }
    }

    /// Memory held, in bytes.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.items.len() * 4
    }

    /// Calls `f` with every item whose box the line `o + t d`, `t >= t0`,
    /// may meet.
    pub fn query(&self, o: DVec3, d: DVec3, t0: f64, stack: &mut Vec<u32>, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = DVec3::ONE / d;
        stack.clear();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !hits(node, o, inv, t0) {
                continue;
            }
            if node.count > 0 {
                let s = node.index as usize;
                for &it in &self.items[s..s + node.count as usize] {
                    f(it);
                }
            } else {
                stack.push(node.index);
                stack.push(n + 1);
            }
        }
    }
}

#[inline]
fn hits(n: &Node, o: DVec3, inv: DVec3, t0: f64) -> bool {
    let mut tmin = t0;
    let mut tmax = f64::INFINITY;
    for k in 0..3 {
        let (lo, hi, oo, iv) = (n.lo[k], n.hi[k], o[k], inv[k]);
        if iv.is_infinite() {
            // Parallel to this slab: inside or not.
            if oo < lo || oo > hi {
                return false;
            }
            continue;
        }
        let a = (lo - oo) * iv;
        let b = (hi - oo) * iv;
        let (a, b) = if a < b { (a, b) } else { (b, a) };
        tmin = tmin.max(a);
        tmax = tmax.min(b);
        if tmin > tmax {
            return false;
        }
    }
    true
}

fn build_rec(
    boxes: &[(DVec3, DVec3)],
    pad: f64,
    items: &mut [u32],
    start: usize,
    end: usize,
    nodes: &mut Vec<Node>,
) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let mut clo = lo;
    let mut chi = hi;
    for &it in &items[start..end] {
        let (a, b) = boxes[it as usize];
        lo = lo.min(a);
        hi = hi.max(b);
        let c = (a + b) * 0.5;
        clo = clo.min(c);
        chi = chi.max(c);
    }
    let me = nodes.len();
    nodes.push(Node {
        lo: lo - DVec3::splat(pad),
        hi: hi + DVec3::splat(pad),
        index: start as u32,
        count: (end - start) as u32,
    });
    if end - start <= LEAF_SIZE {
        return;
    }
    let ext = chi - clo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = (start + end) / 2;
    let key = |it: &u32| {
        let (a, b) = boxes[*it as usize];
        a[axis] + b[axis]
    };
    items[start..end].select_nth_unstable_by(mid - start, |x, y| key(x).total_cmp(&key(y)));
    build_rec(boxes, pad, items, start, mid, nodes);
    let right = nodes.len() as u32;
    build_rec(boxes, pad, items, mid, end, nodes);
    nodes[me].index = right;
    nodes[me].count = 0;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_finds_every_box_on_the_line() {
        // A 10x10 grid of unit boxes in the z = 0 plane.
        let mut boxes = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                let lo = DVec3::new(i as f64, j as f64, 0.0);
                boxes.push((lo, lo + DVec3::new(1.0, 1.0, 0.0)));
            }
        }
        let bvh = Bvh::build(&boxes, 1e-9);
        let mut stack = Vec::new();
        let mut got = Vec::new();
        bvh.query(DVec3::new(3.5, 4.5, -1.0), DVec3::Z, 0.0, &mut stack, |i| {
            got.push(i)
        });
        // Candidates come by leaf: the box hit, plus at most a leaf's worth
        // of neighbours, never a far box.
        assert!(got.contains(&34) && got.len() <= 2 * LEAF_SIZE, "{got:?}");
        assert!(got
            .iter()
            .all(|&i| (i / 10).abs_diff(3) <= 2 && (i % 10).abs_diff(4) <= 2));
        got.clear();
        // Behind the origin: t0 = 0 excludes it, t0 = -inf includes it.
        bvh.query(DVec3::new(3.5, 4.5, 1.0), DVec3::Z, 0.0, &mut stack, |i| {
            got.push(i)
        });
        assert!(got.is_empty());
        bvh.query(
            DVec3::new(3.5, 4.5, 1.0),
            DVec3::Z,
            f64::NEG_INFINITY,
            &mut stack,
            |i| got.push(i),
        );
        assert!(got.contains(&34));
    }
}
