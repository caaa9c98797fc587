//! The GTSP/TSP heuristic on benchmark instances: feasible tours costed as `Gtsp::tour_cost`
//! counts them, berlin52 solved to optimality with a fixed iteration budget, determinism.
use std::path::{Path, PathBuf};
use std::time::Duration;

use cellplan_solve::io::{read_gtsplib, read_optima, read_tsplib};
use cellplan_solve::{Gtsp, GtspMethod, GtspParams, solve_gtsp};

fn bench(sub: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/benchmarks")
        .join(sub)
}

fn params(iters: usize, seed: u64) -> GtspParams {
    GtspParams {
        time_limit: Duration::from_secs(3600),
        seed,
        max_iterations: Some(iters),
        max_stall: None,
        method: GtspMethod::Ils,
    }
}

#[test]
fn gtsp_berlin52_reaches_optimum() {
    let inst = read_tsplib(bench("tsplib/berlin52.tsp")).unwrap();
    let optima = read_optima(bench("tsplib/solutions")).unwrap();
    let g = Gtsp::tsp(inst.costs);
    let sol = solve_gtsp(&g, &params(3000, 1));
    g.check(&sol.tour).unwrap();
    assert_eq!(sol.cost, g.tour_cost(&sol.tour));
    assert_eq!(sol.iterations, 3000);
    assert_eq!(sol.cost, optima["berlin52"]);
}

#[test]
fn gtsp_stops_after_kicks_that_do_not_improve() {
    let inst = read_tsplib(bench("tsplib/berlin52.tsp")).unwrap();
    let g = Gtsp::tsp(inst.costs);
    let stalled = GtspParams {
        max_stall: Some(20),
        ..params(3000, 1)
    };
    let a = solve_gtsp(&g, &stalled);
    g.check(&a.tour).unwrap();
    // It stopped on the stall, well before the kick budget, and found no worse a tour than its
    // own first 20 kicks would have...
    assert!(
        a.iterations >= 20 && a.iterations < 3000,
        "{} kicks",
        a.iterations
    );
    let first = solve_gtsp(&g, &params(20, 1));
    assert!(a.cost <= first.cost);
    // ... and, stopping on work done, it is deterministic.
    assert_eq!(solve_gtsp(&g, &stalled), a);
}

#[test]
fn gtsp_deterministic_for_seed_and_iterations() {
    let inst = read_tsplib(bench("tsplib/kroA100.tsp")).unwrap();
    let g = Gtsp::tsp(inst.costs);
    let a = solve_gtsp(&g, &params(300, 7));
    let b = solve_gtsp(&g, &params(300, 7));
    assert_eq!(a, b);
}

#[test]
fn gtsp_39rat195_feasible_and_near_best_known() {
    let inst = read_gtsplib(bench("gtsplib/39rat195.gtsp")).unwrap();
    let g = inst.gtsp;
    let sol = solve_gtsp(&g, &params(500, 0));
    g.check(&sol.tour).unwrap();
    assert_eq!(sol.cost, g.tour_cost(&sol.tour));
    // Best known 854; a short run stays within 5 %.
    assert!(sol.cost <= 854.0 * 1.05, "39rat195: {}", sol.cost);
    // With depots (two nodes of one cluster taken out as start and end) the tour stays feasible.
    let mut clusters = g.clusters.clone();
    let (s, e) = (clusters[0].remove(0), clusters[0].remove(0));
    let d = Gtsp::new(g.costs.clone(), clusters)
        .unwrap()
        .with_depots(Some(s), Some(e))
        .unwrap();
    let sol = solve_gtsp(&d, &params(200, 3));
    d.check(&sol.tour).unwrap();
    assert_eq!(sol.cost, d.tour_cost(&sol.tour));
}

#[test]
fn ga_burma14_reaches_optimum_and_is_deterministic() {
    let inst = read_tsplib(bench("tsplib/burma14.tsp")).unwrap();
    let optima = read_optima(bench("tsplib/solutions")).unwrap();
    let g = Gtsp::tsp(inst.costs);
    let ga = |seed| {
        solve_gtsp(
            &g,
            &GtspParams {
                method: GtspMethod::Ga,
                ..params(500, seed)
            },
        )
    };
    let sol = ga(1);
    g.check(&sol.tour).unwrap();
    assert_eq!(sol.cost, g.tour_cost(&sol.tour));
    assert_eq!(sol.iterations, 500);
    assert_eq!(sol.cost, optima["burma14"]);
    assert_eq!(ga(1), sol);
}

#[test]
fn ga_39rat195_feasible_with_and_without_depots() {
    let g = read_gtsplib(bench("gtsplib/39rat195.gtsp")).unwrap().gtsp;
    let ga = |p: &Gtsp| {
        let sol = solve_gtsp(
            p,
            &GtspParams {
                method: GtspMethod::Ga,
                ..params(30, 2)
            },
        );
        p.check(&sol.tour).unwrap();
        assert_eq!(sol.cost, p.tour_cost(&sol.tour));
        sol
    };
    let closed = ga(&g);
    assert_eq!(closed.tour.nodes.len(), 39);
    let mut clusters = g.clusters.clone();
    let (s, e) = (clusters[0].remove(0), clusters[0].remove(0));
    let d = Gtsp::new(g.costs.clone(), clusters)
        .unwrap()
        .with_depots(Some(s), Some(e))
        .unwrap();
    assert_eq!(ga(&d).tour.nodes.len(), 39);
}
