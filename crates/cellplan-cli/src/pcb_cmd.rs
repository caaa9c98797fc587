//! `plan`, `verify`, `report` and `compare` on PCB-assembly cells (paper 004): argument checks,
//! output files and printing only; the work is in `cellplan-pcb`, the check in
//! `cellplan-verify::pcb`, the page in `cellplan-report::pcb`.
use crate::Failure;
use crate::plan_cmd::PlanArgs;
use crate::verify_cmd::print_verdict;
use cellplan_model::InputError;
use cellplan_model::io::write_all_atomic;
use cellplan_pcb::PcbCell;
use cellplan_pcb::cell::{Configuration, KIND, MotionModel};
use cellplan_pcb::document::PcbPlan;
use cellplan_pcb::plan::{Optimizer, Outcome, Request};
use cellplan_verify::pcb::{PcbReport, PcbVerifySettings, verify_pcb};
use serde::Serialize;
use std::path::Path;
use std::time::{Duration, Instant};

/// Whether the cell file is a PCB-assembly cell (read by its `[process] kind`).
pub fn is_pcb(cell: &Path) -> Result<bool, Failure> {
    Ok(cellplan_model::process_kind(cell)? == KIND)
}

/// Loads a PCB cell.
pub fn load(path: &Path) -> Result<PcbCell, Failure> {
    Ok(cellplan_pcb::load(path)?)
}

/// The optimiser names of `--optimizer`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OptimizerArg {
    /// Paper 004's GA.
    Ga,
    /// Ours.
    Best,
}

impl From<OptimizerArg> for Optimizer {
    fn from(o: OptimizerArg) -> Self {
        match o {
            OptimizerArg::Ga => Optimizer::Ga,
            OptimizerArg::Best => Optimizer::Best,
        }
    }
}

/// `--configuration`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ConfigurationArg {
    /// Feeders and table fixed.
    AllFixed,
    /// Feeders move, table fixed.
    MovingCds,
    /// Table moves, feeders fixed.
    MovingTable,
    /// All move.
    AllMoving,
}

impl From<ConfigurationArg> for Configuration {
    fn from(c: ConfigurationArg) -> Self {
        match c {
            ConfigurationArg::AllFixed => Configuration::AllFixed,
            ConfigurationArg::MovingCds => Configuration::MovingCds,
            ConfigurationArg::MovingTable => Configuration::MovingTable,
            ConfigurationArg::AllMoving => Configuration::AllMoving,
        }
    }
}

/// `--motion`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MotionArg {
    /// Full speed at once (the paper's assumption).
    ConstantSpeed,
    /// Acceleration-limited.
    Trapezoid,
}

/// Most simulations a run may be given.
pub const MAX_EVALUATIONS: usize = 100_000_000;

/// The cell as the flags ask for it.
fn variant(cell: &PcbCell, args: &PlanArgs) -> Result<PcbCell, Failure> {
    let robots = args.robots.unwrap_or(cell.robots.len());
    if !(1..=2).contains(&robots) {
        return Err(Failure::Usage(format!("--robots must be 1 or 2, not {robots}")));
    }
    let configuration = args.configuration.map_or(cell.configuration, Into::into);
    let motion = match args.motion {
        None => cell.motion,
        Some(MotionArg::ConstantSpeed) => MotionModel::ConstantSpeed,
        Some(MotionArg::Trapezoid) => MotionModel::Trapezoid,
    };
    cell.variant(robots, configuration, motion).map_err(|e| {
        Failure::Input(Box::new(
            InputError::new(&cell.path, format!("cannot plan this cell so: {e}")).hint(
                "a one-robot run of a two-robot cell needs robot 1 to reach both feeders and the whole board",
            ),
        ))
    })
}

