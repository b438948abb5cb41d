//! A bounding volume hierarchy over arbitrary boxes: the walk's boundary
//! triangles (every place a ray line enters the mesh from outside,
//! [`super::walk`]) and the brute-force traversal's pieces (every cell or
//! tet a ray line may meet, [`super::brute`]).
//!
//! Built once per scene (camera independent): median split on the longest
//! axis of the box centres, leaves of at most [`LEAF_SIZE`] items. Boxes are
//! padded by a tiny fraction of the scene size so that the floating-point
//! slab test never rejects an item that the exact crossing predicate would
//! accept; the box test only prunes, every candidate is then decided
//! exactly. [`ray_hits_box`] is the same slab test for callers that keep a
//! box per item (a leaf's box holds several items).
//!
//! [`Bvh::query`] visits candidates in no particular order;
//! [`Bvh::query_ordered`] visits leaves in order of the depth at which the
//! line enters their box (a min-queue of nodes by entry depth), so a caller
//! compositing front to back can finish everything in front of a leaf
//! before looking at it, and stop early.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

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

/// The hierarchy: items are indices `0..n` of the caller's boxes.
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

    /// Renumbers the items so that the items of each leaf are consecutive
    /// (item `k` is the `k`-th in leaf order) and returns the old index of
    /// each new one: a caller reorders its per-item data by it, so that a
    /// leaf's data is contiguous in memory.
    pub fn renumber_in_leaf_order(&mut self) -> Vec<u32> {
        let old = std::mem::take(&mut self.items);
        self.items = (0..old.len() as u32).collect();
        old
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

/// A node waiting in [`Bvh::query_ordered`], smallest entry depth first.
#[derive(Clone, Copy, Debug)]
struct Queued {
    t: f64,
    node: u32,
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Queued {}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: BinaryHeap pops the largest.
        other.t.total_cmp(&self.t).then(other.node.cmp(&self.node))
    }
}

/// The node queue of [`Bvh::query_ordered`], kept between queries to reuse
/// its memory.
#[derive(Clone, Debug, Default)]
pub struct NodeQueue(BinaryHeap<Queued>);

impl Bvh {
    /// Calls `visit(t_leaf, items)` for every leaf whose box the line
    /// `o + t d`, `t >= t0`, may meet, in order of increasing `t_leaf`, the
    /// depth (at least `t0`) where the line enters the leaf's box. When a
    /// leaf is visited, every item not yet visited lies in a box the line
    /// enters at `t_leaf` or later. Stops when `visit` returns false.
    pub fn query_ordered(
        &self,
        o: DVec3,
        d: DVec3,
        t0: f64,
        queue: &mut NodeQueue,
        mut visit: impl FnMut(f64, &[u32]) -> bool,
    ) {
        let heap = &mut queue.0;
        heap.clear();
        let Some(root) = self.nodes.first() else {
            return;
        };
        let inv = DVec3::ONE / d;
        if let Some(t) = ray_box_entry(root.lo, root.hi, o, inv, t0) {
            heap.push(Queued { t, node: 0 });
        }
        while let Some(Queued { t, node }) = heap.pop() {
            let n = &self.nodes[node as usize];
            if n.count > 0 {
                let s = n.index as usize;
                if !visit(t, &self.items[s..s + n.count as usize]) {
                    return;
                }
                continue;
            }
            for child in [node + 1, n.index] {
                let c = &self.nodes[child as usize];
                if let Some(t) = ray_box_entry(c.lo, c.hi, o, inv, t0) {
                    heap.push(Queued { t, node: child });
                }
            }
        }
    }
}

#[inline]
fn hits(n: &Node, o: DVec3, inv: DVec3, t0: f64) -> bool {
    ray_hits_box(n.lo, n.hi, o, inv, t0)
}

/// Whether the line `o + t d`, `t >= t0`, may meet the closed box
/// `lo..=hi` (`inv = 1 / d` componentwise; a zero component of `d` means
/// the line is parallel to that slab and must lie within it).
#[inline]
pub fn ray_hits_box(lo: DVec3, hi: DVec3, o: DVec3, inv: DVec3, t0: f64) -> bool {
    ray_box_entry(lo, hi, o, inv, t0).is_some()
}

/// The depth (at least `t0`) where the line `o + t d` enters the closed box
/// `lo..=hi`, if it meets it at `t >= t0` ([`ray_hits_box`]).
#[inline]
pub fn ray_box_entry(lo: DVec3, hi: DVec3, o: DVec3, inv: DVec3, t0: f64) -> Option<f64> {
    let mut tmin = t0;
    let mut tmax = f64::INFINITY;
    for k in 0..3 {
        let (lo, hi, oo, iv) = (lo[k], hi[k], o[k], inv[k]);
        if iv.is_infinite() {
            // Parallel to this slab: inside or not.
            if oo < lo || oo > hi {
                return None;
            }
            continue;
        }
        let a = (lo - oo) * iv;
        let b = (hi - oo) * iv;
        let (a, b) = if a < b { (a, b) } else { (b, a) };
        tmin = tmin.max(a);
        tmax = tmax.min(b);
        if tmin > tmax {
            return None;
        }
    }
    Some(tmin)
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

    #[test]
    fn ordered_query_goes_front_to_back_and_renumbering_keeps_items() {
        // A 6x6x6 lattice of unit boxes, a diagonal line through it.
        let mut boxes = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                for k in 0..6 {
                    let lo = DVec3::new(i as f64, j as f64, k as f64);
                    boxes.push((lo, lo + DVec3::ONE));
                }
            }
        }
        let (o, d) = (
            DVec3::new(-1.0, 0.3, -0.7),
            DVec3::new(1.0, 0.8, 0.9).normalize(),
        );
        let inv = DVec3::ONE / d;
        let hit: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&i| ray_hits_box(boxes[i as usize].0, boxes[i as usize].1, o, inv, 0.0))
            .collect();
        assert!(hit.len() > 6);
        let mut bvh = Bvh::build(&boxes, 1e-9);
        let mut queue = NodeQueue::default();
        let run = |bvh: &Bvh, queue: &mut NodeQueue| {
            let mut leaves: Vec<(f64, Vec<u32>)> = Vec::new();
            bvh.query_ordered(o, d, 0.0, queue, |t, items| {
                leaves.push((t, items.to_vec()));
                true
            });
            leaves
        };
        let leaves = run(&bvh, &mut queue);
        let entry = |i: u32| {
            let (lo, hi) = boxes[i as usize];
            ray_box_entry(lo, hi, o, inv, 0.0)
        };
        for (k, (t, _)) in leaves.iter().enumerate() {
            // Every item of this leaf and the later ones is entered no
            // earlier than this leaf (boxes padded by 1e-9).
            for (_, items) in &leaves[k..] {
                for &i in items {
                    if let Some(e) = entry(i) {
                        assert!(e >= t - 1e-6, "item {i} entered at {e}, leaf at {t}");
                    }
                }
            }
        }
        let seen: Vec<u32> = leaves.iter().flat_map(|l| l.1.clone()).collect();
        for i in &hit {
            assert!(seen.contains(i), "box {i} missed");
        }
        let order = bvh.renumber_in_leaf_order();
        let again: Vec<u32> = run(&bvh, &mut queue)
            .iter()
            .flat_map(|l| l.1.iter().map(|&k| order[k as usize]))
            .collect();
        assert_eq!(again, seen);
        // Stopping early.
        let mut n = 0;
        bvh.query_ordered(o, d, 0.0, &mut queue, |_, _| {
            n += 1;
            n < 2
        });
        assert_eq!(n, 2);
    }
}
