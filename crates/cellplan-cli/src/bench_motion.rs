//! `cellplan bench motion SCENE...`: the motion core on planning problems without a cell
//! (docs/motion-problems.md), OMPL's benchmark shape: a request (planner, time limit, runs,
//! seeds), one row per problem and run — solved, time, path length, validity checks — and an
//! exact re-check of every path on the robot's collision meshes as given
//! ([`cellplan_verify::motion`]). `--recheck RUN.json` re-checks a peer's paths instead
//! (bench/peers/motion_*.py write them), and `--checks N` times single validity checks.
use cellplan_motion::arm;
use cellplan_motion::plan::{self, PlannerParams, Status, Termination};
use cellplan_motion::problem::{ArmSetup, ProblemError, ProblemSet, read_problems};
use cellplan_verify::motion::{ExactObstacle, ExactRobot};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// What the motion benchmark is asked.
pub struct Request<'a> {
    /// Problem files.
    pub files: &'a [PathBuf],
    /// Planner name.
    pub planner: &'a str,
    /// Wall-clock safety net per query (s); the work budget binds first.
    pub time_limit: f64,
    /// Work budget per query: random samples.
    pub max_samples: usize,
    /// Runs per problem (seeds 0, 1, …).
    pub runs: u64,
    /// Only the first problems of each file.
    pub first: Option<usize>,
    /// Largest point motion between two samples of the exact re-check (m); `None`: no re-check.
    pub exact_step: Option<f64>,
    /// Post-process found paths ([`PlannerParams::simplify`]).
    pub simplify: bool,
}

/// One problem × run.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct Row {
    /// Problem name.
    pub problem: String,
    /// Planner name.
    pub planner: String,
    /// Seed of the run.
    pub seed: u64,
    /// Whether a path was found.
    pub solved: bool,
    /// Why not, or `solved`.
    pub status: String,
    /// Wall time of the query (s).
    pub time_s: f64,
    /// Path length: Euclidean in joint space (rad), as OMPL and VAMP state it.
    pub path_length: Option<f64>,
    /// Waypoints of the path.
    pub waypoints: usize,
    /// Validity checks (clearance evaluations) made.
    pub validity_checks: usize,
    /// Of those, the checks of the path's simplification.
    #[serde(default)]
    pub simplify_checks: usize,
    /// Of the query's time, the simplification's (s).
    #[serde(default)]
    pub simplify_time_s: f64,
    /// The exact re-check passed (`false` when there is no path).
    pub exact_valid: bool,
    /// Configurations the exact re-check tested.
    pub exact_samples: usize,
    /// The exact re-check's first contact.
    pub exact_contact: Option<String>,
    /// The path, in the file's joint order.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub path: Option<Vec<Vec<f64>>>,
}

/// A peer's row as bench/peers/motion_*.py write them.
#[derive(Deserialize)]
struct PeerRow {
    problem: String,
    planner: String,
    solved: bool,
    #[serde(default)]
    time_s: Option<f64>,
    #[serde(default)]
    path_length: Option<f64>,
    #[serde(default)]
    validity_checks: Option<usize>,
    #[serde(default)]
    path: Option<Vec<Vec<f64>>>,
}

fn euclidean_length(path: &[Vec<f64>]) -> f64 {
    path.windows(2)
        .map(|w| {
            w[0].iter()
                .zip(&w[1])
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt()
        })
        .sum()
}

/// The status as a kebab-case word.
fn status_name(status: Status) -> &'static str {
    match status {
        Status::Solved => "solved",
        Status::Approximate => "approximate",
        Status::Timeout => "timeout",
        Status::BudgetExhausted => "budget-exhausted",
        Status::InvalidStart => "invalid-start",
        Status::InvalidGoal => "invalid-goal",
        Status::Infeasible => "infeasible",
    }
}

/// Loads a file and its robot.
pub fn load(file: &Path) -> Result<(ProblemSet, ArmSetup), ProblemError> {
    let set = read_problems(file)?;
    let setup = ArmSetup::load(&set)?;
    Ok((set, setup))
}

