//! `cellplan compare`: allocation × coordination strategies on one cell (paper 000 Table 3),
//! and over random MP sets drawn on the part (Table 4).
use crate::{Failure, load_options, spinner};
use cellplan_core::candidates::{self, CandidateTable};
use cellplan_core::coord::{self, CoordSettings, Coordination};
use cellplan_core::document as output;
use cellplan_core::pipeline;
use cellplan_core::plan::{self, Allocation, PlanSettings};
use cellplan_geom::ShapeSpec;
use cellplan_model::taskgen::{GenOptions, sample_tasks};
use cellplan_model::{Cell, InputError};
use cellplan_report::charts::StrategyBar;
use cellplan_report::html::{CompareRow, compare_html};
use cellplan_verify::{VerifySettings, verify_with};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Args)]
pub struct CompareArgs {
    /// The cell file (TOML).
    pub cell: PathBuf,
    /// Seed of the planners (and of the random MP sets).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Instead of the cell's MPs, draw this many random MP sets on the part (as many MPs as
    /// the cell has, in the region and facing of the cell's MPs) and report mean and spread.
    #[arg(long, value_name = "K")]
    pub random_tasks: Option<usize>,
    /// Print JSON (stable keys: strategies[].allocation, coordination, cycle_time_s,
    /// delta_t_s, conflicts_before, verified, compute_s).
    #[arg(long)]
    pub json: bool,
    /// Also write the Markdown table and the JSON to this folder.
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
    /// PCB assembly: simulations per optimiser run.
    #[arg(long, value_name = "N", default_value_t = 200_000)]
    pub evaluations: usize,
    /// PCB assembly: simulations of the GA runs (default: as `--evaluations`); a GA
    /// simulation is cheaper than one of ours, so equal compute time means more of them.
    #[arg(long, value_name = "N")]
    pub ga_evaluations: Option<usize>,
}

#[derive(Serialize, Clone)]
struct Row {
    case: usize,
    allocation: String,
    coordination: String,
    robots: Vec<RobotTime>,
    cycle_time_s: f64,
    delta_t_s: f64,
    lower_bound_s: f64,
    uncoordinated_cycle_time_s: f64,
    conflicts_before: usize,
    conflicts_resolved: usize,
    waits: usize,
    waiting_s: f64,
    poses_changed: usize,
    verified: bool,
    compute_s: f64,
    coordination_compute_s: f64,
    error: Option<String>,
}

#[derive(Serialize, Clone)]
struct RobotTime {
    name: String,
    tasks: usize,
    total_s: f64,
}

#[derive(Serialize)]
struct Summary {
    allocation: String,
    coordination: String,
    cases: usize,
    solved: usize,
    verified: usize,
    cycle_time_mean_s: f64,
    cycle_time_sd_s: f64,
    delta_t_mean_s: f64,
    delta_t_sd_s: f64,
    compute_mean_s: f64,
    coordination_compute_mean_s: f64,
}

#[derive(Serialize)]
struct Report {
    cell: String,
    seed: u64,
    random_tasks: Option<usize>,
    strategies: Vec<Row>,
    summary: Vec<Summary>,
}

const ALLOCATIONS: [Allocation; 4] = [
    Allocation::Proximity,
    Allocation::LocalRobust,
    Allocation::Balanced,
    Allocation::Zones,
];

