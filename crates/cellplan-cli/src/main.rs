//! The `cellplan` command: thin argument parsing over the `cellplan` library.
//!
//! Exit codes: 0 done; 2 bad input (the message names file, line and a fix; nothing written);
//! 3 the cell is valid but some task no robot can do (the report says which and why);
//! 4 `verify` found the plan violates something (each violation is printed);
//! 1 anything else.
mod bench;
mod bench_motion;
mod cmm_cmd;
mod compare_cmd;
mod pcb_cmd;
mod plan_cmd;
mod report_cmd;
mod studweld_cmd;
mod verify_cmd;

use cellplan_core::{candidates, check};
use cellplan_geom::{DVec3, load_mesh};
use cellplan_model::io::{write_all_atomic, write_atomic};
use cellplan_model::taskgen::{GenOptions, sample_tasks};
use cellplan_model::{Cell, InputError, LoadOptions, Registry};
use cellplan_report::svg;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "cellplan",
    version,
    about = "Plans the work of multi-robot manufacturing cells"
)]
struct Cli {
    /// Worker threads, 1 to 1024 (default: all cores). Results do not depend on it.
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..=MAX_THREADS))]
    threads: Option<u16>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Load and validate a cell, find every task's candidates per robot, report reachability.
    Check(CheckArgs),
    /// Plan the cell: allocation, order, collision-free timed motion per robot; writes the plan.
    Plan(plan_cmd::PlanArgs),
    /// Inspect a subset of a CMM plan's MPs again by reusing its stored paths: no planning.
    Reuse(cmm_cmd::ReuseArgs),
    /// Check a plan independently: MPs, probe poses, limits, clearances, robot–robot, totals.
    Verify(verify_cmd::VerifyArgs),
    /// Run every allocation × coordination strategy on a cell (paper 000 Table 3), or on
    /// random MP sets drawn on its part (Table 4), and print the table.
    Compare(compare_cmd::CompareArgs),
    /// Write the self-contained HTML report of a plan: summary, Gantt chart, time–position
    /// charts before and after coordination, and a 3D playback of the cell.
    Report(report_cmd::ReportArgs),
    /// Export a plan: binary glTF with the robots' motion as an animation, and/or per robot CSV
    /// (time, joints, probe pose; program points) for post-processors.
    Export(report_cmd::ExportArgs),
    /// Generate inputs for building cells.
    #[command(subcommand)]
    Gen(GenCommand),
    /// Run the combinatorial solvers on standard instances (TSPLIB, GTSPLIB, OR-Library) and
    /// compare with the known optima.
    Bench(bench::BenchArgs),
}

#[derive(Args)]
struct CheckArgs {
    /// The cell file (TOML).
    cell: PathBuf,
    /// Print the report as JSON (stable keys: tasks, robots, ik, candidates, unmeasurable, shared).
    #[arg(long)]
    json: bool,
    /// Also draw the cell from above and from the side into this SVG file.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// No progress output.
    #[arg(long, short)]
    quiet: bool,
    /// Cache folder for self-collision pair lists (default: $CELLPLAN_CACHE_DIR, else the
    /// user cache folder).
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Do not read or write the cache.
    #[arg(long)]
    no_cache: bool,
    /// Also write the cell's allocation problem into this file (inspection cells): each robot's
    /// lower-bound move times between home and its candidates, the MPs' measuring times, the
    /// task cap and γ, in the min-max format (docs/minmax-format.md), for `cellplan bench
    /// minmax` and the peers. Its lower bound is the one `cellplan plan` states.
    #[arg(long, value_name = "FILE")]
    minmax_out: Option<PathBuf>,
}

