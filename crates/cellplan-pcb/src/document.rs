//! The PCB-assembly plan document (`plan.json`, `docs/plan-format.md` § PCB assembly): the bins,
//! every device's motion as timed straight moves (standing still between them), every placement
//! with its pick and place rendezvous, and the totals. `cellplan verify` re-derives everything
//! from this document and the cell alone.
use crate::cell::{Configuration, MotionModel, PcbCell};
use crate::sim::{Decision, Schedule, dist};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `format` of a PCB plan.
pub const FORMAT: &str = "cellplan-pcb-plan";
/// Version of the layout.
pub const VERSION: u32 = 1;
/// Largest plan file read (bytes).
pub const MAX_PLAN_BYTES: u64 = 256 << 20;

/// The plan.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PcbPlan {
    /// Always `cellplan-pcb-plan`.
    pub format: String,
    /// Layout version ([`VERSION`]).
    pub version: u32,
    /// `pcb-assembly`.
    pub process: String,
    /// The cell's name.
    pub cell: String,
    /// Which devices move.
    pub configuration: Configuration,
    /// The motion model the times follow.
    pub motion: MotionModel,
    /// `best` (ours) or `ga` (paper 004's GA).
    pub optimizer: String,
    /// Whether the two robots were kept apart.
    pub collision_avoidance: bool,
    /// Seed of the run.
    pub seed: u64,
    /// What each bin holds.
    pub bins: Vec<BinOut>,
    /// Every device: where it starts and its moves.
    pub devices: Vec<DeviceOut>,
    /// The placements in order.
    pub placements: Vec<PlacementOut>,
    /// Per robot totals.
    pub robots: Vec<RobotOut>,
    /// Assembly time: the end of the last placement (s).
    pub cycle_time_s: f64,
    /// A lower bound on any plan's assembly time for this cell and configuration (s).
    pub lower_bound_s: f64,
    /// Wall-clock time of the planning (s; the only number not re-derived).
    pub compute_s: f64,
    /// The simulations the optimiser was given (its work budget; a binding time limit stops it sooner).
    pub evaluations: usize,
}

/// One bin's content.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BinOut {
    /// Feeder name.
    pub feeder: String,
    /// Bin index (0 at the carriage position, counting along +Y).
    pub bin: usize,
    /// Footprint.
    pub footprint: String,
    /// Value.
    pub value: String,
}

/// What kind of device.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum DeviceKind {
    /// A placement robot (position: head X, Y).
    Robot,
    /// A feeder (position: pick line X, carriage Y).
    Feeder,
    /// The table (position: the board origin X, Y).
    Table,
}

/// A device's motion.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DeviceOut {
    /// Name (the cell's; the table is `table`).
    pub name: String,
    /// Kind.
    pub kind: DeviceKind,
    /// Position at time 0 (m).
    pub start: [f64; 2],
    /// Straight moves at full drive (each lasts exactly the drive's time for its length),
    /// in time order; the device stands still between them.
    pub moves: Vec<MoveOut>,
}

/// One straight move.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MoveOut {
    /// Start and end (s).
    pub t: [f64; 2],
    /// From (m).
    pub from: [f64; 2],
    /// To (m).
    pub to: [f64; 2],
}

/// A pick or a placement: when, and where the two devices meet.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Meeting {
    /// Start and end (s).
    pub t: [f64; 2],
    /// The robot head's position (m).
    pub point: [f64; 2],
    /// The other device's position: the feeder's [pick line X, carriage Y], or the table's
    /// board origin (m).
    pub device: [f64; 2],
}

/// One component placed.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlacementOut {
    /// Reference designator.
    pub component: String,
    /// Robot name.
    pub robot: String,
    /// Feeder name.
    pub feeder: String,
    /// Bin.
    pub bin: usize,
    /// The pick.
    pub pick: Meeting,
    /// The placement.
    pub place: Meeting,
    /// Rotation of the component on the board (rad).
    pub rotation_rad: f64,
    /// The robot's safety delay before leaving the pick (s).
    pub safety_delay_s: f64,
}

