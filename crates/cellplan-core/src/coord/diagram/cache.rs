//! What the coordinations of one cell share of their diagrams: robot pairs by the two paths'
//! signatures, and pairs of pieces by what the pieces are ([`DiagramCache`]).
use super::{ConflictBox, DiagramWork, LocalBox, PieceEnds, RobotPath, pair_boxes};
use crate::coord::Ctx;
use crate::plan::PlanError;
use rayon::prelude::*;
use std::collections::HashMap;

/// Boxes of one robot pair, and what they cost.
type Built = (Vec<ConflictBox>, DiagramWork);

/// Built pairs by the second path's signature.
type BySecond = HashMap<Vec<u64>, Built>;

/// Boxes of one robot pair, and what they cost (see [`diagrams_reusing`]).
pub(crate) type PairBoxes = Option<Built>;

/// The boxes of robot pairs already built on a cell, by the two paths' signatures: the
/// plans ours makes of one cell share many robots' paths (a hand-over changes two robots),
/// and a pair's diagram depends on nothing else (the cell, its clearance and the robots'
/// paths). A pair found here is not built again; its work is counted as when it was built, so
/// counts and results are those of a run without the cache.
#[derive(Default)]
pub struct DiagramCache {
    /// By the first path's signature, then the second's.
    pairs: std::sync::Mutex<HashMap<Vec<u64>, BySecond>>,
    /// The pairs of pieces worked out, where kept ([`DiagramCache::with_pieces`]).
    pub(super) pieces: Option<PieceCache>,
}

/// Pairs of pieces [`PieceCache`] holds at most (about 75 bytes each, 300 MB with the map's
/// room when full); beyond, pairs are worked out without being kept.
const PIECE_PAIRS_KEPT: usize = 2_000_000;

/// Pieces [`PieceCache`] numbers at most (a key of 15 words or so each: about 200 MB when
/// full).
const PIECES_NUMBERED: usize = 1_000_000;

/// The conflicts of pairs of pieces already worked out, by what the pieces are: a hand-over
/// changes a few legs of two robots, and the pieces of every other leg recur in the new paths
/// (at other positions: a pair is worked out in the pieces' own positions, so its answer is
/// the same wherever they lie). Each piece (a segment, or a configuration held for a time, of
/// one robot) is known by a number; answers do not depend on which coordination asked first.
#[derive(Default)]
pub(super) struct PieceCache {
    ids: std::sync::Mutex<HashMap<Vec<u64>, u32>>,
    pairs: std::sync::Mutex<HashMap<PieceKey, PieceAnswer>>,
}

/// What a pair of pieces gave: its conflicts (in the pieces' own positions) and its work.
pub(super) type PieceAnswer = (Option<LocalBox>, DiagramWork);

/// A pair of pieces, with whether each starts and ends its path (see [`PieceEnds`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct PieceKey {
    a: u32,
    b: u32,
    ends: u8,
}

impl PieceKey {
    pub(super) fn new(a: u32, b: u32, (ea, eb): PieceEnds) -> PieceKey {
        let ends = [ea[0], ea[1], eb[0], eb[1]]
            .iter()
            .enumerate()
            .fold(0u8, |m, (k, &e)| m | (u8::from(e) << k));
        PieceKey { a, b, ends }
    }
}

impl PieceCache {
    /// The numbers of pieces known by `keys` (`None` stays `None`), new pieces numbered while
    /// fewer than [`PIECES_NUMBERED`] are (beyond, a new piece has none: it is not kept).
    pub(super) fn ids(&self, keys: Vec<Option<Vec<u64>>>) -> Vec<Option<u32>> {
        let mut ids = self.ids.lock().unwrap_or_else(|e| e.into_inner());
        keys.into_iter()
            .map(|k| {
                let k = k?;
                if let Some(&id) = ids.get(&k) {
                    return Some(id);
                }
                if ids.len() >= PIECES_NUMBERED {
                    return None;
                }
                let next = ids.len() as u32;
                ids.insert(k, next);
                Some(next)
            })
            .collect()
    }

    /// The answer held for `key`, or `make`'s, then held (the lock is not held while `make`
    /// works: two threads may work out one pair, and give the same answer).
    pub(super) fn answer(&self, key: PieceKey, make: impl FnOnce() -> PieceAnswer) -> PieceAnswer {
        let held = self
            .pairs
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&key)
            .copied();
        if let Some(answer) = held {
            return answer;
        }
        let answer = make();
        let mut pairs = self.pairs.lock().unwrap_or_else(|e| e.into_inner());
        if pairs.len() < PIECE_PAIRS_KEPT {
            pairs.insert(key, answer);
        }
        answer
    }
}

