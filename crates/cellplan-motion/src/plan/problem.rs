//! What a planner is asked and what it answers: the query ([`Problem`]: one start, one or
//! more goals), when to stop ([`Termination`]), and the outcome ([`PlanResult`] with a
//! [`Status`] and the [`Work`] spent). Also the bookkeeping every planner shares: counting
//! samples and validity calls against the budget, checking the ends, post-processing.
use super::validity::{DIRECT_PROBES, MAX_PROBES};
use super::{JointSpace, PlannerParams, StateValidity, segment_valid, shortcut_with};
use rand_chacha::ChaCha8Rng;
use std::time::{Duration, Instant};

/// A planning query in one static scene: a space, a validity checker, one start and one or
/// more goal configurations. A path may end at any goal.
#[derive(Clone, Copy)]
pub struct Problem<'a> {
    /// The joint space (limits, motion bound, metric).
    pub space: &'a JointSpace,
    /// The validity checker (a clearance, see [`StateValidity`]).
    pub validity: &'a dyn StateValidity,
    /// Where the path starts.
    pub start: &'a [f64],
    /// Where it may end; invalid goals are skipped when at least one is valid.
    pub goals: &'a [Vec<f64>],
    /// Clearances below this (m) count as contact, so that checks end (clamped to at least
    /// 1e-9).
    pub min_clearance: f64,
}

impl<'a> Problem<'a> {
    /// A query from `start` to any of `goals`, with the default `min_clearance` of
    /// [`super::PlanSettings`] (1e-4 m).
    pub fn new(
        space: &'a JointSpace,
        validity: &'a dyn StateValidity,
        start: &'a [f64],
        goals: &'a [Vec<f64>],
    ) -> Self {
        Problem {
            space,
            validity,
            start,
            goals,
            min_clearance: 1e-4,
        }
    }

    /// The same query with another contact threshold (m).
    pub fn with_min_clearance(mut self, min_clearance: f64) -> Self {
        self.min_clearance = min_clearance;
        self
    }

    pub(crate) fn floor(&self) -> f64 {
        self.min_clearance.max(1e-9)
    }
}

/// When a planner stops: a work budget, which makes runs reproducible (same seed, same
/// budget, same path on any machine), and an optional wall-clock limit as a safety net (when
/// it binds, [`Work::clock_bound`] says so and the run may not be reproducible).
///
/// The budget is checked between segment checks: the validity calls may pass
/// `max_validity_calls` by the calls of one segment check. Checking the ends of the query
/// and post-processing a found path are never cut short (the latter is bounded by
/// [`PlannerParams::shortcut_iterations`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Termination {
    /// Most random samples drawn.
    pub max_samples: usize,
    /// Most calls of the validity checker during the search.
    pub max_validity_calls: usize,
    /// Wall-clock limit of the search, if any.
    pub time_limit: Option<Duration>,
}

impl Default for Termination {
    /// 20 000 samples, no limit on validity calls, no wall clock.
    fn default() -> Self {
        Termination {
            max_samples: 20_000,
            max_validity_calls: usize::MAX,
            time_limit: None,
        }
    }
}

impl Termination {
    /// A budget of `max_samples` samples and nothing else.
    pub fn samples(max_samples: usize) -> Self {
        Termination {
            max_samples,
            ..Termination::default()
        }
    }

    /// The same with a wall-clock limit.
    pub fn with_time_limit(mut self, limit: Duration) -> Self {
        self.time_limit = Some(limit);
        self
    }

    /// The same with a limit on validity calls.
    pub fn with_max_validity_calls(mut self, calls: usize) -> Self {
        self.max_validity_calls = calls;
        self
    }
}

/// How a planning run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// A path from the start to a goal ([`PlanResult::goal`]).
    Solved,
    /// A partial path from the start towards a goal, not reaching it (only planners that can
    /// give one, when asked: [`PlannerParams::approximate`]).
    Approximate,
    /// No path: the wall-clock limit stopped the search.
    Timeout,
    /// No path: the work budget (samples or validity calls) ran out.
    BudgetExhausted,
    /// The start is outside the space or invalid.
    InvalidStart,
    /// Every goal is outside the space or invalid.
    InvalidGoal,
    /// No path, provably for this planner (the straight-only planner found every direct
    /// segment blocked).
    Infeasible,
}

impl Status {
    /// Whether the result has a path that reaches a goal.
    pub fn is_solved(self) -> bool {
        self == Status::Solved
    }
}

