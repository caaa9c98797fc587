use std::time::Duration;

use super::*;

fn params(method: MinMaxMethod, seed: u64, iters: usize) -> MinMaxParams {
    MinMaxParams {
        time_limit: Duration::from_secs(3600),
        seed,
        max_iterations: Some(iters),
        method,
    }
}

const METHODS: [MinMaxMethod; 3] = [
    MinMaxMethod::Proximity,
    MinMaxMethod::Algorithm1,
    MinMaxMethod::Ils,
];

/// Optimal route time of vehicle `v` over `tasks`: every order, best nodes by DP.
fn best_route(p: &MinMaxProblem, v: usize, tasks: &[usize]) -> f64 {
    let veh = &p.vehicles[v];
    let c = |a: usize, b: usize| veh.costs.get(a, b);
    let mut order = tasks.to_vec();
    let mut best = f64::INFINITY;
    permute(&mut order, 0, &mut |ord| {
        // dp over (position, node).
        let mut prev: Vec<(usize, f64)> = vec![(veh.depot, 0.0)];
        for &t in ord.iter() {
            let next = veh.alternatives[t]
                .iter()
                .map(|&a| {
                    let d = prev
                        .iter()
                        .map(|&(u, du)| du + c(u, a))
                        .fold(f64::INFINITY, f64::min);
                    (a, d + p.service[t])
                })
                .collect();
            prev = next;
        }
        let end = prev
            .iter()
            .map(|&(u, du)| du + c(u, veh.depot))
            .fold(f64::INFINITY, f64::min);
        best = best.min(end);
    });
    best
}

fn permute(a: &mut Vec<usize>, k: usize, f: &mut impl FnMut(&[usize])) {
    if k == a.len() {
        f(a);
        return;
    }
    for i in k..a.len() {
        a.swap(k, i);
        permute(a, k + 1, f);
        a.swap(k, i);
    }
}

/// The optimal makespan of an instance by enumeration (every allocation, every order).
fn brute_force(p: &MinMaxProblem) -> f64 {
    let k = p.vehicles.len();
    let mut best = f64::INFINITY;
    for code in 0..k.pow(p.tasks as u32) {
        let mut sets = vec![Vec::new(); k];
        let mut c = code;
        for t in 0..p.tasks {
            sets[c % k].push(t);
            c /= k;
        }
        let ok = sets
            .iter()
            .enumerate()
            .all(|(v, s)| s.len() <= p.vehicles[v].cap && s.iter().all(|&t| p.can_do(v, t)));
        if ok {
            let span = (0..k).map(|v| best_route(p, v, &sets[v])).fold(0.0, f64::max);
            best = best.min(span);
        }
    }
    best
}

/// The instance with every cap lowered to the least feasible common value.
fn tight(mut p: MinMaxProblem) -> MinMaxProblem {
    while p.vehicles[0].cap > 0 {
        let mut q = p.clone();
        for v in &mut q.vehicles {
            v.cap -= 1;
        }
        if q.validate().is_err() {
            break;
        }
        p = q;
    }
    p
}

#[test]
fn ils_matches_brute_force_on_tiny_instances() {
    let mut baseline_gaps = 0;
    for seed in 0..10 {
        for n in 2..=6 {
            let alts = if seed % 2 == 0 { (1, 1) } else { (1, 2) };
            let mut p = generate(2, n, alts, seed);
            if seed % 3 == 0 {
                p = tight(p);
            }
            let exact = brute_force(&p);
            for method in [MinMaxMethod::Proximity, MinMaxMethod::Algorithm1] {
                let base = solve(&p, &params(method, seed, 0));
                assert!(base.makespan >= exact - 1e-6);
                baseline_gaps += usize::from(base.makespan > exact + 1e-6);
            }
            let sol = solve(&p, &params(MinMaxMethod::Ils, seed, 40));
            sol.routes.check(&p).unwrap();
            assert!(
                (sol.makespan - exact).abs() < 1e-6,
                "seed {seed} n {n}: ILS {} vs optimum {exact}",
                sol.makespan
            );
        }
    }
    assert!(baseline_gaps > 10, "the baselines should often miss the optimum");
}