#[derive(Serialize)]
struct Summary<'a> {
    plan_file: String,
    report_file: Option<String>,
    program_file: String,
    cycle_time_s: f64,
    lower_bound_s: f64,
    gap_to_lower_bound: f64,
    components: usize,
    robots: Vec<RobotSummary<'a>>,
    configuration: &'static str,
    optimizer: &'static str,
    collision_avoidance: bool,
    evaluations: usize,
    time_limit_hit: bool,
    verified: bool,
    compute_s: f64,
}

#[derive(Serialize)]
struct RobotSummary<'a> {
    name: &'a str,
    components: usize,
    motion_s: f64,
    waiting_s: f64,
    total_s: f64,
}

/// Plans with the flags' optimiser and budget.
pub fn run_plan(
    cell: &PcbCell,
    optimizer: Optimizer,
    evaluations: usize,
    seed: u64,
    time_limit: Option<f64>,
) -> Outcome {
    cellplan_pcb::plan::run(
        cell,
        &Request {
            optimizer,
            evaluations,
            seed,
            deadline: time_limit.map(|t| Instant::now() + Duration::from_secs_f64(t)),
        },
    )
}

/// The verifier's verdict on a plan, robot–robot gap included.
pub fn check(cell: &PcbCell, plan: &PcbPlan) -> PcbReport {
    verify_pcb(cell, plan, &PcbVerifySettings::default())
}

/// `cellplan plan` on a PCB cell.
pub fn plan(args: &PlanArgs) -> Result<(), Failure> {
    let start = Instant::now();
    if args.evaluations == 0 || args.evaluations > MAX_EVALUATIONS {
        return Err(Failure::Usage(format!(
            "--evaluations must be between 1 and {MAX_EVALUATIONS}"
        )));
    }
    if args
        .time_limit
        .is_some_and(|t| !(t.is_finite() && t > 0.0 && t <= 1e6))
    {
        return Err(Failure::Usage(
            "--time-limit must be a number of seconds above 0 and at most 1e6".into(),
        ));
    }
    let loaded = load(&args.cell)?;
    let cell = variant(&loaded, args)?;
    // Before any planning: the output folder must take files.
    let dir = crate::plan_output_dir(args.output.as_deref(), &cell.name, &cell.path)?;
    let show = !args.quiet && !args.json;
    let pb = crate::spinner(show, &format!("planning {} components", cell.len()));
    let optimizer: Optimizer = args.optimizer.into();
    let out = match &args.order {
        Some(file) => {
            cellplan_pcb::plan::run_given(&cell, &read_order(file, &cell)?, args.evaluations, args.seed)
        }
        None => run_plan(&cell, optimizer, args.evaluations, args.seed, args.time_limit),
    };
    pb.set_message("verifying the plan");
    let verdict = check(&loaded, &out.plan);
    if !verdict.ok && !args.no_verify {
        pb.finish_and_clear();
        for v in &verdict.violations {
            eprintln!("{}", describe(v));
        }
        return Err(Failure::Other(format!(
            "the plan failed verification ({} violation(s)) and was not written; --no-verify writes it anyway",
            verdict.violations.len()
        )));
    }
    let mut doc = out.plan.clone();
    doc.compute_s = start.elapsed().as_secs_f64();
    let file = dir.join("plan.json");
    let program_file = dir.join("placement.csv");
    let report_file = dir.join("report.html");
    let text = serde_json::to_string_pretty(&doc).map_err(|e| Failure::Other(e.to_string()))?;
    let program = cellplan_report::pcb::program_csv(&doc);
    let page = (!args.no_report).then(|| cellplan_report::pcb::html(&doc, &cell, Some(&verdict)));
    let mut files: Vec<(&Path, &[u8])> = vec![(&file, text.as_bytes()), (&program_file, program.as_bytes())];
    if let Some(p) = &page {
        files.push((&report_file, p.as_bytes()));
    }
    write_all_atomic(&files)
        .map_err(|e| Failure::Other(format!("cannot write into {}: {e}", dir.display())))?;
    pb.finish_and_clear();
    if args.json {
        let summary = Summary {
            plan_file: file.display().to_string(),
            report_file: page.is_some().then(|| report_file.display().to_string()),
            program_file: program_file.display().to_string(),
            cycle_time_s: doc.cycle_time_s,
            lower_bound_s: doc.lower_bound_s,
            gap_to_lower_bound: gap(doc.cycle_time_s, doc.lower_bound_s),
            components: doc.placements.len(),
            robots: doc
                .robots
                .iter()
                .map(|r| RobotSummary {
                    name: &r.name,
                    components: r.components,
                    motion_s: r.motion_s,
                    waiting_s: r.waiting_s,
                    total_s: r.total_s,
                })
                .collect(),
            configuration: doc.configuration.name(),
            optimizer: if args.order.is_some() {
                "given"
            } else {
                optimizer.name()
            },
            collision_avoidance: doc.collision_avoidance,
            evaluations: doc.evaluations,
            time_limit_hit: out.time_limit_hit,
            verified: verdict.ok,
            compute_s: doc.compute_s,
        };
        crate::print_json(&summary)?;
    } else if !args.quiet {
        print!("{}", render(&doc, &verdict, out.time_limit_hit));
        println!("plan written to {}", file.display());
        println!("placement program written to {}", program_file.display());
        if page.is_some() {
            println!("report written to {}", report_file.display());
        }
    }
    Ok(())
}

