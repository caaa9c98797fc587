//! Sequencing with lazily planned legs on the reduced two-robot example: the lazy bar, what
//! the planned legs answer before any search, and tasks given up without losing the plan.
mod common;
use cellplan_core::candidates::generate;
use cellplan_core::document as output;
use cellplan_core::plan::{self, Allocation};
use cellplan_model::robot::Scratch;
use cellplan_model::{LoadOptions, TaskId};
use cellplan_optical::load;
use cellplan_optical::testing::example_copy;
use common::*;

/// The lazy bar: a robot whose best order cannot finish below the bar stops before planning a
/// leg; with no bar it finishes, and its real time is what the bar is measured against.
#[test]
fn sequencing_against_a_bar_stops_before_planning() {
    let f = fixture();
    let s = settings(Allocation::Balanced);
    let robot = &f.cell.robots[0];
    let graph =
        plan::graph::RobotGraph::new(&f.cell, robot, &f.table, plan::MoveModel::Trapezoid, 8, s.roomy);
    let tasks: Vec<TaskId> = (0..f.cell.tasks.len())
        .map(TaskId)
        .filter(|&t| !graph.alternatives[t.0].is_empty())
        .take(3)
        .collect();
    assert_eq!(tasks.len(), 3, "the robot measures at least three MPs");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(3600);
    let measure = cellplan_optical::of(&f.cell).unwrap().measure_time;
    // Three measurements alone take longer than this bar.
    let bar = 3.0 * measure - 1e-3;
    let run = |bar: f64, planned: &mut plan::sequence::Planned| {
        plan::sequence::sequence(&f.cell, robot, &graph, &tasks, &s, deadline, bar, None, planned).unwrap()
    };
    let mut planned = plan::sequence::Planned::new();
    let beaten = run(bar, &mut planned);
    assert!(beaten.beaten && beaten.nodes.is_empty() && beaten.legs.is_empty());
    assert!(planned.is_empty(), "no leg planned for a hopeless allocation");
    let done = run(f64::INFINITY, &mut planned);
    assert!(!done.beaten);
    assert_eq!(done.nodes.len(), 3);
    assert_eq!(done.legs.len(), 4);
    let real = plan::sequence::order_cost(&graph, &planned, &done.nodes);
    assert!(real < plan::sequence::NO_PATH && real > 3.0 * measure);
    // A bar just above the real time does not stop it.
    let kept = run(real + 1.0, &mut planned.clone());
    assert!(!kept.beaten);
}