#[test]
fn every_method_gives_valid_routes() {
    for (seed, (m, n, alts)) in [(4, 45, (2, 4)), (3, 30, (1, 3)), (5, 20, (1, 2))]
        .into_iter()
        .enumerate()
    {
        for p in [
            generate(m, n, alts, seed as u64),
            tight(generate(m, n, alts, seed as u64)),
        ] {
            for method in METHODS {
                let sol = solve(&p, &params(method, 1, 10));
                sol.routes.check(&p).unwrap();
                for (v, t) in sol.routes.tours.iter().enumerate() {
                    assert!(t.len() <= p.vehicles[v].cap);
                }
                let times = sol.routes.times(&p);
                assert_eq!(sol.makespan, sol.routes.makespan(&p));
                assert!((sol.total - times.iter().sum::<f64>()).abs() < 1e-9);
                assert!(sol.balanced);
            }
        }
    }
}

#[test]
fn ils_beats_baselines_on_cell_instances() {
    for seed in 1..=2 {
        let p = generate(4, 45, (10, 40), seed);
        let prox = solve(&p, &params(MinMaxMethod::Proximity, seed, 0));
        let alg1 = solve(&p, &params(MinMaxMethod::Algorithm1, seed, 0));
        let ils = solve(&p, &params(MinMaxMethod::Ils, seed, 15));
        ils.routes.check(&p).unwrap();
        assert!(ils.makespan <= prox.makespan + 1e-9);
        assert!(ils.makespan <= alg1.makespan + 1e-9);
    }
}

#[test]
fn same_seed_same_routes() {
    let p = generate(4, 30, (2, 5), 7);
    for method in METHODS {
        let a = solve(&p, &params(method, 3, 20));
        let b = solve(&p, &params(method, 3, 20));
        assert_eq!(a, b);
    }
}

#[test]
fn balance_limit_is_reported() {
    let mut p = generate(3, 20, (1, 3), 4);
    let free = solve(&p, &params(MinMaxMethod::Ils, 0, 20));
    let times = free.routes.times(&p);
    let spread =
        times.iter().copied().fold(0.0, f64::max) - times.iter().copied().fold(f64::INFINITY, f64::min);
    p.balance_limit = Some(spread + 1.0);
    assert!(solve(&p, &params(MinMaxMethod::Ils, 0, 20)).balanced);
    p.balance_limit = Some(0.0);
    let sol = solve(&p, &params(MinMaxMethod::Ils, 0, 20));
    sol.routes.check(&p).unwrap();
    assert!(!sol.balanced, "route times are never exactly equal here");
}

#[test]
fn a_vehicle_that_can_do_nothing_is_left_out_of_the_balance() {
    let mut p = generate(3, 20, (1, 3), 4);
    let free = solve(&p, &params(MinMaxMethod::Ils, 0, 20));
    let times = free.routes.times(&p);
    let (hi, lo) = (
        times.iter().copied().fold(0.0, f64::max),
        times.iter().copied().fold(f64::INFINITY, f64::min),
    );
    // Counted at its empty route's 0 s, the idle vehicle would break the limit.
    assert!(lo > 1.0, "every working route lasts more than the margin");
    p.balance_limit = Some(hi - lo + 1.0);
    let idle = Vehicle {
        costs: p.vehicles[0].costs.clone(),
        depot: p.vehicles[0].depot,
        cap: 20,
        alternatives: vec![Vec::new(); 20],
    };
    p.vehicles.push(idle);
    p.validate().unwrap();
    let sol = solve(&p, &params(MinMaxMethod::Ils, 0, 20));
    sol.routes.check(&p).unwrap();
    assert!(sol.balanced);
    // A vehicle that could work but is given nothing still counts.
    let mut q = p.clone();
    q.vehicles[3].alternatives = p.vehicles[0].alternatives.clone();
    q.validate().unwrap();
    assert!(super::violation(&q, &[hi, lo, lo, 0.0]) > 0.0);
    assert_eq!(super::violation(&p, &[hi, lo, lo, 0.0]), 0.0);
}