impl DiagramCache {
    /// A cache that also keeps the pairs of pieces it works out, by what the pieces are (a
    /// segment, or a configuration held for a time, of one robot; a pair is worked out in the
    /// pieces' own positions, so its answer is the same wherever they lie): for the many
    /// coordinations of one cell's plans that share most legs (a hand-over changes a few legs
    /// of two robots). The answers and the work counted are those without it.
    pub fn with_pieces() -> DiagramCache {
        DiagramCache {
            pieces: Some(PieceCache::default()),
            ..DiagramCache::default()
        }
    }

    /// Robot pairs' diagrams held.
    pub fn len(&self) -> usize {
        let pairs = self.pairs.lock().unwrap_or_else(|e| e.into_inner());
        pairs.values().map(HashMap::len).sum()
    }

    /// Whether none is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Pairs of pieces held (none unless made [`DiagramCache::with_pieces`]).
    pub fn piece_pairs(&self) -> usize {
        self.pieces.as_ref().map_or(0, |p| {
            let pairs = p.pairs.lock().unwrap_or_else(|e| e.into_inner());
            pairs.len()
        })
    }

    fn get(&self, a: &RobotPath, b: &RobotPath) -> PairBoxes {
        let pairs = self.pairs.lock().unwrap_or_else(|e| e.into_inner());
        pairs
            .get(a.signature.as_slice())?
            .get(b.signature.as_slice())
            .cloned()
    }

    fn put(&self, a: &RobotPath, b: &RobotPath, part: &Built) {
        let mut pairs = self.pairs.lock().unwrap_or_else(|e| e.into_inner());
        pairs
            .entry(a.signature.clone())
            .or_default()
            .insert(b.signature.clone(), part.clone());
    }
}

/// As [`super::diagrams`], keeping each pair's boxes in `parts` (pairs `(a, b)`, `a < b`, in order);
/// a pair whose entry is already there is not built again (clear the entries of pairs whose
/// paths changed), nor one the context's [`DiagramCache`] holds. The work counts the pairs
/// whose entries were empty (built now, or as built before when the cache had them). Past the
/// context's deadline ([`Ctx::past_deadline`]) no more pairs are built: those built are kept
/// (in `parts` and the cache), and the answer is [`PlanError::TimeLimit`].
pub(crate) fn diagrams_reusing(
    ctx: &Ctx,
    paths: &[RobotPath],
    parts: &mut Vec<PairBoxes>,
) -> Result<(Vec<ConflictBox>, DiagramWork), PlanError> {
    let pairs: Vec<(usize, usize)> = (0..paths.len())
        .flat_map(|a| (a + 1..paths.len()).map(move |b| (a, b)))
        .collect();
    parts.resize(pairs.len(), None);
    // What this call provides (built, or found in the cache): its work is counted.
    let fresh: Vec<usize> = (0..pairs.len()).filter(|&i| parts[i].is_none()).collect();
    if let Some(cache) = ctx.diagrams {
        for &i in &fresh {
            parts[i] = cache.get(&paths[pairs[i].0], &paths[pairs[i].1]);
        }
    }
    let todo: Vec<usize> = (0..pairs.len()).filter(|&i| parts[i].is_none()).collect();
    // Past the coordination's deadline no pair is started (those built are kept).
    let built: Vec<Option<(Vec<ConflictBox>, DiagramWork)>> = todo
        .par_iter()
        .map(|&i| (!ctx.past_deadline()).then(|| pair_boxes(ctx, &paths[pairs[i].0], &paths[pairs[i].1])))
        .collect();
    let mut work = DiagramWork::default();
    let mut cut = false;
    for (i, part) in todo.into_iter().zip(built) {
        let Some(part) = part else {
            cut = true;
            continue;
        };
        if let Some(cache) = ctx.diagrams {
            cache.put(&paths[pairs[i].0], &paths[pairs[i].1], &part);
        }
        parts[i] = Some(part);
    }
    if cut {
        return Err(PlanError::TimeLimit);
    }
    for part in fresh.iter().filter_map(|&i| parts[i].as_ref()) {
        work.cells += part.1.cells;
        work.distances += part.1.distances;
    }
    let boxes = parts.iter().flatten().flat_map(|p| p.0.iter().cloned()).collect();
    Ok((boxes, work))
}