/// One robot's totals.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RobotOut {
    /// Name.
    pub name: String,
    /// Components it places.
    pub components: usize,
    /// Time moving (s).
    pub motion_s: f64,
    /// Time picking and placing (s).
    pub working_s: f64,
    /// Time standing still otherwise until its last placement ends (s).
    pub waiting_s: f64,
    /// End of its last placement (s; 0 if it places nothing).
    pub total_s: f64,
}

/// What the run was, for the document.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// `best` or `ga`.
    pub optimizer: String,
    /// Seed.
    pub seed: u64,
    /// Wall clock (s).
    pub compute_s: f64,
    /// The simulation budget.
    pub evaluations: usize,
    /// The lower bound (s).
    pub lower_bound_s: f64,
}

/// Builds the document of a simulated decision.
pub fn build(cell: &PcbCell, d: &Decision, s: &Schedule, info: &RunInfo) -> PcbPlan {
    let eps = 1e-12;
    let mut bins = Vec::new();
    for (f, feeder) in cell.feeders.iter().enumerate() {
        for (slot, t) in d.slots[f].iter().enumerate() {
            if let Some(t) = t {
                bins.push(BinOut {
                    feeder: feeder.name.clone(),
                    bin: slot,
                    footprint: cell.types[*t].footprint.clone(),
                    value: cell.types[*t].value.clone(),
                });
            }
        }
    }
    let fixed_feeders = !cell.configuration.feeders_move();
    let fixed_table = !cell.configuration.table_moves();
    let mut devices = Vec::new();
    // Robots.
    for (r, robot) in cell.robots.iter().enumerate() {
        let mut moves = Vec::new();
        let mut pos = robot.home;
        let push = |moves: &mut Vec<MoveOut>, t0: f64, t1: f64, from: [f64; 2], to: [f64; 2]| {
            if dist(from, to) > eps {
                moves.push(MoveOut {
                    t: [t0, t1],
                    from,
                    to,
                });
            }
        };
        let mut last_end = None;
        for cy in s.cycles.iter().filter(|c| c.robot == r) {
            push(&mut moves, cy.robot_leaves, cy.robot_at_pick, pos, cy.pick_point);
            let leave = cy.pick[1] + cy.safety_delay;
            push(
                &mut moves,
                leave,
                cy.robot_at_place,
                cy.pick_point,
                cy.place_point,
            );
            pos = cy.place_point;
            last_end = Some(cy.place[1]);
        }
        if let Some(end) = last_end {
            let back = end + robot.drive.time(cell.motion, dist(pos, robot.home));
            push(&mut moves, end, back, pos, robot.home);
        }
        devices.push(DeviceOut {
            name: robot.name.clone(),
            kind: DeviceKind::Robot,
            start: robot.home,
            moves,
        });
    }
    // Feeders.
    for (f, feeder) in cell.feeders.iter().enumerate() {
        let mut moves = Vec::new();
        let first = s.cycles.iter().find(|c| c.feeder == f);
        let start = match (fixed_feeders, first) {
            (true, Some(c)) => c.carriage,
            _ => feeder.home,
        };
        let mut pos = start;
        for cy in s.cycles.iter().filter(|c| c.feeder == f) {
            if (cy.carriage - pos).abs() > eps {
                moves.push(MoveOut {
                    t: [cy.feeder_leaves, cy.feeder_at_pick],
                    from: [feeder.x, pos],
                    to: [feeder.x, cy.carriage],
                });
            }
            pos = cy.carriage;
        }
        devices.push(DeviceOut {
            name: feeder.name.clone(),
            kind: DeviceKind::Feeder,
            start: [feeder.x, start],
            moves,
        });
    }
    // Table.
    {
        let start = match (fixed_table, s.cycles.first()) {
            (true, Some(c)) => c.table,
            _ => cell.table.home,
        };
        let mut pos = start;
        let mut moves = Vec::new();
        for cy in &s.cycles {
            if dist(cy.table, pos) > eps {
                moves.push(MoveOut {
                    t: [cy.table_leaves, cy.table_at_place],
                    from: pos,
                    to: cy.table,
                });
            }
            pos = cy.table;
        }
        devices.push(DeviceOut {
            name: "table".into(),
            kind: DeviceKind::Table,
            start,
            moves,
        });
    }
    let placements = s
        .cycles
        .iter()
        .map(|cy| PlacementOut {
            component: cell.components[cy.component].reference.clone(),
            robot: cell.robots[cy.robot].name.clone(),
            feeder: cell.feeders[cy.feeder].name.clone(),
            bin: cy.slot,
            pick: Meeting {
                t: cy.pick,
                point: cy.pick_point,
                device: [cell.feeders[cy.feeder].x, cy.carriage],
            },
            place: Meeting {
                t: cy.place,
                point: cy.place_point,
                device: cy.table,
            },
            rotation_rad: cell.components[cy.component].rotation,
            safety_delay_s: cy.safety_delay,
        })
        .collect();
    let robots = cell
        .robots
        .iter()
        .enumerate()
        .map(|(r, robot)| {
            robot_totals(
                &devices[r],
                &robot.name,
                s.cycles
                    .iter()
                    .filter(|c| c.robot == r)
                    .map(|c| (c.pick, c.place)),
            )
        })
        .collect();
    PcbPlan {
        format: FORMAT.into(),
        version: VERSION,
        process: crate::cell::KIND.into(),
        cell: cell.name.clone(),
        configuration: cell.configuration,
        motion: cell.motion,
        optimizer: info.optimizer.clone(),
        collision_avoidance: cell.robots.len() == 2 && cell.collision_avoidance,
        seed: info.seed,
        bins,
        devices,
        placements,
        robots,
        cycle_time_s: s.makespan,
        lower_bound_s: info.lower_bound_s,
        compute_s: info.compute_s,
        evaluations: info.evaluations,
    }
}

