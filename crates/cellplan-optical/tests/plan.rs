//! `cellplan plan` through the library on a reduced copy of the two-robot example (its first 8
//! MPs) and on the bundled examples: the allocation strategies, independence of the thread
//! count; every plan re-checked independently of the planner (see `common`).
mod common;
use cellplan_core::candidates::{CandidateTable, generate};
use cellplan_core::document as output;
use cellplan_core::plan::{self, Allocation, PlanSettings};
use cellplan_model::{Cell, LoadOptions, TaskId};
use cellplan_optical::load;
use cellplan_optical::testing::{on_threads, repo_root};
use common::*;
use std::path::Path;

#[test]
fn every_strategy_gives_a_plan_that_rechecks_clean() {
    let f = fixture();
    let prox = make(Allocation::Proximity);
    // Proximity: every MP with the nearest robot able to measure it (the caps do not bind here).
    for (r, rp) in prox.robots.iter().enumerate() {
        for v in &rp.tasks {
            let t = f.cell.tasks.iter().find(|t| t.name == v.task).unwrap();
            let d = |i: usize| (f.cell.robots[i].base.translation - t.position).length();
            for other in f.table.robots_for(t.id) {
                assert!(
                    d(r) <= d(other.0) + 1e-12,
                    "MP {} is not with its nearest robot",
                    v.task
                );
            }
        }
    }
    let robust = make(Allocation::LocalRobust);
    assert!(robust.stats.local_sets_built >= robust.stats.local_sets_chosen);
    let balanced = make(Allocation::Balanced);
    for doc in [&prox, &robust, &balanced] {
        assert!(doc.stats.legs_planned >= doc.robots.iter().map(|r| r.legs.len()).sum::<usize>() / 2);
    }
}

#[test]
fn the_plan_does_not_depend_on_the_thread_count() {
    let f = fixture();
    let s = settings(Allocation::Balanced);
    let run = |threads: usize| {
        on_threads(threads, || {
            let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).unwrap();
            let mut doc = build(&f.cell, &f.table, &outcome, &s);
            doc.compute_s = output::ComputeTimes::default();
            doc
        })
    };
    let one = run(1);
    check_plan(&f.cell, &one);
    assert_eq!(one, run(2));
    let _ = TaskId(0);
}

/// A plan the run can do without (`give_up_at_deadline`) is given up once the deadline has
/// passed; the run's own plan stops searching there but finishes, verified, and says the clock
/// cut it.
#[test]
fn a_plan_that_may_be_given_up_is_given_up_at_the_deadline() {
    let f = fixture();
    let past = PlanSettings {
        deadline: Some(std::time::Instant::now()),
        ..settings(Allocation::Zones)
    };
    let kept = plan::plan(&f.cell, &f.table, &past, &|_| {}).expect("the run's plan finishes");
    assert!(kept.time_limit_hit);
    assert!(kept.robots.iter().map(|r| r.program.visits.len()).sum::<usize>() > 0);
    check_plan(&f.cell, &build(&f.cell, &f.table, &kept, &past));
    let optional = PlanSettings {
        give_up_at_deadline: true,
        ..past
    };
    let given_up = plan::plan(&f.cell, &f.table, &optional, &|_| {});
    assert!(
        matches!(given_up, Err(plan::PlanError::TimeLimit)),
        "{given_up:?}"
    );
    // Before the deadline it is planned as ever.
    let later = PlanSettings {
        deadline: Some(std::time::Instant::now() + std::time::Duration::from_secs(3600)),
        ..optional
    };
    let planned = plan::plan(&f.cell, &f.table, &later, &|_| {}).unwrap();
    let plain = plan::plan(&f.cell, &f.table, &settings(Allocation::Zones), &|_| {}).unwrap();
    assert!(!planned.time_limit_hit);
    assert_eq!(
        planned
            .robots
            .iter()
            .map(|r| &r.program.visits)
            .collect::<Vec<_>>(),
        plain.robots.iter().map(|r| &r.program.visits).collect::<Vec<_>>()
    );
}

