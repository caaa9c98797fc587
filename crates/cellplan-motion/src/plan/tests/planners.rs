//! The conformance suite every planner of the registry passes, and the tests of goal sets,
//! budgets, the PRM roadmap and RRT*'s anytime behaviour.
use super::*;
use std::collections::BTreeSet;

fn params(seed: u64) -> PlannerParams {
    PlannerParams {
        seed,
        ..PlannerParams::default()
    }
}

/// Solves with a fresh planner of the registry; checks that the work counts every validity
/// call the checker saw.
fn solve(name: &str, p: &PlannerParams, problem: &Problem, v: &Discs, stop: &Termination) -> PlanResult {
    let before = v.calls.load(Ordering::Relaxed);
    let mut planner = (planner(name).unwrap().build)(p);
    let result = planner.solve(problem, stop);
    let seen = v.calls.load(Ordering::Relaxed) - before;
    assert_eq!(result.work.validity_calls, seen, "{name}: {:?}", result.status);
    result
}

/// The path starts at the start, ends at the goal it names, and every edge passes the
/// segment check and a dense sampling.
fn assert_valid_path(name: &str, problem: &Problem, v: &Discs, r: &PlanResult) {
    assert_eq!(r.status, Status::Solved, "{name}");
    let goal = r.goal.expect("a goal");
    assert_eq!(r.waypoints.first().unwrap().as_slice(), problem.start, "{name}");
    assert_eq!(r.waypoints.last().unwrap(), &problem.goals[goal], "{name}");
    for w in r.waypoints.windows(2) {
        let check = check_segment(problem.space, v, &w[0], &w[1], problem.min_clearance);
        assert!(check.valid, "{name}: edge {w:?}");
    }
    assert!(brute_force_valid(v, &r.waypoints, 1e-3), "{name}");
}

/// A ring of discs around (8, 8): a goal at its centre is valid but unreachable.
fn ring() -> Vec<(Vec<f64>, f64)> {
    (0..40)
        .map(|k| {
            let a = k as f64 / 40.0 * std::f64::consts::TAU;
            (vec![8.0 + 1.5 * a.cos(), 8.0 + 1.5 * a.sin()], 0.2)
        })
        .collect()
}

#[test]
fn registry_names_are_unique_kebab_case() {
    let mut seen = BTreeSet::new();
    for e in planners() {
        let kebab = e.name.split('-').all(|w| {
            !w.is_empty()
                && w.starts_with(|c: char| c.is_ascii_lowercase())
                && w.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit())
        });
        assert!(kebab, "{}", e.name);
        assert!(seen.insert(e.name), "{} twice", e.name);
        assert!(!e.summary.is_empty());
        assert_eq!((e.build)(&PlannerParams::default()).name(), e.name);
        assert_eq!(planner(e.name).unwrap().name, e.name);
    }
    for name in ["straight", "rrt-connect", "rrt-star", "prm", "leg"] {
        assert!(seen.contains(name), "{name}");
    }
    let err = planner("rrt").unwrap_err();
    assert_eq!(err.valid, planners().iter().map(|e| e.name).collect::<Vec<_>>());
    let message = err.to_string();
    assert!(message.contains("`rrt`"), "{message}");
    for name in &seen {
        assert!(message.contains(name), "{message}");
    }
}

#[test]
fn every_planner_solves_a_trivial_case() {
    let space = square(2, 10.0);
    let v = wall();
    let goals = [vec![9.0, 9.5]];
    let problem = Problem::new(&space, &v, &[1.0, 9.5], &goals);
    for e in planners() {
        let r = solve(e.name, &params(1), &problem, &v, &Termination::samples(2_000));
        assert_valid_path(e.name, &problem, &v, &r);
        assert_eq!(r.goal, Some(0));
        assert!(!r.work.clock_bound);
    }
}

