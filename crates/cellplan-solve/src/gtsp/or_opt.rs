//! Or-opt: move the items at positions `l..=r` (1–3 of them, never wrapping, never the depot
//! item) between positions `q` and `q + 1`, optionally reversed; a single moved cluster may take
//! its best node for the new place.
use super::{Inst, State};

/// A candidate move.
#[derive(Clone, Copy, Debug)]
pub(super) struct Move {
    pub l: usize,
    pub r: usize,
    pub q: usize,
    pub reversed: bool,
    /// New node of the (single) moved cluster.
    pub node: usize,
}

/// Cost of the arcs inside `l..=r`, forward and reversed.
#[inline]
fn inner(inst: &Inst, st: &State, l: usize, r: usize) -> (f64, f64) {
    let (mut f, mut b) = (0.0, 0.0);
    for i in l..r {
        let (u, v) = (st.node(i), st.node(i + 1));
        f += inst.w(u, v);
        b += inst.w(v, u);
    }
    (f, b)
}

/// A segment `l..=r` about to be moved: what its moves share, whatever the place (the same
/// sums [`best_at`] would form for each place, in the same order).
#[derive(Clone, Copy, Debug)]
pub(super) struct Segment {
    l: usize,
    r: usize,
    /// Its first and last nodes.
    f: usize,
    e: usize,
    /// `w(p, f) + w(e, n) − w(p, n)`, with `p` and `n` the nodes around it.
    cut: f64,
    /// Reversing its inner arcs: their cost backwards less forwards (0 for symmetric costs).
    turn: f64,
}

/// The segment `l..=r` of `st`; `None` when it may not move (it holds the depot item).
pub(super) fn segment(inst: &Inst, st: &State, l: usize, r: usize) -> Option<Segment> {
    if inst.depot && l == 0 {
        return None;
    }
    debug_assert!(r < st.t.len());
    let p = st.node(st.prev(l));
    let n = st.node(st.next(r));
    let f = st.node(l);
    let e = st.node(r);
    let turn = if l < r && !inst.sym {
        let (fi, bi) = inner(inst, st, l, r);
        bi - fi
    } else {
        0.0
    };
    Some(Segment {
        l,
        r,
        f,
        e,
        cut: inst.w(p, f) + inst.w(e, n) - inst.w(p, n),
        turn,
    })
}

/// The best move of segment `seg` to between `q` and its successor (both orientations, and
/// the best node for a single cluster), with its cost change; `None` if illegal. The caller
/// takes the move only if its change is below `bar`: a single cluster's nodes are not scanned
/// when their bound shows none can be (the change returned is then that of the cluster's
/// current node, no smaller than the scan's and no smaller than `bar` either).
#[inline]
pub(super) fn best_at(inst: &Inst, st: &State, seg: &Segment, q: usize, bar: f64) -> Option<(f64, Move)> {
    let Segment {
        l,
        r,
        f,
        e,
        cut,
        turn,
    } = *seg;
    let qn = st.next(q);
    if (l..=r).contains(&q) || (l..=r).contains(&qn) {
        return None;
    }
    let u = st.node(q);
    let v = st.node(qn);
    let removed = cut + inst.w(u, v);
    if l == r {
        let cluster = &inst.clusters[st.t[l]];
        let mut best = (inst.w(u, f) + inst.w(f, v), f);
        if cluster.len() > 1 {
            let base = best.0 + inst.s(f);
            best.0 = base;
            // No node beats the current one here, or none can give a change below `bar`.
            let bound = inst.through_bound(u, st.t[l], v);
            let hopeless = bound >= base || (bound - inst.s(f)) - removed >= bar;
            for &z in if hopeless { &[][..] } else { cluster } {
                let x = inst.w(u, z) + inst.s(z) + inst.w(z, v);
                if x < best.0 {
                    best = (x, z);
                }
            }
            best.0 -= inst.s(f);
        }
        let mv = Move {
            l,
            r,
            q,
            reversed: false,
            node: best.1,
        };
        return Some((best.0 - removed, mv));
    }
    let fwd = inst.w(u, f) + inst.w(e, v);
    // `turn` is 0 for symmetric costs (the sum unchanged).
    let rev = inst.w(u, e) + inst.w(f, v) + turn;
    let reversed = rev < fwd;
    let mv = Move {
        l,
        r,
        q,
        reversed,
        node: f,
    };
    Some((fwd.min(rev) - removed, mv))
}

/// Apply `mv`; returns the items at the ends of the changed arcs.
pub(super) fn apply(inst: &Inst, st: &mut State, mv: Move) -> [usize; 6] {
    let Move {
        l,
        r,
        q,
        reversed,
        node,
    } = mv;
    let len = r - l + 1;
    let ends = [
        st.t[st.prev(l)],
        st.t[st.next(r)],
        st.t[q],
        st.t[st.next(q)],
        st.t[l],
        st.t[r],
    ];
    if l == r {
        st.choice[st.t[l]] = node;
    }
    let (lo, hi, at) = if q > r {
        st.t[l..=q].rotate_left(len);
        (l, q, q + 1 - len)
    } else {
        st.t[q + 1..=r].rotate_right(len);
        (q + 1, r, q + 1)
    };
    if reversed {
        st.t[at..at + len].reverse();
    }
    st.reindex(inst, lo, hi);
    ends
}