/// A robot's totals from its moves and its picks and placements (also used by the verifier on
/// the document's own numbers).
pub fn robot_totals(
    device: &DeviceOut,
    name: &str,
    work: impl Iterator<Item = ([f64; 2], [f64; 2])>,
) -> RobotOut {
    let mut components = 0;
    let mut working = 0.0;
    let mut end: f64 = 0.0;
    for (pick, place) in work {
        components += 1;
        working += (pick[1] - pick[0]) + (place[1] - place[0]);
        end = end.max(place[1]);
    }
    let motion: f64 = device
        .moves
        .iter()
        .map(|m| (m.t[1].min(end) - m.t[0].min(end)).max(0.0))
        .sum();
    RobotOut {
        name: name.to_string(),
        components,
        motion_s: motion,
        working_s: working,
        waiting_s: (end - motion - working).max(0.0),
        total_s: end,
    }
}

/// Reads a PCB plan document (bounded), or says why not.
pub fn read(path: &std::path::Path) -> Result<PcbPlan, String> {
    let plan: PcbPlan = cellplan_model::document::read_json(path, MAX_PLAN_BYTES, "a PCB plan document")?;
    cellplan_model::document::check_version((&plan.format, plan.version), (FORMAT, VERSION))?;
    Ok(plan)
}

/// The JSON Schema of the document, as `docs/pcb-plan.schema.json` holds it.
pub fn schema() -> String {
    cellplan_model::document::schema_text(&schemars::schema_for!(PcbPlan))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// `docs/pcb-plan.schema.json` is the schema of these types (regenerate it with
    /// `CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-pcb schema`).
    #[test]
    fn the_schema_in_docs_is_generated_from_the_types() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/pcb-plan.schema.json");
        let schema =
            cellplan_model::document::schema_file_matches(&path, &super::schema()).unwrap_or_else(|e| {
                panic!("{e}; regenerate it with CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-pcb schema")
            });
        let required = schema["required"].as_array().unwrap();
        for key in ["placements", "devices", "cycle_time_s", "lower_bound_s"] {
            assert!(
                required.iter().any(|k| k == key),
                "{key} not required: {required:?}"
            );
        }
    }
}