pub fn run(args: &CompareArgs) -> Result<(), Failure> {
    if crate::pcb_cmd::is_pcb(&args.cell)? {
        return crate::pcb_cmd::compare(args);
    }
    if crate::studweld_cmd::is_studweld(&args.cell)? {
        return crate::studweld_cmd::compare(args);
    }
    if crate::cmm_cmd::is_cmm(&args.cell)? {
        return crate::cmm_cmd::compare(args);
    }
    let show = !args.quiet && !args.json;
    let opts = load_options(false, &None);
    let pb = spinner(show, "loading the cell");
    let base = crate::load_cell(&args.cell, &opts)?;
    let cases = match args.random_tasks {
        None => 1,
        Some(k) if k == 0 || k > 1000 => {
            return Err(Failure::Usage(format!(
                "--random-tasks must be between 1 and 1000, not {k}"
            )));
        }
        Some(k) => k,
    };
    let mut rows = Vec::new();
    for case in 0..cases {
        let mut cell = crate::load_cell(&args.cell, &opts)?;
        if args.random_tasks.is_some() {
            cell.tasks = random_tasks(&base, args.seed + case as u64)?;
        }
        pb.set_message(format!("case {}/{cases}: candidates", case + 1));
        let table = candidates::generate(&cell);
        // The zones run, for ours.
        let mut zones = None;
        for allocation in ALLOCATIONS {
            pb.set_message(format!("case {}/{cases}: planning with {}", case + 1, allocation));
            let settings = PlanSettings {
                allocation,
                seed: args.seed,
                time_limit: Duration::from_secs(3600),
                ..PlanSettings::default()
            };
            let started = Instant::now();
            // The zones run keeps its legs for ours, as `cellplan plan` does.
            let mut cache = plan::PlanCache::default();
            let outcome = match plan::plan_cached(&cell, &table, &settings, &|_| {}, &mut cache) {
                Ok(o) => o,
                Err(e) => {
                    for c in Coordination::RESOLVING {
                        rows.push(failed(case, allocation, c, e.to_string()));
                    }
                    continue;
                }
            };
            let plan_s = started.elapsed().as_secs_f64();
            for strategy in Coordination::RESOLVING {
                pb.set_message(format!(
                    "case {}/{cases}: {} + {}",
                    case + 1,
                    allocation,
                    strategy
                ));
                let cs = CoordSettings {
                    strategy,
                    seed: args.seed,
                    ..CoordSettings::default()
                };
                let row = match coord::coordinate_outcome(&cell, &table, &outcome, &cs) {
                    Ok(c) => {
                        let doc = output::build(&cell, &table, &outcome, &c, &settings, 0.0, 0.0);
                        let report = verify_with(&cell, Some(&table), &doc, &VerifySettings::default());
                        row_of(case, &doc, report.ok, plan_s + c.compute_s, c.compute_s)
                    }
                    Err(e) => failed(case, allocation, strategy, e.to_string()),
                };
                rows.push(row);
            }
            if allocation == Allocation::Zones {
                zones = Some((outcome, settings, plan_s, cache));
            }
        }
        rows.push(ours(&cell, &table, zones, case, args.seed));
    }
    pb.finish_and_clear();
    let summary = summarise(&rows);
    let report = Report {
        cell: base.name.clone(),
        seed: args.seed,
        random_tasks: args.random_tasks,
        strategies: rows,
        summary,
    };
    let json = serde_json::to_string_pretty(&report).map_err(|e| Failure::Other(e.to_string()))?;
    let md = markdown(&report);
    crate::finish_compare(args.output.as_deref(), args.json, &json, &md, || {
        vec![("compare.html", html(&report))]
    })
}

