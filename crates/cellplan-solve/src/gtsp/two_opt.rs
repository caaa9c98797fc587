//! 2-opt: reverse the items at positions `l..=r` (never wrapping, never moving the depot item).
//! With asymmetric costs the reversed segment's arcs are costed from prefix sums.
use super::{Inst, State};

/// Whether reversing `l..=r` is a legal, non-trivial move.
#[inline]
pub(super) fn valid(inst: &Inst, st: &State, l: usize, r: usize) -> bool {
    l < r && !(inst.depot && l == 0) && !(l == 0 && r + 1 == st.t.len())
}

/// The change in cost from reversing positions `l..=r` (`valid` must hold).
#[inline]
pub(super) fn delta(inst: &Inst, st: &State, l: usize, r: usize) -> f64 {
    let a = st.node(st.prev(l));
    let b = st.node(l);
    let c = st.node(r);
    let d = st.node(st.next(r));
    let mut delta = inst.w(a, c) + inst.w(b, d) - inst.w(a, b) - inst.w(c, d);
    if !inst.sym {
        delta += (st.bwd[r] - st.bwd[l]) - (st.fwd[r] - st.fwd[l]);
    }
    delta
}

/// Reverse positions `l..=r`; returns the items at the four ends of the changed arcs.
pub(super) fn apply(inst: &Inst, st: &mut State, l: usize, r: usize) -> [usize; 4] {
    let ends = [st.t[st.prev(l)], st.t[l], st.t[r], st.t[st.next(r)]];
    st.t[l..=r].reverse();
    st.reindex(inst, l, r);
    ends
}

/// For a 2-opt that must create the arcs of reversing `l..=r`: the same segment, or (when it
/// holds position 0 of a depot tour) the complementary one, which changes the same edges.
#[inline]
pub(super) fn legal(inst: &Inst, st: &State, l: usize, r: usize) -> Option<(usize, usize)> {
    if l == 0 && inst.depot {
        let (l2, r2) = (r + 1, st.t.len() - 1);
        return valid(inst, st, l2, r2).then_some((l2, r2));
    }
    valid(inst, st, l, r).then_some((l, r))
}
