//! Coordination on the crossing two-robot cell (`cellplan_optical::testing`) reusing what
//! earlier coordinations built, started from given tour directions, or given up at a deadline:
//! kept diagrams and pairs of pieces change no answer, and a deadline only gives up.
use cellplan_core::coord;
use cellplan_optical::testing::fixture;

/// Coordinating from diagrams kept by an earlier coordination of the same programs gives the
/// same programs, counts and search, and builds nothing new.
#[test]
fn coordination_from_kept_diagrams_is_the_same() {
    let f = fixture();
    let settings = coord::CoordSettings::default();
    let alone = coord::coordinate_outcome(&f.cell, &f.table, &f.outcome, &settings).unwrap();
    let cache = coord::DiagramCache::default();
    let first = coord::coordinate_outcome_cached(&f.cell, &f.table, &f.outcome, &settings, &cache).unwrap();
    let held = cache.len();
    assert!(held >= 1);
    let again = coord::coordinate_outcome_cached(&f.cell, &f.table, &f.outcome, &settings, &cache).unwrap();
    assert_eq!(cache.len(), held, "nothing built again");
    for c in [&first, &again] {
        assert_eq!(c.programs, alone.programs);
        assert_eq!(c.search, alone.search);
        assert_eq!(
            (c.resolved, c.waits, c.reversed.clone()),
            (alone.resolved, alone.waits, alone.reversed.clone())
        );
    }
}

/// A coordination given the run's deadline is given up once it has passed: no pair diagram is
/// started (none is kept), and the answer is `TimeLimit`; without a deadline, or before it,
/// the same coordination answers as ever.
#[test]
fn a_coordination_past_its_deadline_is_given_up() {
    let f = fixture();
    let settings = coord::CoordSettings::default();
    let alone = coord::coordinate_outcome(&f.cell, &f.table, &f.outcome, &settings).unwrap();
    assert!(
        alone.resolved > 0,
        "the crossing robots have something to coordinate"
    );
    let past = coord::CoordSettings {
        deadline: Some(std::time::Instant::now()),
        ..settings.clone()
    };
    let cache = coord::DiagramCache::default();
    let cut = coord::coordinate_outcome_cached(&f.cell, &f.table, &f.outcome, &past, &cache);
    assert!(
        matches!(cut, Err(cellplan_core::plan::PlanError::TimeLimit)),
        "{cut:?}"
    );
    assert_eq!(cache.len(), 0, "no diagram started past the deadline");
    let later = coord::CoordSettings {
        deadline: Some(std::time::Instant::now() + std::time::Duration::from_secs(3600)),
        ..settings
    };
    let kept = coord::coordinate_outcome_cached(&f.cell, &f.table, &f.outcome, &later, &cache).unwrap();
    assert_eq!(kept.programs, alone.programs);
    assert_eq!(kept.search, alone.search);
}

/// Keeping pairs of pieces changes no answer: the crossing plan coordinated with a cache that
/// keeps them is the plan coordinated alone, counts and search included. A hand-over plan (one
/// MP of the second robot given to the first, the plan made keeping what it can) coordinated
/// after it with the same cache is what it is with a fresh one, and works out fewer pairs of
/// pieces: most of its legs' pieces were met before.
#[test]
fn coordination_keeping_pairs_of_pieces_is_the_same() {
    use cellplan_core::plan::{self, PlanCache, PlanSettings};
    let f = fixture();
    let settings = coord::CoordSettings::default();
    let same = |a: &coord::Coordinated, b: &coord::Coordinated| {
        assert_eq!(a.programs, b.programs);
        assert_eq!(a.search, b.search);
        assert_eq!(a.diagram_distances, b.diagram_distances);
        assert_eq!(
            (a.resolved, a.waits, a.reversed.clone()),
            (b.resolved, b.waits, b.reversed.clone())
        );
    };
    let alone = coord::coordinate_outcome(&f.cell, &f.table, &f.outcome, &settings).unwrap();
    let kept = coord::DiagramCache::with_pieces();
    let first = coord::coordinate_outcome_cached(&f.cell, &f.table, &f.outcome, &settings, &kept).unwrap();
    same(&first, &alone);
    let met = kept.piece_pairs();
    assert!(met >= 1, "the robots' pieces meet");
    // One MP handed from the second robot to the first.
    let mut tasks = f.outcome.allocated.tasks.clone();
    let handed = tasks[1].remove(0);
    tasks[0].push(handed);
    let handover = PlanSettings {
        tasks: Some(tasks),
        ..f.settings.clone()
    };
    let o = plan::plan_keeping(
        &f.cell,
        &f.table,
        &handover,
        &|_| {},
        &mut PlanCache::default(),
        Some(&f.outcome),
    )
    .unwrap();
    let fresh = coord::DiagramCache::with_pieces();
    let alone = coord::coordinate_outcome_cached(&f.cell, &f.table, &o, &settings, &fresh).unwrap();
    assert!(!alone.before.is_empty(), "the hand-over plan's robots meet");
    let again = coord::coordinate_outcome_cached(&f.cell, &f.table, &o, &settings, &kept).unwrap();
    same(&again, &alone);
    let new = kept.piece_pairs() - met;
    assert!(
        new < fresh.piece_pairs(),
        "{new} pairs of pieces worked out after the first plan, {} alone",
        fresh.piece_pairs()
    );
}

/// The directions a coordination chose, as `canonical_turns` states them (against each tour's
/// canonical direction, the first robot's taken as canonical), and a coordination started from
/// given directions: up to five robots every combination is searched, so where the search
/// starts does not change the result.
#[test]
fn coordination_from_given_directions_up_to_five_robots_is_the_same() {
    let f = fixture();
    let settings = coord::CoordSettings::default();
    let cache = coord::DiagramCache::default();
    let plain = coord::coordinate_outcome_cached(&f.cell, &f.table, &f.outcome, &settings, &cache).unwrap();
    let turns = coord::canonical_turns(&f.outcome, &plain);
    assert_eq!(turns.len(), f.cell.robots.len());
    assert!(!turns[0], "the first robot's direction is the canonical one");
    for start in [turns.clone(), vec![false, true], vec![true, true]] {
        let from = coord::coordinate_outcome_turned(&f.cell, &f.table, &f.outcome, &settings, &cache, &start)
            .unwrap();
        assert_eq!(from.programs, plain.programs);
        assert_eq!(from.reversed, plain.reversed);
        assert_eq!(coord::canonical_turns(&f.outcome, &from), turns);
    }
}
