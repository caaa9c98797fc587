//! Planners behind one interface ([`MotionPlanner`]), built by name from a static registry
//! ([`planners`], [`planner`]) with one parameter struct ([`PlannerParams`]).
use super::problem::solve_with;
use super::{PlanResult, Prm, Problem, RrtConnect, RrtStar, Straight, Termination, rrt_connect, straight};
use thiserror::Error;

/// A planner of the registry (OMPL's `Planner`): one required method. A planner may keep
/// state between queries in the same static scene (the [`Prm`] keeps its roadmap); the
/// others are stateless and give the same result for the same query, parameters and budget.
pub trait MotionPlanner: Send {
    /// Its name in the registry.
    fn name(&self) -> &'static str;

    /// Plans the query within `stop`. Every edge of a returned path passes
    /// [`super::check_segment`] with the problem's `min_clearance`.
    fn solve(&mut self, problem: &Problem, stop: &Termination) -> PlanResult;
}

/// Parameters of the planners of the registry; each planner reads those it needs.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannerParams {
    /// Seed of the random numbers (ChaCha8) of the search and of the post-processing.
    pub seed: u64,
    /// Longest tree edge (RRT-Connect, RRT*), in the space's metric; 0 or less: a share of
    /// the space's [`super::JointSpace::extent`], [`PlannerParams::range_share`] for
    /// RRT-Connect, a fifth for RRT* (OMPL's default).
    pub range: f64,
    /// RRT-Connect's range when `range` is 0, in shares of the space's extent: by default a
    /// tenth (VAMP's 1.5 rad on the MBM UR5; OMPL's fifth makes edges that fail far more
    /// often in cluttered scenes).
    pub range_share: f64,
    /// RRT-Connect: dynamic domains (Yershova et al. 2005, with VAMP's settings): a node
    /// whose extension failed is extended only towards samples near it.
    pub dynamic_domain: bool,
    /// RRT-Connect: a tree less than half the other's size is extended again instead of in
    /// turn (VAMP's balancing).
    pub balance: bool,
    /// Whether a found path is post-processed by [`super::shortcut`] (shortcuts, then
    /// redundant waypoints dropped).
    pub simplify: bool,
    /// Random shortcut attempts of the post-processing.
    pub shortcut_iterations: usize,
    /// Post-processing: a shortcut that would gain less than 0.5 % of the path's length is a
    /// miss without its segment check (it would count as a miss even when valid). On the MBM
    /// UR5 problems this saves 40 % of the simplification's checks and ends with shorter
    /// paths (median 6.89 → 6.75 rad).
    pub skip_small_shortcuts: bool,
    /// RRT*: the share of samples drawn at a goal not yet in the tree.
    pub goal_bias: f64,
    /// RRT*: the near-neighbour radius `γ (log n / n)^(1/d)` uses this factor times the
    /// smallest `γ` of Karaman & Frazzoli's theorem (above 1 for asymptotic optimality).
    pub rewire_factor: f64,
    /// RRT*: when no goal is reached, return the path to the tree node nearest a goal with
    /// [`super::Status::Approximate`].
    pub approximate: bool,
    /// PRM: neighbours each new roadmap node is linked to; 0: `⌈e (1 + 1/d) ln n⌉` (PRM*).
    pub neighbours: usize,
}

impl Default for PlannerParams {
    fn default() -> Self {
        PlannerParams {
            seed: 0,
            range: 0.0,
            range_share: 0.1,
            dynamic_domain: true,
            balance: true,
            simplify: true,
            shortcut_iterations: 100,
            skip_small_shortcuts: true,
            goal_bias: 0.05,
            rewire_factor: 1.1,
            approximate: false,
            neighbours: 0,
        }
    }
}

/// One planner of the registry.
#[derive(Clone, Copy)]
pub struct Entry {
    /// Stable name, kebab-case (`rrt-connect`).
    pub name: &'static str,
    /// One line on what it does.
    pub summary: &'static str,
    /// Builds it with these parameters.
    pub build: fn(&PlannerParams) -> Box<dyn MotionPlanner>,
}

