//! One planning run on a stud-weld cell: the alternatives, the graph, one or both sequencers
//! (sharing the solved legs), and each sequence's legs, costs and cycle time.
use crate::alternatives::{Alternatives, NoAlternative, alternatives};
use crate::cell::WeldCell;
use crate::leg::{Leg, LegSettings};
use crate::sequence::{self, Cache, Graph, Sequence, Sequencer};

/// One visit of a sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct Visit {
    /// The stud (task index).
    pub stud: usize,
    /// The alternative (index among the stud's).
    pub alternative: usize,
    /// Its configuration.
    pub q: Vec<f64>,
    /// The gun's rotation about the stud axis (rad).
    pub rotation: f64,
    /// Its node cost.
    pub weld_cost: f64,
}

/// One sequencer's result.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Which sequencer.
    pub sequencer: Sequencer,
    /// Visits in order.
    pub visits: Vec<Visit>,
    /// Legs: home → first, between visits, last → home.
    pub legs: Vec<Leg>,
    /// Σ J of the legs.
    pub travel_cost: f64,
    /// Σ node costs.
    pub weld_cost: f64,
    /// Travel + weld.
    pub cost: f64,
    /// Σ leg durations + studs × weld time (s).
    pub cycle_time: f64,
    /// How the sequence was found.
    pub sequence: Sequence,
}

/// The whole run.
pub struct Run {
    /// The alternatives of every stud.
    pub alternatives: Alternatives,
    /// Per sequencer asked for, its outcome.
    pub outcomes: Vec<Outcome>,
    /// OCPs solved in the run.
    pub ocp_solves: usize,
}

/// Why a run gave no plan.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The home configuration is not collision-free.
    #[error("the robot's home configuration is not collision-free at the cell's clearance")]
    Home,
    /// No stud can be welded.
    #[error("no stud can be welded")]
    NothingWeldable,
    /// A leg of the sequence has no collision-free path.
    #[error("no collision-free path between {0} and {1}")]
    NoPath(String, String),
}

fn name(w: &WeldCell, g: &Graph, node: usize) -> String {
    match g.of[node] {
        None => "home".into(),
        Some((s, k)) => format!("{} (alternative {k})", w.cell.tasks[s].name),
    }
}

/// Plans with each of `sequencers` in turn.
pub fn run(w: &WeldCell, sequencers: &[Sequencer], s: &LegSettings) -> Result<Run, PlanError> {
    let validity = cellplan_core::motion::robot_validity(w.cell, w.robot, w.cell.planning.clearance);
    if !validity.is_valid(&w.robot.home) {
        return Err(PlanError::Home);
    }
    let alts = alternatives(w);
    let g = Graph::new(w, &alts);
    if g.clusters.is_empty() {
        return Err(PlanError::NothingWeldable);
    }
    let mut cache = Cache::default();
    let mut outcomes = Vec::new();
    for &sq in sequencers {
        let seq = match sq {
            Sequencer::TravelTime => sequence::travel_time(w, &g, s, &mut cache),
            Sequencer::OptimalControl => sequence::optimal_control(w, &g, s, &mut cache),
        };
        let mut legs = Vec::new();
        for (a, b) in sequence::edges(&seq.nodes) {
            let leg = sequence::cached_leg(&cache, a, b)
                .ok_or_else(|| PlanError::NoPath(name(w, &g, a), name(w, &g, b)))?;
            legs.push(leg);
        }
        let visits: Vec<Visit> = seq
            .nodes
            .iter()
            .filter_map(|&v| g.of[v])
            .map(|(stud, k)| {
                let a = &alts.per_stud[stud][k];
                Visit {
                    stud,
                    alternative: k,
                    q: a.q.clone(),
                    rotation: a.rotation,
                    weld_cost: a.weld_cost,
                }
            })
            .collect();
        let travel_cost: f64 = legs.iter().map(|l| l.cost).sum();
        let weld_cost: f64 = visits.iter().map(|v| v.weld_cost).sum();
        let cycle_time =
            legs.iter().map(|l| l.duration).sum::<f64>() + visits.len() as f64 * w.process.weld_time;
        outcomes.push(Outcome {
            sequencer: sq,
            visits,
            legs,
            travel_cost,
            weld_cost,
            cost: travel_cost + weld_cost,
            cycle_time,
            sequence: seq,
        });
    }
    Ok(Run {
        alternatives: alts,
        outcomes,
        ocp_solves: cache.solves,
    })
}

/// The studs without an alternative, with their names and reasons.
pub fn unweldable<'c>(w: &WeldCell<'c>, alts: &Alternatives) -> Vec<(&'c str, NoAlternative)> {
    alts.unweldable
        .iter()
        .map(|&(s, why)| (w.cell.tasks[s].name.as_str(), why))
        .collect()
}