/// The comparison as an HTML page: the table and the bar chart of paper 000 Fig. 10.
fn html(report: &Report) -> String {
    let f2 = |v: f64| format!("{v:.2}");
    let bound = report
        .strategies
        .iter()
        .map(|r| r.lower_bound_s)
        .find(|v| v.is_finite());
    let (header, rows, bars): (Vec<String>, Vec<CompareRow>, Vec<StrategyBar>) = match report.random_tasks {
        None => {
            let names = robot_columns(&report.strategies);
            let mut header = vec!["allocation + coordination".to_string()];
            header.extend(names);
            header.extend(
                [
                    "cycle s",
                    "Δt s",
                    "uncoordinated s",
                    "conflicts",
                    "resolved",
                    "waits",
                    "poses changed",
                    "verified",
                    "compute s",
                    "coordination s",
                ]
                .map(String::from),
            );
            let label = |r: &Row| format!("{} + {}", r.allocation, r.coordination);
            let ok = || report.strategies.iter().filter(|r| r.error.is_none());
            let rows = report
                .strategies
                .iter()
                .map(|r| {
                    let mut cells = vec![label(r)];
                    if let Some(e) = &r.error {
                        cells.push(format!("failed: {e}"));
                    } else {
                        cells.extend(r.robots.iter().map(|x| f2(x.total_s)));
                        cells.extend([
                            f2(r.cycle_time_s),
                            f2(r.delta_t_s),
                            f2(r.uncoordinated_cycle_time_s),
                            r.conflicts_before.to_string(),
                            r.conflicts_resolved.to_string(),
                            r.waits.to_string(),
                            r.poses_changed.to_string(),
                            if r.verified { "yes".into() } else { "NO".into() },
                            f2(r.compute_s),
                            f2(r.coordination_compute_s),
                        ]);
                    }
                    CompareRow {
                        cells,
                        ours: r.allocation == "ours",
                    }
                })
                .collect();
            let bars = ok()
                .map(|r| StrategyBar {
                    label: label(r),
                    robots: r.robots.iter().map(|x| (x.name.clone(), x.total_s)).collect(),
                    cycle_time_s: r.cycle_time_s,
                    spread_s: None,
                })
                .collect();
            (header, rows, bars)
        }
        Some(_) => {
            let header = [
                "allocation + coordination",
                "solved",
                "verified",
                "cycle s (mean ± sd)",
                "Δt s (mean ± sd)",
                "compute s",
                "coordination s",
            ]
            .map(String::from)
            .to_vec();
            let label = |m: &Summary| format!("{} + {}", m.allocation, m.coordination);
            let rows = report
                .summary
                .iter()
                .map(|m| CompareRow {
                    cells: vec![
                        label(m),
                        format!("{}/{}", m.solved, m.cases),
                        m.verified.to_string(),
                        format!("{:.2} ± {:.2}", m.cycle_time_mean_s, m.cycle_time_sd_s),
                        format!("{:.2} ± {:.2}", m.delta_t_mean_s, m.delta_t_sd_s),
                        f2(m.compute_mean_s),
                        f2(m.coordination_compute_mean_s),
                    ],
                    ours: m.allocation == "ours",
                })
                .collect();
            let bars = report
                .summary
                .iter()
                .filter(|m| m.cycle_time_mean_s.is_finite())
                .map(|m| StrategyBar {
                    label: label(m),
                    robots: vec![("mean cycle".into(), m.cycle_time_mean_s)],
                    cycle_time_s: m.cycle_time_mean_s,
                    spread_s: Some(m.cycle_time_sd_s),
                })
                .collect();
            (header, rows, bars)
        }
    };
    let intro = match report.random_tasks {
        None => format!(
            "Every allocation × coordination strategy on cell {} (seed {}); every plan checked by cellplan verify. Bold: ours as `cellplan plan` runs it.",
            report.cell, report.seed
        ),
        Some(k) => format!(
            "{k} random MP sets drawn on the part of cell {} (seed {}), mean ± standard deviation over the solved sets (paper 000 Table 4).",
            report.cell, report.seed
        ),
    };
    compare_html(
        &format!("cellplan compare — {}", report.cell),
        &intro,
        &header,
        &rows,
        &bars,
        if report.random_tasks.is_none() {
            bound
        } else {
            None
        },
    )
}

/// Ours, whole, as `cellplan plan` decides it ([`pipeline::coordinate`]): `best` coordination
/// of the zones allocation, of the zones allocation planned again knowing what its
/// measurements blocked the other robots, and of the nearest-robot allocation, the shortest
/// coordinated cycle kept (compute: the first zones planning and everything the pipeline did
/// after it).
fn ours(
    cell: &Cell,
    table: &CandidateTable,
    zones: Option<(plan::Outcome, PlanSettings, f64, plan::PlanCache)>,
    case: usize,
    seed: u64,
) -> Row {
    let label = |row: Row| Row {
        allocation: "ours".into(),
        ..row
    };
    let Some((outcome, settings, plan_s, mut cache)) = zones else {
        return label(failed(
            case,
            Allocation::Zones,
            Coordination::Best,
            "no plan".into(),
        ));
    };
    let cs = CoordSettings {
        strategy: Coordination::Best,
        seed,
        ..CoordSettings::default()
    };
    let lap = Instant::now();
    match pipeline::coordinate(cell, table, outcome, settings, &cs, &mut cache) {
        Ok((outcome, settings, c)) => {
            let spent = plan_s + lap.elapsed().as_secs_f64();
            let doc = output::build(cell, table, &outcome, &c, &settings, 0.0, 0.0);
            let report = verify_with(cell, Some(table), &doc, &VerifySettings::default());
            label(row_of(case, &doc, report.ok, spent, c.compute_s))
        }
        Err(e) => label(failed(case, Allocation::Zones, Coordination::Best, e.to_string())),
    }
}