/// Runs the request: every problem of every file, `runs` times, sequentially (so that times are
/// single-core times), then the exact re-checks in parallel.
pub fn run(req: &Request) -> Result<Vec<Row>, ProblemError> {
    let mut rows = Vec::new();
    for file in req.files {
        let (set, mut setup) = load(file)?;
        let problems = &set.problems[..req.first.unwrap_or(usize::MAX).min(set.problems.len())];
        let velocities: Vec<f64> = setup.model.chain.joints.iter().map(|j| j.max_velocity).collect();
        let mut file_rows = Vec::new();
        for problem in problems {
            setup.set_obstacles(&problem.obstacles);
            let validity = setup.validity(problem.margin);
            let space = arm::joint_space(&setup.arm(), &velocities);
            let start = setup.to_chain(&problem.start);
            let goals: Vec<Vec<f64>> = problem.goals.iter().map(|g| setup.to_chain(g)).collect();
            let entry = plan::planner(req.planner).map_err(|e| ProblemError::Invalid {
                path: file.clone(),
                message: e.to_string(),
                hint: "name a planner of the registry".into(),
            })?;
            for seed in 0..req.runs {
                let params = PlannerParams {
                    seed,
                    simplify: req.simplify,
                    ..PlannerParams::default()
                };
                let stop = Termination::samples(req.max_samples)
                    .with_time_limit(Duration::from_secs_f64(req.time_limit));
                let query = plan::Problem::new(&space, &validity, &start, &goals);
                let began = Instant::now();
                let result = (entry.build)(&params).solve(&query, &stop);
                let time_s = began.elapsed().as_secs_f64();
                let status = status_name(result.status).to_string();
                let checks = result.work.validity_calls;
                let simplify_checks = result.work.simplify_calls;
                let path = result.status.is_solved().then_some(result.waypoints);
                let file_path = path.map(|p| p.iter().map(|q| setup.to_file(q)).collect::<Vec<_>>());
                let solved = file_path.is_some();
                file_rows.push(Row {
                    problem: problem.name.clone(),
                    planner: req.planner.to_string(),
                    seed,
                    solved,
                    status,
                    time_s,
                    path_length: file_path.as_deref().map(euclidean_length),
                    waypoints: file_path.as_ref().map_or(0, Vec::len),
                    validity_checks: checks,
                    simplify_checks,
                    simplify_time_s: result.work.simplify_time.as_secs_f64(),
                    exact_valid: false,
                    exact_samples: 0,
                    exact_contact: None,
                    path: file_path,
                });
            }
        }
        if let Some(step) = req.exact_step {
            recheck_rows(&set, &setup, &mut file_rows, step);
        }
        rows.extend(file_rows);
    }
    Ok(rows)
}

/// Fills the exact re-check of every row with a path (rows name their problems).
fn recheck_rows(set: &ProblemSet, setup: &ArmSetup, rows: &mut [Row], step: f64) {
    // One exact robot (its meshes and their hulls) for every row.
    let robot = ExactRobot::new(&setup.model, setup.base, &setup.link_pairs());
    rows.par_iter_mut().for_each(|row| {
        let (Some(problem), Some(path)) = (
            set.problems.iter().find(|p| p.name == row.problem),
            row.path.as_ref(),
        ) else {
            return;
        };
        let obstacles: Vec<ExactObstacle> = problem
            .obstacles
            .iter()
            .filter_map(|o| ExactObstacle::new(&o.name, &o.shape, o.pose))
            .collect();
        let chain_path: Vec<Vec<f64>> = path.iter().map(|q| setup.to_chain(q)).collect();
        let check = robot.check_path(&chain_path, &obstacles, problem.margin, step);
        row.exact_valid = check.valid;
        row.exact_samples = check.samples;
        row.exact_contact = check
            .contact
            .map(|(seg, t, what)| format!("segment {seg} at {t:.4}: {what}"));
    });
}