/// Reads a placement order: one reference per line (blank lines and `#` comments skipped; a
/// CSV's first column). Every component of the cell exactly once.
fn read_order(path: &Path, cell: &PcbCell) -> Result<Vec<usize>, Failure> {
    let text = cellplan_model::io::read_bounded(path, 16 << 20).map_err(|e| {
        InputError::new(path, format!("cannot read the order: {e}"))
            .hint("give a file of references, one per line")
    })?;
    let mut order = Vec::new();
    let mut seen = vec![false; cell.len()];
    for (i, line) in text.lines().enumerate() {
        let r = line.split(',').next().unwrap_or("").trim().trim_matches('"');
        if r.is_empty() || r.starts_with('#') || (i == 0 && r.eq_ignore_ascii_case("ref")) {
            continue;
        }
        let Some(c) = cell.components.iter().position(|c| c.reference == r) else {
            return Err(InputError::at_line(
                path,
                Some(i + 1),
                format!("`{r}` is not a component this cell places"),
            )
            .hint("list the references `cellplan check` counts as placed, one per line")
            .into());
        };
        if std::mem::replace(&mut seen[c], true) {
            return Err(
                InputError::at_line(path, Some(i + 1), format!("`{r}` is listed twice"))
                    .hint("list every component once")
                    .into(),
            );
        }
        order.push(c);
    }
    if let Some(c) = seen.iter().position(|s| !s) {
        return Err(InputError::new(
            path,
            format!(
                "the order lists {} of {} components; `{}` (and maybe others) is missing",
                order.len(),
                cell.len(),
                cell.components[c].reference
            ),
        )
        .hint("list every placed component once")
        .into());
    }
    Ok(order)
}

/// (cycle − bound) / bound.
pub fn gap(cycle: f64, bound: f64) -> f64 {
    if bound > 0.0 { cycle / bound - 1.0 } else { 0.0 }
}