#[test]
fn validation_rejects_bad_problems() {
    let costs = CostMatrix::from_fn(3, |i, j| i.abs_diff(j) as f64);
    let veh = |cap: usize, alts: Vec<Vec<usize>>| Vehicle::new(costs.clone(), 0, cap, alts);
    assert!(veh(1, vec![vec![0]]).is_err(), "depot as alternative");
    assert!(veh(1, vec![vec![3]]).is_err(), "node out of range");
    assert!(veh(1, vec![vec![1], vec![1]]).is_err(), "node serving two tasks");
    assert!(
        Vehicle::new(costs.clone(), 5, 1, vec![]).is_err(),
        "depot out of range"
    );
    let a = veh(1, vec![vec![1], vec![2]]).unwrap();
    let b = veh(5, vec![vec![], vec![]]).unwrap();
    let c = veh(5, vec![vec![], vec![1]]).unwrap();
    // Task 0 only by a; task 1 by a or c.
    assert!(MinMaxProblem::new(vec![a.clone(), c.clone()], 2, vec![0.0; 2], None).is_ok());
    // Nobody can do anything but a, whose cap is 1, though the total cap is 6.
    let err = MinMaxProblem::new(vec![a.clone(), b.clone()], 2, vec![0.0; 2], None);
    assert!(err.is_err());
    assert!(MinMaxProblem::new(vec![a.clone(), c.clone()], 2, vec![0.0], None).is_err());
    assert!(MinMaxProblem::new(vec![a.clone(), c.clone()], 2, vec![0.0, -1.0], None).is_err());
    assert!(MinMaxProblem::new(vec![a.clone(), c.clone()], 2, vec![0.0; 2], Some(-1.0)).is_err());
    assert!(
        MinMaxProblem::new(vec![a, c], 3, vec![0.0; 3], None).is_err(),
        "wrong list count"
    );
    // Routes::check.
    let p = MinMaxProblem::new(
        vec![
            veh(1, vec![vec![1], vec![2]]).unwrap(),
            veh(5, vec![vec![], vec![1]]).unwrap(),
        ],
        2,
        vec![1.0; 2],
        None,
    )
    .unwrap();
    let ok = Routes {
        tours: vec![vec![(0, 1)], vec![(1, 1)]],
    };
    ok.check(&p).unwrap();
    assert_eq!(ok.times(&p), vec![3.0, 3.0]);
    for bad in [
        vec![vec![(0, 1), (1, 2)], vec![]],
        vec![vec![(0, 2)], vec![(1, 1)]],
        vec![vec![(0, 1)], vec![]],
        vec![vec![(0, 1)], vec![(1, 1), (1, 1)]],
        vec![vec![(0, 1)]],
    ] {
        assert!(Routes { tours: bad }.check(&p).is_err());
    }
}

#[test]
fn lower_bound_is_below_every_solution_and_tight_on_one_task() {
    for seed in 0..6 {
        let p = generate(3, 20, (1, 4), seed);
        let lb = lower_bound(&p);
        assert!(lb > 0.0);
        for method in [
            MinMaxMethod::Ils,
            MinMaxMethod::Algorithm1,
            MinMaxMethod::Proximity,
        ] {
            let sol = solve(
                &p,
                &MinMaxParams {
                    method,
                    seed,
                    max_iterations: Some(30),
                    ..MinMaxParams::default()
                },
            );
            assert!(
                lb <= sol.makespan + 1e-9,
                "seed {seed} {method:?}: bound {lb} above {}",
                sol.makespan
            );
        }
    }
    // One vehicle, one task with one node: the bound is the route itself.
    let costs = CostMatrix::from_fn(2, |i, j| if i == j { 0.0 } else { 1.0 + i as f64 });
    let v = Vehicle::new(costs, 0, 1, vec![vec![1]]).unwrap();
    let p = MinMaxProblem::new(vec![v], 1, vec![0.5], None).unwrap();
    assert!((lower_bound(&p) - (1.0 + 0.5 + 2.0)).abs() < 1e-12);
}

