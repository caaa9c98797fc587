//! `plan`, `reuse`, `verify`, `report`, `compare` and `check` on CMM-inspection cells (paper
//! 003): argument checks, output files and printing only; the work is in `cellplan-cmm`, the
//! check in `cellplan-verify::cmm`, the page in `cellplan-report::cmm`. Here: plan, verify,
//! report, check; [`reuse`](mod@reuse) the `reuse` command, [`compare`](mod@compare) Tables 3
//! and 4, [`bench_local`](mod@bench_local) the local paths for the OMPL peer.

mod bench_local;
mod compare;
mod reuse;

use crate::Failure;
use crate::plan_cmd::PlanArgs;
use crate::verify_cmd::print_verdict;
pub use bench_local::bench_local;
use cellplan_cmm::cell::{CmmCell, KIND};
use cellplan_cmm::classify::Method;
use cellplan_cmm::document::{CmmPlan, Strategy};
use cellplan_cmm::plan::{Request, document, reuse, run};
use cellplan_model::InputError;
use cellplan_model::io::write_all_atomic;
use cellplan_solve::GtspMethod;
use cellplan_verify::cmm::{CmmReport, CmmViolation, verify_cmm};
pub use compare::compare;
pub use reuse::{ReuseArgs, run_reuse};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Whether the cell file is a CMM-inspection cell (read by its `[process] kind`).
pub fn is_cmm(cell: &Path) -> Result<bool, Failure> {
    Ok(cellplan_model::process_kind(cell)? == KIND)
}

/// Loads a CMM cell.
pub fn load(path: &Path) -> Result<CmmCell, Failure> {
    Ok(cellplan_cmm::cell::load(path)?)
}

fn order_of(optimizer: crate::pcb_cmd::OptimizerArg) -> GtspMethod {
    match optimizer {
        crate::pcb_cmd::OptimizerArg::Ga => GtspMethod::Ga,
        crate::pcb_cmd::OptimizerArg::Best => GtspMethod::Ils,
    }
}

#[derive(Serialize)]
struct GroupSummary {
    angles_deg: [f64; 2],
    faces: Vec<String>,
    mps: usize,
    /// The head's turn into this group from the previous group (or home) (deg).
    turn_in_deg: f64,
}

#[derive(Serialize)]
struct Summary<'a> {
    plan_file: String,
    report_file: Option<String>,
    program_file: String,
    tasks: &'a [String],
    groups: usize,
    group_detail: Vec<GroupSummary>,
    unmeasured: Vec<(&'a str, &'a str)>,
    movement_s: f64,
    rotation_s: f64,
    inspection_s: f64,
    motion_time_s: f64,
    compute_s: f64,
    classification: &'a str,
    order: &'a str,
    verified: bool,
}

/// Per group in visiting order: its summary with the head's turn into it.
fn group_detail(doc: &CmmPlan) -> Vec<GroupSummary> {
    doc.group_turns()
        .into_iter()
        .map(|(g, turn)| {
            let gr = &doc.groups[g];
            GroupSummary {
                angles_deg: gr.angles_deg,
                faces: gr.faces.clone(),
                mps: gr.mps.len(),
                turn_in_deg: turn,
            }
        })
        .collect()
}

/// The machine program: one row per waypoint (mm, degrees), touches marked.
pub fn program_csv(doc: &CmmPlan) -> String {
    use std::fmt::Write;
    let mut s = String::from("step,x_mm,y_mm,z_mm,a_deg,b_deg,touch\n");
    for (i, w) in doc.path.iter().enumerate() {
        let q = w.q;
        let _ = writeln!(
            s,
            "{i},{:.4},{:.4},{:.4},{:.4},{:.4},{}",
            q[0] * 1e3,
            q[1] * 1e3,
            q[2] * 1e3,
            q[3].to_degrees(),
            q[4].to_degrees(),
            w.touch.as_deref().unwrap_or("")
        );
    }
    s
}

/// Writes plan.json, program.csv and (unless `no_report`) report.html into `dir`.
fn write_plan(
    dir: &Path,
    doc: &CmmPlan,
    cell: &CmmCell,
    verdict: &CmmReport,
    no_report: bool,
) -> Result<(PathBuf, PathBuf, Option<PathBuf>), Failure> {
    let file = dir.join("plan.json");
    let program_file = dir.join("program.csv");
    let report_file = dir.join("report.html");
    let text = serde_json::to_string_pretty(doc).map_err(|e| Failure::Other(e.to_string()))?;
    let program = program_csv(doc);
    let page = (!no_report).then(|| cellplan_report::cmm::html(doc, cell, Some(verdict), None));
    let mut files: Vec<(&Path, &[u8])> = vec![(&file, text.as_bytes()), (&program_file, program.as_bytes())];
    if let Some(p) = &page {
        files.push((&report_file, p.as_bytes()));
    }
    write_all_atomic(&files)
        .map_err(|e| Failure::Other(format!("cannot write into {}: {e}", dir.display())))?;
    Ok((file, program_file, page.is_some().then_some(report_file)))
}