fn failed(case: usize, allocation: Allocation, coordination: Coordination, error: String) -> Row {
    Row {
        case,
        allocation: allocation.to_string(),
        coordination: coordination.to_string(),
        robots: Vec::new(),
        cycle_time_s: f64::NAN,
        delta_t_s: f64::NAN,
        lower_bound_s: f64::NAN,
        uncoordinated_cycle_time_s: f64::NAN,
        conflicts_before: 0,
        conflicts_resolved: 0,
        waits: 0,
        waiting_s: 0.0,
        poses_changed: 0,
        verified: false,
        compute_s: 0.0,
        coordination_compute_s: 0.0,
        error: Some(error),
    }
}

fn row_of(case: usize, doc: &output::Plan, verified: bool, compute_s: f64, coord_s: f64) -> Row {
    Row {
        case,
        allocation: doc.settings.allocation.to_string(),
        coordination: doc.settings.coordination.to_string(),
        robots: doc
            .robots
            .iter()
            .map(|r| RobotTime {
                name: r.name.clone(),
                tasks: r.tasks.len(),
                total_s: r.total_s,
            })
            .collect(),
        cycle_time_s: doc.cycle_time_s,
        delta_t_s: doc.delta_t_s,
        lower_bound_s: doc.lower_bound_s,
        uncoordinated_cycle_time_s: doc.coordination.uncoordinated_cycle_time_s,
        conflicts_before: doc.coordination.conflicts_before.len(),
        conflicts_resolved: doc.stats.conflicts_resolved,
        waits: doc.coordination.waits,
        waiting_s: doc.robots.iter().map(|r| r.waiting_s).sum(),
        poses_changed: doc.coordination.poses_changed,
        verified,
        compute_s,
        coordination_compute_s: coord_s,
        error: None,
    }
}

fn summarise(rows: &[Row]) -> Vec<Summary> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in rows {
        let k = (r.allocation.clone(), r.coordination.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(a, c)| {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.allocation == a && r.coordination == c)
                .collect();
            let ok: Vec<&Row> = of.iter().copied().filter(|r| r.error.is_none()).collect();
            let stats = |f: &dyn Fn(&Row) -> f64| {
                let n = ok.len() as f64;
                if ok.is_empty() {
                    return (f64::NAN, f64::NAN);
                }
                let mean = ok.iter().map(|r| f(r)).sum::<f64>() / n;
                let var = ok.iter().map(|r| (f(r) - mean).powi(2)).sum::<f64>() / n;
                (mean, var.sqrt())
            };
            let (cm, cs) = stats(&|r| r.cycle_time_s);
            let (dm, ds) = stats(&|r| r.delta_t_s);
            Summary {
                allocation: a,
                coordination: c,
                cases: of.len(),
                solved: ok.len(),
                verified: ok.iter().filter(|r| r.verified).count(),
                cycle_time_mean_s: cm,
                cycle_time_sd_s: cs,
                delta_t_mean_s: dm,
                delta_t_sd_s: ds,
                compute_mean_s: stats(&|r| r.compute_s).0,
                coordination_compute_mean_s: stats(&|r| r.coordination_compute_s).0,
            }
        })
        .collect()
}

/// Column names of the per robot times ("R1 s", ...), from the first solved row.
fn robot_columns(rows: &[Row]) -> Vec<String> {
    rows.iter()
        .find(|r| !r.robots.is_empty())
        .map(|r| r.robots.iter().map(|x| format!("{} s", x.name)).collect())
        .unwrap_or_default()
}

