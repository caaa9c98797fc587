//! `cellplan plan`: the main job.
use crate::{Failure, load_options, spinner};
use cellplan::coord::{self, CoordSettings, Coordination};
use cellplan::plan::{self, Allocation, CoverMethod, MoveModel, PlanError, PlanSettings, Stage, output};
use cellplan::verify::{VerifySettings, verify};
use cellplan::{InputError, candidates, io::write_atomic, report::check};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Args)]
pub struct PlanArgs {
    /// The cell file (TOML).
    cell: PathBuf,
    /// Output folder (default: out/<cell name>/); the plan goes to plan.json in it.
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,
    /// Allocation strategy.
    #[arg(long, value_enum, default_value_t = AllocationArg::Balanced)]
    allocation: AllocationArg,
    /// Set-cover method of the local-robust allocation.
    #[arg(long, value_enum, default_value_t = CoverArg::Penalty)]
    cover: CoverArg,
    /// Move-time model of the lower-bound costs (`instant` is paper 000's assumption 2).
    #[arg(long, value_enum, default_value_t = MoveModelArg::Trapezoid)]
    move_model: MoveModelArg,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Budget of the search stages in seconds (they also stop after fixed iteration counts).
    #[arg(long, value_name = "S", default_value_t = 30.0)]
    time_limit: f64,
    /// ε of paper 000 eq. 4 in metres: MPs closer than this may share a local robust set.
    #[arg(long, value_name = "M", default_value_t = 0.3)]
    local_set_radius: f64,
    /// Most sequencing rounds of the lazy loop per robot (each plans the legs its order uses;
    /// twice as many while the best order still needs a leg the quick planner gave up on).
    #[arg(long, value_name = "N", default_value_t = PlanSettings::default().lazy_rounds)]
    lazy_rounds: usize,
    /// Re-allocations of `balanced` on the leg times learnt while sequencing (each costs about
    /// an allocation and a sequencing; an alternative that cannot beat the plan so far is
    /// dropped after one GTSP per robot).
    #[arg(long, value_name = "N", default_value_t = PlanSettings::default().reallocation_rounds)]
    reallocation_rounds: usize,
    /// Coordination of the robots on the common clock (paper 000 §4.2 is `pose-perturbation`;
    /// `none` leaves conflicts in, and the verifier then refuses the plan).
    #[arg(long, value_enum, default_value_t = CoordinationArg::Best)]
    coordination: CoordinationArg,
    /// Write the plan even if `cellplan verify` rejects it.
    #[arg(long)]
    no_verify: bool,
    /// Do not write report.html (the HTML report) beside the plan.
    #[arg(long)]
    no_report: bool,
    /// No progress output and no table.
    #[arg(long, short)]
    quiet: bool,
    /// Print a JSON summary (stable keys: cycle_time_s, delta_t_s, lower_bound_s, robots,
    /// unmeasured, compute_s).
    #[arg(long)]
    json: bool,
    /// Cache folder for self-collision pair lists.
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Do not read or write the cache.
    #[arg(long)]
    no_cache: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum AllocationArg {
    Proximity,
    LocalRobust,
    Balanced,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum CoordinationArg {
    None,
    DelayStartup,
    FixedPriority,
    PosePerturbation,
    Best,
}

impl From<CoordinationArg> for Coordination {
    fn from(a: CoordinationArg) -> Self {
        match a {
            CoordinationArg::None => Coordination::None,
            CoordinationArg::DelayStartup => Coordination::DelayStartup,
            CoordinationArg::FixedPriority => Coordination::FixedPriority,
            CoordinationArg::PosePerturbation => Coordination::PosePerturbation,
            CoordinationArg::Best => Coordination::Best,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum CoverArg {
    Penalty,
    Exact,
}

#[derive(Clone, Copy, ValueEnum)]
enum MoveModelArg {
    Trapezoid,
    Instant,
}

#[derive(Serialize)]
struct Summary<'a> {
    plan_file: String,
    report_file: Option<String>,
    cycle_time_s: f64,
    delta_t_s: f64,
    lower_bound_s: f64,
    ratio_to_lower_bound: f64,
    robots: Vec<RobotSummary<'a>>,
    unmeasured: Vec<&'a str>,
    legs_planned: usize,
    legs_sampled: usize,
    coordination: &'a output::CoordinationOut,
    verified: bool,
    compute_s: f64,
    compute_stages_s: &'a output::ComputeTimes,
}

#[derive(Serialize)]
struct RobotSummary<'a> {
    name: &'a str,
    tasks: usize,
    motion_s: f64,
    measuring_s: f64,
    waiting_s: f64,
    total_s: f64,
}

pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    let start = Instant::now();
    if !(args.time_limit.is_finite() && args.time_limit > 0.0) {
        return Err(Failure::Other(
            "--time-limit must be a positive number of seconds".into(),
        ));
    }
    if !(args.local_set_radius.is_finite() && args.local_set_radius >= 0.0) {
        return Err(Failure::Other(
            "--local-set-radius must be a non-negative length in metres".into(),
        ));
    }
    let show = !args.quiet && !args.json;
    let opts = load_options(args.no_cache, &args.cache_dir);
    let pb = spinner(show, "loading the cell");
    let cell = cellplan::model::load::load(&args.cell, &opts)?;
    let load_s = start.elapsed().as_secs_f64();
    pb.set_message(format!(
        "finding candidates for {} MPs × {} robots",
        cell.tasks.len(),
        cell.robots.len()
    ));
    let lap = Instant::now();
    let table = candidates::generate(&cell);
    let candidates_s = lap.elapsed().as_secs_f64();
    if let Some(e) = check::idle_robot_error(&cell, &table) {
        pb.finish_and_clear();
        return Err(e.into());
    }
    let settings = PlanSettings {
        allocation: match args.allocation {
            AllocationArg::Proximity => Allocation::Proximity,
            AllocationArg::LocalRobust => Allocation::LocalRobust,
            AllocationArg::Balanced => Allocation::Balanced,
        },
        cover: match args.cover {
            CoverArg::Penalty => CoverMethod::Penalty,
            CoverArg::Exact => CoverMethod::Exact,
        },
        move_model: match args.move_model {
            MoveModelArg::Trapezoid => MoveModel::Trapezoid,
            MoveModelArg::Instant => MoveModel::Instant,
        },
        seed: args.seed,
        time_limit: Duration::from_secs_f64(args.time_limit),
        local_set_radius: args.local_set_radius,
        lazy_rounds: args.lazy_rounds.max(1),
        reallocation_rounds: args.reallocation_rounds,
        ..PlanSettings::default()
    };
    let progress = {
        let pb = pb.clone();
        move |stage: Stage| {
            pb.set_message(match stage {
                Stage::Costs => "move-time bounds between candidates",
                Stage::Allocation => "allocating MPs to robots",
                Stage::Sequencing => "sequencing and planning collision-free legs",
                Stage::Timing => "timing the trajectories",
            })
        }
    };
    let failure = |e: PlanError| match e {
        PlanError::Infeasible(m) => Failure::Input(Box::new(
            InputError::new(&cell.path, m).hint("see [process] task_cap and balance_limit in the cell file"),
        )),
        other => Failure::Other(other.to_string()),
    };
    let outcome = plan::plan(&cell, &table, &settings, &progress).map_err(failure)?;
    let coord_settings = CoordSettings {
        strategy: args.coordination.into(),
        seed: args.seed,
        ..CoordSettings::default()
    };
    pb.set_message(
        if coord_settings.strategy == Coordination::Best && settings.allocation == Allocation::Balanced {
            "coordinating the robots on one clock (and the proximity allocation against it)"
        } else {
            "coordinating the robots on one clock"
        },
    );
    let (outcome, settings, coordinated) =
        coord::coordinate_plan(&cell, &table, outcome, settings, &coord_settings).map_err(failure)?;
    let mut doc = output::build(
        &cell,
        &table,
        &outcome,
        &coordinated,
        &settings,
        load_s,
        candidates_s,
    );
    pb.set_message("verifying the plan");
    let lap = Instant::now();
    let report = verify(&cell, &doc, &VerifySettings::default());
    doc.compute_s.verification = lap.elapsed().as_secs_f64();
    doc.verified = report.ok;
    if !report.ok && !args.no_verify {
        pb.finish_and_clear();
        for v in &report.violations {
            eprintln!("{}", crate::verify_cmd::describe(v));
        }
        return Err(Failure::Other(format!(
            "the plan failed verification ({} violation(s)) and was not written; --no-verify writes it anyway",
            report.violations.len()
        )));
    }
    let dir = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&cell.name));
    let file = dir.join("plan.json");
    doc.compute_s.total = start.elapsed().as_secs_f64();
    let text = serde_json::to_string_pretty(&doc).map_err(|e| Failure::Other(e.to_string()))?;
    std::fs::create_dir_all(&dir)
        .and_then(|()| write_atomic(&file, text.as_bytes()))
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", file.display())))?;
    let report_file = dir.join("report.html");
    if !args.no_report {
        pb.set_message("writing the report");
        crate::report_cmd::write_report(
            &report_file,
            &file,
            &doc,
            &cell,
            Some(&report),
            cellplan::report::scene::MESH_BUDGET,
        )?;
    }
    pb.finish_and_clear();
    cell.save_cache();
    if args.json {
        let summary = Summary {
            plan_file: file.display().to_string(),
            report_file: (!args.no_report).then(|| report_file.display().to_string()),
            cycle_time_s: doc.cycle_time_s,
            delta_t_s: doc.delta_t_s,
            lower_bound_s: doc.lower_bound_s,
            ratio_to_lower_bound: doc.ratio_to_lower_bound,
            robots: doc
                .robots
                .iter()
                .map(|r| RobotSummary {
                    name: &r.name,
                    tasks: r.tasks.len(),
                    motion_s: r.motion_s,
                    measuring_s: r.measuring_s,
                    waiting_s: r.waiting_s,
                    total_s: r.total_s,
                })
                .collect(),
            unmeasured: doc.unmeasured.iter().map(|u| u.task.as_str()).collect(),
            legs_planned: doc.stats.legs_planned,
            legs_sampled: doc.stats.legs_sampled,
            coordination: &doc.coordination,
            verified: doc.verified,
            compute_s: doc.compute_s.total,
            compute_stages_s: &doc.compute_s,
        };
        let text = serde_json::to_string_pretty(&summary).map_err(|e| Failure::Other(e.to_string()))?;
        println!("{text}");
    } else if !args.quiet {
        print!("{}", render(&doc));
        println!("plan written to {}", file.display());
        if !args.no_report {
            println!("report written to {}", report_file.display());
        }
    }
    if doc.unmeasured.is_empty() {
        Ok(())
    } else {
        Err(Failure::Infeasible)
    }
}