/// Why a peer's run could not be re-checked: a problem file, or the run file itself.
#[derive(Debug)]
pub enum RecheckError {
    /// A problem file could not be read or set up.
    Problem(ProblemError),
    /// The run file could not be read, or is not a run (`line`: where, when known).
    Run {
        path: PathBuf,
        line: Option<usize>,
        message: String,
    },
}

/// Re-checks a peer's run file (`[{problem, planner, solved, time_s, path_length,
/// validity_checks, path}]`) against the problems of `files`.
pub fn recheck(files: &[PathBuf], run_file: &Path, step: f64) -> Result<Vec<Row>, RecheckError> {
    use cellplan_geom::read::{LimitedReadError, read_limited, show_bytes, utf8_text};
    let limit = cellplan_motion::problem::MAX_FILE_BYTES;
    let run = |line: Option<usize>, message: String| RecheckError::Run {
        path: run_file.to_path_buf(),
        line,
        message,
    };
    let bytes = read_limited(run_file, limit).map_err(|e| match e {
        LimitedReadError::Io(e) => run(None, format!("cannot read it: {e}")),
        LimitedReadError::TooLarge { size } => run(
            None,
            format!(
                "it is {size}, larger than the {} a run file may have",
                show_bytes(limit)
            ),
        ),
    })?;
    let text =
        utf8_text(bytes).map_err(|e| run(Some(e.line), format!("byte {} is not UTF-8 text", e.offset)))?;
    let peers: Vec<PeerRow> = serde_json::from_str(&text).map_err(|e| run(Some(e.line()), e.to_string()))?;
    let mut rows = Vec::new();
    for file in files {
        let (set, setup) = load(file).map_err(RecheckError::Problem)?;
        let mut file_rows: Vec<Row> = peers
            .iter()
            .filter(|p| set.problems.iter().any(|q| q.name == p.problem))
            .map(|p| Row {
                problem: p.problem.clone(),
                planner: p.planner.clone(),
                seed: 0,
                solved: p.solved && p.path.is_some(),
                status: if p.solved {
                    "solved".into()
                } else {
                    "unsolved".into()
                },
                time_s: p.time_s.unwrap_or(f64::NAN),
                path_length: p.path_length,
                waypoints: p.path.as_ref().map_or(0, Vec::len),
                validity_checks: p.validity_checks.unwrap_or(0),
                simplify_checks: 0,
                simplify_time_s: 0.0,
                exact_valid: false,
                exact_samples: 0,
                exact_contact: None,
                path: p.path.clone(),
            })
            .collect();
        recheck_rows(&set, &setup, &mut file_rows, step);
        rows.extend(file_rows);
    }
    Ok(rows)
}