impl std::fmt::Debug for Entry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Entry")
            .field("name", &self.name)
            .field("summary", &self.summary)
            .finish_non_exhaustive()
    }
}

static PLANNERS: [Entry; 5] = [
    Entry {
        name: "straight",
        summary: "the direct segment to the first goal it reaches; infeasible when all are blocked",
        build: |_| Box::new(Straight),
    },
    Entry {
        name: "rrt-connect",
        summary: "RRT-Connect (Kuffner & LaValle 2000): a start tree and a goal forest, grown and connected in turn",
        build: |p| Box::new(RrtConnect { params: p.clone() }),
    },
    Entry {
        name: "rrt-star",
        summary: "RRT* (Karaman & Frazzoli 2011): anytime, spends the whole budget shortening the best path",
        build: |p| Box::new(RrtStar { params: p.clone() }),
    },
    Entry {
        name: "prm",
        summary: "lazy PRM: a roadmap kept across queries in one static scene, edges checked when a shortest path uses them",
        build: |p| Box::new(Prm::new(p)),
    },
    Entry {
        name: "leg",
        summary: "the usual leg: the direct segment if clear, else RRT-Connect, then post-processing",
        build: |p| Box::new(Leg { params: p.clone() }),
    },
];

/// Every planner of the registry, in a stable order.
///
/// ```
/// use cellplan_motion::plan::planners;
/// assert!(planners().iter().any(|e| e.name == "rrt-connect"));
/// ```
pub fn planners() -> &'static [Entry] {
    &PLANNERS
}

/// The registry entry named `name`, or an error listing the valid names.
///
/// ```
/// use cellplan_motion::plan::{JointSpace, PlannerParams, Problem, Termination, planner};
/// let space = JointSpace::new(vec![0.0; 2], vec![1.0; 2], vec![1.0; 2]);
/// let free = |_: &[f64]| 1.0;
/// let goals = [vec![0.9, 0.9]];
/// let problem = Problem::new(&space, &free, &[0.1, 0.1], &goals);
/// let mut rrt = (planner("rrt-connect").unwrap().build)(&PlannerParams::default());
/// let result = rrt.solve(&problem, &Termination::samples(1000));
/// assert!(result.status.is_solved());
/// assert!(planner("rrt").unwrap_err().to_string().contains("rrt-connect"));
/// ```
pub fn planner(name: &str) -> Result<&'static Entry, UnknownPlanner> {
    PLANNERS
        .iter()
        .find(|e| e.name == name)
        .ok_or_else(|| UnknownPlanner {
            name: name.to_string(),
            valid: PLANNERS.iter().map(|e| e.name).collect(),
        })
}

/// No planner of that name.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("unknown planner `{name}` (valid: {})", valid.join(", "))]
pub struct UnknownPlanner {
    /// The name asked for.
    pub name: String,
    /// The names of the registry.
    pub valid: Vec<&'static str>,
}

/// The usual recipe for one leg: the direct segment to the first valid goal it reaches, else
/// [`RrtConnect`] (same budget), then post-processing when [`PlannerParams::simplify`] is
/// set. The work adds up every stage.
#[derive(Clone, Debug, Default)]
pub struct Leg {
    /// Its parameters.
    pub params: PlannerParams,
}

impl MotionPlanner for Leg {
    fn name(&self) -> &'static str {
        "leg"
    }

    fn solve(&mut self, problem: &Problem, stop: &Termination) -> PlanResult {
        solve_with(problem, stop, &self.params, |run, valid| {
            let direct = straight::search(run, problem.start, problem.goals, valid);
            if direct.status != super::Status::Infeasible {
                return direct;
            }
            rrt_connect::search(run, &self.params, problem.start, problem.goals, valid)
        })
    }
}