#[derive(Subcommand)]
enum GenCommand {
    /// Sample measurement points on a mesh surface: area-weighted, spread apart, with outward
    /// normals. Writes a task CSV in the mesh's own units and frame.
    Tasks(GenTasksArgs),
    /// Write paper 003's kind of test part: a cylinder-block-like machined block (mesh, mm) and
    /// its 39 measuring points with cone half-angles (task CSV), as `block.obj` and `tasks.csv`.
    Block(GenBlockArgs),
    /// Write the second CMM test part: a gearbox-housing-like casting (mesh, mm) and its 40
    /// measuring points (task CSV), as `housing.obj` and `tasks.csv`.
    Housing(GenBlockArgs),
}

#[derive(Args)]
struct GenBlockArgs {
    /// Output folder.
    #[arg(short, long, value_name = "DIR")]
    out: PathBuf,
    /// Segments of a full circle (bores, holes, bosses).
    #[arg(long, default_value_t = 48)]
    segments: usize,
}

#[derive(Args)]
struct GenTasksArgs {
    /// The part mesh (STL or OBJ).
    #[arg(long)]
    mesh: PathBuf,
    /// Number of points.
    #[arg(long)]
    count: usize,
    /// RNG seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Keep points within a range of one axis, e.g. `x=0..` or `z=300..1200` (mesh units);
    /// repeat for several axes.
    #[arg(long, value_name = "AXIS=LO..HI", value_parser = parse_region)]
    region: Vec<(usize, f64, f64)>,
    /// Keep points whose outward normal points this way: +x, -x, +y, -y, +z, -z or `x,y,z`.
    #[arg(long, value_parser = parse_direction, allow_hyphen_values = true)]
    facing: Option<DVec3>,
    /// Largest angle between normal and `--facing`, in degrees.
    #[arg(long, default_value_t = 60.0)]
    max_angle: f64,
    /// Move the points by this offset `x,y,z` (mesh units) after sampling — where the cell
    /// file places the part, when its pose is a pure translation. Regions and directions
    /// apply before the move, in the mesh frame.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true)]
    translate: Option<DVec3>,
    /// Output file (default: standard output).
    #[arg(long, short)]
    out: Option<PathBuf>,
}

fn parse_vector(s: &str) -> Result<DVec3, String> {
    let parts: Result<Vec<f64>, _> = s.split(',').map(|p| p.trim().parse::<f64>()).collect();
    match parts.as_deref() {
        Ok([x, y, z]) if x.is_finite() && y.is_finite() && z.is_finite() => Ok(DVec3::new(*x, *y, *z)),
        _ => Err("expected three numbers `x,y,z`".into()),
    }
}

fn parse_region(s: &str) -> Result<(usize, f64, f64), String> {
    let (axis, range) = s.split_once('=').ok_or("expected AXIS=LO..HI, e.g. x=0..1500")?;
    let axis = match axis.trim() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        other => return Err(format!("unknown axis `{other}`: use x, y or z")),
    };
    let (lo, hi) = range
        .split_once("..")
        .ok_or("expected LO..HI (either end may be left out)")?;
    let bound = |v: &str, default: f64| -> Result<f64, String> {
        if v.trim().is_empty() {
            Ok(default)
        } else {
            v.trim().parse().map_err(|_| format!("`{v}` is not a number"))
        }
    };
    let (lo, hi) = (bound(lo, f64::NEG_INFINITY)?, bound(hi, f64::INFINITY)?);
    if lo.is_nan() || hi.is_nan() || lo > hi {
        return Err(format!("the range `{range}` is empty: LO must be at most HI"));
    }
    Ok((axis, lo, hi))
}

/// Largest `gen tasks --translate` component (mesh units): 10 km in millimetres.
const MAX_TRANSLATE: f64 = 1e7;

fn parse_direction(s: &str) -> Result<DVec3, String> {
    let d = match s.trim() {
        "+x" | "x" => DVec3::X,
        "-x" => -DVec3::X,
        "+y" | "y" => DVec3::Y,
        "-y" => -DVec3::Y,
        "+z" | "z" => DVec3::Z,
        "-z" => -DVec3::Z,
        v => {
            parse_vector(v).map_err(|_| "use +x, -x, +y, -y, +z, -z or three numbers `x,y,z`".to_string())?
        }
    };
    if d.length() < 1e-12 || !d.is_finite() {
        return Err("the direction must not be zero".into());
    }
    Ok(d.normalize())
}