fn markdown(report: &Report) -> String {
    let mut s = format!(
        "# {} — allocation × coordination (seed {})\n\n",
        report.cell, report.seed
    );
    if report.random_tasks.is_none() {
        let names = robot_columns(&report.strategies);
        s += &format!(
            "| allocation | coordination | {} | cycle s | Δt s | uncoordinated s | lower bound s | conflicts | resolved | waits | waiting s | poses changed | verified | compute s | coordination s |\n",
            names.join(" | ")
        );
        s += &format!("|{}\n", "---|".repeat(14 + names.len()));
        for r in &report.strategies {
            if let Some(e) = &r.error {
                s += &format!("| {} | {} | failed: {e} |\n", r.allocation, r.coordination);
                continue;
            }
            let times: Vec<String> = r.robots.iter().map(|x| format!("{:.2}", x.total_s)).collect();
            s += &format!(
                "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} | {} | {:.2} | {} | {} | {:.2} | {:.2} |\n",
                r.allocation,
                r.coordination,
                times.join(" | "),
                r.cycle_time_s,
                r.delta_t_s,
                r.uncoordinated_cycle_time_s,
                r.lower_bound_s,
                r.conflicts_before,
                r.conflicts_resolved,
                r.waits,
                r.waiting_s,
                r.poses_changed,
                if r.verified { "yes" } else { "NO" },
                r.compute_s,
                r.coordination_compute_s
            );
        }
    } else {
        s += &format!(
            "{} random MP sets; mean ± standard deviation over the solved cases\n\n",
            report.random_tasks.unwrap_or(0)
        );
        s += "| allocation | coordination | solved | verified | cycle s | Δt s | compute s | coordination s |\n|---|---|---|---|---|---|---|---|\n";
        for m in &report.summary {
            s += &format!(
                "| {} | {} | {}/{} | {} | {:.2} ± {:.2} | {:.2} ± {:.2} | {:.2} | {:.2} |\n",
                m.allocation,
                m.coordination,
                m.solved,
                m.cases,
                m.verified,
                m.cycle_time_mean_s,
                m.cycle_time_sd_s,
                m.delta_t_mean_s,
                m.delta_t_sd_s,
                m.compute_mean_s,
                m.coordination_compute_mean_s
            );
        }
    }
    s
}

/// As many random MPs as `cell` has, on its largest mesh object, in the box of its MPs (grown
/// by 10 cm) and facing within 80° of their mean normal.
fn random_tasks(cell: &Cell, seed: u64) -> Result<Vec<cellplan_model::Task>, Failure> {
    let part = cell
        .objects
        .iter()
        .filter_map(|o| match &o.shape {
            ShapeSpec::Mesh(m) => Some((m.triangles.len(), m.transformed(&o.pose))),
            _ => None,
        })
        .max_by_key(|x| x.0)
        .map(|x| x.1)
        .ok_or_else(|| {
            Failure::Input(Box::new(
                InputError::new(
                    &cell.path,
                    "--random-tasks needs a mesh object (the part) in the cell",
                )
                .hint("add the part as a mesh object"),
            ))
        })?;
    let mut opts = GenOptions::new(cell.tasks.len(), seed);
    let mut lo = cellplan_geom::DVec3::splat(f64::INFINITY);
    let mut hi = cellplan_geom::DVec3::splat(f64::NEG_INFINITY);
    let mut normal = cellplan_geom::DVec3::ZERO;
    for t in &cell.tasks {
        lo = lo.min(t.position);
        hi = hi.max(t.position);
        normal += t.normal;
    }
    for axis in 0..3 {
        opts.region[axis] = (lo[axis] - 0.1, hi[axis] + 0.1);
    }
    if let Some(n) = normal.try_normalize() {
        opts.facing = Some((n, 80f64.to_radians()));
    }
    sample_tasks(&part, &opts).map_err(|m| Failure::Other(format!("random MPs: {m}")))
}