/// What the planned legs say is used before any search: a leg between two nodes that planned
/// legs join is those legs end to end (shortcut), from one end to the other and clear of the
/// scene at the clearance (re-sampled at 1 mrad), with no sampling; a node a full search from
/// home's component did not reach is never searched again, and once two candidates of a task
/// are such nodes, none of its other candidates outside home's component is.
#[test]
fn planned_legs_join_nodes_and_unreached_nodes_are_not_searched_again() {
    use cellplan_motion::plan::PlanError as Motion;
    use plan::sequence::{Leg, Planned, Reach};
    let f = fixture();
    let cell = &f.cell;
    let s = settings(Allocation::Balanced);
    let robot = &cell.robots[0];
    let graph = plan::graph::RobotGraph::new(cell, robot, &f.table, plan::MoveModel::Trapezoid, 8, s.roomy);
    let full = s.final_max_samples;
    // Two candidates with straight legs home → a → b (planned the way the sequencer plans).
    let none = Planned::new();
    let reach = Reach::of(&graph, &none, full);
    let straight = |a: usize, b: usize| {
        reach
            .leg(cell, robot, &graph, &none, a, b, &s, false)
            .ok()
            .filter(|l| l.straight)
    };
    let nodes: Vec<usize> = (1..graph.len()).collect();
    let (a, b, home_a, a_b) = nodes
        .iter()
        .filter_map(|&a| straight(0, a).map(|l| (a, l)))
        .find_map(|(a, home_a)| {
            nodes
                .iter()
                .filter(|&&b| b > a && graph.node_task[b].map(|x| x.0) != graph.node_task[a].map(|x| x.0))
                .find_map(|&b| straight(a, b).map(|l| (a, b, home_a.clone(), l)))
        })
        .expect("two candidates with straight legs from home");
    let mut planned = Planned::new();
    planned.insert((0, a), Ok(home_a.clone()));
    planned.insert((a, b), Ok(a_b.clone()));
    let reach = Reach::of(&graph, &planned, full);
    assert!(reach.joined(0, b) && !reach.is_cut_off(b));
    let joined: Leg = reach
        .leg(cell, robot, &graph, &planned, 0, b, &s, true)
        .expect("the planned legs join home and b");
    assert_eq!(joined.samples, 0, "no sampling for joined nodes");
    assert!(dist(&joined.waypoints[0], &graph.q[0]) < 1e-12);
    assert!(dist(joined.waypoints.last().unwrap(), &graph.q[b]) < 1e-12);
    let mut scratch = Scratch::default();
    for w in joined.waypoints.windows(2) {
        let steps = (dist(&w[0], &w[1]) / 1e-3).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(x, y)| x + t * (y - x)).collect();
            assert!(robot.within_limits(&q));
            robot.body_poses(&q, &mut scratch);
            assert!(
                robot
                    .contact_at(&cell.world, &scratch, cell.planning.clearance - 1e-6)
                    .is_none(),
                "the joined leg comes closer than the clearance at {q:?}"
            );
        }
    }
    // A full search from home's component that found nothing cuts the node off; a search
    // between two nodes outside it does not.
    let task_nodes = |n: usize| graph.alternatives[graph.node_task[n].unwrap().0.0].clone();
    let other = (1..graph.len())
        .find(|&n| {
            !reach.joined(n, 0)
                && task_nodes(n).len() >= 4
                && task_nodes(n).iter().all(|&m| !reach.joined(m, 0))
        })
        .expect("a task with four candidates outside home's component");
    let siblings = task_nodes(other);
    let failed = |samples| {
        Err(plan::LegError::Motion(Motion::NoPath {
            samples,
            validity_calls: 10 * samples,
        }))
    };
    let mut cut = planned.clone();
    cut.insert((a, siblings[0]), failed(full));
    cut.insert(
        (siblings[2].min(siblings[3]), siblings[2].max(siblings[3])),
        failed(full),
    );
    let reach = Reach::of(&graph, &cut, full);
    assert!(reach.is_cut_off(siblings[0]));
    assert!(
        !reach.is_cut_off(siblings[1]),
        "one cut-off candidate leaves the task's others"
    );
    assert!(!reach.is_cut_off(siblings[2]) && !reach.is_cut_off(siblings[3]));
    match reach.leg(cell, robot, &graph, &cut, b, siblings[0], &s, true) {
        Err(plan::LegError::Unreached(u)) => assert_eq!(u.samples, full),
        other => panic!("a cut-off node is searched again: {other:?}"),
    }
    // A quick failure is no proof.
    let mut quick = planned.clone();
    quick.insert((a, siblings[0]), failed(60));
    assert!(!Reach::of(&graph, &quick, full).is_cut_off(siblings[0]));
    // Two candidates cut off: the task is given up on this robot.
    cut.insert((0, siblings[1]), failed(full));
    let reach = Reach::of(&graph, &cut, full);
    assert!(siblings.iter().all(|&n| reach.is_cut_off(n)));
    assert!(!reach.is_cut_off(a) && !reach.is_cut_off(b) && !reach.is_cut_off(0));
}

/// `settings(allocation)` with one sample per leg search, no roadmap and one candidate per
/// task: every leg that is not a straight segment fails.
fn without_sampling(allocation: Allocation) -> plan::PlanSettings {
    let mut s = settings(allocation);
    s.motion.max_samples = 1;
    s.final_max_samples = 1;
    s.roadmap = false;
    s.alternatives = 1;
    s
}