/// `cellplan plan` on a CMM cell.
pub fn plan(args: &PlanArgs) -> Result<(), Failure> {
    let start = Instant::now();
    if args.time_limit.is_some() {
        return Err(Failure::Usage(
            "--time-limit does not apply to CMM cells: the planner's budget is its work (RRT-MRNC rounds and samples, ordering iterations), so the plan depends only on the cell and the seed".into(),
        ));
    }
    if args.order.is_some() {
        return Err(Failure::Usage("--order is a PCB-assembly option".into()));
    }
    let cell = load(&args.cell)?;
    // Before any planning: the output folder must take files.
    let dir = crate::plan_output_dir(args.output.as_deref(), &cell.name, &cell.path)?;
    let show = !args.quiet && !args.json;
    let pb = crate::spinner(show, &format!("planning {} MPs", cell.mps.len()));
    let req = Request {
        order: order_of(args.optimizer),
        classification: None,
        seed: args.seed,
        subset: None,
    };
    let out = run(&cell, &req).map_err(|e| {
        Failure::Input(Box::new(
            InputError::new(&cell.path, format!("cannot plan this cell: {e}"))
                .hint("give the machine a longer Z travel or a shorter stylus"),
        ))
    })?;
    let mut doc = document(&cell, &out, &req, Strategy::Plan);
    pb.set_message("verifying the plan");
    let verdict = verify_cmm(&cell, &doc);
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
    doc.compute_s = start.elapsed().as_secs_f64();
    let (file, program_file, report_file) = write_plan(&dir, &doc, &cell, &verdict, args.no_report)?;
    pb.finish_and_clear();
    if args.json {
        crate::print_json(&Summary {
            plan_file: file.display().to_string(),
            report_file: report_file.as_ref().map(|p| p.display().to_string()),
            program_file: program_file.display().to_string(),
            tasks: &doc.tasks,
            groups: doc.groups.len(),
            group_detail: group_detail(&doc),
            unmeasured: doc
                .unmeasured
                .iter()
                .map(|u| (u.id.as_str(), u.reason.as_str()))
                .collect(),
            movement_s: doc.movement_s,
            rotation_s: doc.rotation_s,
            inspection_s: doc.inspection_s,
            motion_time_s: doc.motion_time_s,
            compute_s: doc.compute_s,
            classification: &doc.classification,
            order: &doc.order,
            verified: verdict.ok,
        })?;
    } else if !args.quiet {
        print!("{}", render(&doc, &verdict));
        println!("plan written to {}", file.display());
        println!("machine program written to {}", program_file.display());
        if let Some(r) = &report_file {
            println!("report written to {}", r.display());
        }
    }
    if doc.unmeasured.is_empty() {
        Ok(())
    } else {
        Err(Failure::Infeasible)
    }
}

fn render(doc: &CmmPlan, verdict: &CmmReport) -> String {
    let mut s = format!(
        "{} — {} MPs in {} orientation groups ({} classification), order {}, seed {}\n\n",
        doc.cell,
        doc.tasks.len(),
        doc.groups.len(),
        doc.classification,
        if doc.order == "ga" {
            "paper 003's GA"
        } else {
            "ours (ILS)"
        },
        doc.seed
    );
    s += &format!(
        "{:<6} {:>9} {:>9} {:>5} {:>8}  faces\n",
        "group", "A °", "B °", "MPs", "turn °"
    );
    for (k, g) in group_detail(doc).iter().enumerate() {
        s += &format!(
            "{:<6} {:>9.1} {:>9.1} {:>5} {:>8.1}  {}\n",
            k + 1,
            g.angles_deg[0],
            g.angles_deg[1],
            g.mps,
            g.turn_in_deg,
            g.faces.join(" + ")
        );
    }
    s += &format!(
        "\nmovement {:.1} s   rotation {:.1} s   inspection {:.1} s   motion time {:.1} s   computed in {:.2} s\n",
        doc.movement_s, doc.rotation_s, doc.inspection_s, doc.motion_time_s, doc.compute_s
    );
    for u in &doc.unmeasured {
        s += &format!("unmeasured {}: {}\n", u.id, u.reason);
    }
    s += &if verdict.ok {
        format!(
            "verified: every segment clear of part and fixtures by the clearance (closest {:.1} mm), every touch within its cone, the stored paths clear, times recomputed\n",
            verdict.closest_m * 1e3
        )
    } else {
        format!(
            "NOT VERIFIED ({} violation(s); written with --no-verify)\n",
            verdict.violations.len()
        )
    };
    s
}

