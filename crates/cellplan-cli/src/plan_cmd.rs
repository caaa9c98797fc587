//! `cellplan plan`: the main job.
use crate::{Failure, load_options, spinner};
use cellplan_core::CandidateTable;
use cellplan_core::coord::{CoordSettings, Coordination};
use cellplan_core::document as output;
use cellplan_core::pipeline::{self, PipelineError, Step};
use cellplan_core::plan::{Allocation, CoverMethod, MoveModel, PlanSettings, Stage};
use cellplan_model::io::write_all_atomic;
use cellplan_model::{Cell, InputError};
use cellplan_verify::VerifySettings;
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Args)]
pub struct PlanArgs {
    /// The cell file (TOML).
    pub cell: PathBuf,
    /// Output folder (default: out/CELL_NAME/); the plan goes to plan.json in it.
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// Allocation strategy.
    #[arg(long, value_enum, default_value_t = Allocation::Zones)]
    allocation: Allocation,
    /// Set-cover method of the local-robust allocation.
    #[arg(long, value_enum, default_value_t = CoverMethod::Penalty)]
    cover: CoverMethod,
    /// Move-time model of the lower-bound costs (`instant` is paper 000's assumption 2).
    #[arg(long, value_enum, default_value_t = MoveModel::Trapezoid)]
    move_model: MoveModel,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Wall-clock limit of the whole run in seconds. By default there is none: every search
    /// stops at its work budget, so the plan depends only on the cell and the seed (not on
    /// the machine or the thread count); when a limit binds, the output says so. The limit
    /// stops the searches (allocation, sequencing rounds, the route bound) and gives up the
    /// plans the run can do without (ours' tries after its first plan, its hand-overs, and
    /// their coordinations); what the first plan needs (the legs of its tours, its
    /// coordination), blending and verification still finish, and the output says by how much
    /// the run went past the limit.
    #[arg(long, value_name = "S")]
    pub time_limit: Option<f64>,
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
    #[arg(long, value_enum, default_value_t = Coordination::Best)]
    coordination: Coordination,
    /// After coordination, legs without a wait on the way run through their corners without
    /// stopping: each corner's blend stays within this much of the corner in every joint
    /// (rad) and is checked against the scene and the other robots' timelines; 0: every leg
    /// stops at every waypoint.
    #[arg(long, value_name = "RAD", default_value_t = cellplan_core::coord::BLEND_DEVIATION)]
    blend_deviation: f64,
    /// Inspection cells: also prove a tighter lower bound from whole routes (column
    /// generation over the allocation problem), no round starting once its pricings have
    /// looked at this many billion arcs (a round may take it past; the README cell's
    /// converges within 1, the bench gives 20). The plan states the larger bound with the
    /// duals that prove it; `verify` checks it from them with one pricing per robot.
    /// `--time-limit` bounds it too: no round starts past it (the output then says the clock
    /// cut it).
    #[arg(long, value_name = "G_ARCS")]
    route_bound: Option<f64>,
    /// Write the plan even if `cellplan verify` rejects it.
    #[arg(long)]
    pub no_verify: bool,
    /// Do not write report.html (the HTML report) beside the plan.
    #[arg(long)]
    pub no_report: bool,
    /// No progress output and no table.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print a JSON summary (stable keys: cycle_time_s, delta_t_s, lower_bound_s, robots,
    /// unmeasured, idle_robots, compute_s).
    #[arg(long)]
    pub json: bool,
    /// PCB assembly and CMM inspection: the optimiser (`best` ours, `ga` the paper's GA —
    /// paper 004's for PCB, paper 003's enhanced GA for the CMM's orders).
    #[arg(long, value_enum, default_value_t = crate::pcb_cmd::OptimizerArg::Best)]
    pub optimizer: crate::pcb_cmd::OptimizerArg,
    /// PCB assembly: which devices move (default: the cell's `configuration`).
    #[arg(long, value_enum)]
    pub configuration: Option<crate::pcb_cmd::ConfigurationArg>,
    /// PCB assembly: plan a two-robot cell with its first robot alone (1), or as given.
    #[arg(long, value_name = "N")]
    pub robots: Option<usize>,
    /// PCB assembly: motion model (default: the cell's `motion`).
    #[arg(long, value_enum)]
    pub motion: Option<crate::pcb_cmd::MotionArg>,
    /// PCB assembly: place in this order (a file of references, one per line, e.g. another
    /// tool's program) and optimise only the rest; the plan's optimiser is then `given`.
    #[arg(long, value_name = "FILE")]
    pub order: Option<PathBuf>,
    /// PCB assembly: simulations the optimiser may spend (the work budget).
    #[arg(long, value_name = "N", default_value_t = 200_000)]
    pub evaluations: usize,
    /// Cache folder for self-collision pair lists.
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Do not read or write the cache.
    #[arg(long)]
    no_cache: bool,
}

