//! `plan`, `verify` and `compare` on stud-weld cells (paper 002): argument checks, output files
//! and printing only; the work is in `cellplan-studweld`, the check in
//! `cellplan-verify::studweld`.
use crate::Failure;
use crate::compare_cmd::CompareArgs;
use crate::plan_cmd::PlanArgs;
use crate::verify_cmd::print_verdict;
use cellplan_model::io::write_atomic;
use cellplan_model::{Cell, InputError, LoadOptions};
use cellplan_studweld::cell::WeldCell;
use cellplan_studweld::document::{WeldPlan, build};
use cellplan_studweld::leg::LegSettings;
use cellplan_studweld::plan::{PlanError, run};
use cellplan_studweld::sequence::Sequencer;
use cellplan_verify::studweld::{WeldReport, verify_weld};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// Whether the cell file is a stud-weld cell (read by its `[process] kind`).
pub fn is_studweld(cell: &Path) -> Result<bool, Failure> {
    Ok(cellplan_model::process_kind(cell)? == cellplan_studweld::KIND)
}

fn load(path: &Path) -> Result<Cell, Failure> {
    Ok(crate::load_cell(path, &LoadOptions::default())?)
}

fn plan_error(cell: &Cell, e: PlanError) -> Failure {
    match e {
        PlanError::NothingWeldable => Failure::Infeasible,
        other => Failure::Input(Box::new(
            InputError::new(&cell.path, format!("cannot plan this cell: {other}"))
                .hint("move the robot's base or home, or the studs"),
        )),
    }
}

#[derive(Serialize)]
struct Summary<'a> {
    plan_file: String,
    sequencer: &'static str,
    cost: f64,
    travel_cost: f64,
    weld_cost: f64,
    cycle_time_s: f64,
    studs: usize,
    welded: usize,
    alternatives: Vec<usize>,
    unweldable: Vec<(&'a str, &'a str)>,
    fallback_legs: usize,
    lazy_rounds: usize,
    converged: bool,
    exact_gtsp: bool,
    ocp_solves: usize,
    compute_s: f64,
    verified: bool,
}

fn fallbacks(doc: &WeldPlan) -> usize {
    doc.legs.iter().filter(|l| l.fallback.is_some()).count()
}

fn describe(r: &WeldReport) -> Vec<String> {
    r.violations
        .iter()
        .map(|v| format!("{:?}: {}", v.kind, v.detail))
        .collect()
}

/// `cellplan plan` on a stud-weld cell: the optimal-control sequence, verified, to plan.json.
pub fn plan(args: &PlanArgs) -> Result<(), Failure> {
    let start = Instant::now();
    if args.time_limit.is_some() {
        return Err(Failure::Usage(
            "--time-limit does not apply to stud-weld cells: the budget is work (the cell's `ocp_budget`, solver iterations, planner samples), so the plan depends only on the cell and the seed".into(),
        ));
    }
    let cell = load(&args.cell)?;
    let w = WeldCell::new(&cell)?;
    // Before any planning: the output folder must take files.
    let dir = crate::plan_output_dir(args.output.as_deref(), &cell.name, &cell.path)?;
    let show = !args.quiet && !args.json;
    let pb = crate::spinner(show, &format!("planning {} studs", cell.tasks.len()));
    let settings = LegSettings {
        seed: args.seed,
        ..LegSettings::default()
    };
    let out = run(&w, &[Sequencer::OptimalControl], &settings).map_err(|e| plan_error(&cell, e))?;
    let o = &out.outcomes[0];
    let doc = build(&w, &out, o);
    pb.set_message("verifying the plan");
    let verdict = verify_weld(&cell, &doc);
    pb.finish_and_clear();
    if !verdict.ok && !args.no_verify {
        for line in describe(&verdict) {
            eprintln!("{line}");
        }
        return Err(Failure::Other(format!(
            "the plan failed verification ({} violation(s)) and was not written; --no-verify writes it anyway",
            verdict.violations.len()
        )));
    }
    let file = dir.join("plan.json");
    let text = serde_json::to_string_pretty(&doc).map_err(|e| Failure::Other(e.to_string()))?;
    write_atomic(&file, text.as_bytes())
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", file.display())))?;
    let compute_s = start.elapsed().as_secs_f64();
    let t = doc.totals;
    if args.json {
        crate::print_json(&Summary {
            plan_file: file.display().to_string(),
            sequencer: o.sequencer.name(),
            cost: t.cost,
            travel_cost: t.travel_cost,
            weld_cost: t.weld_cost,
            cycle_time_s: t.cycle_time_s,
            studs: cell.tasks.len(),
            welded: doc.visits.len(),
            alternatives: doc.alternatives.iter().map(|a| a.count).collect(),
            unweldable: doc
                .unweldable
                .iter()
                .map(|u| (u.stud.as_str(), u.reason.as_str()))
                .collect(),
            fallback_legs: fallbacks(&doc),
            lazy_rounds: doc.sequencing.rounds,
            converged: doc.sequencing.converged,
            exact_gtsp: doc.sequencing.exact,
            ocp_solves: doc.sequencing.ocp_solves,
            compute_s,
            verified: verdict.ok,
        })?;
    } else if !args.quiet {
        println!(
            "{} studs welded of {}; J = {:.1} (travel {:.1}, welding {:.1}); cycle {:.2} s; {} OCPs in {} lazy rounds{}; {} fallback legs; {:.1} s; verified: {}",
            doc.visits.len(),
            cell.tasks.len(),
            t.cost,
            t.travel_cost,
            t.weld_cost,
            t.cycle_time_s,
            doc.sequencing.ocp_solves,
            doc.sequencing.rounds,
            if doc.sequencing.converged {
                ""
            } else {
                " (budget ended)"
            },
            fallbacks(&doc),
            compute_s,
            verdict.ok
        );
        for u in &doc.unweldable {
            println!("unweldable: {} — {}", u.stud, u.text);
        }
        println!("plan: {}", file.display());
    }
    if doc.unweldable.is_empty() {
        Ok(())
    } else {
        Err(Failure::Infeasible)
    }
}