enum Failure {
    Input(Box<InputError>),
    /// A command-line value out of range (exit 2, the flag named).
    Usage(String),
    Infeasible,
    /// `verify` found violations.
    Rejected,
    Other(String),
}

impl From<InputError> for Failure {
    fn from(e: InputError) -> Self {
        Failure::Input(Box::new(e))
    }
}

fn spinner(show: bool, message: &str) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::new_spinner();
    pb.set_message(message.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// Most points `gen tasks` makes.
const MAX_GENERATED_TASKS: usize = 100_000;

/// The output folder of a plan: `output` when given, else `out/<name>` ([`output_dir_named`]);
/// refused before any planning when it cannot take files.
pub(crate) fn plan_output_dir(
    output: Option<&std::path::Path>,
    name: &str,
    cell_path: &std::path::Path,
) -> Result<PathBuf, Failure> {
    let dir = match output {
        Some(d) => d.to_path_buf(),
        None => output_dir_named(name, cell_path)?,
    };
    ensure_writable(&dir)?;
    Ok(dir)
}

/// Refuses an output file that cannot be written (a folder there, or a parent folder that cannot
/// take files) before any work, making nothing: a usage error naming it and `flag`, the option
/// that gave it.
pub(crate) fn ensure_file_target(path: &std::path::Path, flag: &str) -> Result<(), Failure> {
    if path.is_dir() {
        return Err(Failure::Usage(format!(
            "{} is a folder; give a file path with {flag}",
            path.display()
        )));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    cellplan_model::io::check_creatable(parent).map_err(|e| {
        Failure::Usage(format!(
            "cannot write {}: {e}; give a file in a writable folder with {flag}",
            path.display()
        ))
    })
}

/// Refuses an output folder that cannot take files (a usage error naming it).
pub(crate) fn ensure_writable(dir: &std::path::Path) -> Result<(), Failure> {
    cellplan_model::io::check_writable(dir).map_err(|e| {
        Failure::Usage(format!(
            "cannot write into the output folder {}: {e}; give a writable folder with -o",
            dir.display()
        ))
    })
}

/// `out/<name>` for the cell file `cell_path` of any process, refused when the name would lead
/// outside `out/` (an absolute path, `..`, a separator): the name comes from the cell file.
pub(crate) fn output_dir_named(name: &str, cell_path: &std::path::Path) -> Result<PathBuf, Failure> {
    let plain = !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\', '\0'])
        && std::path::Path::new(name).components().count() == 1;
    if !plain {
        return Err(Failure::Usage(format!(
            "the cell name `{name}` is not a plain folder name, so it cannot name the output folder out/<name>; \
             give the output folder with -o, or change `name` in {}",
            cell_path.display()
        )));
    }
    Ok(PathBuf::from("out").join(name))
}

/// The processes this binary knows.
pub(crate) fn registry() -> Registry {
    Registry::new()
        .with(cellplan_optical::ENTRY)
        .with(cellplan_studweld::ENTRY)
}

/// Loads a cell with the processes of [`registry`].
#[allow(clippy::result_large_err)] // built once, on the cold path of refusing input
pub(crate) fn load_cell(path: &std::path::Path, opts: &LoadOptions) -> Result<Cell, InputError> {
    cellplan_model::load(path, &registry(), opts)
}

/// Loader options from the cache flags shared by the commands that load a cell.
fn load_options(no_cache: bool, cache_dir: &Option<PathBuf>) -> LoadOptions {
    LoadOptions {
        cache_dir: if no_cache {
            None
        } else {
            cache_dir.clone().or_else(LoadOptions::default_cache_dir)
        },
        ..LoadOptions::default()
    }
}

fn run_check(args: &CheckArgs) -> Result<(), Failure> {
    let inspection_only = || {
        Failure::Usage(format!(
            "--minmax-out writes an inspection cell's allocation problem; {} is not an inspection cell",
            args.cell.display()
        ))
    };
    if pcb_cmd::is_pcb(&args.cell)? {
        if args.minmax_out.is_some() {
            return Err(inspection_only());
        }
        return pcb_cmd::check_cell(&args.cell, args.json);
    }
    if cmm_cmd::is_cmm(&args.cell)? {
        if args.minmax_out.is_some() {
            return Err(inspection_only());
        }
        return cmm_cmd::check_cell(&args.cell, args.json);
    }
    let start = Instant::now();
    let show = !args.quiet && !args.json;
    let opts = load_options(args.no_cache, &args.cache_dir);
    let pb = spinner(show, "loading the cell");
    let cell = load_cell(&args.cell, &opts)?;
    pb.set_message(format!(
        "finding candidates for {} tasks × {} robots",
        cell.tasks.len(),
        cell.robots.len()
    ));
    let table = candidates::generate(&cell);
    pb.finish_and_clear();
    if let Some(e) = check::idle_robot_error(&cell, &table).or_else(|| check::cap_error(&cell, &table)) {
        return Err(e.into());
    }
    let report = check::report(&cell, &table);
    cell.save_cache();
    if let Some(path) = &args.svg {
        let drawing = svg::render(&cell, Some(&table));
        write_atomic(path, drawing.as_bytes())
            .map_err(|e| Failure::Other(format!("cannot write {}: {e}", path.display())))?;
    }
    if let Some(path) = &args.minmax_out {
        let note = write_allocation_problem(&cell, &table, path)?;
        if !args.quiet {
            eprintln!("{note}");
        }
    }
    if args.json {
        let text = serde_json::to_string_pretty(&report).map_err(|e| Failure::Other(e.to_string()))?;
        println!("{text}");
    } else {
        print!("{}", check::render_text(&cell, &table, &report));
        let _ = std::io::Write::flush(&mut std::io::stdout());
        if !args.quiet {
            eprintln!("checked in {:.2} s", start.elapsed().as_secs_f64());
        }
    }
    if report.unmeasurable.is_empty() {
        Ok(())
    } else {
        Err(Failure::Infeasible)
    }
}

/// Writes `cell`'s allocation problem ([`cellplan_core::plan::allocation_problem`], with the
/// default planning settings) to `path` in the min-max format; says what it wrote.
fn write_allocation_problem(
    cell: &Cell,
    table: &candidates::CandidateTable,
    path: &std::path::Path,
) -> Result<String, Failure> {
    let settings = cellplan_core::plan::PlanSettings::default();
    let (problem, tasks) = cellplan_core::plan::allocation_problem(cell, table, &settings)
        .map_err(|e| Failure::Other(e.to_string()))?;
    // The matrices are dense: a large cell's would pass what the reader takes (and fill the
    // memory first), so writing stops there.
    let mut out = Capped {
        buf: Vec::new(),
        cap: cellplan_solve::io::MAX_FILE_BYTES as usize,
    };
    if cellplan_solve::io::write_minmax(&problem, &cell.name, &mut out).is_err() {
        let largest = problem.vehicles.iter().map(|v| v.costs.n()).max().unwrap_or(0);
        return Err(Failure::Usage(format!(
            "the allocation problem of {} passes the {} MiB a min-max file may hold (its matrices are dense; the largest robot has {largest} nodes): nothing written to {}; write it for a smaller task list",
            cell.path.display(),
            cellplan_solve::io::MAX_FILE_BYTES >> 20,
            path.display()
        )));
    }
    write_atomic(path, &out.buf)
        .map_err(|e| Failure::Other(format!("cannot write {}: {e}", path.display())))?;
    let nodes: usize = problem.vehicles.iter().map(|v| v.costs.n()).sum();
    Ok(format!(
        "wrote {}: {} robots, {} of the cell's {} MPs as tasks 0..{} (those some robot can measure, in the cell's order), {nodes} nodes in all; lower bound {:.2} s",
        path.display(),
        problem.vehicles.len(),
        tasks.len(),
        cell.tasks.len(),
        tasks.len().saturating_sub(1),
        cellplan_solve::minmax::lower_bound(&problem)
    ))
}

/// A byte buffer that refuses to grow past `cap` (the write fails instead).
pub(crate) struct Capped {
    pub(crate) buf: Vec<u8>,
    pub(crate) cap: usize,
}

impl std::io::Write for Capped {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        if self.buf.len() + bytes.len() > self.cap {
            return Err(std::io::Error::other("past the cap"));
        }
        self.buf.extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn run_gen_tasks(args: &GenTasksArgs) -> Result<(), Failure> {
    let mesh = load_mesh(&args.mesh).map_err(|e| match e {
        cellplan_geom::MeshError::Parse { path, line, message } => {
            InputError::at_line(&path, line, message).hint("fix or re-export the mesh (STL or OBJ)")
        }
        other => InputError::new(&args.mesh, other.to_string()).hint("give an STL or OBJ file"),
    })?;
    if args.count == 0 || args.count > MAX_GENERATED_TASKS {
        return Err(Failure::Usage(format!(
            "--count must be between 1 and {MAX_GENERATED_TASKS}, not {}",
            args.count
        )));
    }
    if !(args.max_angle.is_finite() && (0.0..=180.0).contains(&args.max_angle)) {
        return Err(Failure::Usage(format!(
            "--max-angle must be between 0 and 180 degrees, not {}",
            cellplan_model::shown(args.max_angle)
        )));
    }
    if let Some(t) = args.translate
        && t.abs().max_element() > MAX_TRANSLATE
    {
        return Err(Failure::Usage(format!(
            "--translate {},{},{} is beyond {} (mesh units: 10 km in mm)",
            cellplan_model::shown(t.x),
            cellplan_model::shown(t.y),
            cellplan_model::shown(t.z),
            cellplan_model::shown(MAX_TRANSLATE)
        )));
    }
    if let Some(path) = &args.out {
        ensure_file_target(path, "-o")?;
    }
    let mut opts = GenOptions::new(args.count, args.seed);
    for &(axis, lo, hi) in &args.region {
        opts.region[axis] = (lo, hi);
    }
    opts.facing = args.facing.map(|d| (d, args.max_angle.to_radians()));
    let mut tasks = sample_tasks(&mesh, &opts).map_err(|e| {
        InputError::new(&args.mesh, e.to_string())
            .hint("widen `--region`, loosen `--facing`/`--max-angle`, or ask for fewer points")
    })?;
    if let Some(offset) = args.translate {
        tasks.iter_mut().for_each(|t| t.position += offset);
    }
    let text = cellplan_model::tasks::tasks_to_csv(&tasks, 1.0, 1.0, &[]);
    match &args.out {
        Some(path) => write_atomic(path, text.as_bytes())
            .map_err(|e| Failure::Other(format!("cannot write {}: {e}", path.display())))?,
        None => print!("{text}"),
    }
    Ok(())
}

fn run_gen_block(args: &GenBlockArgs, housing: bool) -> Result<(), Failure> {
    if !(8..=720).contains(&args.segments) {
        return Err(Failure::Usage(format!(
            "--segments must be between 8 and 720, not {}",
            args.segments
        )));
    }
    let (mesh, mps, faces, what, name): (_, _, &[&str], _, _) = if housing {
        let spec = cellplan_cmm::housing::HousingSpec {
            segments: args.segments,
            ..Default::default()
        };
        let (mesh, mps) = cellplan_cmm::housing::housing(&spec);
        (
            mesh,
            mps,
            &cellplan_cmm::housing::HOUSING_FACES,
            "a gearbox-housing-like casting, mm (crates/cellplan-cmm/src/housing.rs documents it)",
            "housing",
        )
    } else {
        let spec = cellplan_cmm::part::BlockSpec {
            segments: args.segments,
            ..Default::default()
        };
        let (mesh, mps) = cellplan_cmm::part::cylinder_block(&spec);
        (
            mesh,
            mps,
            &cellplan_cmm::part::BLOCK_FACES,
            "paper 003's kind of cylinder block, mm (crates/cellplan-cmm/src/part.rs documents it)",
            "block",
        )
    };
    let obj = cellplan_cmm::part::to_obj(
        &mesh,
        &format!("cellplan gen {name} --segments {}: {what}", args.segments),
    );
    let csv = cellplan_cmm::part::to_csv(&mps, faces);
    let (a, b) = (args.out.join(format!("{name}.obj")), args.out.join("tasks.csv"));
    write_all_atomic(&[(&a, obj.as_bytes()), (&b, csv.as_bytes())])
        .map_err(|e| Failure::Other(format!("cannot write into {}: {e}", args.out.display())))?;
    eprintln!(
        "{}: {} triangles; {}: {} measuring points",
        a.display(),
        mesh.triangles.len(),
        b.display(),
        mps.len()
    );
    Ok(())
}

fn run_bench(args: &bench::BenchArgs) -> Result<(), Failure> {
    if args.kind == bench::Kind::Motion {
        return run_bench_motion(args);
    }
    if args.kind == bench::Kind::CmmLocal {
        let [cell] = args.files.as_slice() else {
            return Err(Failure::Usage("cmm-local takes one CMM cell file".into()));
        };
        return cmm_cmd::bench_local(cell, args.max_samples);
    }
    let failure = |e| match e {
        bench::BenchError::Input(e) => Failure::Input(Box::new(
            InputError::at_line(e.path(), e.line(), e.detail()).hint(
                "give TSPLIB (.tsp), GTSPLIB (.gtsp), OR-Library set-cover or cellplan min-max \
                 (docs/minmax-format.md) files of the kind named",
            ),
        )),
        bench::BenchError::Usage(m) => Failure::Usage(m),
        bench::BenchError::Failed(m) => Failure::Other(m),
    };
    if args.generate {
        eprintln!("{}", bench::generate(args).map_err(failure)?);
        return Ok(());
    }
    let rows = bench::run(args).map_err(failure)?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).map_err(|e| Failure::Other(e.to_string()))?
        );
    } else {
        print!("{}", bench::render(&rows));
    }
    Ok(())
}