/// Two robots 2 m apart facing a box, four MPs close together on its top, all nearer to R1
/// and measurable by both: proximity gives all four to R1; local robust sets group them
/// (closer than ε, same normal) and Algorithm 1 gives the set to R1 (the shorter tour from its
/// base); the balanced min-max splits them two and two (four measurements on one robot take
/// 6 s, two take 3 s).
#[test]
fn allocation_strategies_give_the_known_answers_on_a_hand_made_cell() {
    let fanuc = repo_root().join("data/robots/fanuc_r2000ic");
    let scratch = tempfile::Builder::new()
        .prefix("cellplan-plan-known-")
        .tempdir()
        .unwrap();
    let dir = scratch.path();
    let robot = |name: &str, y: i32| {
        format!(
            r#"
[[robots]]
name = "{name}"
urdf = "{f}/urdf/r2000ic125l.urdf"
packages = {{ fanuc_r2000ic_support = "{f}/fanuc_r2000ic_support" }}
opw = "{f}/fanuc_r2000ic_support/config/opw_parameters_r2000ic125l.yaml"
base = {{ xyz = [0, {y}, 0] }}
home = [0, -30, 0, 0, -60, 0]
tool = "probe"
"#,
            f = fanuc.display()
        )
    };
    let cell = format!(
        r#"name = "known"
units = {{ length = "mm", angle = "deg" }}

[process]
kind = "optical-inspection"
standoff = 250
stripe_length = 60
baseline = 100

[tools.probe]
tcp = {{ xyz = [0, 0, 300] }}

[[tools.probe.shape]]
box = [180, 120, 220]
pose = {{ xyz = [45, 0, 190] }}
{}{}
[[objects]]
name = "part"
box = [600, 600, 600]
pose = {{ xyz = [1900, 0, 300] }}

[tasks]
file = "tasks.csv"
"#,
        robot("R1", 1000),
        robot("R2", -1000)
    );
    std::fs::write(dir.join("cell.toml"), cell).unwrap();
    std::fs::write(
        dir.join("tasks.csv"),
        "id,x,y,z,nx,ny,nz\nA,1800,150,600,0,0,1\nB,1900,150,600,0,0,1\nC,1800,250,600,0,0,1\nD,1900,250,600,0,0,1\n",
    )
    .unwrap();
    let cell = load(&dir.join("cell.toml"), &LoadOptions::default()).expect("the hand-made cell loads");
    let table = generate(&cell);
    for t in 0..4 {
        assert_eq!(table.robots_for(TaskId(t)).len(), 2, "both robots measure MP {t}");
    }
    let graphs: Vec<_> = cell
        .robots
        .iter()
        .map(|r| plan::graph::RobotGraph::new(&cell, r, &table, plan::MoveModel::Trapezoid, 8, 0.02))
        .collect();
    let counts = |a: Allocation| {
        let s = settings(a);
        let got = plan::allocate::allocate(&cell, &table, &graphs, &s, None).unwrap();
        got.tasks.iter().map(Vec::len).collect::<Vec<_>>()
    };
    assert_eq!(counts(Allocation::Proximity), vec![4, 0]);
    assert_eq!(counts(Allocation::LocalRobust), vec![4, 0]);
    assert_eq!(counts(Allocation::Balanced), vec![2, 2]);
    // And the plans of all three recheck clean.
    for a in [
        Allocation::Proximity,
        Allocation::LocalRobust,
        Allocation::Balanced,
    ] {
        let s = settings(a);
        let outcome = plan::plan(&cell, &table, &s, &|_| {}).unwrap();
        build_checked(&cell, &table, &outcome, &s);
    }
}

