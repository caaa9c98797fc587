//! The plan document of a stud-weld cell (`cellplan-studweld-plan`, version 1): the sequence
//! (stud, alternative, configuration, gun rotation, node cost, times), each leg's motion (the
//! DMOC trajectory or the fallback timed path) with its J and duration, the alternatives per
//! stud, the unweldable studs, the totals of Table 2 and how the sequence was found. SI units;
//! `docs/plan-format.md` describes it.
use crate::cell::WeldCell;
use crate::leg::Motion;
use crate::plan::{Outcome, Run};
use crate::sequence::Sequencer;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The document's `format`.
pub const FORMAT: &str = "cellplan-studweld-plan";
/// The document's `version`.
pub const VERSION: u32 = 1;
/// Largest plan file read (bytes).
pub const MAX_PLAN_BYTES: u64 = 256 << 20;

/// A stud-weld plan.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
pub struct WeldPlan {
    /// [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The cell's name.
    pub cell: String,
    /// The sequencer that made it.
    pub sequencer: Sequencer,
    /// The process parameters (SI).
    pub parameters: serde_json::Value,
    /// Per stud (task order): how many alternatives and the range of their node costs.
    pub alternatives: Vec<StudAlternatives>,
    /// Studs that no alternative reaches, with the reason.
    pub unweldable: Vec<Unweldable>,
    /// The welds in order.
    pub visits: Vec<VisitDoc>,
    /// The moves: home → first weld, between welds, last weld → home.
    pub legs: Vec<LegDoc>,
    /// The costs and the cycle time.
    pub totals: Totals,
    /// How the sequence was found.
    pub sequencing: Sequencing,
}

/// The alternatives of one stud.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
pub struct StudAlternatives {
    /// Stud id.
    pub stud: String,
    /// Number of alternatives.
    pub count: usize,
    /// Least and largest node cost (absent when none).
    pub weld_cost_range: Option<[f64; 2]>,
}

/// A stud without alternative.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
pub struct Unweldable {
    /// Stud id.
    pub stud: String,
    /// Stable reason code (`no-ik`, `joint-limits`, `collision`, `torque`).
    pub reason: String,
    /// The reason for people.
    pub text: String,
}

/// One weld.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
pub struct VisitDoc {
    /// Stud id.
    pub stud: String,
    /// Index among the stud's alternatives.
    pub alternative: usize,
    /// The gun's rotation about the stud axis (rad).
    pub rotation_rad: f64,
    /// The joint configuration held (rad).
    pub q: Vec<f64>,
    /// Its node cost: weld time · (c_t + c_e |g(q)|²).
    pub weld_cost: f64,
    /// When the weld starts (s from the cycle's start).
    pub start_s: f64,
    /// When it ends.
    pub end_s: f64,
}

/// One move.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
pub struct LegDoc {
    /// Stud id it leaves (`home` for the first).
    pub from: String,
    /// Stud id it reaches (`home` for the last).
    pub to: String,
    /// When it starts (s).
    pub start_s: f64,
    /// Its duration (s).
    pub duration_s: f64,
    /// Its J.
    pub cost: f64,
    /// The motion.
    pub motion: Motion,
    /// Interior-point iterations spent on it (all attempts).
    pub iterations: usize,
    /// Why the optimal-control solution was not used (the leg is then a timed path).
    pub fallback: Option<String>,
    /// Accepted collision trust-region iterations (0: the unconstrained optimum was clear).
    pub trust_iterations: usize,
}

/// Table 2's figures.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, JsonSchema)]
pub struct Totals {
    /// J of the cycle: travel + welding.
    pub cost: f64,
    /// Σ J of the moves.
    pub travel_cost: f64,
    /// Σ node costs.
    pub weld_cost: f64,
    /// The cycle's duration (s).
    pub cycle_time_s: f64,
}

/// How the sequence was found.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, JsonSchema)]
pub struct Sequencing {
    /// Sequencing rounds of the lazy loop.
    pub rounds: usize,
    /// Whether the loop ended with every edge of the tour solved (not cut by the budget).
    pub converged: bool,
    /// Whether every GTSP was solved exactly (Held–Karp); else by the iterated local search.
    pub exact: bool,
    /// Optimal-control problems solved in the whole run (shared between sequencers).
    pub ocp_solves: usize,
    /// Optimal control: J / estimate over the solved legs (least, median, largest).
    pub estimate_ratio: Option<[f64; 3]>,
}

