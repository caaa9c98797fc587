//! The coordinated plans ours keeps while it chooses: the best so far and the shortest few
//! that lost (blended against the winner at the end, see [`super::coordinate`]).
use crate::coord::{Coordinated, cycle_and_delta};
use crate::plan::{Outcome, PlanError, PlanSettings};

/// One of ours' coordinated plans: the plan, the settings it was made with, its coordination.
pub(super) type Tried = (Outcome, PlanSettings, Coordinated);

/// The plan ours makes aside (see [`coordinate`]): the plan, its settings and its
/// coordination (`None` when it ended no sooner than the best cycle so far, uncoordinated).
pub(super) type AsideRun = Option<(Outcome, PlanSettings, Option<Result<Coordinated, PlanError>>)>;

/// How many of ours' coordinated plans that lost are kept to be blended against the winner.
pub(super) const RUNNERS_UP: usize = 2;
/// A runner-up is blended only if its cycle before blending is within this share of the
/// winner's.
pub(super) const RUNNER_UP_REACH: f64 = 0.05;

/// The shortest few coordinated plans that lost (see [`RUNNERS_UP`]).
pub(super) struct RunnersUp {
    pub(super) kept: Vec<Tried>,
    pub(super) room: usize,
}

impl RunnersUp {
    /// Keeps `run` if it is among the `room` shortest (by cycle, then Δt, then the earlier).
    pub(super) fn keep(&mut self, run: Option<Tried>) {
        let Some(run) = run else { return };
        if self.room == 0 {
            return;
        }
        let key = cycle_and_delta(&run.2.timed);
        let at = self.kept.partition_point(|r| cycle_and_delta(&r.2.timed) <= key);
        self.kept.insert(at, run);
        self.kept.truncate(self.room);
    }

    /// A coordinated plan that is not the first: it becomes `best` if its cycle (then Δt) is
    /// shorter, and the plan it replaces is kept as a runner-up; else it is kept as one.
    pub(super) fn offer(&mut self, best: &mut Option<Tried>, run: Tried) {
        match best {
            Some(b) => {
                self.offer_to(b, run);
            }
            None => self.keep(Some(run)),
        }
    }

    /// [`RunnersUp::offer`] against a best plan there is: whether `run` replaced it.
    pub(super) fn offer_to(&mut self, best: &mut Tried, run: Tried) -> bool {
        let shorter = cycle_and_delta(&run.2.timed) < cycle_and_delta(&best.2.timed);
        if shorter {
            self.keep(Some(std::mem::replace(best, run)));
        } else {
            self.keep(Some(run));
        }
        shorter
    }
}