/// The two bundled example cells, whole, with the default settings: the plans re-check clean.
#[test]
fn both_example_cells_plan_and_recheck_clean() {
    for name in ["autobody-2r", "autobody-4r"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../examples/{name}/cell.toml"));
        let cell = load(&path, &LoadOptions::default()).expect("the example loads");
        let table = generate(&cell);
        let s = PlanSettings {
            time_limit: std::time::Duration::from_secs(3600),
            ..PlanSettings::default()
        };
        let outcome = plan::plan(&cell, &table, &s, &|_| {}).expect("the example plans");
        let doc = build(&cell, &table, &outcome, &s);
        assert!(
            doc.unmeasured.is_empty(),
            "{name}: every MP of the examples is measurable"
        );
        check_plan(&cell, &doc);
        verified(&cell, &doc);
    }
}

/// The zones allocation starts from the nearest robot and only hands tasks on while the
/// robots' lower-bound times, sorted longest first, fall: its busiest robot is never busier
/// (on those bounds) than the proximity allocation's, every task goes to a robot that can do
/// it, and the plan it gives verifies.
#[test]
fn zones_never_make_the_busiest_robot_busier_than_proximity() {
    let f = fixture();
    let busiest = |allocation: Allocation| {
        let s = settings(allocation);
        let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).expect("the reduced cell plans");
        let worst = outcome
            .graphs
            .iter()
            .zip(&outcome.allocated.tasks)
            .map(|(g, tasks)| {
                let order = plan::sequence::best_order(g, tasks, &Default::default(), 0, &Default::default());
                plan::sequence::order_cost(g, &Default::default(), &order)
            })
            .fold(0.0, f64::max);
        for (r, tasks) in outcome.allocated.tasks.iter().enumerate() {
            for t in tasks {
                assert!(!f.table.get(*t, cellplan_model::RobotId(r)).candidates.is_empty());
            }
        }
        (worst, outcome, s)
    };
    let (prox, ..) = busiest(Allocation::Proximity);
    let (zones, outcome, s) = busiest(Allocation::Zones);
    assert!(zones <= prox + 1e-6, "zones {zones} vs proximity {prox}");
    let doc = build(&f.cell, &f.table, &outcome, &s);
    check_plan(&f.cell, &doc);
    verified(&f.cell, &doc);
}

#[test]
fn strips_cut_the_mps_along_the_line_of_the_robots_and_each_robot_sweeps_its_strip() {
    let cell = load(&small_cell(20), &LoadOptions::default()).unwrap();
    let table = generate(&cell);
    let line = cellplan_core::pipeline::robot_line(&cell).expect("two robots make a line");
    let s = PlanSettings {
        sweep: Some(line),
        ..settings(Allocation::Zones)
    };
    let outcome = plan::plan(&cell, &table, &s, &|_| {}).unwrap();
    let key = plan::sweep_keys(&cell, Some(line));
    let place = |r: usize| {
        let b = cell.robots[r].base.translation;
        b.x * line[0] + b.y * line[1]
    };
    let mut robots: Vec<usize> = (0..cell.robots.len()).collect();
    robots.sort_by(|&a, &b| place(a).total_cmp(&place(b)));
    let tasks_of = |r: usize| -> Vec<usize> { outcome.allocated.tasks[r].iter().map(|t| t.0).collect() };
    let shared = |t: usize| table.robots_for(TaskId(t)).len() == cell.robots.len();
    for pair in robots.windows(2) {
        let (a, b) = (tasks_of(pair[0]), tasks_of(pair[1]));
        assert!(!a.is_empty() && !b.is_empty(), "every robot has a strip");
        // Of the MPs both can measure, the first robot's all lie before the second's.
        let last_a = a
            .iter()
            .filter(|&&t| shared(t))
            .map(|&t| key[t])
            .fold(f64::MIN, f64::max);
        let first_b = b
            .iter()
            .filter(|&&t| shared(t))
            .map(|&t| key[t])
            .fold(f64::MAX, f64::min);
        assert!(last_a <= first_b, "strips overlap: {last_a} > {first_b}");
    }
    // Each robot measures its strip in three groups of rising place, one after the other.
    for (r, rr) in outcome.robots.iter().enumerate() {
        let mut mine = tasks_of(r);
        mine.sort_by(|&x, &y| key[x].total_cmp(&key[y]).then(x.cmp(&y)));
        let group =
            |t: usize| mine.iter().position(|&x| x == t).unwrap() * plan::sequence::SWEEP_GROUPS / mine.len();
        let groups: Vec<usize> = rr.program.visits.iter().map(|v| group(v.task.0)).collect();
        assert!(
            groups.windows(2).all(|w| w[0] <= w[1]),
            "robot {r} goes back: {groups:?}"
        );
    }
    // The plan holds up.
    build_checked(&cell, &table, &outcome, &s);
}