/// Asserts that the lower bound of each of `problems` (by seed) is positive and at most the
/// brute-force optimum, and, so that this is not vacuous, within a fifth of it on some.
fn assert_bound_below_optimum(problems: impl Iterator<Item = (u64, MinMaxProblem)>) {
    let mut closest: f64 = 0.0;
    for (seed, p) in problems {
        let lb = lower_bound(&p);
        let opt = brute_force(&p);
        assert!(
            lb > 0.0 && lb <= opt + 1e-9,
            "seed {seed}: bound {lb} above the optimum {opt}"
        );
        closest = closest.max(lb / opt);
    }
    assert!(closest > 0.8, "best bound/optimum {closest}");
}

#[test]
fn lower_bound_is_below_the_optimum_of_small_problems() {
    assert_bound_below_optimum((0..40).map(|seed| {
        let p = generate(2, 1 + seed as usize % 6, (1, 2), seed);
        (seed, if seed % 3 == 0 { tight(p) } else { p })
    }));
}

/// A random instance: `k` vehicles, `n` tasks, random one-way costs (a leg and its way back
/// differ), services and alternatives, some tasks only some vehicles can do, caps at least
/// the fair share.
fn random_asymmetric(k: usize, n: usize, seed: u64) -> MinMaxProblem {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    loop {
        let vehicles: Vec<Vehicle> = (0..k)
            .map(|_| {
                let mut next = 1;
                let alternatives: Vec<Vec<usize>> = (0..n)
                    .map(|_| {
                        let count = if rng.random::<f64>() < 0.2 {
                            0
                        } else {
                            rng.random_range(1..=2)
                        };
                        (0..count)
                            .map(|_| {
                                next += 1;
                                next - 1
                            })
                            .collect()
                    })
                    .collect();
                let costs: Vec<f64> = (0..next * next).map(|_| 0.1 + rng.random::<f64>()).collect();
                let costs = CostMatrix::from_fn(next, |i, j| if i == j { 0.0 } else { costs[i * next + j] });
                let cap = n.div_ceil(k) + rng.random_range(0..=n);
                Vehicle::new(costs, 0, cap, alternatives).unwrap()
            })
            .collect();
        let service = (0..n).map(|_| rng.random::<f64>()).collect();
        if let Ok(p) = MinMaxProblem::new(vehicles, n, service, None) {
            return p;
        }
    }
}

#[test]
fn lower_bound_is_below_the_optimum_of_three_vehicles_with_one_way_legs() {
    assert_bound_below_optimum((0..60).map(|seed| (seed, random_asymmetric(3, 1 + seed as usize % 6, seed))));
}

#[test]
fn assignment_within_caps_moves_tasks_along_augmenting_paths() {
    // Task 0 either vehicle, task 1 only vehicle 0: task 0 must move to vehicle 1.
    let can = |v: usize, t: usize| t == 0 || v == 0;
    let sets = super::assign_within_caps(2, &[1, 1], can).unwrap();
    assert_eq!(sets, vec![vec![1], vec![0]]);
    // A third task only vehicle 0 can do does not fit.
    let can3 = |v: usize, t: usize| t == 0 || v == 0;
    assert_eq!(super::assign_within_caps(3, &[1, 1], can3), Err(2));
}

