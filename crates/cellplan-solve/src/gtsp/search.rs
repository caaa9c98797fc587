//! Local search driven by a queue of items to look at ("don't-look bits"): for an item, the best
//! of its node re-choice in place, its 2-opt moves with neighbour items and the Or-opt moves of
//! the 1–3-item segments it ends; after convergence, the layer pass, and again until neither
//! improves.
use std::collections::VecDeque;

use super::{EPS, Inst, State, layer, or_opt, two_opt};

/// The queue of items to look at.
#[derive(Default)]
pub(super) struct Queue {
    q: VecDeque<usize>,
    inq: Vec<bool>,
}

impl Queue {
    pub(super) fn push(&mut self, x: usize) {
        if x >= self.inq.len() {
            self.inq.resize(x + 1, false);
        }
        if !self.inq[x] {
            self.inq[x] = true;
            self.q.push_back(x);
        }
    }

    fn pop(&mut self) -> Option<usize> {
        let x = self.q.pop_front()?;
        self.inq[x] = false;
        Some(x)
    }
}

enum Best {
    None,
    Node(usize, usize),
    Rev(usize, usize),
    Or(or_opt::Move),
}

/// The best improving move around item `x`, if any.
fn best_move(inst: &Inst, st: &State, x: usize) -> Best {
    let m = st.t.len();
    let mut best = (-EPS, Best::None);
    let px = st.pos[x];
    // Node re-choice in place.
    if inst.clusters[x].len() > 1 {
        let (a, b) = (st.node(st.prev(px)), st.node(st.next(px)));
        let cur = st.choice[x];
        let now = inst.w(a, cur) + inst.s(cur) + inst.w(cur, b);
        // Every node's change is at least the bound's (see `ClusterBounds`).
        let hopeless = inst.through_bound(a, x, b) - now >= best.0;
        for &z in if hopeless { &[][..] } else { &inst.clusters[x][..] } {
            let d = inst.w(a, z) + inst.s(z) + inst.w(z, b) - now;
            if d < best.0 {
                best = (d, Best::Node(x, z));
            }
        }
    }
    for &y in &inst.neigh[x] {
        let py = st.pos[y];
        // 2-opt creating the edge x-y after both, and before both.
        let cands = if px < py {
            [(px + 1, py), (px, py.wrapping_sub(1))]
        } else {
            [(py + 1, px), (py, px.wrapping_sub(1))]
        };
        for (l, r) in cands {
            if r >= m || l > r {
                continue;
            }
            if let Some((l, r)) = two_opt::legal(inst, st, l, r) {
                let d = two_opt::delta(inst, st, l, r);
                if d < best.0 {
                    best = (d, Best::Rev(l, r));
                }
            }
        }
    }
    // Or-opt of segments ending at x, next to a neighbour of x.
    for len in 1..=3usize.min(m.saturating_sub(2)) {
        let mut segs = [(usize::MAX, 0); 2];
        if px + len <= m {
            segs[0] = (px, px + len - 1);
        }
        if len > 1 && px + 1 >= len {
            segs[1] = (px + 1 - len, px);
        }
        for (l, r) in segs {
            if l == usize::MAX {
                continue;
            }
            let Some(seg) = or_opt::segment(inst, st, l, r) else {
                continue;
            };
            for &y in &inst.neigh[x] {
                let py = st.pos[y];
                for q in [py, st.prev(py)] {
                    if let Some((d, mv)) = or_opt::best_at(inst, st, &seg, q, best.0)
                        && d < best.0
                    {
                        best = (d, Best::Or(mv));
                    }
                }
            }
        }
    }
    best.1
}

/// Improve until no move around a queued item helps and the layer pass finds nothing.
pub(super) fn local_search(inst: &Inst, st: &mut State, queue: &mut Queue, memo: &mut layer::LayerMemo) {
    if st.t.len() < 3 {
        layer::layer_pass(inst, st, memo);
        return;
    }
    loop {
        while let Some(x) = queue.pop() {
            match best_move(inst, st, x) {
                Best::None => {}
                Best::Node(x, z) => {
                    st.choice[x] = z;
                    st.refresh(inst);
                    let p = st.pos[x];
                    queue.push(x);
                    queue.push(st.t[st.prev(p)]);
                    queue.push(st.t[st.next(p)]);
                }
                Best::Rev(l, r) => {
                    for e in two_opt::apply(inst, st, l, r) {
                        queue.push(e);
                    }
                    queue.push(x);
                }
                Best::Or(mv) => {
                    for e in or_opt::apply(inst, st, mv) {
                        queue.push(e);
                    }
                    queue.push(x);
                }
            }
        }
        let changed = layer::layer_pass(inst, st, memo);
        if changed.is_empty() {
            return;
        }
        for x in changed {
            let p = st.pos[x];
            queue.push(x);
            queue.push(st.t[st.prev(p)]);
            queue.push(st.t[st.next(p)]);
        }
    }
}