/// The work and time a run spent.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Work {
    /// Random samples drawn.
    pub samples: usize,
    /// Calls of the validity checker: ends, search and post-processing.
    pub validity_calls: usize,
    /// Of these, the calls made by post-processing.
    pub simplify_calls: usize,
    /// Wall time of the whole run.
    pub wall_time: Duration,
    /// Wall time of the search (ends included).
    pub search_time: Duration,
    /// Wall time of the post-processing.
    pub simplify_time: Duration,
    /// Whether the wall-clock limit ended the search (the result may then depend on the
    /// machine's speed).
    pub clock_bound: bool,
}

/// The outcome of a planning run.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanResult {
    /// How it ended.
    pub status: Status,
    /// The path (straight segments between waypoints, each passing
    /// [`super::check_segment`]), from the start to the goal [`PlanResult::goal`]; empty
    /// unless the status is [`Status::Solved`] or [`Status::Approximate`] (an approximate
    /// path ends short of the goal and may be the start alone).
    pub waypoints: Vec<Vec<f64>>,
    /// Index in [`Problem::goals`] of the goal reached (or approached, when approximate).
    pub goal: Option<usize>,
    /// Whether the path is the direct segment (two waypoints, no search).
    pub straight: bool,
    /// Clearance of the start where it is invalid (below the floor; negative infinity outside
    /// the joint limits); NaN where it is valid: the ends are tested against the floor, and
    /// measured only where they fail it.
    pub start_clearance: f64,
    /// Clearance of each invalid goal, as the start's; NaN for a valid goal, and for every goal
    /// when the start is invalid (not tested).
    pub goal_clearances: Vec<f64>,
    /// The work and time spent.
    pub work: Work,
}

impl PlanResult {
    /// Length of the path in the space's metric (0 without a path).
    pub fn length(&self, space: &JointSpace) -> f64 {
        super::path_length(space, &self.waypoints)
    }
}

/// What a search found (before post-processing).
pub(crate) struct Found {
    pub status: Status,
    pub waypoints: Vec<Vec<f64>>,
    pub goal: Option<usize>,
    pub straight: bool,
}

impl Found {
    /// No path, for `status`.
    pub fn none(status: Status) -> Self {
        Found {
            status,
            waypoints: Vec::new(),
            goal: None,
            straight: false,
        }
    }

    /// A path to goal `goal`.
    pub fn path(waypoints: Vec<Vec<f64>>, goal: usize) -> Self {
        Found {
            status: Status::Solved,
            waypoints,
            goal: Some(goal),
            straight: false,
        }
    }
}

/// The state of one run: what it may spend and has spent.
pub(crate) struct Run<'a> {
    pub space: &'a JointSpace,
    pub validity: &'a dyn StateValidity,
    pub floor: f64,
    stop: &'a Termination,
    began: Instant,
    pub samples: usize,
    pub calls: usize,
    pub clock_bound: bool,
}

impl<'a> Run<'a> {
    pub fn new(problem: &Problem<'a>, stop: &'a Termination) -> Self {
        Run {
            space: problem.space,
            validity: problem.validity,
            floor: problem.floor(),
            stop,
            began: Instant::now(),
            samples: 0,
            calls: 0,
            clock_bound: false,
        }
    }

    /// Whether the straight segment `a → b` is proven valid (counts its calls).
    pub fn segment(&mut self, a: &[f64], b: &[f64]) -> bool {
        self.segment_probed(a, b, MAX_PROBES)
    }

    /// [`Run::segment`] for a query's direct segment, start to goal, probed more densely
    /// ([`DIRECT_PROBES`]): the same answer.
    pub fn direct_segment(&mut self, a: &[f64], b: &[f64]) -> bool {
        self.segment_probed(a, b, DIRECT_PROBES)
    }

    /// [`Run::segment`] with at most `max_probes` probes.
    fn segment_probed(&mut self, a: &[f64], b: &[f64], max_probes: usize) -> bool {
        segment_valid(
            self.space,
            self.validity,
            (a, b),
            self.floor,
            max_probes,
            &mut self.calls,
        )
    }

    /// The clearance of `q`, negative infinity outside the space (one call inside): the
    /// report of a state [`Run::state_valid`] has failed.
    pub fn measure(&mut self, q: &[f64]) -> f64 {
        if self.space.contains(q) {
            self.calls += 1;
            self.validity.clearance(q)
        } else {
            f64::NEG_INFINITY
        }
    }