/// `cellplan bench motion`: plan (or re-check a peer's run, or time single checks) and print.
fn run_bench_motion(args: &bench::BenchArgs) -> Result<(), Failure> {
    let problem_failure = |e: cellplan_motion::problem::ProblemError| {
        let hint = e.hint().to_string();
        let (path, line) = match &e {
            cellplan_motion::problem::ProblemError::Json { path, line, .. } => (path.clone(), Some(*line)),
            cellplan_motion::problem::ProblemError::Io { path, .. }
            | cellplan_motion::problem::ProblemError::Invalid { path, .. } => (path.clone(), None),
            cellplan_motion::problem::ProblemError::Robot(_) => (PathBuf::from("robot"), None),
        };
        let err = match line {
            Some(l) => InputError::at_line(&path, Some(l), e.to_string()),
            None => InputError::new(&path, e.to_string()),
        };
        Failure::Input(Box::new(err.hint(hint)))
    };
    if let Err(e) = cellplan_motion::plan::planner(&args.planner) {
        return Err(Failure::Usage(e.to_string()));
    }
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !positive(args.time_limit) || !positive(args.exact_step_mm) {
        return Err(Failure::Usage(
            "--time-limit and --exact-step-mm must be positive".into(),
        ));
    }
    if let Some(n) = args.checks {
        let rows = bench_motion::time_checks(&args.files, n, args.first).map_err(problem_failure)?;
        return print_json(&rows);
    }
    let step = args.exact_step_mm * 1e-3;
    let mut rows = match &args.recheck {
        Some(run) => bench_motion::recheck(&args.files, run, step).map_err(|e| match e {
            bench_motion::RecheckError::Problem(e) => problem_failure(e),
            bench_motion::RecheckError::Run { path, line, message } => Failure::Input(Box::new(
                InputError::at_line(&path, line, message).hint(
                    "give a JSON list of {problem, planner, solved, time_s, path_length, validity_checks, path}, \
                     as bench/peers/motion_vamp.py and motion_ompl.py write it",
                ),
            )),
        })?,
        None => bench_motion::run(&bench_motion::Request {
            files: &args.files,
            planner: &args.planner,
            time_limit: args.time_limit,
            max_samples: args.max_samples,
            runs: args.runs,
            first: args.first,
            exact_step: (!args.no_exact).then_some(step),
            simplify: !args.no_simplify,
        })
        .map_err(problem_failure)?,
    };
    if !args.with_paths {
        rows.iter_mut().for_each(|r| r.path = None);
    }
    if args.json {
        print_json(&rows)
    } else {
        print!("{}", bench_motion::render(&rows));
        Ok(())
    }
}

