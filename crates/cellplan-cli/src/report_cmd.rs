//! `cellplan report` (the HTML page of a plan) and `cellplan export` (glTF, CSV).
use crate::Failure;
use cellplan_core::Plan;
use cellplan_core::document::{self, DocumentError};
use cellplan_model::{
    Cell, InputError, LoadOptions,
    io::{write_all_atomic, write_atomic},
};
use cellplan_report::html::{PlanReport, plan_html};
use cellplan_report::scene::{MESH_BUDGET, Scene};
use cellplan_verify::{self as verify, VerifySettings};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args)]
pub struct ReportArgs {
    /// The plan (plan.json written by `cellplan plan`).
    plan: PathBuf,
    /// The cell file it was made for (default: the plan's `cell_file`).
    cell: Option<PathBuf>,
    /// Output file (default: report.html beside the plan).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Do not run the verifier for the page (it then shows the plan's own `verified`).
    #[arg(long)]
    no_verify: bool,
    /// Triangle budget per drawn mesh (larger meshes are decimated for drawing).
    #[arg(long, default_value_t = MESH_BUDGET)]
    mesh_budget: usize,
}

#[derive(Args)]
pub struct ExportArgs {
    /// The plan (plan.json written by `cellplan plan`).
    plan: PathBuf,
    /// The cell file it was made for (default: the plan's `cell_file`).
    cell: Option<PathBuf>,
    /// Write the cell and the robots' motion as binary glTF with an animation.
    #[arg(long, value_name = "FILE")]
    gltf: Option<PathBuf>,
    /// Write per robot CSV files (trajectory samples and program points) into this folder.
    #[arg(long, value_name = "DIR")]
    csv: Option<PathBuf>,
    /// Triangle budget per exported mesh (larger meshes are decimated).
    #[arg(long, default_value_t = MESH_BUDGET)]
    mesh_budget: usize,
    /// Export without running the verifier first (by default a plan that does not hold for the
    /// cell, e.g. one made for another cell's robots, is not exported: exit 4).
    #[arg(long)]
    no_verify: bool,
}

/// Reads and validates a plan document, with errors that name the file, the line or the
/// place in the document, and what to do.
pub fn read_plan(path: &Path) -> Result<Plan, Failure> {
    document::read(path).map_err(|e| {
        let hint = match &e {
            DocumentError::Version { .. } => "plan the cell again with this cellplan (`cellplan plan CELL`)",
            DocumentError::Read(_) | DocumentError::TooLarge { .. } => {
                "give the plan.json that `cellplan plan` wrote"
            }
            _ => "give the plan.json that `cellplan plan` wrote, unedited (docs/plan-format.md)",
        };
        Failure::Input(Box::new(
            InputError::at_line(path, e.line(), e.to_string()).hint(hint),
        ))
    })
}

/// The cell a plan was made for: `cell` when given, else the plan's `cell_file`.
fn load_cell(plan_path: &Path, plan: &Plan, cell: &Option<PathBuf>) -> Result<Cell, Failure> {
    let path = match cell {
        Some(c) => c.clone(),
        None => {
            let p = PathBuf::from(&plan.cell_file);
            if !p.exists() {
                return Err(Failure::Input(Box::new(
                    InputError::new(
                        plan_path,
                        format!("the plan's cell file {} is not there", plan.cell_file),
                    )
                    .hint("give the cell file as the second argument"),
                )));
            }
            p
        }
    };
    let cell = crate::load_cell(&path, &LoadOptions::default())?;
    document::matches_cell(plan, &cell).map_err(mismatch(plan_path))?;
    if cell.name != plan.cell {
        eprintln!(
            "note: the plan was made for cell `{}`, {} is cell `{}`",
            plan.cell,
            path.display(),
            cell.name
        );
    }
    Ok(cell)
}

fn mismatch<E: std::fmt::Display>(plan_path: &Path) -> impl Fn(E) -> Failure + '_ {
    move |m| {
        Failure::Input(Box::new(
            InputError::new(plan_path, m.to_string()).hint("give the cell file the plan was made for"),
        ))
    }
}

/// The HTML report of `plan` (read from `plan_path`).
pub fn render_report(
    plan_path: &Path,
    plan: &Plan,
    cell: &Cell,
    verification: Option<&verify::Report>,
    mesh_budget: usize,
) -> Result<String, Failure> {
    let scene = Scene::new(cell, mesh_budget);
    let name = plan_path.display().to_string();
    plan_html(&PlanReport {
        plan,
        cell,
        scene: &scene,
        verification,
        plan_file: Some(&name),
    })
    .map_err(mismatch(plan_path))
}

/// Writes the HTML report of `plan` to `path`; returns the bytes written.
pub fn write_report(
    path: &Path,
    plan_path: &Path,
    plan: &Plan,
    cell: &Cell,
    verification: Option<&verify::Report>,
    mesh_budget: usize,
) -> Result<usize, Failure> {
    let page = render_report(plan_path, plan, cell, verification, mesh_budget)?;
    write_atomic(path, page.as_bytes())
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", path.display())))?;
    Ok(page.len())
}