fn read_plan(plan_path: &Path) -> Result<WeldPlan, Failure> {
    cellplan_studweld::document::read(plan_path).map_err(|e| {
        Failure::Input(Box::new(
            InputError::new(plan_path, e)
                .hint("give a plan.json that `cellplan plan` wrote for a stud-weld cell"),
        ))
    })
}

/// `cellplan report` on a stud-weld plan: the page, verified.
pub fn report(plan_path: &Path, cell_path: &Path, out: &Path) -> Result<(), Failure> {
    let cell = load(cell_path)?;
    let plan = read_plan(plan_path)?;
    let w = WeldCell::new(&cell)?;
    let verdict = verify_weld(&cell, &plan);
    let page = cellplan_report::studweld::html(&plan, &w, Some(&verdict));
    write_atomic(out, page.as_bytes())
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", out.display())))
}

/// `cellplan verify` on a stud-weld plan.
pub fn verify(plan_path: &Path, cell_path: &Path, json: bool) -> Result<(), Failure> {
    let cell = load(cell_path)?;
    let plan = read_plan(plan_path)?;
    let report = verify_weld(&cell, &plan);
    let summary = format!(
        "largest discrete Euler–Lagrange residual {:.1e} (relative); {} pieces proven clear",
        report.max_dynamics_residual, report.segments_checked
    );
    let lines = describe(&report);
    print_verdict(&report, report.ok, &lines, String::clone, &summary, json)
}

#[derive(Serialize)]
struct Strategy {
    sequencer: &'static str,
    cost: f64,
    travel_cost: f64,
    weld_cost: f64,
    cycle_time_s: f64,
    lazy_rounds: usize,
    converged: bool,
    fallback_legs: usize,
    verified: bool,
}

#[derive(Serialize)]
struct Comparison {
    cell: String,
    studs: usize,
    alternatives: Vec<usize>,
    ocp_solves: usize,
    compute_s: f64,
    strategies: Vec<Strategy>,
}

/// `cellplan compare` on a stud-weld cell: paper 002's Table 2 (the travel-time sequence, then
/// each leg optimised, against the sequence on optimal-control costs), both verified.
pub fn compare(args: &CompareArgs) -> Result<(), Failure> {
    let start = Instant::now();
    if args.random_tasks.is_some() {
        return Err(Failure::Usage(
            "--random-tasks does not apply to stud-weld cells".into(),
        ));
    }
    let cell = load(&args.cell)?;
    let w = WeldCell::new(&cell)?;
    let pb = crate::spinner(!args.quiet && !args.json, "planning both sequences");
    let settings = LegSettings {
        seed: args.seed,
        ..LegSettings::default()
    };
    let out = run(&w, &[Sequencer::TravelTime, Sequencer::OptimalControl], &settings)
        .map_err(|e| plan_error(&cell, e))?;
    let mut strategies = Vec::new();
    for o in &out.outcomes {
        let doc = build(&w, &out, o);
        let verdict = verify_weld(&cell, &doc);
        for line in describe(&verdict) {
            eprintln!("{}: {line}", o.sequencer.name());
        }
        strategies.push(Strategy {
            sequencer: o.sequencer.name(),
            cost: o.cost,
            travel_cost: o.travel_cost,
            weld_cost: o.weld_cost,
            cycle_time_s: o.cycle_time,
            lazy_rounds: o.sequence.rounds,
            converged: o.sequence.converged,
            fallback_legs: fallbacks(&doc),
            verified: verdict.ok,
        });
    }
    pb.finish_and_clear();
    let c = Comparison {
        cell: cell.name.clone(),
        studs: cell.tasks.len(),
        alternatives: out.alternatives.per_stud.iter().map(Vec::len).collect(),
        ocp_solves: out.ocp_solves,
        compute_s: start.elapsed().as_secs_f64(),
        strategies,
    };
    let text = serde_json::to_string_pretty(&c).map_err(|e| Failure::Other(e.to_string()))?;
    let mut table = String::from(
        "| sequence | travel | welding | total J | cycle (s) | verified |\n|---|---|---|---|---|---|\n",
    );
    for s in &c.strategies {
        table.push_str(&format!(
            "| {} | {:.1} | {:.1} | {:.1} | {:.2} | {} |\n",
            s.sequencer, s.travel_cost, s.weld_cost, s.cost, s.cycle_time_s, s.verified
        ));
    }
    table.push_str(&format!("{} OCPs solved, {:.1} s\n", c.ocp_solves, c.compute_s));
    crate::finish_compare(args.output.as_deref(), args.json, &text, &table, Vec::new)?;
    if c.strategies.iter().all(|s| s.verified) {
        Ok(())
    } else {
        Err(Failure::Rejected)
    }
}