fn render(doc: &PcbPlan, verdict: &PcbReport, hit: bool) -> String {
    let mut s = format!(
        "{} — {} components, {} robot(s), {}, optimiser {}, seed {}\n\n",
        doc.cell,
        doc.placements.len(),
        doc.robots.len(),
        doc.configuration.name(),
        doc.optimizer,
        doc.seed
    );
    s += &format!(
        "{:<10} {:>10} {:>10} {:>10} {:>10} {:>9}\n",
        "robot", "components", "motion s", "working s", "waiting s", "total s"
    );
    for r in &doc.robots {
        s += &format!(
            "{:<10} {:>10} {:>10.3} {:>10.3} {:>10.3} {:>9.3}\n",
            r.name, r.components, r.motion_s, r.working_s, r.waiting_s, r.total_s
        );
    }
    let delays: f64 = doc.placements.iter().map(|p| p.safety_delay_s).sum();
    if doc.robots.len() == 2 {
        s += &format!(
            "\nsafety delays {:.3} s in {} placements (collision avoidance {})\n",
            delays,
            doc.placements.iter().filter(|p| p.safety_delay_s > 1e-9).count(),
            if doc.collision_avoidance { "on" } else { "off" }
        );
    }
    s += &format!(
        "\nassembly time {:.3} s   lower bound {:.3} s (gap {:.1} %)   {} simulations, compute {:.2} s\n",
        doc.cycle_time_s,
        doc.lower_bound_s,
        100.0 * gap(doc.cycle_time_s, doc.lower_bound_s),
        doc.evaluations,
        doc.compute_s
    );
    if hit {
        s += "time limit reached: the search stopped before its work budget, so this plan depends on this machine's speed\n";
    }
    s += &if verdict.ok {
        "verified: every device replayed on one clock — speeds, travel, every pick and placement a true meeting, each component once, the robots apart\n".to_string()
    } else {
        format!(
            "NOT VERIFIED ({} violation(s); written with --no-verify)\n",
            verdict.violations.len()
        )
    };
    s
}

/// One violation on one line.
pub fn describe(v: &cellplan_verify::pcb::PcbViolation) -> String {
    let who = v.device.as_deref().unwrap_or("-");
    let when = v.time_s.map_or(String::new(), |t| format!(" at {t:.3} s"));
    let comp = v
        .component
        .as_ref()
        .map_or(String::new(), |c| format!(" component {c}"));
    format!("{:?} {who}{when}{comp}: {}", v.kind, v.detail)
}

/// `cellplan verify` on a PCB plan.
/// (`robot_robot` false: crossings are counted, not refused.)
pub fn verify(plan_path: &Path, cell_path: &Path, json: bool, robot_robot: bool) -> Result<(), Failure> {
    let cell = load(cell_path)?;
    let plan = cellplan_pcb::document::read(plan_path).map_err(|e| {
        Failure::Input(Box::new(
            InputError::new(plan_path, e)
                .hint("give a plan.json that `cellplan plan` wrote for this PCB cell"),
        ))
    })?;
    let report = verify_pcb(&cell, &plan, &PcbVerifySettings { robot_robot });
    let summary = format!(
        "assembly time {:.3} s (recomputed), lower bound {:.3} s{}",
        report.cycle_time_s,
        report.lower_bound_s,
        if report.crossings > 0 && report.ok {
            format!(
                "; {} robot crossing(s), not checked (--no-robot-robot)",
                report.crossings
            )
        } else {
            String::new()
        }
    );
    print_verdict(&report, report.ok, &report.violations, describe, &summary, json)
}

/// `cellplan report` on a PCB plan.
pub fn report(plan_path: &Path, cell_path: &Path, out: &Path) -> Result<(), Failure> {
    let cell = load(cell_path)?;
    let plan = cellplan_pcb::document::read(plan_path).map_err(|e| {
        Failure::Input(Box::new(
            InputError::new(plan_path, e)
                .hint("give a plan.json that `cellplan plan` wrote for this PCB cell"),
        ))
    })?;
    let report = check(&cell, &plan);
    let n_robots = plan.robots.len();
    let cell = cell
        .variant(n_robots, plan.configuration, plan.motion)
        .map_err(|e| Failure::Other(e.to_string()))?;
    let page = cellplan_report::pcb::html(&plan, &cell, Some(&report));
    cellplan_model::io::write_atomic(out, page.as_bytes())
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", out.display())))?;
    Ok(())
}