#[test]
fn robots_facing_each_other_make_two_rows_along_the_part() {
    // facing-4r-roof: two robots on each side of the car, facing across it.
    let cell = repo_cell("bench/cells/facing-4r-roof/cell.toml");
    let (line, rows) = plan::robot_rows(&cell).expect("four robots");
    assert_eq!(rows.len(), 2, "{rows:?}");
    for row in &rows {
        assert_eq!(row.len(), 2);
        // The robots of a row stand on one side of the car (same x).
        let x: Vec<f64> = row.iter().map(|&r| cell.robots[r].base.translation.x).collect();
        assert!((x[0] - x[1]).abs() < 1e-9, "{x:?}");
    }
    // The line runs along the car (y), not across it.
    assert!(line[1].abs() > 0.99, "{line:?}");
    // The README cell: one row of four along the car.
    let readme = repo_cell("examples/autobody-4r/cell.toml");
    let (line, rows) = plan::robot_rows(&readme).unwrap();
    assert_eq!(rows, vec![vec![0, 1, 2, 3]]);
    assert!(line[1].abs() > 0.99, "{line:?}");
}

/// A hand-over whose plan, the other robots' programs kept, coordinates to a cycle far longer
/// than the one to beat ([`plan::rebalance::FAR_WORSE`]) is not planned again with every robot
/// sequenced anew: each allocation is judged once. One that coordinates a little longer is.
#[test]
fn a_hand_over_coordinated_far_worse_is_not_sequenced_again() {
    use plan::rebalance::{FAR_WORSE, ends, makespan};
    let (cell, table, s, _, base) = readme_nearest();
    let score = makespan(&base);
    let run = |factor: f64| -> Vec<Vec<Vec<TaskId>>> {
        let mut seen = Vec::new();
        let mut judge =
            |o: &plan::Outcome, _: Option<(&plan::Outcome, &())>| -> Option<(f64, Vec<f64>, ())> {
                seen.push(o.allocated.tasks.clone());
                Some((score * factor, ends(o), ()))
            };
        let mut cache = plan::PlanCache::default();
        let (found, clock) = rebalanced(&cell, &table, &base, &s, &mut cache, &mut judge);
        assert!(found.is_none() && !clock);
        seen
    };
    let far = run(1.0 + 2.0 * FAR_WORSE);
    assert!(far.len() >= 2, "{} plans judged", far.len());
    assert!(far.windows(2).all(|w| w[0] != w[1]), "an allocation judged twice");
    let near = run(1.0 + FAR_WORSE / 2.0);
    assert!(
        near.windows(2).any(|w| w[0] == w[1]),
        "no hand-over judged again with every robot sequenced anew"
    );
}

