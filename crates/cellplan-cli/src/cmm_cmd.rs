//! `plan`, `reuse`, `verify`, `report`, `compare` and `check` on CMM-inspection cells (paper
//! 003): argument checks, output files and printing only; the work is in `cellplan-cmm`, the
//! check in `cellplan-verify::cmm`, the page in `cellplan-report::cmm`.
use crate::Failure;
use crate::plan_cmd::PlanArgs;
use cellplan_cmm::cell::{CmmCell, KIND};
use cellplan_cmm::classify::{Method, classify_with};
use cellplan_cmm::document::{CmmPlan, Strategy};
use cellplan_cmm::plan::{Request, ReuseError, document, reuse, run};
use cellplan_model::InputError;
use cellplan_model::io::{check_writable, write_all_atomic};
use cellplan_solve::GtspMethod;
use cellplan_verify::cmm::{CmmReport, CmmViolation, verify_cmm};
use clap::Args;
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
    let mut at = [doc.home[3].to_degrees(), doc.home[4].to_degrees()];
    doc.group_order
        .iter()
        .map(|&g| {
            let gr = &doc.groups[g];
            let turn = (gr.angles_deg[0] - at[0])
                .abs()
                .max((gr.angles_deg[1] - at[1]).abs());
            at = gr.angles_deg;
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

fn output_dir(cell: &CmmCell) -> Result<PathBuf, Failure> {
    let name = &cell.name;
    let plain = !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\', '\0'])
        && Path::new(name).components().count() == 1;
    if !plain {
        return Err(Failure::Usage(format!(
            "the cell name `{name}` is not a plain folder name; give the output folder with -o"
        )));
    }
    Ok(PathBuf::from("out").join(name))
}

/// Writes plan.json, program.csv and (unless `no_report`) report.html into `dir`.
fn write_plan(
    dir: &Path,
    doc: &CmmPlan,
    cell: &CmmCell,
    verdict: &CmmReport,
    no_report: bool,
    table4: Option<&[cellplan_report::cmm::Table4Row]>,
) -> Result<(PathBuf, PathBuf, Option<PathBuf>), Failure> {
    let file = dir.join("plan.json");
    let program_file = dir.join("program.csv");
    let report_file = dir.join("report.html");
    let text = serde_json::to_string_pretty(doc).map_err(|e| Failure::Other(e.to_string()))?;
    let program = program_csv(doc);
    let page = (!no_report).then(|| cellplan_report::cmm::html(doc, cell, Some(verdict), table4));
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
    let dir = match &args.output {
        Some(d) => d.clone(),
        None => output_dir(&cell)?,
    };
    check_writable(&dir).map_err(|e| {
        Failure::Usage(format!(
            "cannot write into the output folder {}: {e}; give a writable folder with -o",
            dir.display()
        ))
    })?;
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
    let (file, program_file, report_file) = write_plan(&dir, &doc, &cell, &verdict, args.no_report, None)?;
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
    if json {
        crate::print_json(&report)?;
    } else {
        for v in &report.violations {
            println!("{}", describe(v));
        }
        println!(
            "{}: {} violation(s); {} MPs touched; motion time {:.3} s (recomputed); closest approach {:.2} mm over {} samples",
            if report.ok { "ok" } else { "NOT OK" },
            report.violations.len(),
            report.touched,
            report.motion_time_s,
            report.closest_m * 1e3,
            report.samples
        );
    }
    if report.ok { Ok(()) } else { Err(Failure::Rejected) }
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
#[derive(Args)]
pub struct ReuseArgs {
    /// The plan (plan.json written by `cellplan plan` on a CMM cell, or by an earlier reuse).
    plan: PathBuf,
    /// The MPs to inspect again: ids separated by commas, or `@FILE` (one id per line, `#`
    /// comments, a CSV's first column).
    #[arg(long, value_name = "IDS")]
    tasks: String,
    /// The cell file (default: the one the plan names).
    #[arg(long, value_name = "FILE")]
    cell: Option<PathBuf>,
    /// `reuse-roots` (paper 003's path reuse, the default) or `reuse-initial-path` (walk the
    /// plan's whole path, touching only these MPs).
    #[arg(long, value_enum, default_value_t = ReuseStrategy::ReuseRoots)]
    strategy: ReuseStrategy,
    /// Output folder (default: `reuse/` beside the plan).
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,
    /// Do not write report.html.
    #[arg(long)]
    no_report: bool,
    /// Print a JSON summary (stable keys: tasks, motion_time_s, compute_s, verified).
    #[arg(long)]
    json: bool,
    /// No table.
    #[arg(long, short)]
    quiet: bool,
}

/// `--strategy` of `reuse`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ReuseStrategy {
    /// Through the stored roots.
    ReuseRoots,
    /// Along the initial path.
    ReuseInitialPath,
}

/// The subset named by `--tasks`: MP indices of the cell, each once.
fn parse_subset(arg: &str, cell: &CmmCell, plan: &CmmPlan) -> Result<Vec<usize>, Failure> {
    let (ids, file): (Vec<(String, Option<usize>)>, Option<PathBuf>) = match arg.strip_prefix('@') {
        Some(f) => {
            let path = PathBuf::from(f);
            let text = cellplan_model::io::read_bounded(&path, 1 << 20).map_err(|e| {
                InputError::new(&path, format!("cannot read the MP list: {e}")).hint("one MP id per line")
            })?;
            let ids = text
                .lines()
                .enumerate()
                .filter_map(|(i, l)| {
                    let id = l.split(',').next().unwrap_or("").trim().trim_matches('"');
                    {
                        let header = i == 0 && id.eq_ignore_ascii_case("id");
                        !(id.is_empty() || id.starts_with('#') || header)
                    }
                    .then(|| (id.to_string(), Some(i + 1)))
                })
                .collect();
            (ids, Some(path))
        }
        None => (
            arg.split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(|s| (s.to_string(), None))
                .collect(),
            None,
        ),
    };
    let fail = |line: Option<usize>, msg: String, hint: String| -> Failure {
        match &file {
            Some(f) => Failure::Input(Box::new(InputError::at_line(f, line, msg).hint(hint))),
            None => Failure::Usage(format!("--tasks: {msg}; {hint}")),
        }
    };
    if ids.is_empty() {
        return Err(fail(None, "no MP named".into(), "name at least one MP".into()));
    }
    let stored: std::collections::HashSet<&str> = plan
        .groups
        .iter()
        .flat_map(|g| g.mps.iter().map(String::as_str))
        .collect();
    let mut out = Vec::new();
    for (id, line) in ids {
        let Some(i) = cell.mp(&id) else {
            return Err(fail(
                line,
                format!("`{id}` is not an MP of the cell {}", cell.path.display()),
                "use the ids of the cell's task file".into(),
            ));
        };
        if !stored.contains(id.as_str()) {
            let why = plan
                .unmeasured
                .iter()
                .find(|u| u.id == id)
                .map_or("it is not in the plan".to_string(), |u| u.reason.clone());
            return Err(fail(
                line,
                format!("the plan never measured MP `{id}` ({why}), so it holds no path to it"),
                "plan the cell again with this MP measurable, or leave it out".into(),
            ));
        }
        if out.contains(&i) {
            return Err(fail(
                line,
                format!("`{id}` is named twice"),
                "name each MP once".into(),
            ));
        }
        out.push(i);
    }
    Ok(out)
}

#[derive(Serialize)]
struct ReuseSummary<'a> {
    plan_file: String,
    strategy: &'static str,
    tasks: &'a [String],
    movement_s: f64,
    rotation_s: f64,
    inspection_s: f64,
    motion_time_s: f64,
    compute_s: f64,
    verified: bool,
}

/// `cellplan reuse PLAN --tasks …`.
pub fn run_reuse(args: &ReuseArgs) -> Result<(), Failure> {
    let plan = read_plan(&args.plan)?;
    let cell_path = args
        .cell
        .clone()
        .unwrap_or_else(|| PathBuf::from(&plan.cell_file));
    if !cell_path.exists() {
        return Err(Failure::Usage(format!(
            "the plan's cell file {} does not exist; give it with --cell",
            cell_path.display()
        )));
    }
    let cell = load(&cell_path)?;
    let subset = parse_subset(&args.tasks, &cell, &plan)?;
    let strategy = match args.strategy {
        ReuseStrategy::ReuseRoots => Strategy::ReuseRoots,
        ReuseStrategy::ReuseInitialPath => Strategy::ReuseInitialPath,
    };
    let doc = reuse(&cell, &plan, &subset, strategy).map_err(|e| match e {
        ReuseError::Plan(m) => Failure::Input(Box::new(
            InputError::new(&args.plan, m).hint("the plan does not fit this cell; give the cell it was made for with --cell"),
        )),
        ReuseError::Unknown(v) => Failure::Usage(format!(
            "--tasks: the plan's path never touches {}; with --strategy reuse-initial-path only MPs the path touches can be chosen",
            v.iter().map(|&i| cell.mps[i].name.as_str()).collect::<Vec<_>>().join(", ")
        )),
    })?;
    let verdict = verify_cmm(&cell, &doc);
    if !verdict.ok {
        for v in &verdict.violations {
            eprintln!("{}", describe(v));
        }
        return Err(Failure::Other(format!(
            "the reused path failed verification ({} violation(s)) and was not written: the stored paths of {} do not hold for this cell",
            verdict.violations.len(),
            args.plan.display()
        )));
    }
    let dir = args
        .output
        .clone()
        .unwrap_or_else(|| args.plan.parent().unwrap_or(Path::new(".")).join("reuse"));
    check_writable(&dir).map_err(|e| {
        Failure::Usage(format!(
            "cannot write into the output folder {}: {e}; give a writable folder with -o",
            dir.display()
        ))
    })?;
    let (file, _, report_file) = write_plan(&dir, &doc, &cell, &verdict, args.no_report, None)?;
    if args.json {
        crate::print_json(&ReuseSummary {
            plan_file: file.display().to_string(),
            strategy: doc.strategy.name(),
            tasks: &doc.tasks,
            movement_s: doc.movement_s,
            rotation_s: doc.rotation_s,
            inspection_s: doc.inspection_s,
            motion_time_s: doc.motion_time_s,
            compute_s: doc.compute_s,
            verified: verdict.ok,
        })?;
    } else if !args.quiet {
        println!(
            "{} — {} of {} MPs by {}: movement {:.1} s, rotation {:.1} s, inspection {:.1} s, motion time {:.1} s; made in {:.1} µs, no planning",
            doc.cell,
            doc.tasks.len(),
            plan.groups.iter().map(|g| g.mps.len()).sum::<usize>(),
            doc.strategy.name(),
            doc.movement_s,
            doc.rotation_s,
            doc.inspection_s,
            doc.motion_time_s,
            doc.compute_s * 1e6
        );
        println!("verified: every segment clear, every touch within its cone, times recomputed");
        println!("plan written to {}", file.display());
        if let Some(r) = report_file {
            println!("report written to {}", r.display());
        }
    }
    Ok(())
}

/// One row of `compare` on a CMM cell: a strategy's means over the random subsets.
#[derive(Serialize, Clone)]
struct StrategyRow {
    strategy: &'static str,
    subsets: usize,
    motion_time_s: f64,
    movement_s: f64,
    rotation_s: f64,
    inspection_s: f64,
    compute_s: f64,
    /// Mean of this strategy's motion time over re-planning's, subset by subset.
    ratio_to_replan: f64,
    worst_ratio_to_replan: f64,
    verified: bool,
}

#[derive(Serialize)]
struct PlanRow {
    order: &'static str,
    groups: usize,
    motion_time_s: f64,
    movement_s: f64,
    rotation_s: f64,
    compute_s: f64,
    /// Of it, the orderings alone (the GA or ours on the same groups).
    order_compute_s: f64,
    verified: bool,
}

#[derive(Serialize)]
struct SubsetRow {
    tasks: Vec<String>,
    reuse_roots_s: f64,
    reuse_initial_path_s: f64,
    replan_s: f64,
    reuse_compute_s: f64,
    replan_compute_s: f64,
}

#[derive(Serialize)]
struct CompareOut {
    cell: String,
    mps: usize,
    seed: u64,
    plans: Vec<PlanRow>,
    strategies: Vec<StrategyRow>,
    subsets: Vec<SubsetRow>,
}

/// `cellplan compare` on a CMM cell: the whole job ordered by paper 003's GA and by ours
/// (Table 3), then `--random-tasks K` (default 20) random subsets of 3–20 MPs inspected again by
/// the three strategies of Table 4, every plan verified.
pub fn compare(args: &crate::compare_cmd::CompareArgs) -> Result<(), Failure> {
    let cell = load(&args.cell)?;
    let k = args.random_tasks.unwrap_or(20);
    if !(1..=1000).contains(&k) {
        return Err(Failure::Usage("--random-tasks must be between 1 and 1000".into()));
    }
    let show = !args.quiet && !args.json;
    let pb = crate::spinner(show, "planning the whole job (paper 003's GA, ours)");
    let mut plans = Vec::new();
    let mut base: Option<CmmPlan> = None;
    for order in [GtspMethod::Ga, GtspMethod::Ils] {
        let req = Request {
            order,
            classification: None,
            seed: args.seed,
            subset: None,
        };
        let out = run(&cell, &req).map_err(|e| Failure::Other(e.to_string()))?;
        let doc = document(&cell, &out, &req, Strategy::Plan);
        let verdict = verify_cmm(&cell, &doc);
        plans.push(PlanRow {
            order: if order == GtspMethod::Ga { "ga" } else { "ours" },
            groups: doc.groups.len(),
            motion_time_s: doc.motion_time_s,
            movement_s: doc.movement_s,
            rotation_s: doc.rotation_s,
            compute_s: doc.compute_s,
            order_compute_s: out.job.order_s,
            verified: verdict.ok,
        });
        base = Some(doc);
    }
    let base = base.ok_or_else(|| Failure::Other("no plan".into()))?;
    let measured: Vec<usize> = base.tasks.iter().filter_map(|id| cell.mp(id)).collect();
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(args.seed);
    let mut rows = Vec::new();
    let mut sums: [[f64; 5]; 3] = [[0.0; 5]; 3];
    let mut ratios: [Vec<f64>; 3] = Default::default();
    let mut verified = [true; 3];
    for s in 0..k {
        pb.set_message(format!("subset {} of {k}", s + 1));
        let hi = 20.min(measured.len());
        let size = rng.random_range(3.min(hi)..=hi);
        let mut subset = measured.clone();
        for i in (1..subset.len()).rev() {
            subset.swap(i, rng.random_range(0..=i));
        }
        subset.truncate(size);
        let roots = reuse(&cell, &base, &subset, Strategy::ReuseRoots)
            .map_err(|e| Failure::Other(format!("{e:?}")))?;
        let initial = reuse(&cell, &base, &subset, Strategy::ReuseInitialPath)
            .map_err(|e| Failure::Other(format!("{e:?}")))?;
        let req = Request {
            order: GtspMethod::Ils,
            classification: None,
            seed: args.seed,
            subset: Some(subset.clone()),
        };
        let out = run(&cell, &req).map_err(|e| Failure::Other(e.to_string()))?;
        let replan = document(&cell, &out, &req, Strategy::Replan);
        let docs = [&roots, &initial, &replan];
        for (j, d) in docs.iter().enumerate() {
            let verdict = verify_cmm(&cell, d);
            let whole = d.tasks.len() == subset.len();
            if !(verdict.ok && whole) {
                pb.suspend(|| {
                    eprintln!(
                        "subset {}: the {} plan {}",
                        s + 1,
                        d.strategy.name(),
                        match verdict.violations.first() {
                            Some(v) => format!("is not verified: {}", describe(v)),
                            None => format!(
                                "leaves MPs unmeasured: {}",
                                d.unmeasured
                                    .iter()
                                    .map(|u| format!("{} ({})", u.id, u.reason))
                                    .collect::<Vec<_>>()
                                    .join("; ")
                            ),
                        }
                    )
                });
            }
            verified[j] &= verdict.ok && whole;
            sums[j][0] += d.motion_time_s;
            sums[j][1] += d.movement_s;
            sums[j][2] += d.rotation_s;
            sums[j][3] += d.inspection_s;
            sums[j][4] += d.compute_s;
            ratios[j].push(d.motion_time_s / replan.motion_time_s);
        }
        rows.push(SubsetRow {
            tasks: roots.tasks.clone(),
            reuse_roots_s: roots.motion_time_s,
            reuse_initial_path_s: initial.motion_time_s,
            replan_s: replan.motion_time_s,
            reuse_compute_s: roots.compute_s,
            replan_compute_s: replan.compute_s,
        });
    }
    pb.finish_and_clear();
    let n = k as f64;
    let strategies = [Strategy::ReuseRoots, Strategy::ReuseInitialPath, Strategy::Replan]
        .iter()
        .enumerate()
        .map(|(j, s)| StrategyRow {
            strategy: s.name(),
            subsets: k,
            motion_time_s: sums[j][0] / n,
            movement_s: sums[j][1] / n,
            rotation_s: sums[j][2] / n,
            inspection_s: sums[j][3] / n,
            compute_s: sums[j][4] / n,
            ratio_to_replan: ratios[j].iter().sum::<f64>() / n,
            worst_ratio_to_replan: ratios[j].iter().copied().fold(0.0, f64::max),
            verified: verified[j],
        })
        .collect();
    let out = CompareOut {
        cell: cell.name.clone(),
        mps: cell.mps.len(),
        seed: args.seed,
        plans,
        strategies,
        subsets: rows,
    };
    let text = serde_json::to_string_pretty(&out).map_err(|e| Failure::Other(e.to_string()))?;
    let table = compare_table(&out);
    if let Some(dir) = &args.output {
        let md = dir.join("compare.md");
        let js = dir.join("compare.json");
        let rp = dir.join("report.html");
        let table4: Vec<cellplan_report::cmm::Table4Row> = out
            .strategies
            .iter()
            .map(|r| cellplan_report::cmm::Table4Row {
                strategy: r.strategy.to_string(),
                subsets: r.subsets,
                motion_time_s: r.motion_time_s,
                compute_s: r.compute_s,
                ratio_to_replan: r.ratio_to_replan,
                verified: r.verified,
            })
            .collect();
        let verdict = verify_cmm(&cell, &base);
        let page = cellplan_report::cmm::html(&base, &cell, Some(&verdict), Some(&table4));
        write_all_atomic(&[
            (&md, table.as_bytes()),
            (&js, text.as_bytes()),
            (&rp, page.as_bytes()),
        ])
        .map_err(|e| Failure::Other(format!("cannot write into {}: {e}", dir.display())))?;
    }
    if args.json {
        println!("{text}");
    } else {
        print!("{table}");
    }
    Ok(())
}

fn compare_table(out: &CompareOut) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "{} — {} MPs, seed {}\n\nThe whole job (paper 003 Table 3):\n\n| order | groups | movement s | rotation s | motion s | compute s | of it ordering s | verified |\n|---|---|---|---|---|---|---|---|\n",
        out.cell, out.mps, out.seed
    );
    for p in &out.plans {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.3} | {} |",
            if p.order == "ga" {
                "paper 003's GA"
            } else {
                "ours (ILS)"
            },
            p.groups,
            p.movement_s,
            p.rotation_s,
            p.motion_time_s,
            p.compute_s,
            p.order_compute_s,
            if p.verified { "yes" } else { "NO" }
        );
    }
    let k = out.strategies.first().map_or(0, |r| r.subsets);
    let _ = write!(
        s,
        "\nRe-inspecting {k} random subsets of 3–20 MPs (paper 003 Table 4; means):\n\n| strategy | motion s | movement s | rotation s | × re-planning (mean, worst) | compute | verified |\n|---|---|---|---|---|---|---|\n"
    );
    for r in &out.strategies {
        let compute = if r.compute_s < 0.01 {
            format!("{:.1} µs", r.compute_s * 1e6)
        } else {
            format!("{:.2} s", r.compute_s)
        };
        let _ = writeln!(
            s,
            "| {} | {:.1} | {:.1} | {:.1} | {:.3}, {:.3} | {} | {} |",
            r.strategy,
            r.motion_time_s,
            r.movement_s,
            r.rotation_s,
            r.ratio_to_replan,
            r.worst_ratio_to_replan,
            compute,
            if r.verified { "yes" } else { "NO" }
        );
    }
    s
}

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
    let orientations = cell.orientations();
    let adjacent = |f: usize, g: usize| cell.adjacent(f, g);
    let space = cellplan_cmm::motion::space(&probe, &cell.travel);
    let validity = cellplan_cmm::motion::CmmValidity {
        probe: &probe,
        margin: cell.clearance,
    };
    let usable = cellplan_cmm::plan::approach_usable(&cell, &space, &validity, &cell.mps);
    let by = |m| {
        classify_with(
            &cell.mps,
            &adjacent,
            &probe,
            &orientations,
            cell.touch_clearance,
            m,
            &usable,
        )
    };
    let exact = by(Method::Exact);
    let greedy = by(Method::Greedy);
    let out = CheckOut {
        cell: cell.name.clone(),
        mps: cell.mps.len(),
        faces: cell.faces.len(),
        orientations: orientations.len(),
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

/// `cellplan bench cmm-local CELL`: every root → MP path of the cell's plan as a problem for
/// the OMPL peer, with ours re-solved (straight segment, else RRT* with `samples` samples) and
/// timed; the JSON goes to stdout (docs in bench/peers/README.md).
pub fn bench_local(cell_path: &Path, samples: usize) -> Result<(), Failure> {
    use cellplan_cmm::motion::{CmmValidity, space};
    use cellplan_cmm::mrnc::{MrncSettings, local_path};
    use serde_json::json;
    let cell = load(cell_path)?;
    let req = Request {
        order: GtspMethod::Ils,
        classification: None,
        seed: 0,
        subset: None,
    };
    let out = run(&cell, &req).map_err(|e| Failure::Other(e.to_string()))?;
    let probe = cell.probe();
    let full = space(&probe, &cell.travel);
    let validity = CmmValidity {
        probe: &probe,
        margin: cell.clearance,
    };
    let s = MrncSettings {
        rrt_samples: samples,
        pretouch: cell.pretouch,
        ..MrncSettings::default()
    };
    let pose = |p: &cellplan_geom::Pose| json!({"xyz": p.translation.to_array(), "quat": [p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]});
    let mut statics = Vec::new();
    for (k, (name, spec, p)) in cell.statics.iter().enumerate() {
        match spec {
            cellplan_geom::ShapeSpec::Mesh(_) if k == 0 => statics.push(json!({
                "name": name,
                "mesh": std::fs::canonicalize(&cell.part_file.0).unwrap_or(cell.part_file.0.clone()),
                "mesh_scale": cell.part_file.1,
                "pose": pose(p),
            })),
            cellplan_geom::ShapeSpec::Box { half_extents } => statics.push(json!({
                "name": name,
                "box": (*half_extents * 2.0).to_array(),
                "pose": pose(p),
            })),
            _ => {
                return Err(Failure::Usage(format!(
                    "cmm-local exports the part and box fixtures only; `{name}` is another shape"
                )));
            }
        }
    }
    let mut problems = Vec::new();
    for (g, group) in out.job.groups.iter().enumerate() {
        let (a, b) = group.paths.angles;
        let mut sp = full.clone();
        sp.lower[3] = a;
        sp.upper[3] = a;
        sp.lower[4] = b;
        sp.upper[4] = b;
        // Each MP from its root (the paths RRT-MRNC stores) and from the group's start (what
        // a planner without roots must solve).
        let pairs = group.members.iter().enumerate().flat_map(|(k, &mp)| {
            [("root", &group.paths.roots[k]), ("start", &group.paths.start)]
                .map(|(kind, from)| (k, mp, kind, from))
        });
        for (k, mp, kind, root) in pairs {
            let goal = &group.paths.approaches[k];
            let started = Instant::now();
            let found = local_path(&sp, &validity, root, goal, &s, k as u64);
            let time_s = started.elapsed().as_secs_f64();
            let length = |w: &[Vec<f64>]| {
                w.windows(2)
                    .map(|p| {
                        ((p[1][0] - p[0][0]).powi(2)
                            + (p[1][1] - p[0][1]).powi(2)
                            + (p[1][2] - p[0][2]).powi(2))
                        .sqrt()
                    })
                    .sum::<f64>()
            };
            let lo: Vec<f64> = (0..3)
                .map(|j| full.lower[j].max(root[j].min(goal[j]) - s.local_margin))
                .collect();
            let hi: Vec<f64> = (0..3)
                .map(|j| full.upper[j].min(root[j].max(goal[j]) + s.local_margin))
                .collect();
            problems.push(json!({
                "group": g,
                "mp": cell.mps[mp].name,
                "from": kind,
                "angles": [a, b],
                "start": &root[..3],
                "goal": &goal[..3],
                "bounds": {"lower": lo, "upper": hi},
                "ours": {
                    "solved": found.is_some(),
                    "length_m": found.as_ref().map(|f| length(&f.waypoints)),
                    "time_s": time_s,
                    "samples": samples,
                    "straight": found.as_ref().is_some_and(|f| f.straight),
                },
            }));
        }
    }
    let b = &cell.bodies;
    let h = &cell.head;
    let doc = json!({
        "cell": cell.name,
        "scene": {
            "statics": statics,
            "probe": {
                "l1": h.l1, "l2": h.l2, "ball_diameter": h.ball_diameter,
                "stem_diameter": b.stem_diameter, "extension_diameter": b.extension_diameter,
                "head": [b.head.0, b.head.1], "ram": [b.ram.0, b.ram.1],
            },
            "clearance": cell.clearance,
        },
        "problems": problems,
    });
    crate::print_json(&doc)
}
