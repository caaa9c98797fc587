//! `cellplan bench`: the combinatorial solvers on standard instance files, against the known
//! optima found in a `solutions` file beside each instance (`name : value` lines).
use cellplan_solve::io::{read_gtsplib, read_optima, read_orlib_setcover, read_tsplib};
use cellplan_solve::{Gtsp, gtsp, held_karp, setcover};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Which problem the files hold.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Kind {
    /// TSPLIB symmetric TSP.
    Tsp,
    /// GTSPLIB generalized TSP.
    Gtsp,
    /// OR-Library set cover.
    Setcover,
}

/// Solver method.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Method {
    /// Iterated local search (tsp, gtsp).
    Ils,
    /// Exact: Held–Karp for tsp/gtsp, branch and bound for set cover.
    Exact,
    /// Greedy set cover.
    Greedy,
    /// Paper 000's penalty/auxiliary-function set cover.
    Penalty,
}

#[derive(Args)]
pub struct BenchArgs {
    /// Problem kind.
    #[arg(value_enum)]
    kind: Kind,
    /// Instance files.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Time limit per run, in seconds.
    #[arg(long, default_value_t = 1.0)]
    time_limit: f64,
    /// Runs per instance (seeds 0, 1, ...).
    #[arg(long, default_value_t = 1)]
    runs: u64,
    /// Method (default: ils for tsp/gtsp, exact for setcover).
    #[arg(long, value_enum)]
    method: Option<Method>,
    /// Print JSON (a list of objects with instance, cost, mean_cost, optimum, gap_percent, time_s).
    #[arg(long)]
    pub json: bool,
}

/// One instance's result.
#[derive(Serialize)]
pub struct Row {
    instance: String,
    method: String,
    cost: f64,
    mean_cost: f64,
    optimum: Option<f64>,
    gap_percent: Option<f64>,
    time_s: f64,
    runs: u64,
    proven_optimal: bool,
}

fn optimum_for(file: &Path, name: &str) -> Option<f64> {
    let solutions = file.parent()?.join("solutions");
    read_optima(&solutions).ok()?.get(name).copied()
}

fn route(p: &Gtsp, method: Method, limit: Duration, seed: u64) -> Result<(f64, bool), String> {
    match method {
        Method::Ils => {
            let params = gtsp::GtspParams {
                time_limit: limit,
                seed,
                max_iterations: None,
            };
            Ok((gtsp::solve(p, &params).cost, false))
        }
        Method::Exact => held_karp::solve(p, held_karp::HeldKarpLimits::default())
            .map(|e| (e.cost, true))
            .map_err(|e| e.to_string()),
        other => Err(format!("method {other:?} is for set cover")),
    }
}

/// Why a benchmark run stopped.
pub enum BenchError {
    /// An instance file is missing or malformed.
    Input(cellplan_solve::ReadError),
    /// Arguments that do not fit together.
    Usage(String),
}

impl From<String> for BenchError {
    fn from(m: String) -> Self {
        BenchError::Usage(m)
    }
}

/// An instance as read.
enum Instance {
    /// A (generalized) TSP.
    Route(Gtsp),
    /// A set cover.
    Cover(cellplan_solve::SetCover),
}

/// Runs the benchmark; returns the rows or what went wrong.
pub fn run(args: &BenchArgs) -> Result<Vec<Row>, BenchError> {
    if !(args.time_limit > 0.0 && args.time_limit.is_finite()) {
        return Err(BenchError::Usage(
            "`--time-limit` must be a positive number of seconds".into(),
        ));
    }
    let limit = Duration::from_secs_f64(args.time_limit);
    let method = args.method.unwrap_or(match args.kind {
        Kind::Tsp | Kind::Gtsp => Method::Ils,
        Kind::Setcover => Method::Exact,
    });
    let mut rows = Vec::new();
    for file in &args.files {
        let name = file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let optimum = optimum_for(file, &name);
        // Read once; only the solving is timed.
        let instance = match args.kind {
            Kind::Tsp => Instance::Route(Gtsp::tsp(read_tsplib(file).map_err(BenchError::Input)?.costs)),
            Kind::Gtsp => Instance::Route(read_gtsplib(file).map_err(BenchError::Input)?.gtsp),
            Kind::Setcover => Instance::Cover(read_orlib_setcover(file).map_err(BenchError::Input)?),
        };
        let mut costs = Vec::new();
        let mut proven = false;
        let start = Instant::now();
        for seed in 0..args.runs.max(1) {
            let (cost, exact) = match &instance {
                Instance::Route(p) => route(p, method, limit, seed)?,
                Instance::Cover(sc) => {
                    let cover = match method {
                        Method::Exact => setcover::exact(
                            sc,
                            &setcover::ExactLimits {
                                time_limit: Some(limit),
                                ..setcover::ExactLimits::default()
                            },
                        ),
                        Method::Greedy => setcover::greedy(sc),
                        Method::Penalty => setcover::penalty_method(
                            sc,
                            &setcover::PenaltyParams {
                                seed,
                                ..setcover::PenaltyParams::default()
                            },
                        ),
                        Method::Ils => {
                            return Err(BenchError::Usage("method ils is for tsp and gtsp".into()));
                        }
                    };
                    (cover.cost, cover.proven_optimal)
                }
            };
            proven |= exact;
            costs.push(cost);
        }
        let best = costs.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = costs.iter().sum::<f64>() / costs.len() as f64;
        rows.push(Row {
            instance: name,
            method: format!("{method:?}").to_lowercase(),
            cost: best,
            mean_cost: mean,
            optimum,
            gap_percent: optimum.map(|o| if o > 0.0 { 100.0 * (best - o) / o } else { 0.0 }),
            time_s: start.elapsed().as_secs_f64() / costs.len() as f64,
            runs: costs.len() as u64,
            proven_optimal: proven,
        });
    }
    Ok(rows)
}

/// The rows as a table.
pub fn render(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<14} {:<8} {:>12} {:>12} {:>12} {:>8} {:>8}\n",
        "instance", "method", "best", "mean", "optimum", "gap %", "time s"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<14} {:<8} {:>12.1} {:>12.1} {:>12} {:>8} {:>8.3}{}\n",
            r.instance,
            r.method,
            r.cost,
            r.mean_cost,
            r.optimum.map_or("-".into(), |o| format!("{o:.0}")),
            r.gap_percent.map_or("-".into(), |g| format!("{g:.3}")),
            r.time_s,
            if r.proven_optimal { "  proven" } else { "" }
        ));
    }
    if !rows.is_empty() {
        let gaps: Vec<f64> = rows.iter().filter_map(|r| r.gap_percent).collect();
        if !gaps.is_empty() {
            s.push_str(&format!(
                "mean gap {:.3} % over {} instances with a known optimum\n",
                gaps.iter().sum::<f64>() / gaps.len() as f64,
                gaps.len()
            ));
        }
    }
    s
}