/// One row of `compare` on a PCB cell.
#[derive(Serialize, Clone)]
struct CompareRow {
    optimizer: &'static str,
    configuration: &'static str,
    robots: usize,
    collision_avoidance: bool,
    cycle_time_s: f64,
    lower_bound_s: f64,
    gap_to_lower_bound: f64,
    safety_delays_s: f64,
    crossings: usize,
    verified: bool,
    evaluations: usize,
    compute_s: f64,
    /// Simulations after which the run first reached its final assembly time within 0.1 %.
    evaluations_to_final: usize,
}

#[derive(Serialize)]
struct CompareOut {
    cell: String,
    components: usize,
    seed: u64,
    strategies: Vec<CompareRow>,
}

/// `cellplan compare` on a PCB cell: the one-robot configurations (with the cell's first robot)
/// and, on a two-robot cell, two robots with and without collision avoidance; each with the
/// paper's GA and ours, on the same budget of simulations unless `--ga-evaluations` says
/// otherwise.
pub fn compare(args: &crate::compare_cmd::CompareArgs) -> Result<(), Failure> {
    let ga_evals = args.ga_evaluations.unwrap_or(args.evaluations);
    for e in [args.evaluations, ga_evals] {
        if e == 0 || e > MAX_EVALUATIONS {
            return Err(Failure::Usage(format!(
                "--evaluations and --ga-evaluations must be between 1 and {MAX_EVALUATIONS}"
            )));
        }
    }
    let base = load(&args.cell)?;
    let show = !args.quiet && !args.json;
    let mut cases: Vec<(usize, Configuration, bool)> = Vec::new();
    if base.variant(1, Configuration::AllMoving, base.motion).is_ok() {
        cases.extend(Configuration::ALL.iter().map(|&c| (1, c, false)));
    }
    if base.robots.len() == 2 {
        cases.push((2, Configuration::AllMoving, true));
        cases.push((2, Configuration::AllMoving, false));
    }
    let pb = crate::spinner(show, "comparing");
    let mut rows = Vec::new();
    for &(robots, configuration, avoid) in &cases {
        let Ok(mut cell) = base.variant(robots, configuration, base.motion) else {
            continue;
        };
        if robots == 2 {
            cell.collision_avoidance = avoid;
        }
        for optimizer in [Optimizer::Ga, Optimizer::Best] {
            pb.set_message(format!(
                "{} robot(s), {}, {}{}",
                robots,
                configuration.name(),
                optimizer.name(),
                if robots == 2 && !avoid {
                    ", no collision avoidance"
                } else {
                    ""
                }
            ));
            let evals = if optimizer == Optimizer::Ga {
                ga_evals
            } else {
                args.evaluations
            };
            let out = run_plan(&cell, optimizer, evals, args.seed, None);
            // The no-avoidance runs are checked against their own cell (avoidance off), with
            // crossings counted rather than refused.
            let verdict = verify_pcb(
                &cell,
                &out.plan,
                &PcbVerifySettings {
                    robot_robot: robots < 2 || avoid,
                },
            );
            let last = out.plan.cycle_time_s;
            let to_final = out
                .trace
                .iter()
                .find(|(_, v)| *v <= last * 1.001)
                .map_or(evals, |t| t.0);
            rows.push(CompareRow {
                optimizer: optimizer.name(),
                configuration: configuration.name(),
                robots,
                collision_avoidance: robots == 2 && avoid,
                cycle_time_s: out.plan.cycle_time_s,
                lower_bound_s: out.plan.lower_bound_s,
                gap_to_lower_bound: gap(out.plan.cycle_time_s, out.plan.lower_bound_s),
                safety_delays_s: out.plan.placements.iter().map(|p| p.safety_delay_s).sum(),
                crossings: verdict.crossings,
                verified: verdict.ok,
                evaluations: out.plan.evaluations,
                compute_s: out.plan.compute_s,
                evaluations_to_final: to_final,
            });
        }
    }
    pb.finish_and_clear();
    let out = CompareOut {
        cell: base.name.clone(),
        components: base.len(),
        seed: args.seed,
        strategies: rows,
    };
    let text = serde_json::to_string_pretty(&out).map_err(|e| Failure::Other(e.to_string()))?;
    let table = compare_table(&out);
    crate::finish_compare(args.output.as_deref(), args.json, &text, &table, Vec::new)
}

