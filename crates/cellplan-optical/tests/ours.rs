//! Ours (`pipeline::coordinate`: `best` on the zones allocation, with its other plans and
//! hand-overs) on the crossing cell of `coord.rs`: it keeps the shortest of its plans, within
//! its budget of work, the same on one thread as on two, and every plan it gives verifies.
use cellplan_core::coord;
use cellplan_core::document as output;
use cellplan_optical::testing::{fixture, on_threads};
use cellplan_verify::{VerifySettings, verify};

/// The fixture's zones plan, with its settings and the leg cache it filled (where ours starts).
fn zones_plan(
    f: &cellplan_optical::testing::Fixture,
) -> (
    cellplan_core::plan::PlanSettings,
    cellplan_core::plan::PlanCache,
    cellplan_core::plan::Outcome,
) {
    use cellplan_core::plan::{self, Allocation, PlanCache, PlanSettings};
    let zones = PlanSettings {
        allocation: Allocation::Zones,
        ..f.settings.clone()
    };
    let mut cache = PlanCache::default();
    let outcome = plan::plan_cached(&f.cell, &f.table, &zones, &|_| {}, &mut cache).unwrap();
    (zones, cache, outcome)
}

/// A plan made with another plan's graphs but none of its planned legs
/// (`PlanCache::graphs_only`, as ours plans its balanced allocation) is the plan made afresh,
/// and the legs the motion planner already gave are served by the graphs' memos.
#[test]
fn a_plan_on_shared_graphs_is_the_plan_made_afresh() {
    use cellplan_core::plan::{self, Allocation, PlanCache, PlanSettings};
    let f = fixture();
    let (_, cache, _) = zones_plan(f);
    let balanced = PlanSettings {
        allocation: Allocation::Balanced,
        ..f.settings.clone()
    };
    let afresh = plan::plan_cached(&f.cell, &f.table, &balanced, &|_| {}, &mut PlanCache::default()).unwrap();
    let mut shared = cache.graphs_only();
    let before = shared.legs_served();
    let again = plan::plan_cached(&f.cell, &f.table, &balanced, &|_| {}, &mut shared).unwrap();
    assert!(shared.legs_served() > before, "no leg was served by the memo");
    assert_eq!(afresh.robots.len(), again.robots.len());
    for (a, b) in afresh.robots.iter().zip(&again.robots) {
        assert_eq!(a.sequence.nodes, b.sequence.nodes);
        assert_eq!(a.program.duration(), b.program.duration());
        let paths = |r: &plan::RobotResult| -> Vec<Vec<Vec<f64>>> {
            r.sequence.legs.iter().map(|l| l.waypoints.clone()).collect()
        };
        assert_eq!(paths(a), paths(b));
    }
}

/// Ours (`pipeline::coordinate` with `best` on the zones allocation) keeps the shortest of its
/// plans: never longer than the zones plan coordinated alone, whichever of its plans wins (the
/// zones again with the blocking penalties, or the nearest robots), and the plan verifies with
/// the settings of the plan that won.
#[test]
fn ours_keeps_the_shortest_of_its_plans() {
    use cellplan_core::plan::Allocation;
    let f = fixture();
    let coord_settings = coord::CoordSettings::default();
    let (zones, mut cache, outcome) = zones_plan(f);
    let alone = coord::coordinate_outcome(&f.cell, &f.table, &outcome, &coord_settings).unwrap();
    let (o, s, c) =
        cellplan_core::pipeline::coordinate(&f.cell, &f.table, outcome, zones, &coord_settings, &mut cache)
            .unwrap();
    assert!(matches!(
        s.allocation,
        Allocation::Zones | Allocation::Proximity | Allocation::Balanced
    ));
    if s.allocation != Allocation::Zones {
        assert!(s.task_penalty.is_empty());
    }
    let doc = cellplan_core::document::build(&f.cell, &f.table, &o, &c, &s, 0.0, 0.0);
    let report = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
    assert!(doc.cycle_time_s <= coord::cycle_and_delta(&alone.timed).0 + 1e-9);
    // The plan says how ours went: its first plan and others coordinated, the winner blended,
    // the parts' seconds within the stage's; a plain coordination says nothing.
    let ours = doc.stats.ours.expect("ours states its run");
    assert!(ours.tries_coordinated >= 2, "{ours:?}");
    assert!(ours.blended >= 1, "{ours:?}");
    let t = doc.compute_s.ours.expect("and its parts' seconds");
    let parts = [t.tries, t.handovers, t.blend];
    assert!(parts.iter().all(|&s| s >= 0.0), "{t:?}");
    assert!(
        parts.iter().sum::<f64>() <= c.compute_s + 1e-9,
        "{t:?} against {}",
        c.compute_s
    );
    assert!(alone.ours.is_none());
}

