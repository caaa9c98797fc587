//! Every benchmark file in data/benchmarks loads, and known optima are reproduced from the
//! published optimal tours.
use std::path::{Path, PathBuf};

use cellplan_solve::io::{read_gtsplib, read_optima, read_orlib_setcover, read_tsplib};
use cellplan_solve::{Gtsp, Tour};

fn bench(sub: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/benchmarks")
        .join(sub)
}

fn files(sub: &str, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(bench(sub))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

/// The cost of a 1-based closed tour of a TSPLIB instance.
fn tsplib_tour_cost(name: &str, one_based: &[usize]) -> f64 {
    let inst = read_tsplib(bench(&format!("tsplib/{name}.tsp"))).unwrap();
    assert_eq!(one_based.len(), inst.dimension, "{name}: tour length");
    let g = Gtsp::tsp(inst.costs);
    let tour = Tour {
        nodes: one_based.iter().map(|v| v - 1).collect(),
    };
    g.check(&tour).unwrap();
    g.tour_cost(&tour)
}

#[test]
fn every_tsplib_file_loads_with_its_dimension() {
    let optima = read_optima(bench("tsplib/solutions")).unwrap();
    let all = files("tsplib", "tsp");
    assert_eq!(all.len(), 82);
    for p in all {
        let inst = read_tsplib(&p).unwrap_or_else(|e| panic!("{e}"));
        let text = std::fs::read_to_string(&p).unwrap();
        let dim: usize = text
            .lines()
            .find(|l| l.trim_start().starts_with("DIMENSION"))
            .and_then(|l| l.split(':').nth(1))
            .and_then(|v| v.trim().parse().ok())
            .unwrap();
        assert_eq!(inst.dimension, dim, "{}", p.display());
        assert_eq!(inst.costs.n(), dim, "{}", p.display());
        assert!(inst.costs.is_symmetric(0.0), "{}", p.display());
        // The identity tour can never beat the optimum.
        let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
        let opt = optima
            .get(&stem)
            .unwrap_or_else(|| panic!("no optimum for {stem}"));
        let g = Gtsp::tsp(inst.costs);
        let identity = g.tour_cost(&Tour {
            nodes: (0..dim).collect(),
        });
        assert!(
            identity >= *opt,
            "{stem}: identity tour {identity} < optimum {opt}"
        );
    }
}

#[test]
fn optima_file() {
    let optima = read_optima(bench("tsplib/solutions")).unwrap();
    assert_eq!(optima["berlin52"], 7542.0);
    assert_eq!(optima["att48"], 10628.0);
    assert_eq!(optima["burma14"], 3323.0);
    assert_eq!(optima["dsj1000"], 18660188.0);
}

#[test]
fn berlin52_distances_and_optimal_tour() {
    let inst = read_tsplib(bench("tsplib/berlin52.tsp")).unwrap();
    assert_eq!(inst.name, "berlin52");
    // Node 1 (565, 575), node 2 (25, 185): sqrt(540² + 390²) = 666.11 -> 666.
    assert_eq!(inst.costs.get(0, 1), 666.0);
    // Node 1 (565, 575), node 3 (345, 750): sqrt(220² + 175²) = 281.11 -> 281.
    assert_eq!(inst.costs.get(0, 2), 281.0);
    let opt = [
        1, 49, 32, 45, 19, 41, 8, 9, 10, 43, 33, 51, 11, 52, 14, 13, 47, 26, 27, 28, 12, 25, 4, 6, 15, 5, 24,
        48, 38, 37, 40, 39, 36, 35, 34, 44, 46, 16, 29, 50, 20, 23, 30, 2, 7, 42, 21, 17, 3, 18, 31, 22,
    ];
    assert_eq!(tsplib_tour_cost("berlin52", &opt), 7542.0);
}

#[test]
fn att48_pseudo_euclidean() {
    let inst = read_tsplib(bench("tsplib/att48.tsp")).unwrap();
    // Node 1 (6734, 1453), node 2 (2233, 10): r = sqrt((4501² + 1443²) / 10) = 1494.70,
    // nint = 1495 >= r, so 1495.
    assert_eq!(inst.costs.get(0, 1), 1495.0);
    let opt = [
        1, 8, 38, 31, 44, 18, 7, 28, 6, 37, 19, 27, 17, 43, 30, 36, 46, 33, 20, 47, 21, 32, 39, 48, 5, 42,
        24, 10, 45, 35, 4, 26, 2, 29, 34, 41, 16, 22, 3, 23, 14, 25, 13, 11, 12, 15, 40, 9,
    ];
    assert_eq!(tsplib_tour_cost("att48", &opt), 10628.0);
}

#[test]
fn geo_instances() {
    let opt = [1, 2, 14, 3, 4, 5, 6, 12, 7, 13, 8, 11, 9, 10];
    assert_eq!(tsplib_tour_cost("burma14", &opt), 3323.0);
    let opt = [1, 14, 13, 12, 7, 6, 15, 5, 11, 9, 10, 16, 3, 2, 4, 8];
    assert_eq!(tsplib_tour_cost("ulysses16", &opt), 6859.0);
    let opt = [
        1, 14, 13, 12, 7, 6, 15, 5, 11, 9, 10, 19, 20, 21, 16, 3, 2, 17, 22, 4, 18, 8,
    ];
    assert_eq!(tsplib_tour_cost("ulysses22", &opt), 7013.0);
}

#[test]
fn gtsplib_files() {
    let g = read_gtsplib(bench("gtsplib/39rat195.gtsp")).unwrap();
    assert_eq!(g.name, "39rat195");
    assert_eq!(g.gtsp.clusters.len(), 39);
    assert_eq!(g.gtsp.costs.n(), 195);
    let mut all: Vec<usize> = g.gtsp.clusters.concat();
    all.sort_unstable();
    assert_eq!(all, (0..195).collect::<Vec<_>>());
    assert_eq!(g.gtsp.clusters[0], vec![181, 193, 194]);

    let g = read_gtsplib(bench("gtsplib/107si535.gtsp")).unwrap();
    assert_eq!(g.gtsp.clusters.len(), 107);
    assert_eq!(g.gtsp.costs.n(), 535);

    let g = read_gtsplib(bench("gtsplib/tiny.gtsp")).unwrap();
    assert_eq!(g.name, "tiny");
    assert_eq!(g.gtsp.clusters, vec![vec![0, 1], vec![2, 3], vec![4, 5]]);
    assert_eq!(g.gtsp.costs.get(0, 1), 3.0);
    assert_eq!(g.gtsp.costs.get(1, 0), 3.0);

    let g = read_gtsplib(bench("gtsplib/test.gtsp")).unwrap();
    assert_eq!(g.gtsp.clusters.len(), 133);
    assert_eq!(g.gtsp.costs.n(), 266);

    assert_eq!(files("gtsplib", "gtsp").len(), 4);
}

#[test]
fn every_orlib_setcover_file_loads() {
    let mut count = 0;
    for p in files("orlib-setcover", "txt") {
        let sc = read_orlib_setcover(&p).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(sc.covers.len(), sc.rows, "{}", p.display());
        assert_eq!(sc.costs.len(), sc.columns, "{}", p.display());
        assert!(sc.covers.iter().flatten().all(|&c| c < sc.columns));
        count += 1;
    }
    assert!(count >= 50, "{count} files");
    let sc = read_orlib_setcover(bench("orlib-setcover/scp41.txt")).unwrap();
    assert_eq!((sc.rows, sc.columns), (200, 1000));
    assert_eq!(sc.costs[0], 1.0);
    // Choosing every column covers every row.
    assert!(sc.cover_cost(&(0..sc.columns).collect::<Vec<_>>()).is_ok());
}

#[test]
fn missing_file_is_an_io_error() {
    let e = read_tsplib(bench("tsplib/nope.tsp")).unwrap_err();
    assert!(matches!(e, cellplan_solve::ReadError::Io { .. }), "{e}");
    assert!(e.to_string().contains("nope.tsp"), "{e}");
}