/// How every `compare` ends: `compare.json` (the JSON `text`), `compare.md` (the markdown
/// `table`) and the `extra` files (named within the folder; made only when there is one)
/// written all or nothing into `output`, then `text` (with `json`) or `table` printed.
fn finish_compare(
    output: Option<&std::path::Path>,
    json: bool,
    text: &str,
    table: &str,
    extra: impl FnOnce() -> Vec<(&'static str, String)>,
) -> Result<(), Failure> {
    if let Some(dir) = output {
        let extra = extra();
        let mut files = vec![
            (dir.join("compare.json"), text.as_bytes()),
            (dir.join("compare.md"), table.as_bytes()),
        ];
        files.extend(extra.iter().map(|(name, body)| (dir.join(name), body.as_bytes())));
        let files: Vec<(&std::path::Path, &[u8])> = files.iter().map(|(p, b)| (p.as_path(), *b)).collect();
        cellplan_model::io::write_all_atomic(&files)
            .map_err(|e| Failure::Other(format!("cannot write into {}: {e}", dir.display())))?;
    }
    if json {
        println!("{text}");
    } else {
        print!("{table}");
    }
    Ok(())
}

/// Prints `value` as pretty JSON.
fn print_json<T: serde::Serialize>(value: &T) -> Result<(), Failure> {
    println!(
        "{}",
        serde_json::to_string_pretty(value).map_err(|e| Failure::Other(e.to_string()))?
    );
    Ok(())
}

/// Most worker threads `--threads` takes: a machine with more cores than this gains nothing
/// from more, and a pool of a hundred thousand threads takes minutes to start.
const MAX_THREADS: i64 = 1024;

fn main() -> ExitCode {
    // Long messages stay on one line, so that they can be searched for.
    let _ = miette::set_hook(Box::new(|_| {
        Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())
    }));
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(usize::from(n))
            .build_global();
    }
    let result = match &cli.command {
        Command::Check(a) => run_check(a),
        Command::Plan(a) => plan_cmd::run(a),
        Command::Verify(a) => verify_cmd::run(a),
        Command::Reuse(a) => cmm_cmd::run_reuse(a),
        Command::Compare(a) => compare_cmd::run(a),
        Command::Report(a) => report_cmd::run_report(a),
        Command::Export(a) => report_cmd::run_export(a),
        Command::Gen(GenCommand::Tasks(a)) => run_gen_tasks(a),
        Command::Gen(GenCommand::Block(a)) => run_gen_block(a, false),
        Command::Gen(GenCommand::Housing(a)) => run_gen_block(a, true),
        Command::Bench(a) => run_bench(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("{:?}", miette::Report::new(*e));
            ExitCode::from(2)
        }
        Err(Failure::Usage(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(Failure::Infeasible) => ExitCode::from(3),
        Err(Failure::Rejected) => ExitCode::from(4),
        Err(Failure::Other(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
    }
}