/// The route bound of `p` from an ILS solution.
fn route_bound_of(p: &MinMaxProblem, settings: &RouteBoundSettings) -> RouteBound {
    let start = solve(
        p,
        &MinMaxParams {
            max_iterations: Some(30),
            ..MinMaxParams::default()
        },
    );
    route_bound(p, &start.routes, settings)
}

#[test]
fn route_bound_is_between_the_leg_bound_and_the_optimum() {
    let mut tighter = 0;
    let mut closest: f64 = 0.0;
    let problems = (0..40)
        .map(|seed| generate(2, 2 + seed as usize % 5, (1, 3), seed))
        .chain((0..40).map(|seed| random_asymmetric(3, 2 + seed as usize % 5, seed)));
    for (i, p) in problems.enumerate() {
        let legs = lower_bound(&p);
        let rb = route_bound_of(&p, &RouteBoundSettings::default());
        let opt = brute_force(&p);
        assert!(rb.converged, "problem {i}: not converged ({rb:?})");
        assert!(
            legs <= rb.bound + 1e-12 && rb.bound <= opt + 1e-7,
            "problem {i}: leg bound {legs}, route bound {}, optimum {opt}",
            rb.bound
        );
        // The relaxation's value (the last restricted problem's, up to the solver's accuracy),
        // unless the leg bound is above it.
        let relaxation = rb.master + 1e-6 * rb.master.max(1.0);
        assert!(rb.bound <= relaxation.max(legs), "problem {i}: {rb:?}");
        tighter += usize::from(rb.bound > legs + 1e-6);
        closest = closest.max(rb.bound / opt);
    }
    // Not vacuous: the routes see what the legs do not, and close the gap on some.
    assert!(tighter >= 40, "tighter than the leg bound on {tighter} of 80");
    assert!(closest > 0.999, "best route bound/optimum {closest}");
}

#[test]
fn route_bound_of_one_vehicle_remembering_every_task_is_its_shortest_route() {
    // One vehicle: every route the relaxation weighs must cover every task, so with elementary
    // routes (a memory as large as the tasks) its value is the shortest route.
    for seed in 0..12 {
        let n = 2 + seed as usize % 5;
        let mut p = random_asymmetric(1, n, seed);
        p.vehicles[0].cap = n;
        let settings = RouteBoundSettings {
            ng: n,
            ..RouteBoundSettings::default()
        };
        let rb = route_bound_of(&p, &settings);
        let opt = brute_force(&p);
        assert!(rb.converged, "seed {seed}: {rb:?}");
        assert!(
            (rb.bound - opt).abs() <= 1e-6 * opt,
            "seed {seed}: route bound {} against the shortest route {opt}",
            rb.bound
        );
    }
}

#[test]
fn no_round_starts_past_the_budget() {
    // With no work allowed, the first round is the last, also when it prices quickly and
    // finds nothing (an exact round used to follow it: two rounds on two vehicles × six
    // tasks, seed 139).
    for seed in 0..160 {
        let p = random_asymmetric(2, 1 + seed as usize % 6, seed);
        let settings = RouteBoundSettings {
            max_work: 0,
            ..RouteBoundSettings::default()
        };
        let rb = route_bound_of(&p, &settings);
        assert_eq!(rb.rounds, 1, "seed {seed}: {rb:?}");
    }
}

