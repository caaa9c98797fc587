//! What the runs of [`super::plan_cached`] on one cell share ([`PlanCache`]).
use super::graph::{MoveModel, RobotGraph};
use super::sequence;
use std::sync::{Arc, OnceLock};

/// What runs of [`super::plan_cached`] on one cell share: the robot graphs (they depend on the cell,
/// the move model, `alternatives` and `roomy` only) and every leg planned so far. Each leg is
/// a function of its robot, its two nodes and the settings, so a later run with the same
/// settings plans only the legs no run planned before. The planned legs are also what the
/// lazy sequencing knows (their real times replace the bounds), so a run's plan depends on
/// the legs the cache holds: runs that share one give the plans of one after the other only
/// in that order (a run made ahead, to be dropped if not needed, takes a copy). The graphs'
/// memo of legs ([`PlanCache::graphs_only`]) changes no plan; nor does the lower bound of the
/// graphs' min-max problem, found once for all ([`super::allocate::allocate_bounded`]).
#[derive(Clone, Debug, Default)]
pub struct PlanCache {
    graphs: Option<CachedGraphs>,
    pub(super) planned: Vec<sequence::Planned>,
}

impl PlanCache {
    /// The robot graphs made for `key` (move model, `alternatives`, `roomy` bits) and the memo
    /// of their lower bound: those held, or `make`'s, then held (with room for the planned
    /// legs of `robots` robots, none planned).
    pub(super) fn graphs_for(
        &mut self,
        key: (MoveModel, usize, u64),
        robots: usize,
        make: impl FnOnce() -> Vec<RobotGraph>,
    ) -> (Arc<Vec<RobotGraph>>, Arc<OnceLock<f64>>) {
        match &self.graphs {
            Some((k, g, b)) if *k == key => (Arc::clone(g), Arc::clone(b)),
            _ => {
                let g = Arc::new(make());
                let b = Arc::new(OnceLock::new());
                self.graphs = Some((key, Arc::clone(&g), Arc::clone(&b)));
                self.planned = vec![Default::default(); robots];
                (g, b)
            }
        }
    }

    /// A cache with this one's robot graphs (and the legs their memos hold) but no planned
    /// legs: a plan made with it is the plan made afresh, without planning again the legs
    /// the motion planner already gave.
    pub fn graphs_only(&self) -> PlanCache {
        PlanCache {
            graphs: self.graphs.clone(),
            planned: Vec::new(),
        }
    }

    /// Legs the motion planner did not plan again because its graphs' memos held them
    /// (see [`sequence::LegMemo`]).
    pub fn legs_served(&self) -> usize {
        self.graphs
            .as_ref()
            .map_or(0, |(_, g, _)| g.iter().map(|g| g.legs.served()).sum())
    }
}

/// The robot graphs of [`PlanCache`] with what they were made for (move model, `alternatives`,
/// `roomy`) and the lower bound of their min-max problem once found.
type CachedGraphs = ((MoveModel, usize, u64), Arc<Vec<RobotGraph>>, Arc<OnceLock<f64>>);