#[test]
fn rebalancing_hands_tasks_from_the_robot_ending_last_until_the_robots_end_sooner() {
    use plan::rebalance::{MORE_PLANS, REBALANCE_PLANS, ends, makespan};
    // The nearest-robot allocation ignores how long each robot works (5 to 14 MPs here).
    let (cell, table, s, mut cache, base) = readme_nearest();
    let before = makespan(&base);
    let judged = std::cell::Cell::new(0);
    let mut judge = |o: &plan::Outcome, _: Option<(&plan::Outcome, &())>| {
        judged.set(judged.get() + 1);
        Some((makespan(o), ends(o), ()))
    };
    // Past the deadline no hand-over is planned, and the search says the clock cut it.
    let late = PlanSettings {
        deadline: Some(std::time::Instant::now()),
        ..s.clone()
    };
    let cut = rebalanced(&cell, &table, &base, &late, &mut cache, &mut judge);
    assert!(cut.0.is_none() && cut.1, "the clock cut must show");
    assert_eq!(judged.get(), 0);
    let (o, fixed, ()) = rebalanced(&cell, &table, &base, &s, &mut cache, &mut judge)
        .0
        .expect("the nearest robots are unbalanced here");
    assert!(judged.get() >= 1);
    assert!(makespan(&o) < before - 1e-6, "{} !< {before}", makespan(&o));
    // The plan is the fixed allocation it was made with: every task once, within the caps,
    // each with a robot able to do it, a few hand-overs away from the start.
    assert_eq!(Some(&o.allocated.tasks), fixed.tasks.as_ref());
    let mut all: Vec<usize> = o.allocated.tasks.iter().flatten().map(|t| t.0).collect();
    all.sort();
    assert_eq!(all, (0..cell.tasks.len()).collect::<Vec<_>>());
    let moved: usize = o
        .allocated
        .tasks
        .iter()
        .zip(&base.allocated.tasks)
        .map(|(a, b)| a.iter().filter(|t| !b.contains(t)).count())
        .sum();
    assert!(
        (1..=REBALANCE_PLANS + MORE_PLANS).contains(&moved),
        "{moved} tasks moved"
    );
    for (r, tasks) in o.allocated.tasks.iter().enumerate() {
        assert!(tasks.len() <= cell.planning.task_cap);
        for &t in tasks {
            assert!(table.robots_for(t).iter().any(|x| x.0 == r));
        }
        // Each robot measures exactly its tasks.
        let mut visited: Vec<usize> = o.robots[r].program.visits.iter().map(|v| v.task.0).collect();
        let mut mine: Vec<usize> = tasks.iter().map(|t| t.0).collect();
        visited.sort();
        mine.sort();
        assert_eq!(visited, mine);
    }
    build_checked(&cell, &table, &o, &fixed);
}

/// A plan made from another with one task handed over (`plan_keeping`): the robots whose tasks
/// did not change keep their programs from the first plan (so their paths, and coordination
/// reuses the diagrams of their pairs) unless sequenced again they got shorter ones; the two
/// robots of the hand-over measure their new tasks; the plan verifies.
#[test]
fn a_hand_over_keeps_the_other_robots_programs() {
    let (cell, table, s, mut cache, base) = readme_nearest();
    // The first task of some robot that another robot with room under the cap can do.
    let mut tasks = base.allocated.tasks.clone();
    let m = cell.robots.len();
    let (from, to, t) = (0..m)
        .flat_map(|a| (0..m).map(move |b| (a, b)))
        .filter(|&(a, b)| a != b && tasks[b].len() < cell.planning.task_cap)
        .find_map(|(a, b)| {
            let t = tasks[a]
                .iter()
                .find(|&&t| table.robots_for(t).iter().any(|x| x.0 == b))?;
            Some((a, b, *t))
        })
        .expect("neighbours share tasks");
    tasks[from].retain(|&x| x != t);
    tasks[to].push(t);
    let fixed = PlanSettings {
        tasks: Some(tasks.clone()),
        ..s.clone()
    };
    let o = plan::plan_keeping(&cell, &table, &fixed, &|_| {}, &mut cache, Some(&base)).unwrap();
    assert_eq!(o.allocated.tasks, tasks);
    for r in (0..m).filter(|&r| r != from && r != to) {
        let (now, was) = (&o.robots[r].program, &base.robots[r].program);
        assert!(now.duration() <= was.duration() + 1e-9, "robot {r}");
        if now.duration() >= was.duration() - 1e-9 {
            assert_eq!(now, was, "robot {r}");
        }
    }
    assert!(o.robots[to].program.visits.iter().any(|v| v.task == t));
    assert!(o.robots[from].program.visits.iter().all(|v| v.task != t));
    build_checked(&cell, &table, &o, &fixed);
}