#[test]
fn a_run_the_clock_cut_is_the_run_of_its_rounds() {
    for seed in 0..6 {
        let p = random_asymmetric(3, 3 + seed as usize % 4, seed);
        // Past already: no round, the leg bound.
        let past = RouteBoundSettings {
            deadline: Some(std::time::Instant::now()),
            ..RouteBoundSettings::default()
        };
        let rb = route_bound_of(&p, &past);
        assert!(
            rb.clock_cut && rb.rounds == 0 && !rb.converged,
            "seed {seed}: {rb:?}"
        );
        assert_eq!(rb.bound, lower_bound(&p));
        // Cut wherever the clock cuts it: the same as the run of as many rounds, no clock.
        for micros in [50, 500, 5_000] {
            let soon = RouteBoundSettings {
                deadline: Some(std::time::Instant::now() + std::time::Duration::from_micros(micros)),
                ..RouteBoundSettings::default()
            };
            let cut = route_bound_of(&p, &soon);
            let again = route_bound_of(
                &p,
                &RouteBoundSettings {
                    max_rounds: cut.rounds,
                    ..RouteBoundSettings::default()
                },
            );
            assert!(!again.clock_cut);
            assert_eq!(
                (cut.bound.to_bits(), cut.work, cut.rounds, cut.converged),
                (again.bound.to_bits(), again.work, again.rounds, again.converged),
                "seed {seed}, {micros} µs"
            );
        }
        // Without a clock, nothing says it cut the run.
        assert!(!route_bound_of(&p, &RouteBoundSettings::default()).clock_cut);
    }
}

#[test]
fn the_duals_of_the_bound_certify_it() {
    let settings = RouteBoundSettings::default();
    let mut certified = 0;
    for seed in 0..20 {
        let p = random_asymmetric(2 + seed as usize % 2, 3 + seed as usize % 4, seed);
        let rb = route_bound_of(&p, &settings);
        let opt = brute_force(&p);
        let Some((pi, mu)) = &rb.duals else {
            // No round beat the leg bound.
            assert_eq!(rb.bound, rb.legs, "seed {seed}");
            continue;
        };
        // One pricing per vehicle gives the bound again, bit for bit.
        let again = lagrangian_bound(&p, pi, mu, &settings).expect("feasible duals");
        assert_eq!(again.to_bits(), rb.bound.to_bits(), "seed {seed}");
        certified += 1;
        // Any other feasible duals bound the optimum too.
        let half: Vec<f64> = mu.iter().map(|x| 0.5 * x).collect();
        let more: Vec<f64> = pi.iter().map(|x| 1.1 * x).collect();
        for (a, b) in [(pi, &half), (&more, mu)] {
            let v = lagrangian_bound(&p, a, b, &settings).expect("feasible duals");
            assert!(v <= opt + 1e-7, "seed {seed}: {v} against the optimum {opt}");
        }
        // Infeasible duals are refused.
        let mut negative = pi.clone();
        negative[0] = -1.0;
        assert!(lagrangian_bound(&p, &negative, mu, &settings).is_none());
        let heavy: Vec<f64> = mu.iter().map(|x| x + 1.0).collect();
        assert!(lagrangian_bound(&p, pi, &heavy, &settings).is_none());
        assert!(lagrangian_bound(&p, &pi[1..], mu, &settings).is_none());
        // So are duals whose value is not a number (prices near the largest floats).
        let huge = vec![f64::MAX; pi.len()];
        assert!(lagrangian_bound(&p, &huge, mu, &settings).is_none());
    }
    assert!(certified >= 10, "{certified} of 20 certified");
}

/// The least `μ·time(r) − π(r)` over vehicle `v`'s elementary routes of at most `cap` tasks,
/// the empty one (0) included: every set of tasks it can do, in its best order and nodes.
fn least_reduced_cost(p: &MinMaxProblem, v: usize, pi: &[f64], mu: f64, cap: usize) -> f64 {
    let doable: Vec<usize> = (0..p.tasks).filter(|&t| p.can_do(v, t)).collect();
    let mut least: f64 = 0.0;
    for code in 1u32..(1 << doable.len()) {
        let set: Vec<usize> = (0..doable.len())
            .filter(|&i| code >> i & 1 == 1)
            .map(|i| doable[i])
            .collect();
        if set.len() <= cap {
            let prices: f64 = set.iter().map(|&t| pi[t]).sum();
            least = least.min(mu * best_route(p, v, &set) - prices);
        }
    }
    least
}

