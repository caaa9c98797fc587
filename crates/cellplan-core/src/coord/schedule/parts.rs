//! Searches over parts of a diagram: each pair of robots alone (a lower bound of the whole),
//! and a small set of boxes that no order can pass.
use super::{ConflictBox, Found, Track, search};

/// The infeasible core's search stops after this many searches' budgets of nodes.
const CORE_SEARCHES: usize = 40;

/// A lower bound of the makespan of every schedule of `paths` through `boxes`: the longest
/// path, and for each pair of robots that share boxes, the shortest schedule of the two alone
/// through their boxes (any schedule of all the robots is one of the pair too, its makespan at
/// least the pair's), where the pair's search proves it within its share of `budget`. `None`
/// when a pair's search proves that the two alone have no order of passing (then neither have
/// all). Returns the nodes the pairs' searches took too.
pub(super) fn floor(
    paths: &[Track],
    boxes: &[ConflictBox],
    budget: usize,
    min_wait: f64,
) -> (Option<f64>, usize) {
    let mut floor = paths.iter().map(|p| p.len).fold(0.0, f64::max);
    let mut by_pair: std::collections::BTreeMap<(usize, usize), Vec<ConflictBox>> = Default::default();
    for b in boxes {
        by_pair.entry(b.robots).or_default().push(b.clone());
    }
    if by_pair.len() < 2 {
        return (Some(floor), 0);
    }
    let share = (budget / by_pair.len()).max(1);
    let mut spent = 0;
    for ((a, b), boxes) in by_pair {
        let two: Vec<Track> = paths
            .iter()
            .filter(|p| p.robot == a || p.robot == b)
            .cloned()
            .collect();
        let (found, nodes) = search(&two, &boxes, share, min_wait, false);
        spent += nodes;
        match found {
            Found::Schedule(s) if s.proven => floor = f64::max(floor, s.makespan),
            Found::Infeasible => return (None, spent),
            Found::Schedule(_) | Found::Unknown => {}
        }
    }
    (Some(floor), spent)
}

/// A small set of boxes that no order can pass (indices into `boxes`), when `boxes` are
/// infeasible: a deletion filter in halving chunks (a set whose feasibility the search cannot
/// decide within `budget` counts as feasible, so the core is infeasible for certain). Each
/// test is one search; after [`CORE_SEARCHES`] searches' worth of nodes the filter stops and
/// the boxes left (infeasible, not always minimal) are the core.
pub(crate) fn infeasible_core(
    paths: &[Track],
    boxes: &[ConflictBox],
    budget: usize,
    min_wait: f64,
) -> Vec<usize> {
    let spent = std::cell::Cell::new(0usize);
    let limit = budget.max(1).saturating_mul(CORE_SEARCHES);
    let infeasible = |keep: &[usize]| -> bool {
        let b: Vec<ConflictBox> = keep.iter().map(|&i| boxes[i].clone()).collect();
        let (found, nodes) = search(paths, &b, budget, min_wait, false);
        spent.set(spent.get() + nodes);
        matches!(found, Found::Infeasible)
    };
    let mut keep: Vec<usize> = (0..boxes.len()).collect();
    if !infeasible(&keep) {
        return Vec::new();
    }
    let mut chunk = keep.len().div_ceil(2).max(1);
    loop {
        let mut i = 0;
        while i < keep.len() {
            if spent.get() >= limit {
                return keep;
            }
            let end = (i + chunk).min(keep.len());
            let trial: Vec<usize> = keep[..i].iter().chain(&keep[end..]).copied().collect();
            if infeasible(&trial) {
                keep = trial;
            } else {
                i = end;
            }
        }
        if chunk == 1 {
            return keep;
        }
        chunk = chunk.div_ceil(2);
    }
}