/// The plans `rebalance` judges from `base` when the robot `stuck` ends `wait` seconds later
/// than planned, waiting that long for robot `waited`, and the judge takes none of them.
fn judged_waiting(
    (cell, table, s, cache, base): (
        &Cell,
        &CandidateTable,
        &PlanSettings,
        &mut plan::PlanCache,
        &plan::Outcome,
    ),
    (stuck, waited, wait): (usize, usize, f64),
) -> Vec<plan::Outcome> {
    use plan::rebalance::{Waits, ends, makespan, rebalance};
    let m = cell.robots.len();
    let mut end = ends(base);
    end[stuck] += wait;
    let mut waits = vec![vec![0.0; m]; m];
    waits[stuck][waited] = wait;
    let mut seen: Vec<plan::Outcome> = Vec::new();
    let mut judge = |o: &plan::Outcome, _: Option<(&plan::Outcome, &())>| -> Option<(f64, Vec<f64>, ())> {
        seen.push(o.clone());
        None
    };
    let (found, clock) = rebalance(
        cell,
        table,
        (
            base,
            makespan(base) + wait,
            &end,
            &Waits {
                totals: waits,
                stalls: Vec::new(),
            },
        ),
        s,
        cache,
        &|_| true,
        (&mut judge, &|_| unreachable!("no plan is taken")),
    )
    .unwrap();
    assert!(found.is_none() && !clock);
    seen
}