/// The document of one outcome of `run`.
pub fn build(w: &WeldCell, run: &Run, o: &Outcome) -> WeldPlan {
    let tasks = &w.cell.tasks;
    let alternatives = run
        .alternatives
        .per_stud
        .iter()
        .enumerate()
        .map(|(s, list)| StudAlternatives {
            stud: tasks[s].name.clone(),
            count: list.len(),
            weld_cost_range: (!list.is_empty()).then(|| {
                list.iter()
                    .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], a| {
                        [lo.min(a.weld_cost), hi.max(a.weld_cost)]
                    })
            }),
        })
        .collect();
    let unweldable = run
        .alternatives
        .unweldable
        .iter()
        .map(|&(s, why)| Unweldable {
            stud: tasks[s].name.clone(),
            reason: why.code().into(),
            text: why.text().into(),
        })
        .collect();
    let names: Vec<String> = std::iter::once("home".to_string())
        .chain(o.visits.iter().map(|v| tasks[v.stud].name.clone()))
        .chain(std::iter::once("home".to_string()))
        .collect();
    let mut t = 0.0;
    let mut visits = Vec::new();
    let mut legs = Vec::new();
    for (i, leg) in o.legs.iter().enumerate() {
        legs.push(LegDoc {
            from: names[i].clone(),
            to: names[i + 1].clone(),
            start_s: t,
            duration_s: leg.duration,
            cost: leg.cost,
            motion: leg.motion.clone(),
            iterations: leg.iterations,
            fallback: leg.fallback.clone(),
            trust_iterations: leg.trust_iterations,
        });
        t += leg.duration;
        if let Some(v) = o.visits.get(i) {
            visits.push(VisitDoc {
                stud: tasks[v.stud].name.clone(),
                alternative: v.alternative,
                rotation_rad: v.rotation,
                q: v.q.clone(),
                weld_cost: v.weld_cost,
                start_s: t,
                end_s: t + w.process.weld_time,
            });
            t += w.process.weld_time;
        }
    }
    WeldPlan {
        format: FORMAT.into(),
        version: VERSION,
        cell: w.cell.name.clone(),
        sequencer: o.sequencer,
        parameters: w.cell.process.parameters(),
        alternatives,
        unweldable,
        visits,
        legs,
        totals: Totals {
            cost: o.cost,
            travel_cost: o.travel_cost,
            weld_cost: o.weld_cost,
            cycle_time_s: o.cycle_time,
        },
        sequencing: Sequencing {
            rounds: o.sequence.rounds,
            converged: o.sequence.converged,
            exact: o.sequence.exact,
            ocp_solves: run.ocp_solves,
            estimate_ratio: o.sequence.estimate_ratio,
        },
    }
}

/// Reads a plan document (bounded), checking its format and version.
pub fn read(path: &std::path::Path) -> Result<WeldPlan, String> {
    let doc: WeldPlan = cellplan_model::document::read_json(path, MAX_PLAN_BYTES, "stud-weld plan")?;
    cellplan_model::document::check_version((&doc.format, doc.version), (FORMAT, VERSION))?;
    Ok(doc)
}

/// The JSON Schema of the document, as `docs/studweld-plan.schema.json` holds it.
pub fn schema() -> String {
    cellplan_model::document::schema_text(&schemars::schema_for!(WeldPlan))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// `docs/studweld-plan.schema.json` is the schema of these types (regenerate it with
    /// `CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-studweld schema`).
    #[test]
    fn the_schema_in_docs_is_generated_from_the_types() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/studweld-plan.schema.json");
        let schema =
            cellplan_model::document::schema_file_matches(&path, &super::schema()).unwrap_or_else(|e| {
                panic!(
                    "{e}; regenerate it with CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-studweld schema"
                )
            });
        let required = schema["required"].as_array().unwrap();
        for key in [
            "visits",
            "legs",
            "totals",
            "alternatives",
            "unweldable",
            "sequencing",
        ] {
            assert!(
                required.iter().any(|k| k == key),
                "{key} not required: {required:?}"
            );
        }
    }
}
