//! The pipeline as `cellplan plan` runs it — candidates, allocation, sequencing with lazily
//! planned legs, timing, coordination, the document and its verification — and the one place
//! that decides what "ours" is: with `best` coordination and the balanced allocation, the
//! proximity allocation is planned and coordinated too, and the shorter coordinated cycle wins.
//! `cellplan compare` takes its "ours" row from here as well.
use crate::candidates::{self, CandidateTable};
use crate::check::{cap_error, idle_robot_error};
use crate::coord::{CoordSettings, Coordinated, Coordination, coordinate_outcome, cycle_and_delta};
use crate::document::{self, Plan};
use crate::plan::{self, Allocation, Outcome, PlanError, PlanSettings, Stage};
use cellplan_model::{Cell, InputError};
use std::time::Instant;

/// The steps of a run, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Candidate generation.
    Candidates,
    /// A planning stage.
    Plan(Stage),
    /// Coordination (with `proximity_too` when ours also coordinates the proximity allocation).
    Coordination {
        /// Whether the proximity allocation is coordinated too.
        proximity_too: bool,
    },
    /// The verifier.
    Verification,
}

/// Why a run made no plan.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The cell is unusable as given (a robot that can do nothing, caps that cannot hold the
    /// tasks).
    #[error(transparent)]
    Input(Box<InputError>),
    /// Planning failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
}

/// What a run made.
#[derive(Debug)]
pub struct Run<R> {
    /// The candidate table.
    pub table: CandidateTable,
    /// The plan document (`verified` set from the verifier's verdict).
    pub plan: Plan,
    /// The verifier's report on it.
    pub report: R,
}

/// The independent check a run ends with (`cellplan_verify` provides it; the core does not
/// depend on its verifier): the verdict and the report.
pub type Verifier<'a, R> = &'a dyn Fn(&Cell, &CandidateTable, &Plan) -> (bool, R);

/// Runs the whole pipeline on a loaded cell: `load_s` is what loading took (for the
/// document's compute times); `verify` checks the document at the end.
pub fn run<R>(
    cell: &Cell,
    settings: &PlanSettings,
    coord: &CoordSettings,
    load_s: f64,
    progress: &(dyn Fn(Step) + Sync),
    verify: Verifier<'_, R>,
) -> Result<Run<R>, PipelineError> {
    if !cell.process.relations().is_empty() {
        // Precedence and pairing are part of the interface for the processes to come; no
        // allocation or sequencing honours them yet, so a plan that ignored them would be wrong.
        return Err(PlanError::Unsupported {
            what: "planning with relations between tasks (precedence, pairing)",
            process: cell.process.kind(),
        }
        .into());
    }
    progress(Step::Candidates);
    let lap = Instant::now();
    let table = candidates::generate(cell);
    let candidates_s = lap.elapsed().as_secs_f64();
    if let Some(e) = idle_robot_error(cell, &table).or_else(|| cap_error(cell, &table)) {
        return Err(PipelineError::Input(Box::new(e)));
    }
    let outcome = plan::plan(cell, &table, settings, &|s| progress(Step::Plan(s)))?;
    progress(Step::Coordination {
        proximity_too: ours_tries_proximity(settings, coord),
    });
    let (outcome, settings, coordinated) = coordinate(cell, &table, outcome, settings.clone(), coord)?;
    let mut plan = document::build(
        cell,
        &table,
        &outcome,
        &coordinated,
        &settings,
        load_s,
        candidates_s,
    );
    progress(Step::Verification);
    let lap = Instant::now();
    let (ok, report) = verify(cell, &table, &plan);
    plan.compute_s.verification = lap.elapsed().as_secs_f64();
    plan.verified = ok;
    Ok(Run { table, plan, report })
}

/// Whether ours (`best` on the balanced allocation) also plans the proximity allocation.
pub fn ours_tries_proximity(settings: &PlanSettings, coord: &CoordSettings) -> bool {
    coord.strategy == Coordination::Best && settings.allocation == Allocation::Balanced
}

/// What `cellplan plan` runs: `outcome` (planned with `settings`) coordinated with
/// `coord`; with `best` and the balanced allocation (ours), the proximity allocation is planned
/// and coordinated too, first, and its cycle is the bar of the balanced one
/// ([`CoordSettings::bar`]); the shorter coordinated cycle (then Δt) wins, with the compute of
/// both. Returns the winning run, its settings and its coordination.
pub fn coordinate(
    cell: &Cell,
    table: &CandidateTable,
    outcome: Outcome,
    settings: PlanSettings,
    coord: &CoordSettings,
) -> Result<(Outcome, PlanSettings, Coordinated), PlanError> {
    if !ours_tries_proximity(&settings, coord) {
        let c = coordinate_outcome(cell, table, &outcome, coord)?;
        return Ok((outcome, settings, c));
    }
    // Robots in their own zones meet less: the nearest-robot allocation often wins.
    let prox_settings = PlanSettings {
        allocation: Allocation::Proximity,
        ..settings.clone()
    };
    let prox = plan::plan(cell, table, &prox_settings, &|_| {})
        .ok()
        .and_then(|o| {
            let c = coordinate_outcome(cell, table, &o, coord).ok()?;
            Some((o, c))
        });
    let bar = prox.as_ref().map(|(_, c)| cycle_and_delta(&c.timed).0);
    let lap = Instant::now();
    let balanced = coordinate_outcome(cell, table, &outcome, &CoordSettings { bar, ..coord.clone() });
    let balanced_s = lap.elapsed().as_secs_f64();
    Ok(match (balanced, prox) {
        (Ok(b), Some((po, mut pc))) => {
            pc.compute_s += balanced_s;
            if cycle_and_delta(&pc.timed) < cycle_and_delta(&b.timed) {
                (po, prox_settings, pc)
            } else {
                let spent = pc.compute_s;
                (
                    outcome,
                    settings,
                    Coordinated {
                        compute_s: spent,
                        ..b
                    },
                )
            }
        }
        (Ok(b), None) => (outcome, settings, b),
        // The balanced coordination failed.
        (Err(_), Some((po, mut pc))) => {
            pc.compute_s += balanced_s;
            (po, prox_settings, pc)
        }
        (Err(e), None) => return Err(e),
    })
}
