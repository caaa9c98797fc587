//! `cellplan bench`: the combinatorial solvers on standard instance files, against the known
//! optima found in a `solutions` file beside each instance (`name : value` lines); and min-max
//! routing on cellplan's own format (docs/minmax-format.md), against its BEST_KNOWN line.
use cellplan_solve::io::{
    read_gtsplib, read_minmax_instance, read_optima, read_orlib_setcover, read_tsplib, write_minmax,
};
use cellplan_solve::{Gtsp, gtsp, held_karp, minmax, setcover};
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
    /// cellplan min-max multi-vehicle routing with alternatives (docs/minmax-format.md).
    Minmax,
    /// The local paths (root → MP) of a CMM cell's plan, as problems for the OMPL peer
    /// (bench/peers/cmm_local_ompl.py), with ours solved and timed: JSON on stdout.
    CmmLocal,
    /// Motion planning problems without a cell (docs/motion-problems.md), every path
    /// re-checked exactly.
    Motion,
}

/// Solver method.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Method {
    /// Iterated local search (tsp, gtsp).
    Ils,
    /// Paper 003's enhanced genetic algorithm (tsp, gtsp).
    Ga,
    /// Exact: Held–Karp for tsp/gtsp, branch and bound for set cover.
    Exact,
    /// Greedy set cover.
    Greedy,
    /// Paper 000's penalty/auxiliary-function set cover.
    Penalty,
    /// Min-max: paper 000's Algorithm 1 generalised to m vehicles.
    Algorithm1,
    /// Min-max: every task to the vehicle whose depot is nearest.
    Proximity,
}

#[derive(Args)]
pub struct BenchArgs {
    /// Problem kind.
    #[arg(value_enum)]
    pub kind: Kind,
    /// Instance files.
    #[arg(required_unless_present = "generate")]
    pub files: Vec<PathBuf>,
    /// Time limit per run, in seconds (motion: a wall-clock safety net per query; the work
    /// budget binds first).
    #[arg(long, default_value_t = 1.0)]
    pub time_limit: f64,
    /// Runs per instance (seeds 0, 1, ...).
    #[arg(long, default_value_t = 1)]
    pub runs: u64,
    /// Motion: the planner, by its registry name (straight, rrt-connect, rrt-star, prm, leg).
    #[arg(long, default_value = "leg")]
    pub planner: String,
    /// Motion: the work budget per query, in random samples.
    #[arg(long, default_value_t = 20_000)]
    pub max_samples: usize,
    /// Motion: only the first N problems of each file.
    #[arg(long, value_name = "N")]
    pub first: Option<usize>,
    /// Motion: re-check the paths of a peer's run file (bench/peers/motion_*.py) instead of
    /// planning.
    #[arg(long, value_name = "RUN_JSON")]
    pub recheck: Option<PathBuf>,
    /// Motion: time N single validity checks per problem (random configurations, with and
    /// without the broad phase) instead of planning.
    #[arg(long, value_name = "N")]
    pub checks: Option<usize>,
    /// Motion: largest point motion between two samples of the exact re-check, in mm.
    #[arg(long, default_value_t = 1.0)]
    pub exact_step_mm: f64,
    /// Motion: skip the exact re-check (`exact_valid` is then false everywhere; for timing the
    /// planner alone).
    #[arg(long)]
    pub no_exact: bool,
    /// Motion: no post-processing (shortcuts, redundant waypoints): the planner's raw path, as
    /// VAMP's and OMPL's planners return it without their simplification.
    #[arg(long)]
    pub no_simplify: bool,
    /// Motion: keep the paths in the JSON rows.
    #[arg(long)]
    pub with_paths: bool,
    /// Method (default: ils for tsp/gtsp/minmax, exact for setcover; minmax also takes
    /// algorithm1 and proximity).
    #[arg(long, value_enum)]
    method: Option<Method>,
    /// Print JSON (a list of objects with instance, cost, mean_cost, optimum, gap_percent, time_s).
    #[arg(long)]
    pub json: bool,
    /// Min-max only: write a random inspection-shaped instance (`minmax::generate`) to `--out`
    /// instead of benchmarking.
    #[arg(long, conflicts_with = "files", requires_all = ["vehicles", "tasks", "out"])]
    pub generate: bool,
    /// With `--generate`: number of vehicles (robots).
    #[arg(long, requires = "generate")]
    vehicles: Option<usize>,
    /// With `--generate`: number of tasks.
    #[arg(long, requires = "generate")]
    tasks: Option<usize>,
    /// With `--generate`: nodes per (robot, reachable task), an inclusive range `LO..HI`.
    #[arg(long, requires = "generate", default_value = "1..4", value_name = "LO..HI")]
    alternatives: String,
    /// With `--generate`: the seed.
    #[arg(long, requires = "generate", default_value_t = 1)]
    seed: u64,
    /// With `--generate`: round costs and service times to this many decimals (smaller files).
    #[arg(long, requires = "generate", default_value_t = 4)]
    decimals: u32,
    /// With `--generate`: the file to write (atomically).
    #[arg(long, short, requires = "generate", value_name = "FILE")]
    out: Option<PathBuf>,
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
    /// Min-max: the total route time of the best-makespan run.
    #[serde(skip_serializing_if = "Option::is_none")]
    total: Option<f64>,
    /// Min-max: number of vehicles.
    #[serde(skip_serializing_if = "Option::is_none")]
    vehicles: Option<usize>,
    /// Min-max: number of tasks.
    #[serde(skip_serializing_if = "Option::is_none")]
    tasks: Option<usize>,
    /// Min-max: the lower bounds of the makespan.
    #[serde(skip_serializing_if = "Option::is_none", flatten)]
    bounds: Option<MinMaxBounds>,
}