/// Once the direct hand-overs are spent without help, a robot the last one waits for is
/// relieved: one of its tasks goes to a third robot (never to the waiting one), within a budget
/// of its own; without waits there is no relief (the test below). Groups come after them, to a
/// robot with room for them (none here: see the next test).
#[test]
fn a_robot_the_last_one_waits_for_is_relieved_when_the_hand_overs_do_not_help() {
    use plan::rebalance::{
        MORE_JUDGED, REBALANCE_JUDGED, RELIEF_JUDGED, RELIEF_PLANS, Waits, ends, makespan, rebalance,
    };
    let (cell, table, s, mut cache, base) = readme_nearest();
    let m = cell.robots.len();
    // As if coordination had made the robot that ends last wait 5 s for the busiest other one.
    let mut end = ends(&base);
    let stuck = last_robot(&end);
    let waited = (0..m)
        .filter(|&r| r != stuck)
        .max_by_key(|&r| base.allocated.tasks[r].len())
        .unwrap();
    // A judge that no plan satisfies: every hand-over is tried, then every relief.
    let seen = judged_waiting((&cell, &table, &s, &mut cache, &base), (stuck, waited, 5.0));
    end[stuck] += 5.0;
    let mut waits = vec![vec![0.0; m]; m];
    waits[stuck][waited] = 5.0;
    // Which robot gave a task to which, in each plan judged.
    let moved = |o: &plan::Outcome| -> (usize, usize) {
        let (mut from, mut to) = (None, None);
        for r in 0..m {
            let (now, was) = (&o.allocated.tasks[r], &base.allocated.tasks[r]);
            if was.iter().any(|t| !now.contains(t)) {
                assert!(from.replace(r).is_none(), "two robots gave tasks");
            }
            if now.iter().any(|t| !was.contains(t)) {
                assert!(to.replace(r).is_none(), "two robots took tasks");
            }
        }
        (from.expect("a task given"), to.expect("a task taken"))
    };
    let kinds: Vec<(usize, usize)> = seen.iter().map(moved).collect();
    let direct = kinds.iter().take_while(|k| k.0 == stuck).count();
    let reliefs = kinds[direct..].iter().take_while(|k| k.0 != stuck).count();
    let relief = &kinds[direct..direct + reliefs];
    // No group: the busiest robot has no room under the cap for the last one's tasks (the
    // next test gives the wait to a robot that has). Then more direct hand-overs (the README
    // cell is small enough), on their own budget.
    let more = &kinds[direct + reliefs..];
    assert!(direct <= REBALANCE_JUDGED, "{direct} direct hand-overs judged");
    assert!(
        (1..=MORE_JUDGED).contains(&more.len()) && more.iter().all(|k| k.0 == stuck),
        "{kinds:?}"
    );
    // None of them is one judged before.
    for (i, o) in seen.iter().enumerate().skip(direct + reliefs) {
        assert!(
            seen[..direct]
                .iter()
                .all(|p| p.allocated.tasks != o.allocated.tasks),
            "plan {i} judged again"
        );
    }
    assert!(
        (1..=RELIEF_JUDGED.min(RELIEF_PLANS)).contains(&relief.len()),
        "{} reliefs judged: {kinds:?}",
        relief.len()
    );
    for &(from, to) in relief {
        assert_eq!(from, waited, "{kinds:?}");
        assert!(to != stuck && to != waited, "{kinds:?}");
    }
    for o in &seen[direct..] {
        let fixed = PlanSettings {
            tasks: Some(o.allocated.tasks.clone()),
            ..s.clone()
        };
        build_checked(&cell, &table, o, &fixed);
    }
    // The caller's work budget is asked before every plan, `Beyond` for a relief or a group
    // and `Within` for a hand-over: the hand-overs' asks first, then the reliefs', then the
    // more hand-overs' (no reorder: no wait names its task).
    let asked = std::cell::RefCell::new(Vec::new());
    let mut judge =
        |_: &plan::Outcome, _: Option<(&plan::Outcome, &())>| -> Option<(f64, Vec<f64>, ())> { None };
    let mut cache = plan::PlanCache::default();
    rebalance(
        &cell,
        &table,
        (
            &base,
            makespan(&base) + 5.0,
            &end,
            &Waits {
                totals: waits,
                stalls: Vec::new(),
            },
        ),
        &s,
        &mut cache,
        &|ask| {
            asked.borrow_mut().push(ask == plan::rebalance::Ask::Beyond);
            true
        },
        (&mut judge, &|_| unreachable!("no plan is taken")),
    )
    .unwrap();
    let asked = asked.into_inner();
    let hand_overs = asked.iter().take_while(|r| !**r).count();
    let beyond = asked[hand_overs..].iter().take_while(|r| **r).count();
    assert!(hand_overs >= direct, "{asked:?}");
    assert!(beyond >= relief.len(), "{asked:?}");
    assert!(
        asked[hand_overs + beyond..].iter().all(|r| !*r) && asked.len() - hand_overs - beyond >= more.len(),
        "{asked:?}"
    );
}

