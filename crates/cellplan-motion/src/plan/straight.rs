//! The direct segment only.
use super::problem::{Found, Run};
use super::{
    JointSpace, MotionPlanner, PlanError, PlanResult, PlanSettings, PlannedPath, Planner, PlannerParams,
    Problem, StateValidity, Status, Termination, solve_with,
};

/// Only the direct segment: to each valid goal in turn, the first that passes
/// [`super::check_segment`] wins. When every one is blocked the query is
/// [`Status::Infeasible`] for this planner. No samples; the segment to the first valid goal
/// is always checked, further goals only within the budget.
#[derive(Clone, Copy, Debug, Default)]
pub struct Straight;

/// The search of [`Straight`], shared with [`super::Leg`].
pub(crate) fn search(run: &mut Run, start: &[f64], goals: &[Vec<f64>], valid: &[usize]) -> Found {
    for (k, &g) in valid.iter().enumerate() {
        if k > 0
            && let Some(why) = run.must_stop()
        {
            return Found::none(why);
        }
        if run.direct_segment(start, &goals[g]) {
            let mut found = Found::path(vec![start.to_vec(), goals[g].clone()], g);
            found.straight = true;
            return found;
        }
    }
    Found::none(Status::Infeasible)
}

impl MotionPlanner for Straight {
    fn name(&self) -> &'static str {
        "straight"
    }

    fn solve(&mut self, problem: &Problem, stop: &Termination) -> PlanResult {
        solve_with(problem, stop, &PlannerParams::default(), |run, valid| {
            search(run, problem.start, problem.goals, valid)
        })
    }
}

impl Planner for Straight {
    fn name(&self) -> &str {
        "straight"
    }

    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError> {
        settings.with_problem(space, validity, start, goal, |problem| {
            Straight.solve(problem, &settings.termination()).into_planned()
        })
    }
}
