//! `cellplan verify`: the independent check of a plan.
use crate::Failure;
use cellplan_model::LoadOptions;
use cellplan_verify::{VerifySettings, Violation, verify};
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct VerifyArgs {
    /// The plan (plan.json written by `cellplan plan`).
    plan: PathBuf,
    /// The cell file it was made for.
    cell: PathBuf,
    /// Print the verdict as JSON (stable keys: ok, violations).
    #[arg(long)]
    json: bool,
    /// Skip the robot–robot clearance check (for plans not coordinated yet).
    #[arg(long)]
    no_robot_robot: bool,
    /// Time step (s) with which the robot–robot check reports a contact's interval (between
    /// contacts it steps as far as the robots' motion bound proves them apart).
    #[arg(long, value_name = "S", default_value_t = VerifySettings::default().time_step)]
    time_step: f64,
}

pub fn run(args: &VerifyArgs) -> Result<(), Failure> {
    if crate::pcb_cmd::is_pcb(&args.cell)? {
        return crate::pcb_cmd::verify(&args.plan, &args.cell, args.json, !args.no_robot_robot);
    }
    if crate::studweld_cmd::is_studweld(&args.cell)? {
        return crate::studweld_cmd::verify(&args.plan, &args.cell, args.json);
    }
    if crate::cmm_cmd::is_cmm(&args.cell)? {
        return crate::cmm_cmd::verify(&args.plan, &args.cell, args.json);
    }
    if !(args.time_step.is_finite() && (1e-4..=1.0).contains(&args.time_step)) {
        return Err(Failure::Usage(format!(
            "--time-step must be between 0.0001 and 1 s, not {}",
            cellplan_model::shown(args.time_step)
        )));
    }
    let plan = crate::report_cmd::read_plan(&args.plan)?;
    let cell = crate::load_cell(&args.cell, &LoadOptions::default())?;
    let settings = VerifySettings {
        robot_robot: !args.no_robot_robot,
        time_step: args.time_step,
        ..VerifySettings::default()
    };
    if let Some(why) = cellplan_verify::too_large(&plan, &settings) {
        return Err(Failure::Input(Box::new(
            cellplan_model::InputError::new(&args.plan, format!("the plan is too large to check: {why}"))
                .hint("give a larger --time-step, or check a plan `cellplan plan` wrote"),
        )));
    }
    let report = verify(&cell, &plan, &settings);
    let summary = format!(
        "cycle time {:.2} s, Δt {:.2} s (recomputed); {} configurations and {} robot-pair instants checked",
        report.cycle_time_s, report.delta_t_s, report.configurations_checked, report.pair_instants_checked
    );
    print_verdict(
        &report,
        report.ok,
        &report.violations,
        describe,
        &summary,
        args.json,
    )
}

/// How every `verify` ends: the report as JSON, or one line per violation and `ok` / `NOT OK`
/// with the count and `summary`; [`Failure::Rejected`] (exit 4) when not `ok`.
pub(crate) fn print_verdict<R: serde::Serialize, V>(
    report: &R,
    ok: bool,
    violations: &[V],
    describe: impl Fn(&V) -> String,
    summary: &str,
    json: bool,
) -> Result<(), Failure> {
    if json {
        crate::print_json(report)?;
    } else {
        for v in violations {
            println!("{}", describe(v));
        }
        println!(
            "{}: {} violation(s); {summary}",
            if ok { "ok" } else { "NOT OK" },
            violations.len()
        );
    }
    if ok { Ok(()) } else { Err(Failure::Rejected) }
}

/// One violation on one line.
pub fn describe(v: &Violation) -> String {
    let who = match (&v.robot, &v.other) {
        (Some(a), Some(b)) => format!("{a} & {b}"),
        (Some(a), None) => a.clone(),
        _ => "-".into(),
    };
    let when = v.time_s.map_or(String::new(), |t| format!(" at {t:.2} s"));
    let task = v.task.as_ref().map_or(String::new(), |t| format!(" MP {t}"));
    format!("{:?} {who}{when}{task}: {}", v.kind, v.detail)
}