/// Ours makes its balanced plan aside (on small cells like this one), planned and coordinated
/// beside its other plans and judged at its turn: on one thread it is made when the others are
/// done, on two while they are made. Either way ours gives the same plan, and it verifies.
#[test]
fn ours_is_the_same_plan_on_one_thread_and_on_two() {
    let f = fixture();
    let run = |threads: usize| {
        on_threads(threads, || {
            let (zones, mut cache, outcome) = zones_plan(f);
            let coord_settings = coord::CoordSettings::default();
            let (o, s, c) = cellplan_core::pipeline::coordinate(
                &f.cell,
                &f.table,
                outcome,
                zones,
                &coord_settings,
                &mut cache,
            )
            .unwrap();
            let mut doc = cellplan_core::document::build(&f.cell, &f.table, &o, &c, &s, 0.0, 0.0);
            doc.compute_s = output::ComputeTimes::default();
            doc
        })
    };
    let one = run(1);
    let report = verify(&f.cell, &one, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
    assert_eq!(one, run(2));
}

/// Ours within a budget of diagram work that no second coordination fits: the first plan (the
/// zones allocation) is the only one coordinated, so ours gives what the zones plan gives
/// coordinated alone; with the default budget ours is no longer than that.
#[test]
fn ours_past_its_work_budget_keeps_its_first_plan() {
    use cellplan_core::plan::{Allocation, PlanCache};
    let f = fixture();
    let tight = coord::CoordSettings {
        ours_distances: 0,
        ..coord::CoordSettings::default()
    };
    let (zones, mut cache, outcome) = zones_plan(f);
    // Ours compares its plans unblended and blends the winner.
    let unblended = coord::CoordSettings {
        blend_deviation: 0.0,
        ..tight.clone()
    };
    let alone = coord::coordinate_outcome(&f.cell, &f.table, &outcome, &unblended).unwrap();
    let alone = coord::blend_coordinated(&f.cell, &f.table, alone, &tight).unwrap();
    assert!(alone.diagram_distances > 0, "the diagrams asked nothing");
    let (o, s, c) = cellplan_core::pipeline::coordinate(
        &f.cell,
        &f.table,
        outcome.clone(),
        zones.clone(),
        &tight,
        &mut cache,
    )
    .unwrap();
    assert_eq!(s.allocation, Allocation::Zones);
    assert!(s.task_penalty.is_empty() && s.tasks.is_none());
    assert_eq!(c.programs, alone.programs);
    let doc = cellplan_core::document::build(&f.cell, &f.table, &o, &c, &s, 0.0, 0.0);
    let report = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
    let mut cache = PlanCache::default();
    let (_, _, wide) = cellplan_core::pipeline::coordinate(
        &f.cell,
        &f.table,
        outcome,
        zones,
        &coord::CoordSettings::default(),
        &mut cache,
    )
    .unwrap();
    assert!(coord::cycle_and_delta(&wide.timed).0 <= doc.cycle_time_s + 1e-9);
}

/// Ours planning every try first (as on large cells) within a budget that allows one
/// coordination: the plan coordinated is the most promising of its plans — here another than the
/// zones plan it starts from, whose robots end sooner uncoordinated; every coordination is
/// polished as it is made, so the winner is not polished again; the plan verifies.
#[test]
fn ours_planning_first_coordinates_its_most_promising_plan() {
    use cellplan_core::plan::rebalance::makespan;
    let f = fixture();
    let first = coord::CoordSettings {
        ours_distances: 0,
        plan_first_pairs: 0,
        ..coord::CoordSettings::default()
    };
    let (zones, mut cache, outcome) = zones_plan(f);
    let start = makespan(&outcome);
    let zones_tasks = outcome.allocated.tasks.clone();
    let (o, s, c) =
        cellplan_core::pipeline::coordinate(&f.cell, &f.table, outcome, zones, &first, &mut cache).unwrap();
    // On this cell one of the tries ends sooner than the zones plan (13.9 s against 16.2 s):
    // coordinating the first plan, as the pipelined order does within this budget, would keep
    // the zones plan.
    assert!(
        o.allocated.tasks != zones_tasks && makespan(&o) < start - 1e-9,
        "the zones plan ({start} s) was coordinated, not the most promising"
    );
    let (run, _) = c.ours.expect("ours states its run");
    assert!(run.polished_throughout && !run.polished, "{run:?}");
    let doc = cellplan_core::document::build(&f.cell, &f.table, &o, &c, &s, 0.0, 0.0);
    let report = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
}
