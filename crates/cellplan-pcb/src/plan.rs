//! One planning run: an optimiser on a cell, the schedule it gives, the plan document.
use crate::bound::lower_bound;
use crate::cell::PcbCell;
use crate::document::{PcbPlan, RunInfo, build};
use crate::ga::{self, GaSettings};
use crate::search::{self, SearchSettings};
use crate::sim::{Decision, Given, Schedule, simulate};
use std::time::Instant;

/// Which optimiser.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Optimizer {
    /// Paper 004's GA.
    Ga,
    /// Ours.
    Best,
}

impl Optimizer {
    /// The name in files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Optimizer::Ga => "ga",
            Optimizer::Best => "best",
        }
    }
}

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct Request {
    /// Optimiser.
    pub optimizer: Optimizer,
    /// Simulations (the work budget; the plan depends only on it and the seed).
    pub evaluations: usize,
    /// Seed.
    pub seed: u64,
    /// Wall-clock safety net: the search stops at it (and says so).
    pub deadline: Option<Instant>,
}

/// The result of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The decision.
    pub decision: Decision,
    /// Its schedule.
    pub schedule: Schedule,
    /// The plan document.
    pub plan: PcbPlan,
    /// (simulations, best assembly time) whenever the best improved.
    pub trace: Vec<(usize, f64)>,
    /// Whether the deadline stopped the search.
    pub time_limit_hit: bool,
}

/// Plans `cell` (in its configuration, motion model and robot count).
pub fn run(cell: &PcbCell, req: &Request) -> Outcome {
    let start = Instant::now();
    let (decision, trace, hit) = match req.optimizer {
        Optimizer::Ga => {
            let r = ga::run(
                cell,
                &GaSettings {
                    evaluations: req.evaluations,
                    seed: req.seed,
                    deadline: req.deadline,
                    ..GaSettings::default()
                },
            );
            (r.0, r.2, r.3)
        }
        Optimizer::Best => {
            let r = search::run(
                cell,
                &SearchSettings {
                    evaluations: req.evaluations,
                    seed: req.seed,
                    deadline: req.deadline,
                },
                None,
            );
            (r.0, r.2, r.3)
        }
    };
    let schedule = simulate(cell, &decision, &mut Given(&decision), rule(cell, req.optimizer));
    let plan = build(
        cell,
        &decision,
        &schedule,
        &RunInfo {
            optimizer: req.optimizer.name().into(),
            seed: req.seed,
            compute_s: start.elapsed().as_secs_f64(),
            evaluations: req.evaluations,
            lower_bound_s: lower_bound(cell),
        },
    );
    Outcome {
        decision,
        schedule,
        plan,
        trace,
        time_limit_hit: hit,
    }
}

/// A plan with the placement order given (every component once) and the rest ours: the
/// document names the optimiser `given`.
pub fn run_given(cell: &PcbCell, order: &[usize], evaluations: usize, seed: u64) -> Outcome {
    let start = Instant::now();
    let (decision, value) = search::settle_order(cell, order, evaluations);
    let schedule = simulate(cell, &decision, &mut Given(&decision), search::rule(cell));
    let plan = build(
        cell,
        &decision,
        &schedule,
        &RunInfo {
            optimizer: "given".into(),
            seed,
            compute_s: start.elapsed().as_secs_f64(),
            evaluations,
            lower_bound_s: lower_bound(cell),
        },
    );
    Outcome {
        decision,
        schedule,
        plan,
        trace: vec![(evaluations, value)],
        time_limit_hit: false,
    }
}

/// The delay rule each optimiser's plans are made with.
pub fn rule(cell: &PcbCell, optimizer: Optimizer) -> crate::sim::DelayRule {
    match optimizer {
        Optimizer::Ga => ga::rule(cell),
        Optimizer::Best => search::rule(cell),
    }
}