#[test]
fn every_planner_goes_around_the_wall() {
    let space = square(2, 10.0);
    let v = wall();
    let goals = [vec![9.0, 1.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    let stop = Termination::samples(3_000);
    for e in planners() {
        for seed in 0..3 {
            let r = solve(e.name, &params(seed), &problem, &v, &stop);
            if e.name == "straight" {
                assert_eq!(r.status, Status::Infeasible);
                assert!(r.waypoints.is_empty() && r.goal.is_none());
                assert_eq!(r.work.samples, 0);
                continue;
            }
            assert_valid_path(e.name, &problem, &v, &r);
            assert!(!r.straight, "{}", e.name);
            assert!(r.waypoints.iter().any(|q| q[1] > 8.3), "{}", e.name);
            assert!(r.work.samples > 0, "{}", e.name);
            assert!(r.work.simplify_calls > 0 && r.work.simplify_calls < r.work.validity_calls);
        }
    }
}

#[test]
fn every_planner_is_reproducible_for_a_seed() {
    let space = square(2, 10.0);
    let v = wall();
    let goals = [vec![9.0, 1.0], vec![9.0, 3.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    let stop = Termination::samples(2_000);
    for e in planners() {
        let a = solve(e.name, &params(5), &problem, &v, &stop);
        let b = solve(e.name, &params(5), &problem, &v, &stop);
        assert_eq!(a.status, b.status, "{}", e.name);
        assert_eq!(a.waypoints, b.waypoints, "{}", e.name);
        assert_eq!(a.goal, b.goal, "{}", e.name);
        assert_eq!(a.work.samples, b.work.samples, "{}", e.name);
        assert_eq!(a.work.validity_calls, b.work.validity_calls, "{}", e.name);
        if e.name != "straight" {
            // Another seed, another path.
            let c = solve(e.name, &params(6), &problem, &v, &stop);
            assert!(c.status.is_solved());
            assert_ne!(a.waypoints, c.waypoints, "{}", e.name);
        }
    }
}

#[test]
fn every_planner_honours_the_work_budget() {
    let space = square(2, 10.0);
    let v = Discs::new(ring(), 0.01);
    let blocked = [vec![8.0, 8.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &blocked);
    for e in planners() {
        let by_samples = solve(e.name, &params(3), &problem, &v, &Termination::samples(200));
        let by_calls = Termination::samples(1_000_000).with_max_validity_calls(400);
        let by_calls = solve(e.name, &params(3), &problem, &v, &by_calls);
        if e.name == "straight" {
            assert_eq!(by_samples.status, Status::Infeasible);
            assert_eq!(by_calls.status, Status::Infeasible);
            continue;
        }
        assert_eq!(by_samples.status, Status::BudgetExhausted, "{}", e.name);
        assert_eq!(by_samples.work.samples, 200, "{}", e.name);
        assert!(by_samples.waypoints.is_empty() && by_samples.goal.is_none());
        assert_eq!(by_calls.status, Status::BudgetExhausted, "{}", e.name);
        assert!(by_calls.work.validity_calls >= 400, "{}", e.name);
        assert!(by_calls.work.samples < 1_000_000, "{}", e.name);
        assert!(!by_samples.work.clock_bound && !by_calls.work.clock_bound);
        // A wall clock that has run out stops the search and says so.
        let stop = Termination::samples(200).with_time_limit(Duration::ZERO);
        let timed = solve(e.name, &params(3), &problem, &v, &stop);
        assert_eq!(timed.status, Status::Timeout, "{}", e.name);
        assert!(timed.work.clock_bound && timed.work.samples == 0, "{}", e.name);
    }
    // The straight planner checks further goals only within the budget.
    let wall = wall();
    let goals = [vec![9.0, 1.0], vec![9.0, 2.0]];
    let problem = Problem::new(&space, &wall, &[1.0, 1.0], &goals);
    let stop = Termination::default().with_max_validity_calls(3);
    let r = solve("straight", &params(0), &problem, &wall, &stop);
    assert_eq!(r.status, Status::BudgetExhausted);
}

#[test]
fn every_planner_reports_invalid_ends() {
    let space = square(2, 10.0);
    let v = wall();
    let stop = Termination::samples(500);
    let ok_goal = vec![9.0, 1.0];
    for e in planners() {
        let goals = [ok_goal.clone()];
        let p = Problem::new(&space, &v, &[5.0, 2.0], &goals);
        let r = solve(e.name, &params(0), &p, &v, &stop);
        assert_eq!(r.status, Status::InvalidStart, "{}", e.name);
        assert!(r.start_clearance < 0.0 && r.goal_clearances[0].is_nan());
        // The test against the floor, then the measure for the report.
        assert_eq!(r.work.validity_calls, 2);
        // Outside the limits: no call at all.
        let p = Problem::new(&space, &v, &[-1.0, 1.0], &goals);
        let r = solve(e.name, &params(0), &p, &v, &stop);
        assert_eq!(r.status, Status::InvalidStart);
        assert_eq!(r.start_clearance, f64::NEG_INFINITY);
        // Every goal invalid: inside a disc, outside the limits, NaN.
        let goals = [vec![5.0, 8.2], vec![11.0, 1.0], vec![9.0, f64::NAN]];
        let p = Problem::new(&space, &v, &[1.0, 1.0], &goals);
        let r = solve(e.name, &params(0), &p, &v, &stop);
        assert_eq!(r.status, Status::InvalidGoal, "{}", e.name);
        assert!(r.goal_clearances.iter().all(|&c| c < 0.0 || c.is_nan()));
        assert!(matches!(r.into_planned(), Err(PlanError::GoalInvalid { clearance }) if clearance < 0.0));
        // Invalid goals among valid ones are skipped.
        let goals = [vec![5.0, 8.2], vec![1.0, 9.0]];
        let p = Problem::new(&space, &v, &[1.0, 1.0], &goals);
        let r = solve(e.name, &params(0), &p, &v, &stop);
        assert_valid_path(e.name, &p, &v, &r);
        assert_eq!(r.goal, Some(1), "{}", e.name);
    }
}

#[test]
fn goal_sets_pick_a_reachable_goal_when_the_first_is_blocked() {
    let space = square(2, 10.0);
    let mut discs = ring();
    discs.extend(wall().discs);
    let v = Discs::new(discs, 0.01);
    // Goal 0 is inside the ring (valid, unreachable); goal 1 is beyond the wall.
    let goals = [vec![8.0, 8.0], vec![9.0, 1.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    for e in planners() {
        if e.name == "straight" {
            continue;
        }
        let r = solve(e.name, &params(2), &problem, &v, &Termination::samples(3_000));
        assert_valid_path(e.name, &problem, &v, &r);
        assert_eq!(r.goal, Some(1), "{}", e.name);
    }
    // The straight planner takes the first goal it sees directly.
    let goals = [vec![9.0, 1.0], vec![4.0, 1.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    let r = solve("straight", &params(0), &problem, &v, &Termination::default());
    assert_valid_path("straight", &problem, &v, &r);
    assert_eq!(r.goal, Some(1));
    assert!(r.straight);
}

#[test]
fn a_reused_prm_roadmap_makes_fewer_validity_calls() {
    let space = square(2, 10.0);
    let v = wall();
    let p = PlannerParams {
        simplify: false,
        ..params(4)
    };
    let stop = Termination::samples(5_000);
    let first_goals = [vec![9.0, 1.0]];
    let first = Problem::new(&space, &v, &[1.0, 1.0], &first_goals);
    let second_goals = [vec![8.5, 2.5]];
    let second = Problem::new(&space, &v, &[1.5, 2.0], &second_goals);

    let mut kept = Prm::new(&p);
    let r1 = kept.solve(&first, &stop);
    assert_valid_path("prm", &first, &v, &r1);
    let nodes = kept.roadmap().len();
    let checked = kept.roadmap().checked_edge_count();
    assert!(nodes > 2 && checked >= r1.waypoints.len() - 1);
    assert!(kept.roadmap().edge_count() > checked);
    let reused = kept.solve(&second, &stop);
    assert_valid_path("prm", &second, &v, &reused);

    let fresh = Prm::new(&p).solve(&second, &stop);
    assert_valid_path("prm", &second, &v, &fresh);
    assert!(
        reused.work.validity_calls < fresh.work.validity_calls,
        "reused {} fresh {}",
        reused.work.validity_calls,
        fresh.work.validity_calls
    );
    assert!(reused.work.samples < fresh.work.samples);

    // A roadmap handed over gives what keeping the planner gives.
    let mut again = Prm::new(&p);
    again.solve(&first, &stop);
    let mut handed = Prm::with_roadmap(&p, again.into_roadmap());
    assert_eq!(handed.solve(&second, &stop).waypoints, reused.waypoints);

    // Another space: the roadmap starts afresh.
    let other = space.clone().with_weights(vec![1.0, 2.0]);
    let third = Problem::new(&other, &v, &[1.5, 2.0], &second_goals);
    let r3 = kept.solve(&third, &stop);
    assert!(r3.status.is_solved());
    // Its nodes: the query's two and the valid samples of this query.
    assert!(
        kept.roadmap().len() <= r3.work.samples + 2,
        "the old nodes are gone"
    );
}

#[test]
fn rrt_star_cost_does_not_increase_with_more_samples() {
    let space = square(2, 10.0);
    let v = wall();
    let goals = [vec![9.0, 1.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    let p = PlannerParams {
        simplify: false,
        ..params(11)
    };
    let mut costs = Vec::new();
    for budget in [400, 800, 1_600, 3_200] {
        let r = RrtStar { params: p.clone() }.solve(&problem, &Termination::samples(budget));
        assert_valid_path("rrt-star", &problem, &v, &r);
        assert_eq!(r.work.samples, budget, "anytime: it spends the budget");
        assert_eq!(r.work.simplify_calls, 0);
        assert_eq!(r.work.simplify_time, Duration::ZERO);
        costs.push(r.length(&space));
    }
    for w in costs.windows(2) {
        assert!(w[1] <= w[0] + 1e-12, "{costs:?}");
    }
    assert!(costs[3] < costs[0], "{costs:?}");
    let shortest = 2.0 * ((4.0f64).powi(2) + (7.35f64).powi(2)).sqrt();
    assert!(costs[3] < 1.3 * shortest, "{costs:?}");
}

#[test]
fn rrt_star_gives_an_approximate_path_when_asked() {
    let space = square(2, 10.0);
    let v = Discs::new(ring(), 0.01);
    let goals = [vec![8.0, 8.0]];
    let start = [1.0, 1.0];
    let problem = Problem::new(&space, &v, &start, &goals);
    let p = PlannerParams {
        approximate: true,
        ..params(1)
    };
    let r = RrtStar { params: p }.solve(&problem, &Termination::samples(500));
    assert_eq!(r.status, Status::Approximate);
    assert_eq!(r.goal, Some(0));
    assert_eq!(r.waypoints[0], start.to_vec());
    let end = r.waypoints.last().unwrap();
    assert!(space.distance(end, &goals[0]) < 2.0, "{end:?}");
    assert!(brute_force_valid(&v, &r.waypoints, 1e-3));
    assert!(matches!(
        r.into_planned(),
        Err(PlanError::NoPath { samples: 500, .. })
    ));
}

/// RRT-Connect with and without the VAMP tuning (dynamic domains, balanced trees): both solve
/// the wall and the ring's outside, with valid paths, and the tuning changes the search; a
/// cell's legs keep the OMPL-like search.
#[test]
fn rrt_connect_tuning_solves_and_cells_keep_the_ompl_search() {
    let space = square(2, 10.0);
    let v = wall();
    let goals = [vec![9.0, 1.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    let stop = Termination::samples(5_000);
    let mut calls = Vec::new();
    for (dynamic_domain, balance) in [(false, false), (true, false), (false, true), (true, true)] {
        let mut total = 0;
        for seed in 0..4 {
            let p = PlannerParams {
                dynamic_domain,
                balance,
                ..params(seed)
            };
            let r = solve("rrt-connect", &p, &problem, &v, &stop);
            assert_valid_path("rrt-connect", &problem, &v, &r);
            total += r.work.validity_calls;
        }
        calls.push(total);
    }
    assert!(calls[1..].iter().any(|&c| c != calls[0]), "{calls:?}");
    let cell = PlanSettings::default().params();
    assert!(!cell.dynamic_domain && !cell.balance && cell.range_share == 0.2);
    let standalone = PlannerParams::default();
    assert!(standalone.dynamic_domain && standalone.balance && standalone.range_share == 0.1);
}

/// Shortcuts that would gain little are left unchecked with `skip_small_shortcuts`: fewer
/// simplification checks over eight seeds, every path still valid and never longer than the
/// raw one.
#[test]
fn small_shortcuts_left_unchecked_save_checks() {
    let space = square(2, 10.0);
    let v = wall();
    let goals = [vec![9.0, 1.0]];
    let problem = Problem::new(&space, &v, &[1.0, 1.0], &goals);
    let stop = Termination::samples(5_000);
    let mut calls = [0, 0];
    for (i, skip_small_shortcuts) in [false, true].into_iter().enumerate() {
        for seed in 0..8 {
            let raw = solve(
                "leg",
                &PlannerParams {
                    simplify: false,
                    ..params(seed)
                },
                &problem,
                &v,
                &stop,
            );
            let p = PlannerParams {
                skip_small_shortcuts,
                ..params(seed)
            };
            let r = solve("leg", &p, &problem, &v, &stop);
            assert_valid_path("leg", &problem, &v, &r);
            assert!(path_length(&space, &r.waypoints) <= path_length(&space, &raw.waypoints) + 1e-12);
            calls[i] += r.work.simplify_calls;
        }
    }
    assert!(calls[1] < calls[0], "{calls:?}");
}
