//! Strongly connected components (Tarjan, iterative), used to find the
//! visibility cycles a topological sort leaves behind.
//!
//! [`tarjan`] runs over the nodes for which `alive` is true, following the
//! successors that `succ` lists, and returns the components in *reverse*
//! topological order (a component comes after every component it has an
//! edge to... i.e. sinks first), as Tarjan's algorithm naturally produces
//! them. No recursion: the explicit stack keeps deep graphs (a million
//! cells) safe.

/// Components of the subgraph induced by `alive` nodes, sinks first.
pub fn tarjan(
    n: usize,
    alive: impl Fn(u32) -> bool,
    mut succ: impl FnMut(u32, &mut Vec<u32>),
) -> Vec<Vec<u32>> {
    const UNSEEN: u32 = u32::MAX;
    let mut index = vec![UNSEEN; n];
    let mut low = vec![0u32; n];
    let mut on_stack = vec![false; n];
    let mut stack: Vec<u32> = Vec::new();
    let mut comps: Vec<Vec<u32>> = Vec::new();
    let mut next = 0u32;
    // Call stack frames: (node, where its successors start in `succs`,
    // position of the next one to follow). The successors of every frame
    // live on one stack, popped with the frame (no vector per node).
    let mut frames: Vec<(u32, usize, usize)> = Vec::new();
    let mut succs: Vec<u32> = Vec::new();
    macro_rules! visit {
        ($v:expr) => {{
            let v: u32 = $v;
            index[v as usize] = next;
            low[v as usize] = next;
            next += 1;
            stack.push(v);
            on_stack[v as usize] = true;
            let begin = succs.len();
            succ(v, &mut succs);
            frames.push((v, begin, begin));
        }};
    }
    for root in 0..n as u32 {
        if !alive(root) || index[root as usize] != UNSEEN {
            continue;
        }
        visit!(root);
        while let Some(frame) = frames.last_mut() {
            let v = frame.0;
            // A frame's successors end where the next frame's begin (or at
            // the top of the stack for the last frame).
            if frame.2 < succs.len() {
                let w = succs[frame.2];
                frame.2 += 1;
                if w as usize >= n || !alive(w) {
                    continue;
                }
                if index[w as usize] == UNSEEN {
                    visit!(w);
                } else if on_stack[w as usize] {
                    low[v as usize] = low[v as usize].min(index[w as usize]);
                }
                continue;
            }
            if let Some((_, begin, _)) = frames.pop() {
                succs.truncate(begin);
            }
            if let Some(parent) = frames.last() {
                let p = parent.0 as usize;
                low[p] = low[p].min(low[v as usize]);
            }
            if low[v as usize] == index[v as usize] {
                let mut comp = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w as usize] = false;
                    comp.push(w);
                    if w == v {
                        break;
                    }
                }
                comps.push(comp);
            }
        }
    }
    comps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_cycles_in_reverse_topological_order() {
        // 0 -> 1 -> 2 -> 0 (cycle), 2 -> 3, 3 -> 4 -> 3 (cycle), 5 isolated.
        let edges: Vec<Vec<u32>> = vec![vec![1], vec![2], vec![0, 3], vec![4], vec![3], vec![]];
        let comps = tarjan(6, |_| true, |v, out| out.extend(&edges[v as usize]));
        let mut sorted: Vec<Vec<u32>> = comps
            .iter()
            .map(|c| {
                let mut c = c.clone();
                c.sort();
                c
            })
            .collect();
        sorted.sort();
        assert_eq!(sorted, vec![vec![0, 1, 2], vec![3, 4], vec![5]]);
        let pos = |x: u32| comps.iter().position(|c| c.contains(&x)).unwrap();
        // {3,4} is reachable from {0,1,2}: it comes first (sinks first).
        assert!(pos(3) < pos(0));
    }

    #[test]
    fn deep_chain_does_not_overflow() {
        let n = 200_000;
        let comps = tarjan(
            n,
            |_| true,
            |v, out| {
                if (v as usize) + 1 < n {
                    out.push(v + 1)
                }
            },
        );
        assert_eq!(comps.len(), n);
        assert_eq!(comps[0], vec![n as u32 - 1]);
    }
}