#[test]
fn exact_pricing_finds_the_least_reduced_cost_under_every_cap() {
    // With a memory as large as the tasks, ng-routes are the elementary routes, so the
    // Lagrangian bound at any duals is Σπ plus each vehicle's least reduced cost, found here
    // by enumeration. Caps from one task up make the labels' depth count (a route past its
    // vehicle's cap is no route); high prices make long routes pay, so caps bind (counted),
    // and make deeper labels cheaper than shallower ones at the same node.
    use rand::{RngExt, SeedableRng};
    let mut binding = 0;
    for seed in 0..60u64 {
        let (m, n) = (1 + seed as usize % 3, 2 + seed as usize % 5);
        let mut p = random_asymmetric(m, n, seed);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1000 + seed);
        for v in &mut p.vehicles {
            v.cap = rng.random_range(1..=n);
        }
        let pi: Vec<f64> = (0..n).map(|_| 3.0 * rng.random::<f64>()).collect();
        let raw: Vec<f64> = (0..m).map(|_| rng.random::<f64>()).collect();
        let sum: f64 = raw.iter().sum();
        let mu: Vec<f64> = raw.iter().map(|x| x / sum).collect();
        let settings = RouteBoundSettings {
            ng: n,
            ..RouteBoundSettings::default()
        };
        let got = lagrangian_bound(&p, &pi, &mu, &settings).expect("feasible duals");
        let least: Vec<f64> = (0..m)
            .map(|v| least_reduced_cost(&p, v, &pi, mu[v], p.vehicles[v].cap))
            .collect();
        let want = pi.iter().sum::<f64>() + least.iter().sum::<f64>();
        assert!(
            (got - want).abs() <= 1e-9 * want.abs().max(1.0),
            "seed {seed}: priced {got}, enumerated {want}"
        );
        // The cap binds where the best route without it takes more tasks.
        binding += usize::from((0..m).any(|v| least_reduced_cost(&p, v, &pi, mu[v], n) < least[v] - 1e-9));
    }
    assert!(binding >= 30, "a cap binds in {binding} of 60");
}

#[test]
fn route_bound_cut_by_its_budget_is_still_a_bound() {
    for seed in 0..10 {
        let p = random_asymmetric(3, 3 + seed as usize % 4, seed);
        let settings = RouteBoundSettings {
            max_work: 1,
            ..RouteBoundSettings::default()
        };
        let rb = route_bound_of(&p, &settings);
        let opt = brute_force(&p);
        assert!(rb.rounds <= 2, "seed {seed}: {rb:?}");
        // Too large to price: the leg bound alone, no round made.
        let large = RouteBoundSettings {
            max_arcs: 1,
            ..RouteBoundSettings::default()
        };
        let alone = route_bound_of(&p, &large);
        assert_eq!((alone.bound, alone.rounds), (lower_bound(&p), 0), "seed {seed}");
        assert!(
            lower_bound(&p) <= rb.bound + 1e-12 && rb.bound <= opt + 1e-7,
            "seed {seed}: {rb:?} against {opt}"
        );
    }
}

#[test]
fn generation_is_refused_exactly_past_the_bytes_its_matrices_could_take() {
    // One robot reaches every task: at most 1 + 10 × 3 nodes, 31² entries of 8 bytes, besides
    // 256 bytes for the robot and 32 + 24 for each task.
    let most = 31 * 31 * 8 + 256 + 10 * (32 + 24);
    let p = generate_within(1, 10, (1, 3), 4, most).expect("within the limit");
    assert_eq!(
        p,
        generate(1, 10, (1, 3), 4),
        "the same instance as without a limit"
    );
    let e = generate_within(1, 10, (1, 3), 4, most - 1).unwrap_err();
    assert!(e.0.contains("robot 0 reaches 10 tasks"), "{e}");
    let e = generate_within(3, 1 << 40, (1, 1), 4, u64::MAX >> 24).unwrap_err();
    assert!(e.0.contains("before any cost is stored"), "{e}");
}