    /// Whether `q` is in the space and its clearance reaches the floor (one call inside).
    pub fn state_valid(&mut self, q: &[f64]) -> bool {
        if !self.space.contains(q) {
            return false;
        }
        self.calls += 1;
        self.validity.clear_of(q, self.floor)
    }

    /// Why the search must stop now, ignoring the sample budget (validity calls, clock).
    pub fn must_stop(&mut self) -> Option<Status> {
        if self.calls >= self.stop.max_validity_calls {
            return Some(Status::BudgetExhausted);
        }
        if let Some(limit) = self.stop.time_limit
            && self.began.elapsed() >= limit
        {
            self.clock_bound = true;
            return Some(Status::Timeout);
        }
        None
    }

    /// Draws one more sample into `out`, or says why not.
    pub fn sample(&mut self, rng: &mut ChaCha8Rng, out: &mut Vec<f64>) -> Result<(), Status> {
        if self.samples >= self.stop.max_samples {
            return Err(Status::BudgetExhausted);
        }
        if let Some(why) = self.must_stop() {
            return Err(why);
        }
        self.samples += 1;
        self.space.sample(rng, out);
        Ok(())
    }

    /// Counts a sample drawn by the planner itself (say a goal-biased one), or says why not.
    pub fn count_sample(&mut self) -> Result<(), Status> {
        if self.samples >= self.stop.max_samples {
            return Err(Status::BudgetExhausted);
        }
        if let Some(why) = self.must_stop() {
            return Err(why);
        }
        self.samples += 1;
        Ok(())
    }
}

/// The edge length of tree planners: `params.range`, or `share` of the space's extent.
pub(crate) fn range_of(space: &JointSpace, params: &PlannerParams, share: f64) -> f64 {
    if params.range > 0.0 {
        params.range
    } else {
        (share * space.extent()).max(1e-6)
    }
}

/// Runs one query the way every planner does: tests the start and the goals against the floor
/// ([`StateValidity::clear_of`], one validity call each, and one more to measure an end that
/// fails, for the report; an invalid start or all goals invalid end the run), calls `search`
/// with the run and the indices of the valid goals, then post-processes a found path with
/// [`shortcut_with`] when `params.simplify` is set, and fills in the work.
pub(crate) fn solve_with(
    problem: &Problem,
    stop: &Termination,
    params: &PlannerParams,
    search: impl FnOnce(&mut Run, &[usize]) -> Found,
) -> PlanResult {
    let mut run = Run::new(problem, stop);
    let mut result = PlanResult {
        status: Status::InvalidStart,
        waypoints: Vec::new(),
        goal: None,
        straight: false,
        start_clearance: f64::NAN,
        goal_clearances: vec![f64::NAN; problem.goals.len()],
        work: Work::default(),
    };
    // The ends are tested against the floor (each part asked only as far as it), and measured
    // only where they fail it, for the report.
    let found = if !run.state_valid(problem.start) {
        result.start_clearance = run.measure(problem.start);
        Found::none(Status::InvalidStart)
    } else {
        let mut valid = Vec::new();
        for (i, g) in problem.goals.iter().enumerate() {
            if run.state_valid(g) {
                valid.push(i);
            } else {
                result.goal_clearances[i] = run.measure(g);
            }
        }
        if valid.is_empty() {
            Found::none(Status::InvalidGoal)
        } else {
            search(&mut run, &valid)
        }
    };
    result.work.search_time = run.began.elapsed();
    result.status = found.status;
    result.goal = found.goal;
    result.straight = found.straight;
    result.waypoints = found.waypoints;
    let with_path = matches!(found.status, Status::Solved | Status::Approximate);
    if with_path && params.simplify && result.waypoints.len() > 2 {
        let t = Instant::now();
        let calls = shortcut_with(
            run.space,
            run.validity,
            &mut result.waypoints,
            (params.seed, params.shortcut_iterations),
            run.floor,
            params.skip_small_shortcuts,
        );
        result.work.simplify_calls = calls;
        run.calls += calls;
        result.work.simplify_time = t.elapsed();
    }
    result.work.samples = run.samples;
    result.work.validity_calls = run.calls;
    result.work.clock_bound = run.clock_bound;
    result.work.wall_time = run.began.elapsed();
    result
}