fn render(doc: &output::Plan) -> String {
    let mut s = format!(
        "{} — allocation {}, coordination {}, seed {}\n\n",
        doc.cell,
        doc.settings.allocation.name(),
        doc.settings.coordination.name(),
        doc.settings.seed
    );
    s += &format!(
        "{:<10} {:>6} {:>10} {:>12} {:>10} {:>9}\n",
        "robot", "MPs", "motion s", "measuring s", "waiting s", "total s"
    );
    for r in &doc.robots {
        s += &format!(
            "{:<10} {:>6} {:>10.2} {:>12.2} {:>10.2} {:>9.2}\n",
            r.name,
            r.tasks.len(),
            r.motion_s,
            r.measuring_s,
            r.waiting_s,
            r.total_s
        );
    }
    let c = &doc.coordination;
    s += &format!(
        "\nconflicts before coordination {}, resolved {} ({} waits, {} poses changed); cycle time without coordination {:.2} s\n",
        c.conflicts_before.len(),
        c.conflicts_resolved,
        c.waits,
        c.poses_changed,
        c.uncoordinated_cycle_time_s
    );
    for k in &c.conflicts_before {
        s += &format!(
            "  {:.2}–{:.2} s {} & {} (scenario {}): {}; {}\n",
            k.start_s, k.end_s, k.robots[0], k.robots[1], k.scenario, k.activity[0], k.activity[1]
        );
    }
    for k in &c.conflicts_after {
        s += &format!(
            "  NOT RESOLVED {:.2}–{:.2} s {} & {}: {}; {}\n",
            k.start_s, k.end_s, k.robots[0], k.robots[1], k.activity[0], k.activity[1]
        );
    }
    s += &format!(
        "\ncycle time {:.2} s   Δt {:.2} s   lower bound {:.2} s (ratio {:.3})\n",
        doc.cycle_time_s, doc.delta_t_s, doc.lower_bound_s, doc.ratio_to_lower_bound
    );
    s += &format!(
        "legs planned {} ({} by the sampling planner), sequencing rounds {}\n",
        doc.stats.legs_planned, doc.stats.legs_sampled, doc.stats.sequencing_rounds
    );
    let c = &doc.compute_s;
    s += &format!(
        "compute: load {:.2} s, candidates {:.2} s, costs {:.2} s, allocation {:.2} s, sequencing+motion {:.2} s, timing {:.2} s, coordination {:.2} s, verification {:.2} s, total {:.2} s\n",
        c.load,
        c.candidates,
        c.costs,
        c.allocation,
        c.sequencing_motion,
        c.timing,
        c.coordination,
        c.verification,
        c.total
    );
    s += if doc.verified {
        "verified: every MP once, probe constraints, limits, clearance to the scene and between robots\n"
    } else {
        "NOT VERIFIED (written with --no-verify)\n"
    };
    if !doc.unmeasured.is_empty() {
        s += "\nnot measured:\n";
        for u in &doc.unmeasured {
            s += &format!("  {}: {}\n", u.task, u.reason);
        }
    }
    s
}
