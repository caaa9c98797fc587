//! `cellplan reuse PLAN --tasks …`: a subset of a CMM plan's MPs inspected again from its
//! stored paths, verified before it is written.
use super::*;
use cellplan_cmm::plan::ReuseError;
use clap::Args;

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
    crate::ensure_writable(&dir)?;
    let (file, _, report_file) = write_plan(&dir, &doc, &cell, &verdict, args.no_report)?;
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