fn compare_table(out: &CompareOut) -> String {
    let mut s = format!(
        "{} — {} components, seed {}\n\n| robots | configuration | collision avoidance | optimiser | assembly s | bound s | gap | delays s | verified | simulations | compute s |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        out.cell, out.components, out.seed
    );
    for r in &out.strategies {
        let _ = std::fmt::Write::write_fmt(
            &mut s,
            format_args!(
                "| {} | {} | {} | {} | {:.3} | {:.3} | {:.1} % | {:.3} | {} | {} | {:.2} |\n",
                r.robots,
                r.configuration,
                if r.robots == 2 {
                    if r.collision_avoidance { "yes" } else { "no" }
                } else {
                    "-"
                },
                r.optimizer,
                r.cycle_time_s,
                r.lower_bound_s,
                100.0 * r.gap_to_lower_bound,
                r.safety_delays_s,
                if r.verified {
                    "yes".to_string()
                } else if r.crossings > 0 {
                    format!("no ({} crossings)", r.crossings)
                } else {
                    "NO".to_string()
                },
                r.evaluations,
                r.compute_s
            ),
        );
    }
    s
}

#[derive(Serialize)]
struct CheckOut {
    cell: String,
    board: String,
    footprints: usize,
    components: usize,
    types: usize,
    bins: [usize; 2],
    robots: usize,
    skipped: std::collections::BTreeMap<&'static str, usize>,
    lower_bound_s: Vec<(String, f64)>,
}

/// `cellplan check` on a PCB cell: what is placed, what is skipped and why, the bounds.
pub fn check_cell(path: &Path, json: bool) -> Result<(), Failure> {
    let cell = load(path)?;
    let mut skipped = std::collections::BTreeMap::new();
    let side = cell
        .components
        .first()
        .map_or(cellplan_pcb::board::Side::Front, |c| c.side);
    let placed: std::collections::HashSet<&str> =
        cell.components.iter().map(|c| c.reference.as_str()).collect();
    for c in &cell.board.components {
        if placed.contains(c.reference.as_str()) {
            continue;
        }
        let why = if c.dnp {
            "do not populate"
        } else if c.excluded {
            "excluded from position files"
        } else if c.reference.contains('*') {
            "not annotated"
        } else if c.side != side {
            "other side"
        } else {
            "mounting or `components` not placed here"
        };
        *skipped.entry(why).or_insert(0) += 1;
    }
    let mut bounds = Vec::new();
    for robots in 1..=cell.robots.len() {
        for conf in Configuration::ALL {
            if robots == 2 && conf != Configuration::AllMoving {
                continue;
            }
            if let Ok(v) = cell.variant(robots, conf, cell.motion) {
                bounds.push((
                    format!("{robots} robot(s), {}", conf.name()),
                    cellplan_pcb::bound::lower_bound(&v),
                ));
            }
        }
    }
    let out = CheckOut {
        cell: cell.name.clone(),
        board: cell.board.title.clone(),
        footprints: cell.board.components.len(),
        components: cell.len(),
        types: cell.types.len(),
        bins: [cell.feeders[0].bins, cell.feeders[1].bins],
        robots: cell.robots.len(),
        skipped,
        lower_bound_s: bounds,
    };
    if json {
        return crate::print_json(&out);
    }
    println!(
        "{} — board {}: {} footprints, {} to place ({} types) with {} robot(s); feeders hold {} + {} bins",
        out.cell, out.board, out.footprints, out.components, out.types, out.robots, out.bins[0], out.bins[1]
    );
    for (why, n) in &out.skipped {
        println!("  not placed: {n} ({why})");
    }
    for (what, lb) in &out.lower_bound_s {
        println!("  lower bound {lb:.3} s ({what})");
    }
    Ok(())
}