/// A leg the sampler cannot solve never loses the plan: with no samples at all (and no
/// roadmap), every leg that is not a straight segment fails; a task every order reaches only through such legs
/// is given up by its robot, tried on the other robot, and listed unmeasured (`no-path`, with
/// the planner's words) — the rest is planned and the verifier accepts the plan.
#[test]
fn a_task_without_a_path_is_given_up_and_the_rest_planned() {
    let f = fixture();
    let s = without_sampling(Allocation::Balanced);
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).expect("a plan despite the legs");
    let doc = build(&f.cell, &f.table, &outcome, &s);
    assert!(
        !outcome.unreached.is_empty(),
        "this budget must leave some task without a path"
    );
    for u in &outcome.unreached {
        let name = &f.cell.tasks[u.0.0].name;
        let listed = doc.unmeasured.iter().find(|x| &x.task == name).expect("listed");
        assert_eq!(listed.reason, output::NO_PATH);
        assert!(
            listed
                .detail
                .as_deref()
                .is_some_and(|d| d.contains("no collision-free path"))
        );
        assert!(doc.robots.iter().all(|r| r.tasks.iter().all(|v| &v.task != name)));
    }
    let done: usize = doc.robots.iter().map(|r| r.tasks.len()).sum();
    assert_eq!(done + doc.unmeasured.len(), f.cell.tasks.len());
    assert!(done > 0);
    check_plan(&f.cell, &doc);
    verified(&f.cell, &doc);
    // With the robots at (or next to) their task cap, a task given up stays unmeasured rather
    // than push a robot over its cap (a random task set of `compare` once did: 15 MPs under
    // φ = 14, which the verifier rejected).
    let path = example_copy("plan-test-capped", "autobody-2r-small", 8, |text| {
        let t = text.replace("task_cap = 14", "task_cap = 4");
        assert!(t.contains("task_cap = 4"));
        t
    });
    let cell = load(&path, &LoadOptions::default()).expect("the capped cell loads");
    let table = generate(&cell);
    let outcome = plan::plan(&cell, &table, &s, &|_| {}).expect("a plan despite the legs");
    assert!(!outcome.unreached.is_empty());
    assert!(outcome.allocated.tasks.iter().all(|t| t.len() <= 4));
    let doc = build(&cell, &table, &outcome, &s);
    check_plan(&cell, &doc);
    verified(&cell, &doc);
}

/// A plan that gives up tasks is still balanced on its real times: the hand-overs move only
/// tasks some robot measures, the tasks given up stay given up with their reasons in every
/// plan the rebalancing makes, and a plan kept from it verifies and lists them unmeasured.
#[test]
fn a_plan_that_gives_up_tasks_is_still_rebalanced() {
    use plan::rebalance::{ends, makespan};
    let f = fixture();
    let s = without_sampling(Allocation::Proximity);
    let mut cache = plan::PlanCache::default();
    let base =
        plan::plan_cached(&f.cell, &f.table, &s, &|_| {}, &mut cache).expect("a plan despite the legs");
    assert!(
        !base.unreached.is_empty(),
        "this budget must leave some task without a path"
    );
    let given_up: Vec<TaskId> = base.unreached.iter().map(|u| u.0).collect();
    let judged = std::cell::Cell::new(0);
    let mut judge = |o: &plan::Outcome, _: Option<(&plan::Outcome, &())>| {
        judged.set(judged.get() + 1);
        assert_eq!(
            o.unreached, base.unreached,
            "the tasks given up, with their reasons"
        );
        for t in &given_up {
            assert!(o.allocated.tasks.iter().all(|r| !r.contains(t)));
        }
        Some((makespan(o), ends(o), ()))
    };
    let before = makespan(&base);
    let (found, clock) = rebalanced(&f.cell, &f.table, &base, &s, &mut cache, &mut judge);
    assert!(!clock);
    assert!(judged.get() >= 1, "no hand-over was judged");
    let (o, fixed, ()) = found.expect("the nearest robots are unbalanced here");
    assert!(makespan(&o) < before - 1e-6);
    let doc = build_checked(&f.cell, &f.table, &o, &fixed);
    for t in &given_up {
        let name = &f.cell.tasks[t.0].name;
        let listed = doc.unmeasured.iter().find(|x| &x.task == name).expect("listed");
        assert_eq!(listed.reason, output::NO_PATH);
    }
    let done: usize = doc.robots.iter().map(|r| r.tasks.len()).sum();
    assert_eq!(done + doc.unmeasured.len(), f.cell.tasks.len());
}
