//! Reorders: a robot's tasks left to the end of its tour ([`PlanSettings::late`]), and the
//! reorders `rebalance` tries where a robot waits on its way to a task (see
//! [`plan::rebalance::REORDER_JUDGED`]). Every plan re-checked and verified (see `common`).
mod common;
use cellplan_core::plan::{self, PlanSettings};
use cellplan_model::TaskId;
use common::*;

/// The tasks a robot visits, in its program's order.
fn visits(o: &plan::Outcome, r: usize) -> Vec<TaskId> {
    o.robots[r].program.visits.iter().map(|v| v.task).collect()
}

#[test]
fn late_tasks_end_their_robots_tours() {
    let (cell, table, s, mut cache, base) = readme_nearest();
    // Each robot's first task (of a robot with at least three) is left to the end.
    let late: Vec<TaskId> = (0..cell.robots.len())
        .filter(|&r| base.robots[r].program.visits.len() >= 3)
        .map(|r| visits(&base, r)[0])
        .collect();
    assert!(late.len() >= 2, "the README cell's robots have tasks");
    let fixed = PlanSettings {
        tasks: Some(base.allocated.tasks.clone()),
        late: late.clone(),
        ..s.clone()
    };
    // Kept programs that do not leave their late tasks to the end are not kept.
    let o = plan::plan_keeping(&cell, &table, &fixed, &|_| {}, &mut cache, Some(&base)).unwrap();
    assert!(o.unreached.is_empty());
    for r in 0..cell.robots.len() {
        let (now, was) = (visits(&o, r), visits(&base, r));
        let mut sorted = (now.clone(), was.clone());
        sorted.0.sort();
        sorted.1.sort();
        assert_eq!(sorted.0, sorted.1, "robot {r} keeps its tasks");
        match late.iter().find(|t| was.contains(t)) {
            Some(t) => assert_eq!(now.last(), Some(t), "robot {r}: {now:?}"),
            // A robot without late tasks keeps its program (or a shorter one).
            None => assert!(o.robots[r].program.duration() <= base.robots[r].program.duration() + 1e-9),
        }
    }
    build_checked(&cell, &table, &o, &fixed);
}

/// Where the robot that ends last waits on its way to a task for another robot, `rebalance`
/// tries the plan with that task left to the end of its tour and the one with the other
/// robot's task left to the end of that robot's: the allocation unchanged, every other robot
/// keeping its program, within the reorders' budget. The caller's budget refusing the
/// hand-overs leaves the reorders, asked for as such on a cell this small.
#[test]
fn a_wait_is_tried_with_the_tasks_it_is_about_left_to_the_end() {
    use plan::rebalance::{Ask, REORDER_JUDGED, Stall, Waits, ends, makespan, rebalance};
    let (cell, table, s, mut cache, base) = readme_nearest();
    let m = cell.robots.len();
    let mut end = ends(&base);
    let stuck = last_robot(&end);
    let waited = (stuck + 1) % m;
    // As if the last robot had waited 5 s on its way to its second task for the other robot,
    // then at its third task.
    let (heading, blocker) = (visits(&base, stuck)[1], visits(&base, waited)[2]);
    end[stuck] += 5.0;
    let mut totals = vec![vec![0.0; m]; m];
    totals[stuck][waited] = 5.0;
    let stall = Stall {
        robot: stuck,
        heading: Some(heading),
        seconds: 5.0,
        for_robot: waited,
        blocker: Some(blocker),
    };
    let waits = Waits {
        totals,
        stalls: vec![stall],
    };
    let mut seen: Vec<plan::Outcome> = Vec::new();
    let mut judge = |o: &plan::Outcome, _: Option<(&plan::Outcome, &())>| -> Option<(f64, Vec<f64>, ())> {
        seen.push(o.clone());
        None
    };
    let asked = std::cell::RefCell::new(Vec::new());
    let (found, clock) = rebalance(
        &cell,
        &table,
        (&base, makespan(&base) + 5.0, &end, &waits),
        &s,
        &mut cache,
        &|ask| {
            asked.borrow_mut().push(ask);
            ask != Ask::Within
        },
        (&mut judge, &|_| unreachable!("no plan is taken")),
    )
    .unwrap();
    assert!(found.is_none() && !clock);
    // The first hand-over is refused; then only reorders are asked for.
    let asked = asked.into_inner();
    assert_eq!(asked[0], Ask::Within);
    assert!(
        asked.len() > 1 && asked[1..].iter().all(|&a| a == Ask::Reorder),
        "{asked:?}"
    );
    assert!(
        (1..=REORDER_JUDGED).contains(&seen.len()),
        "{} judged",
        seen.len()
    );
    let mut left = Vec::new();
    for o in &seen {
        assert_eq!(o.allocated.tasks, base.allocated.tasks);
        // One of the two robots leaves its task to the end; every other robot keeps its
        // program or a shorter one.
        let r = if visits(o, stuck).last() == Some(&heading) && visits(&base, stuck).last() != Some(&heading)
        {
            stuck
        } else {
            assert_eq!(visits(o, waited).last(), Some(&blocker));
            waited
        };
        let task = if r == stuck { heading } else { blocker };
        for q in (0..m).filter(|&q| q != r) {
            assert!(o.robots[q].program.duration() <= base.robots[q].program.duration() + 1e-9);
        }
        left.push(r);
        let late = PlanSettings {
            tasks: Some(o.allocated.tasks.clone()),
            late: vec![task],
            ..s.clone()
        };
        build_checked(&cell, &table, o, &late);
    }
    // The waiting robot's task first (longest wait first, then the other robot's).
    assert_eq!(left[0], stuck, "{left:?}");
}