/// When single tasks do not help, the robot that ends last hands groups of its tasks (two or
/// more) to a robot it waits for that can take them, within a budget of their own; each
/// group's plan re-checks clean.
#[test]
fn the_last_robot_hands_groups_of_tasks_to_the_robot_it_waits_for() {
    use plan::rebalance::{GROUP_JUDGED, ends};
    let (cell, table, s, mut cache, base) = readme_nearest();
    let m = cell.robots.len();
    let end = ends(&base);
    let stuck = last_robot(&end);
    // The robot that can take most of the last one's tasks (within its room under the cap)
    // waited for 5 s.
    let can = |r: usize| {
        let able = base.allocated.tasks[stuck]
            .iter()
            .filter(|&&t| table.robots_for(t).iter().any(|x| x.0 == r))
            .count();
        able.min(
            cell.planning
                .task_cap
                .saturating_sub(base.allocated.tasks[r].len()),
        )
    };
    let waited = (0..m).filter(|&r| r != stuck).max_by_key(|&r| can(r)).unwrap();
    assert!(can(waited) >= 2, "the README cell's nearest plan shares tasks");
    let seen = judged_waiting((&cell, &table, &s, &mut cache, &base), (stuck, waited, 5.0));
    let given = |o: &plan::Outcome, r: usize| {
        base.allocated.tasks[r]
            .iter()
            .filter(|t| !o.allocated.tasks[r].contains(t))
            .count()
    };
    let groups: Vec<&plan::Outcome> = seen.iter().filter(|o| given(o, stuck) >= 2).collect();
    assert!(
        (1..=GROUP_JUDGED).contains(&groups.len()),
        "{} groups judged of {}",
        groups.len(),
        seen.len()
    );
    for o in groups {
        // The group goes to the robot waited for, whole; the other robots keep their tasks.
        for (r, (now, was)) in o.allocated.tasks.iter().zip(&base.allocated.tasks).enumerate() {
            if r == stuck {
                continue;
            }
            let new = now.iter().filter(|t| !was.contains(t)).count();
            if r == waited {
                assert_eq!((given(o, r), new), (0, given(o, stuck)), "robot {r}");
            } else {
                assert_eq!(now, was, "robot {r}");
            }
        }
        let fixed = PlanSettings {
            tasks: Some(o.allocated.tasks.clone()),
            ..s.clone()
        };
        build_checked(&cell, &table, o, &fixed);
    }
}

/// A hand-over whose plan keeping the other robots' programs does not help is planned again
/// with every robot sequenced anew (other paths, which may meet less): the judge gets the two
/// plans of one allocation, the kept one first, and never the same plan twice; the budgets hold.
#[test]
fn a_hand_over_that_does_not_help_is_tried_with_every_robot_sequenced_again() {
    use plan::rebalance::{MORE_JUDGED, MORE_PLANS, REBALANCE_JUDGED, REBALANCE_PLANS};
    let (cell, table, s, mut cache, base) = readme_nearest();
    let mut seen: Vec<plan::Outcome> = Vec::new();
    // A judge that no plan satisfies: every hand-over's plans are judged, none kept.
    let mut judge = |o: &plan::Outcome, _: Option<(&plan::Outcome, &())>| -> Option<(f64, Vec<f64>, ())> {
        seen.push(o.clone());
        None
    };
    let (found, clock) = rebalanced(&cell, &table, &base, &s, &mut cache, &mut judge);
    assert!(found.is_none() && !clock);
    assert!(
        (2..=REBALANCE_JUDGED + MORE_JUDGED).contains(&seen.len()),
        "{} judged",
        seen.len()
    );
    let mut pairs = 0;
    for w in seen.windows(2) {
        let (kept, fresh) = (&w[0], &w[1]);
        let programs = |o: &plan::Outcome| o.robots.iter().map(|r| r.program.clone()).collect::<Vec<_>>();
        assert_ne!(programs(kept), programs(fresh), "the same plan judged twice");
        if kept.allocated.tasks != fresh.allocated.tasks {
            continue;
        }
        pairs += 1;
        // The kept plan: robots of unchanged tasks have the base's programs or shorter ones.
        for (r, (now, was)) in kept.robots.iter().zip(&base.robots).enumerate() {
            if kept.allocated.tasks[r] == base.allocated.tasks[r] {
                assert!(
                    now.program.duration() <= was.program.duration() + 1e-9,
                    "robot {r}"
                );
            }
        }
    }
    assert!(pairs >= 1, "no allocation was tried both ways");
    assert!(seen.len() <= REBALANCE_PLANS + MORE_PLANS);
    for o in &seen {
        let fixed = PlanSettings {
            tasks: Some(o.allocated.tasks.clone()),
            ..s.clone()
        };
        build_checked(&cell, &table, o, &fixed);
    }
}