/// The two lower bounds of a min-max instance's makespan (`cellplan bench minmax`).
#[derive(Debug, Serialize)]
pub struct MinMaxBounds {
    /// `minmax::lower_bound`: legs one at a time (the bound `cellplan plan` states).
    lower_bound: f64,
    /// `minmax::route_bound`: column generation over ng-routes (at least `lower_bound`).
    route_bound: f64,
    /// Whether the route relaxation was solved (else the bound is that of the last round).
    route_bound_converged: bool,
    route_bound_rounds: usize,
    /// Arcs its pricings looked at (its work; `RouteBoundSettings::max_work` at most, give or
    /// take a round).
    route_bound_work: u64,
    /// Time of both bounds, in seconds.
    bounds_time_s: f64,
    /// How the route bound's run ended, in words (the table's; the JSON has the fields).
    #[serde(skip)]
    ending: String,
}

fn optimum_for(file: &Path, name: &str) -> Option<f64> {
    let solutions = file.parent()?.join("solutions");
    read_optima(&solutions).ok()?.get(name).copied()
}

fn route(p: &Gtsp, method: Method, limit: Duration, seed: u64) -> Result<(f64, bool), String> {
    match method {
        Method::Ils | Method::Ga => {
            let params = gtsp::GtspParams {
                time_limit: limit,
                seed,
                max_iterations: None,
                max_stall: None,
                method: if method == Method::Ga {
                    gtsp::GtspMethod::Ga
                } else {
                    gtsp::GtspMethod::Ils
                },
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
    /// A solver returned an invalid solution (a bug), or the output could not be written.
    Failed(String),
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
    if args.kind == Kind::Minmax {
        return run_minmax(args, limit);
    }
    let method = args.method.unwrap_or(match args.kind {
        Kind::Tsp | Kind::Gtsp | Kind::Minmax | Kind::Motion | Kind::CmmLocal => Method::Ils,
        Kind::Setcover => Method::Exact,
    });
    if matches!(method, Method::Algorithm1 | Method::Proximity) {
        return Err(BenchError::Usage(format!(
            "method {} is for minmax",
            format!("{method:?}").to_lowercase()
        )));
    }
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
            Kind::Minmax | Kind::Motion | Kind::CmmLocal => {
                return Err(BenchError::Usage(
                    "min-max and motion are benchmarked by their own runners".into(),
                ));
            }
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
                        other => {
                            return Err(BenchError::Usage(format!(
                                "method {} is not for set cover",
                                format!("{other:?}").to_lowercase()
                            )));
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
            total: None,
            vehicles: None,
            tasks: None,
            bounds: None,
        });
    }
    Ok(rows)
}

fn stem(file: &Path) -> String {
    file.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// `cellplan bench minmax FILE...`: every run's routes are checked before they are reported.
fn run_minmax(args: &BenchArgs, limit: Duration) -> Result<Vec<Row>, BenchError> {
    let method = args.method.unwrap_or(Method::Ils);
    let mm = match method {
        Method::Ils => minmax::MinMaxMethod::Ils,
        Method::Algorithm1 => minmax::MinMaxMethod::Algorithm1,
        Method::Proximity => minmax::MinMaxMethod::Proximity,
        other => {
            return Err(BenchError::Usage(format!(
                "method {} is not for minmax; use ils, algorithm1 or proximity",
                format!("{other:?}").to_lowercase()
            )));
        }
    };
    let mut rows = Vec::new();
    for file in &args.files {
        let inst = read_minmax_instance(file).map_err(BenchError::Input)?;
        let p = &inst.problem;
        let mut runs: Vec<(f64, f64)> = Vec::new();
        let mut best_routes: Option<(f64, minmax::Routes)> = None;
        let start = Instant::now();
        for seed in 0..args.runs.max(1) {
            let params = minmax::MinMaxParams {
                time_limit: limit,
                seed,
                max_iterations: None,
                method: mm,
            };
            let sol = minmax::solve(p, &params);
            sol.routes.check(p).map_err(|e| {
                BenchError::Failed(format!(
                    "{}: the {method:?} solution of seed {seed} is invalid: {e}",
                    file.display()
                ))
            })?;
            let makespan = sol.routes.makespan(p);
            if (makespan - sol.makespan).abs() > 1e-9 * makespan.max(1.0) {
                return Err(BenchError::Failed(format!(
                    "{}: seed {seed} reports makespan {} but its routes take {makespan}",
                    file.display(),
                    sol.makespan
                )));
            }
            runs.push((makespan, sol.routes.times(p).iter().sum()));
            if best_routes.as_ref().is_none_or(|b| makespan < b.0) {
                best_routes = Some((makespan, sol.routes));
            }
        }
        let elapsed = start.elapsed().as_secs_f64();
        let bounds = best_routes.map(|(_, routes)| {
            let began = Instant::now();
            let settings = minmax::RouteBoundSettings::default();
            let routes = minmax::route_bound(p, &routes, &settings);
            MinMaxBounds {
                ending: cellplan_core::document::RouteBoundRun::new(&routes, settings.max_work).ending(),
                lower_bound: routes.legs,
                route_bound: routes.bound,
                route_bound_converged: routes.converged,
                route_bound_rounds: routes.rounds,
                route_bound_work: routes.work,
                bounds_time_s: began.elapsed().as_secs_f64(),
            }
        });
        let (best, total) =
            runs.iter().copied().fold(
                (f64::INFINITY, f64::INFINITY),
                |a, b| if b.0 < a.0 { b } else { a },
            );
        let mean = runs.iter().map(|r| r.0).sum::<f64>() / runs.len() as f64;
        let optimum = inst.best_known;
        rows.push(Row {
            instance: stem(file),
            method: format!("{method:?}").to_lowercase(),
            cost: best,
            mean_cost: mean,
            optimum,
            gap_percent: optimum.map(|o| if o > 0.0 { 100.0 * (best - o) / o } else { 0.0 }),
            time_s: elapsed / runs.len() as f64,
            runs: runs.len() as u64,
            proven_optimal: false,
            total: Some(total),
            vehicles: Some(p.vehicles.len()),
            tasks: Some(p.tasks),
            bounds,
        });
    }
    Ok(rows)
}

/// `cellplan bench minmax --generate`: writes the instance atomically; returns what was written.
pub fn generate(args: &BenchArgs) -> Result<String, BenchError> {
    if args.kind != Kind::Minmax {
        return Err(BenchError::Usage("`--generate` is for minmax only".into()));
    }
    let (Some(m), Some(n), Some(out)) = (args.vehicles, args.tasks, &args.out) else {
        return Err(BenchError::Usage(
            "`--generate` needs --vehicles, --tasks and --out".into(),
        ));
    };
    let range = args
        .alternatives
        .split_once("..=")
        .or_else(|| args.alternatives.split_once(".."));
    let (lo, hi) = match range.map(|(a, b)| (a.trim().parse::<usize>(), b.trim().parse::<usize>())) {
        Some((Ok(lo), Ok(hi))) if lo >= 1 && lo <= hi => (lo, hi),
        _ => {
            return Err(BenchError::Usage(format!(
                "`--alternatives {}`: expected an inclusive range LO..HI with 1 <= LO <= HI, e.g. 10..40",
                args.alternatives
            )));
        }
    };
    if m == 0 {
        return Err(BenchError::Usage("`--vehicles` must be at least 1".into()));
    }
    // The matrices are dense: refused before they are made when they could pass what the
    // reader takes back (and fill the memory first).
    let limit = cellplan_solve::io::MAX_FILE_BYTES;
    let mut p = minmax::generate_within(m, n, (lo, hi), args.seed, limit).map_err(|e| {
        BenchError::Usage(format!(
            "`--generate --vehicles {m} --tasks {n} --alternatives {lo}..{hi}`: {e}; nothing written to {}; ask for fewer tasks or alternatives",
            out.display()
        ))
    })?;
    let scale = 10f64.powi(args.decimals.min(12) as i32);
    let round = |x: f64| (x * scale).round() / scale;
    for v in &mut p.vehicles {
        let k = v.costs.n();
        let data = v.costs.data().iter().map(|&c| round(c)).collect();
        v.costs = cellplan_solve::CostMatrix::new(k, data)
            .map_err(|e| BenchError::Failed(e.to_string()))?
            .into();
    }
    p.service.iter_mut().for_each(|s| *s = round(*s));
    p.validate().map_err(|e| BenchError::Failed(e.to_string()))?;
    let mut capped = crate::Capped {
        buf: Vec::new(),
        cap: limit as usize,
    };
    if write_minmax(&p, &stem(out), &mut capped).is_err() {
        return Err(BenchError::Usage(format!(
            "the instance passes the {} MiB a min-max file may hold: nothing written to {}; ask for fewer tasks or alternatives, or fewer `--decimals`",
            limit >> 20,
            out.display()
        )));
    }
    let buf = capped.buf;
    cellplan_model::io::write_atomic(out, &buf)
        .map_err(|e| BenchError::Failed(format!("cannot write {}: {e}", out.display())))?;
    let nodes: usize = p.vehicles.iter().map(|v| v.costs.n()).sum();
    Ok(format!(
        "wrote {}: {m} vehicles, {n} tasks, {nodes} nodes in all, {} bytes",
        out.display(),
        buf.len()
    ))
}

/// The rows as a table.
pub fn render(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<14} {:<8} {:>12} {:>12} {:>12} {:>8} {:>8}\n",
        "instance", "method", "best", "mean", "optimum", "gap %", "time s"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<14} {:<8} {:>12.prec$} {:>12.prec$} {:>12} {:>8} {:>8.3}{}{}\n",
            r.instance,
            r.method,
            r.cost,
            r.mean_cost,
            r.optimum.map_or("-".into(), |o| format!("{o:.0}")),
            r.gap_percent.map_or("-".into(), |g| format!("{g:.3}")),
            r.time_s,
            if r.proven_optimal { "  proven" } else { "" },
            r.total.map_or(String::new(), |t| format!("  total {t:.3}")),
            prec = if r.total.is_some() { 3 } else { 1 }
        ));
        if let Some(b) = &r.bounds {
            s.push_str(&format!(
                "  lower bounds: legs {:.3}, routes {:.3} ({}, {} rounds, {:.1} s): the cost is at most {:.1} % above\n",
                b.lower_bound,
                b.route_bound,
                b.ending,
                b.route_bound_rounds,
                b.bounds_time_s,
                100.0 * (r.cost / b.route_bound - 1.0),
            ));
        }
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