pub fn run_report(args: &ReportArgs) -> Result<(), Failure> {
    // The pages of the other processes: (is this kind, write its page).
    type IsKind = fn(&Path) -> Result<bool, Failure>;
    type PageFn = fn(&Path, &Path, &Path) -> Result<(), Failure>;
    let pages: [(IsKind, PageFn); 3] = [
        (crate::pcb_cmd::is_pcb, crate::pcb_cmd::report),
        (crate::cmm_cmd::is_cmm, crate::cmm_cmd::report),
        (crate::studweld_cmd::is_studweld, crate::studweld_cmd::report),
    ];
    let out = args
        .output
        .clone()
        .unwrap_or_else(|| args.plan.parent().unwrap_or(Path::new(".")).join("report.html"));
    crate::ensure_file_target(&out, "-o")?;
    if let Some(cell) = &args.cell {
        for (is_kind, page) in pages {
            if is_kind(cell)? {
                page(&args.plan, cell, &out)?;
                eprintln!("report written to {}", out.display());
                return Ok(());
            }
        }
    }
    let start = Instant::now();
    let plan = read_plan(&args.plan)?;
    let cell = load_cell(&args.plan, &plan, &args.cell)?;
    let load_s = start.elapsed().as_secs_f64();
    let lap = Instant::now();
    let verdict = (!args.no_verify).then(|| verify::verify(&cell, &plan, &VerifySettings::default()));
    let verify_s = lap.elapsed().as_secs_f64();
    let lap = Instant::now();
    let bytes = write_report(
        &out,
        &args.plan,
        &plan,
        &cell,
        verdict.as_ref(),
        args.mesh_budget.max(12),
    )?;
    eprintln!(
        "report written to {} ({:.2} MB; {:.2} s: reading plan and cell {:.2} s, verifying {:.2} s, page {:.2} s){}",
        out.display(),
        bytes as f64 / 1e6,
        start.elapsed().as_secs_f64(),
        load_s,
        verify_s,
        lap.elapsed().as_secs_f64(),
        match &verdict {
            Some(v) if !v.ok => format!("; the plan has {} violation(s)", v.violations.len()),
            _ => String::new(),
        }
    );
    Ok(())
}

pub fn run_export(args: &ExportArgs) -> Result<(), Failure> {
    if args.gltf.is_none() && args.csv.is_none() {
        return Err(Failure::Usage(
            "nothing to export: give --gltf FILE and/or --csv DIR".into(),
        ));
    }
    // Both targets checked first: one that cannot be written leaves the other unwritten.
    if let Some(path) = &args.gltf {
        crate::ensure_file_target(path, "--gltf")?;
    }
    if let Some(dir) = &args.csv {
        cellplan_model::io::check_creatable(dir).map_err(|e| {
            Failure::Usage(format!(
                "cannot write into {}: {e}; give a writable folder with --csv",
                dir.display()
            ))
        })?;
    }
    let plan = read_plan(&args.plan)?;
    let cell = load_cell(&args.plan, &plan, &args.cell)?;
    // What a controller is given is checked first: a plan that does not hold for this cell (its
    // robots' bases, tools, the scene) would run other poses than the ones planned.
    if !args.no_verify {
        let verdict = verify::verify(&cell, &plan, &VerifySettings::default());
        if !verdict.ok {
            for v in verdict.violations.iter().take(5) {
                eprintln!("{}", crate::verify_cmd::describe(v));
            }
            eprintln!(
                "NOT OK: {} violation(s) of the plan on {}; nothing exported (`cellplan verify` lists them, --no-verify exports anyway)",
                verdict.violations.len(),
                cell.path.display()
            );
            return Err(Failure::Rejected);
        }
    }
    let scene = Scene::new(&cell, args.mesh_budget.max(12));
    if let Some(path) = &args.gltf {
        let start = Instant::now();
        let bytes = cellplan_report::gltf::glb(&plan, &cell, &scene).map_err(mismatch(&args.plan))?;
        write_atomic(path, &bytes)
            .map_err(|e| Failure::Other(format!("cannot write {}: {e}", path.display())))?;
        eprintln!(
            "glTF written to {} ({:.2} MB, {:.2} s)",
            path.display(),
            bytes.len() as f64 / 1e6,
            start.elapsed().as_secs_f64()
        );
    }
    if let Some(dir) = &args.csv {
        let files = cellplan_report::csv::files(&plan, &scene).map_err(mismatch(&args.plan))?;
        let outputs: Vec<(PathBuf, &[u8])> = files
            .iter()
            .map(|(name, text)| (dir.join(name), text.as_bytes()))
            .collect();
        let outputs: Vec<(&Path, &[u8])> = outputs.iter().map(|(p, b)| (p.as_path(), *b)).collect();
        write_all_atomic(&outputs)
            .map_err(|e| Failure::Other(format!("cannot write the CSV files in {}: {e}", dir.display())))?;
        eprintln!("{} CSV files written to {}", files.len(), dir.display());
    }
    Ok(())
}