/// The timing of single validity checks in one file's scenes.
#[derive(Serialize, Debug)]
pub struct CheckRow {
    /// Scene (file) name.
    pub scene: String,
    /// Configurations timed (random, within the limits, over the file's problems).
    pub configurations: usize,
    /// Share of them valid.
    pub valid_share: f64,
    /// Median time of one check with the sphere-cover broad phase (µs): each configuration
    /// checked 8 times in a row, timed together (the checker's hint is warm after the first).
    pub median_us: f64,
    /// Median time of a configuration's first check, timed alone (µs), the configurations
    /// checked once each in turn: the hint the checker keeps (the part asked first) comes from
    /// the configuration before, as for a sampler's independent samples.
    pub median_once_us: f64,
    /// Median time of one check with exact distances only (µs).
    pub median_exact_only_us: f64,
    /// Median time with the broad phase over the valid configurations only (µs): a valid
    /// configuration proves every part, an invalid one stops at the first that fails.
    pub median_valid_us: f64,
    /// The same over the invalid configurations (µs).
    pub median_invalid_us: f64,
    /// Checks where the answers differ (with and without the broad phase, first and later
    /// checks; must be 0).
    pub disagreements: usize,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Times `per_problem` random valid-or-not configurations per problem, each checked with and
/// without the broad phase (single thread).
pub fn time_checks(
    files: &[PathBuf],
    per_problem: usize,
    first: Option<usize>,
) -> Result<Vec<CheckRow>, ProblemError> {
    let mut out = Vec::new();
    for file in files {
        let (set, mut setup) = load(file)?;
        let problems = &set.problems[..first.unwrap_or(usize::MAX).min(set.problems.len())];
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let (mut with, mut without, mut once) = (Vec::new(), Vec::new(), Vec::new());
        let (mut with_valid, mut with_invalid) = (Vec::new(), Vec::new());
        let (mut valid, mut disagree) = (0, 0);
        for problem in problems {
            setup.set_obstacles(&problem.obstacles);
            let fast = setup.validity(problem.margin);
            let mut exact = setup.validity(problem.margin);
            exact.broad_phase = false;
            let chain = &setup.model.chain;
            let configs: Vec<Vec<f64>> = (0..per_problem)
                .map(|_| {
                    chain
                        .joints
                        .iter()
                        .map(|j| rng.random_range(j.lower..=j.upper))
                        .collect()
                })
                .collect();
            // One check of each configuration in turn, each timed alone (a sampler's stream).
            let firsts: Vec<bool> = configs
                .iter()
                .map(|q| {
                    let t = Instant::now();
                    let first = std::hint::black_box(fast.is_valid(std::hint::black_box(q)));
                    once.push(t.elapsed().as_secs_f64() * 1e6);
                    first
                })
                .collect();
            for (q, &first) in configs.iter().zip(&firsts) {
                // Each timed alone, a batch of 8 for the clock's resolution.
                let t = Instant::now();
                let mut a = false;
                for _ in 0..8 {
                    a = std::hint::black_box(fast.is_valid(std::hint::black_box(q)));
                }
                let us = t.elapsed().as_secs_f64() * 1e6 / 8.0;
                with.push(us);
                if a {
                    with_valid.push(us);
                } else {
                    with_invalid.push(us);
                }
                let t = Instant::now();
                let mut b = false;
                for _ in 0..8 {
                    b = std::hint::black_box(exact.is_valid(std::hint::black_box(q)));
                }
                without.push(t.elapsed().as_secs_f64() * 1e6 / 8.0);
                valid += usize::from(a);
                disagree += usize::from(a != b || a != first);
            }
        }
        let n = with.len();
        out.push(CheckRow {
            scene: set.scene.clone(),
            configurations: n,
            valid_share: valid as f64 / n.max(1) as f64,
            median_us: median(with),
            median_once_us: median(once),
            median_exact_only_us: median(without),
            median_valid_us: median(with_valid),
            median_invalid_us: median(with_invalid),
            disagreements: disagree,
        });
    }
    Ok(out)
}

/// A plain-text table of rows, per scene: solved, median time, exact failures.
pub fn render(rows: &[Row]) -> String {
    let mut scenes: Vec<String> = rows
        .iter()
        .map(|r| r.problem.split('/').next().unwrap_or("").to_string())
        .collect();
    scenes.dedup();
    let mut out = format!(
        "{:<20} {:>8} {:>8} {:>12} {:>10} {:>14}\n",
        "scene", "queries", "solved", "median_ms", "checks", "exact_invalid"
    );
    for scene in scenes {
        let of: Vec<&Row> = rows
            .iter()
            .filter(|r| r.problem.starts_with(&format!("{scene}/")))
            .collect();
        let solved: Vec<&&Row> = of.iter().filter(|r| r.solved).collect();
        let ms = median(solved.iter().map(|r| r.time_s * 1e3).collect());
        let checks = median(solved.iter().map(|r| r.validity_checks as f64).collect());
        let bad = solved.iter().filter(|r| !r.exact_valid).count();
        out += &format!(
            "{:<20} {:>8} {:>8} {:>12.3} {:>10.0} {:>14}\n",
            scene,
            of.len(),
            solved.len(),
            ms,
            checks,
            bad
        );
    }
    out
}