/// One violation on one line.
pub fn describe(v: &CmmViolation) -> String {
    let at = v.at.map_or(String::new(), |i| format!(" at {i}"));
    let mp = v.mp.as_ref().map_or(String::new(), |m| format!(" MP {m}"));
    format!("{:?}{at}{mp}: {}", v.kind, v.detail)
}

fn read_plan(path: &Path) -> Result<CmmPlan, Failure> {
    cellplan_cmm::document::read(path).map_err(|e| {
        Failure::Input(Box::new(
            InputError::new(path, e).hint("give a plan.json that `cellplan plan` wrote for a CMM cell"),
        ))
    })
}

/// `cellplan verify` on a CMM plan.
pub fn verify(plan_path: &Path, cell_path: &Path, json: bool) -> Result<(), Failure> {
    let cell = load(cell_path)?;
    let plan = read_plan(plan_path)?;
    let report = verify_cmm(&cell, &plan);
    let summary = format!(
        "{} MPs touched; motion time {:.3} s (recomputed); closest approach {:.2} mm over {} samples",
        report.touched,
        report.motion_time_s,
        report.closest_m * 1e3,
        report.samples
    );
    print_verdict(&report, report.ok, &report.violations, describe, &summary, json)
}

/// `cellplan report` on a CMM plan.
pub fn report(plan_path: &Path, cell_path: &Path, out: &Path) -> Result<(), Failure> {
    let cell = load(cell_path)?;
    let plan = read_plan(plan_path)?;
    let verdict = verify_cmm(&cell, &plan);
    let page = cellplan_report::cmm::html(&plan, &cell, Some(&verdict), None);
    cellplan_model::io::write_atomic(out, page.as_bytes())
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", out.display())))?;
    Ok(())
}

/// `cellplan reuse`.

#[derive(Serialize)]
struct CheckOut {
    cell: String,
    mps: usize,
    faces: usize,
    orientations: usize,
    groups_exact: usize,
    groups_greedy: usize,
    unmeasurable: Vec<String>,
}

/// `cellplan check` on a CMM cell: MPs, faces, and the classification both ways.
pub fn check_cell(path: &Path, json: bool) -> Result<(), Failure> {
    let cell = load(path)?;
    let probe = cell.probe();
    let space = cellplan_cmm::motion::space(&probe, &cell.travel);
    let validity = cellplan_cmm::motion::CmmValidity {
        probe: &probe,
        margin: cell.clearance,
    };
    let by = |m| cellplan_cmm::plan::classification(&cell, &probe, &space, &validity, &cell.mps, m);
    let exact = by(Method::Exact);
    let greedy = by(Method::Greedy);
    let out = CheckOut {
        cell: cell.name.clone(),
        mps: cell.mps.len(),
        faces: cell.faces.len(),
        orientations: exact.orientations,
        groups_exact: exact.groups.len(),
        groups_greedy: greedy.groups.len(),
        unmeasurable: exact
            .unmeasurable
            .iter()
            .map(|&i| cell.mps[i].name.clone())
            .collect(),
    };
    if json {
        return crate::print_json(&out);
    }
    println!(
        "{} — {} MPs on {} faces; {} candidate head orientations; {} groups (exact), {} (greedy)",
        out.cell, out.mps, out.faces, out.orientations, out.groups_exact, out.groups_greedy
    );
    for g in &exact.groups {
        println!(
            "  A {:>6.1}° B {:>7.1}°: {:>3} MPs on {}",
            g.angles.0.to_degrees(),
            g.angles.1.to_degrees(),
            g.members.len(),
            g.faces
                .iter()
                .map(|&f| cell.faces[f].as_str())
                .collect::<Vec<_>>()
                .join(" + ")
        );
    }
    for id in &out.unmeasurable {
        println!("  unmeasurable: {id} (no orientation within its cone touches it clear of the part)");
    }
    Ok(())
}