#[derive(Serialize)]
struct Summary<'a> {
    plan_file: String,
    report_file: Option<String>,
    cycle_time_s: f64,
    delta_t_s: f64,
    /// Whether Δt is within the cell's balance limit γ (true without one).
    balance_limit_met: bool,
    /// Whether `--time-limit` stopped a search early (the plan then depends on machine speed).
    time_limit_hit: bool,
    lower_bound_s: f64,
    ratio_to_lower_bound: f64,
    /// With `--route-bound`: the route bound (`lower_bound_s` is the larger of it and the leg
    /// bound).
    #[serde(skip_serializing_if = "Option::is_none")]
    route_bound: Option<RouteBoundSummary>,
    robots: Vec<RobotSummary<'a>>,
    unmeasured: Vec<&'a str>,
    /// Robots that can do none of the tasks (they stay at home; Δt leaves them out).
    idle_robots: Vec<&'a str>,
    legs_planned: usize,
    legs_sampled: usize,
    coordination: &'a output::CoordinationOut,
    verified: bool,
    compute_s: f64,
    compute_stages_s: &'a output::ComputeTimes,
}

/// The route bound and how its search went (`stats.route_bound`), side by side.
#[derive(Serialize)]
struct RouteBoundSummary {
    bound_s: f64,
    legs_s: f64,
    max_work: u64,
    work: u64,
    rounds: usize,
    converged: bool,
    cut_by_clock: bool,
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
    if crate::pcb_cmd::is_pcb(&args.cell)? {
        return crate::pcb_cmd::plan(args);
    }
    if crate::studweld_cmd::is_studweld(&args.cell)? {
        return crate::studweld_cmd::plan(args);
    }
    if crate::cmm_cmd::is_cmm(&args.cell)? {
        return crate::cmm_cmd::plan(args);
    }
    let start = Instant::now();
    if args
        .time_limit
        .is_some_and(|t| !(t.is_finite() && t > 0.0 && t <= 1e6))
    {
        return Err(Failure::Usage(
            "--time-limit must be a number of seconds above 0 and at most 1e6".into(),
        ));
    }
    if !(args.local_set_radius.is_finite() && (0.0..=100.0).contains(&args.local_set_radius)) {
        return Err(Failure::Usage(
            "--local-set-radius must be a length in metres between 0 and 100".into(),
        ));
    }
    if !(args.blend_deviation.is_finite() && (0.0..=1.0).contains(&args.blend_deviation)) {
        return Err(Failure::Usage(
            "--blend-deviation must be an angle in radians between 0 (no blends) and 1".into(),
        ));
    }
    if args
        .route_bound
        .is_some_and(|g| !(g.is_finite() && (1e-9..=1000.0).contains(&g)))
    {
        return Err(Failure::Usage(
            "--route-bound must be a number of billion arcs from 1e-9 (one arc) to 1000 (20 is the bench's budget)".into(),
        ));
    }
    if args.lazy_rounds > 1000 || args.reallocation_rounds > 1000 {
        return Err(Failure::Usage(
            "--lazy-rounds and --reallocation-rounds must be at most 1000".into(),
        ));
    }
    let show = !args.quiet && !args.json;
    let opts = load_options(args.no_cache, &args.cache_dir);
    let pb = spinner(show, "loading the cell");
    let cell = crate::load_cell(&args.cell, &opts)?;
    // Before any planning: the output folder must take files.
    let dir = crate::plan_output_dir(args.output.as_deref(), &cell.name, &cell.path)?;
    let load_s = start.elapsed().as_secs_f64();
    let settings = PlanSettings {
        allocation: args.allocation,
        cover: args.cover,
        move_model: args.move_model,
        seed: args.seed,
        time_limit: args
            .time_limit
            .map_or(PlanSettings::NO_TIME_LIMIT, Duration::from_secs_f64),
        local_set_radius: args.local_set_radius,
        lazy_rounds: args.lazy_rounds.max(1),
        reallocation_rounds: args.reallocation_rounds,
        route_bound_work: args.route_bound.map(|g| (g * 1e9).round() as u64),
        ..PlanSettings::default()
    };
    let coord_settings = CoordSettings {
        strategy: args.coordination,
        seed: args.seed,
        blend_deviation: args.blend_deviation,
        ..CoordSettings::default()
    };
    let words = cell.process.words();
    let progress = {
        let pb = pb.clone();
        let (tasks, robots) = (cell.tasks.len(), cell.robots.len());
        move |step: Step| {
            pb.set_message(match step {
                Step::Candidates => {
                    format!("finding candidates for {tasks} {} × {robots} robots", words.tasks)
                }
                Step::Plan(Stage::Costs) => "move-time bounds between candidates".into(),
                Step::Plan(Stage::Allocation) => format!("allocating {} to robots", words.tasks),
                Step::Plan(Stage::Sequencing) => "sequencing and planning collision-free legs".into(),
                Step::Plan(Stage::Timing) => "timing the trajectories".into(),
                Step::Coordination { zones_too: true } => {
                    "coordinating the robots on one clock (and ours' other plans: strips, the nearest robots, the zones again)".into()
                }
                Step::Coordination { zones_too: false } => "coordinating the robots on one clock".into(),
                Step::Verification => "verifying the plan".into(),
            })
        }
    };
    let verifier = |cell: &Cell, table: &CandidateTable, plan: &output::Plan| {
        let report = cellplan_verify::verify_with(cell, Some(table), plan, &VerifySettings::default());
        (report.ok, report)
    };
    let run = pipeline::run(&cell, &settings, &coord_settings, load_s, &progress, &verifier).map_err(
        |e| match e {
            PipelineError::Input(e) => Failure::Input(e),
            PipelineError::Plan(e) if e.is_input() => Failure::Input(Box::new(
                InputError::new(&cell.path, e.to_string())
                    .hint("see `task_cap` and `balance_limit` in the [planning] table of the cell file"),
            )),
            PipelineError::Plan(e) => Failure::Other(e.to_string()),
        },
    )?;
    let (mut doc, report) = (run.plan, run.report);
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
    let file = dir.join("plan.json");
    let report_file = dir.join("report.html");
    doc.compute_s.total = start.elapsed().as_secs_f64();
    let text = serde_json::to_string_pretty(&doc).map_err(|e| Failure::Other(e.to_string()))?;
    // The plan and its report are written together or not at all.
    let page = if args.no_report {
        None
    } else {
        pb.set_message("writing the report");
        Some(crate::report_cmd::render_report(
            &file,
            &doc,
            &cell,
            Some(&report),
            cellplan_report::scene::MESH_BUDGET,
        )?)
    };
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&file, text.as_bytes())];
    if let Some(page) = &page {
        files.push((&report_file, page.as_bytes()));
    }
    write_all_atomic(&files)
        .map_err(|e| Failure::Other(format!("cannot write into {}: {e}", dir.display())))?;
    pb.finish_and_clear();
    cell.save_cache();
    if args.json {
        let summary = Summary {
            plan_file: file.display().to_string(),
            report_file: (!args.no_report).then(|| report_file.display().to_string()),
            cycle_time_s: doc.cycle_time_s,
            delta_t_s: doc.delta_t_s,
            balance_limit_met: balance_met(&doc),
            time_limit_hit: doc.stats.time_limit_hit,
            lower_bound_s: doc.lower_bound_s,
            ratio_to_lower_bound: doc.ratio_to_lower_bound,
            route_bound: doc
                .route_bound
                .as_ref()
                .zip(doc.stats.route_bound.as_ref())
                .map(|(b, run)| RouteBoundSummary {
                    bound_s: b.bound_s,
                    legs_s: b.legs_s,
                    max_work: run.max_work,
                    work: run.work,
                    rounds: run.rounds,
                    converged: run.converged,
                    cut_by_clock: run.cut_by_clock,
                }),
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
            idle_robots: doc.idle_robots.iter().map(|i| i.robot.as_str()).collect(),
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
        print!("{}", render(&doc, cell.process.words().working));
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

/// Whether the plan's Δt is within γ (true when the cell sets none).
fn balance_met(doc: &output::Plan) -> bool {
    doc.settings
        .balance_limit_s
        .is_none_or(|g| doc.delta_t_s <= g + 1e-9)
}

fn render(doc: &output::Plan, working: &str) -> String {
    let mut s = format!(
        "{} — allocation {}, coordination {}, seed {}\n\n",
        doc.cell, doc.settings.allocation, doc.settings.coordination, doc.settings.seed
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
        doc.stats.conflicts_resolved,
        c.waits,
        c.poses_changed,
        c.uncoordinated_cycle_time_s
    );
    if let Some(p) = &doc.stats.passage_search {
        s += &format!(
            "passage orders: {} conflict boxes ({} exact distances), {} search nodes, {}{}\n",
            p.boxes,
            p.distances,
            p.nodes,
            if p.proven {
                "the shortest schedule the boxes allow"
            } else {
                "node budget reached: the best schedule found"
            },
            match p.reversed {
                0 => String::new(),
                1 => "; 1 tour runs the other way round".to_string(),
                n => format!("; {n} tours run the other way round"),
            }
        );
    }
    for k in &c.conflicts_before {
        s += &format!(
            "  {:.2}–{:.2} s {} & {} (scenario {}): {}; {}\n",
            k.start_s,
            k.end_s,
            k.robots[0],
            k.robots[1],
            k.scenario,
            k.activity[0].text(working),
            k.activity[1].text(working)
        );
    }
    for k in &c.conflicts_after {
        s += &format!(
            "  NOT RESOLVED {:.2}–{:.2} s {} & {}: {}; {}\n",
            k.start_s,
            k.end_s,
            k.robots[0],
            k.robots[1],
            k.activity[0].text(working),
            k.activity[1].text(working)
        );
    }
    s += &format!(
        "\ncycle time {:.2} s   Δt {:.2} s   lower bound {:.2} s (ratio {:.3})\n",
        doc.cycle_time_s, doc.delta_t_s, doc.lower_bound_s, doc.ratio_to_lower_bound
    );
    if let Some(r) = &doc.route_bound {
        let run = doc.stats.route_bound.as_ref().map_or(String::new(), |run| {
            format!(
                "; {} rounds, {:.2} G arcs, {}",
                run.rounds,
                run.work as f64 * 1e-9,
                run.ending()
            )
        });
        s += &format!(
            "route bound {:.2} s (the leg bound {:.2} s{run})\n",
            r.bound_s, r.legs_s
        );
    }
    if !balance_met(doc)
        && let Some(g) = doc.settings.balance_limit_s
    {
        s += &format!(
            "balance limit γ = {g:.2} s not met: Δt {:.2} s (the shortest cycle found spreads the robots' end times more)\n",
            doc.delta_t_s
        );
    }
    if doc.stats.time_limit_hit {
        s += "time limit reached: a search stopped before its work budget, so this plan depends on this machine's speed (a longer --time-limit gives the plan the same input and seed always give)\n";
        if let Some(limit) = doc.settings.time_limit_s
            && doc.compute_s.total > limit
        {
            s += &format!(
                "  the run took {:.1} s against the {limit:.1} s limit: what the first plan needs (its legs, its coordination), blending and verification are not cut\n",
                doc.compute_s.total
            );
        }
    }
    s += &format!(
        "legs planned {} ({} by the sampling planner), sequencing rounds {}\n",
        doc.stats.legs_planned, doc.stats.legs_sampled, doc.stats.sequencing_rounds
    );
    let legs = doc.robots.iter().flat_map(|r| &r.legs);
    let (blended, corners) = legs.fold((0, 0), |(l, c), leg| {
        (l + usize::from(!leg.blends.is_empty()), c + leg.blends.len())
    });
    if blended > 0 {
        s += &format!("blended: {blended} legs run through {corners} corners without stopping\n");
    }
    let c = &doc.compute_s;
    // Ours plans and coordinates its other plans and hand-overs within its coordination stage.
    let ours = pipeline::is_ours(doc.settings.allocation, doc.settings.coordination);
    s += &format!(
        "compute: load {:.2} s, candidates {:.2} s, costs {:.2} s, allocation {:.2} s, sequencing+motion {:.2} s, timing {:.2} s, {} {:.2} s, verification {:.2} s, total {:.2} s\n",
        c.load,
        c.candidates,
        c.costs,
        c.allocation,
        c.sequencing_motion,
        c.timing,
        if ours {
            "coordination with ours' other plans"
        } else {
            "coordination"
        },
        c.coordination,
        c.verification,
        c.total
    );
    if let (Some(o), Some(t)) = (&doc.stats.ours, &c.ours) {
        s += &format!(
            "  (ours: {} plans coordinated{} in {:.2} s, then {} hand-overs judged in {:.2} s{}{}, the winner{} blended in {:.2} s)\n",
            o.tries_coordinated,
            if o.polished_throughout {
                " and polished"
            } else {
                ""
            },
            t.tries,
            o.handovers_judged,
            t.handovers,
            if o.handover_taken { ", one taken" } else { "" },
            if o.polished_throughout {
                String::new()
            } else {
                format!(
                    ", the winner polished in {:.2} s{}",
                    t.polish,
                    if o.polished { " (kept)" } else { "" }
                )
            },
            match o.blended {
                0 | 1 => String::new(),
                2 => " and a runner-up".to_string(),
                n => format!(" and {} runners-up", n - 1),
            },
            t.blend
        );
    }
    if c.route_bound > 0.0 {
        s += &format!(
            "  (of which the route bound {:.2} s; verification checks it from its duals)\n",
            c.route_bound
        );
    }
    s += &if doc.verified {
        format!(
            "verified: every MP once, probe constraints, limits, clearance to the scene and between robots (proven to within {} mm between the samples)\n",
            cellplan_verify::PROOF_TOLERANCE * 1e3
        )
    } else {
        "NOT VERIFIED (written with --no-verify)\n".to_string()
    };
    if !doc.unmeasured.is_empty() {
        s += "\nnot measured:\n";
        for u in &doc.unmeasured {
            s += &format!("  {}: {}", u.task, u.reason);
            if let Some(d) = &u.detail {
                s += &format!(" ({d})");
            }
            s += "\n";
        }
    }
    if !doc.idle_robots.is_empty() {
        s += "\nidle (can do none of the tasks; Δt leaves them out):\n";
        for i in &doc.idle_robots {
            s += &format!("  {}: {}\n", i.robot, i.reason);
        }
    }
    s
}
