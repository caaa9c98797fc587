//! The PCB-assembly cell (`[process] kind = "pcb-assembly"`): one or two X–Y gantry placement
//! robots, two 1-DOF component delivery systems (CDS, "feeders") moving in Y with bins at a
//! pitch, an X–Y table carrying the board (paper 004, Fig. 1 and Fig. 6). `docs/cell-format.md`
//! documents every key; keep the two in step.
//!
//! World frame: x to the right, y away from the operator, SI units inside. Feeder 1 stands left
//! of the table (lower x), feeder 2 right. With two robots, robot 1 serves feeder 1 and robot 2
//! feeder 2; they share one X axis and may not cross: robot 1 stays at least the safety gap left
//! of robot 2.
use crate::board::{self, Component};
use serde::Deserialize;
use std::ops::Range;
use std::path::PathBuf;

mod load;
pub use load::{DEFAULT_ACCELERATION, FEEDER_SPEED, ROBOT_SPEED, TABLE_SPEED, load};

/// The `[process] kind` of this process.
pub const KIND: &str = "pcb-assembly";
/// Most bins per feeder.
pub const MAX_BINS: usize = 1000;

/// Which devices move (paper 004 §3.2: the software runs the four single-robot set-ups; the
/// fixed devices' positions are then optimised once for the whole board).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Deserialize,
    serde::Serialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Configuration {
    /// Feeders and table stand still.
    AllFixed,
    /// The feeders move, the table stands still.
    MovingCds,
    /// The table moves, the feeders stand still.
    MovingTable,
    /// Feeders and table move.
    AllMoving,
}

impl Configuration {
    /// All four, in the paper's order.
    pub const ALL: [Configuration; 4] = [
        Configuration::AllFixed,
        Configuration::MovingCds,
        Configuration::MovingTable,
        Configuration::AllMoving,
    ];

    /// Whether the feeders move.
    pub fn feeders_move(self) -> bool {
        matches!(self, Configuration::MovingCds | Configuration::AllMoving)
    }

    /// Whether the table moves.
    pub fn table_moves(self) -> bool {
        matches!(self, Configuration::MovingTable | Configuration::AllMoving)
    }

    /// The name in files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Configuration::AllFixed => "all-fixed",
            Configuration::MovingCds => "moving-cds",
            Configuration::MovingTable => "moving-table",
            Configuration::AllMoving => "all-moving",
        }
    }
}

/// How a device moves between two points: straight line, at most its speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum MotionModel {
    /// Full speed at once (the paper's assumption).
    ConstantSpeed,
    /// Accelerate, cruise, decelerate (each device's `acceleration`).
    Trapezoid,
}

/// How fast a device moves.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, schemars::JsonSchema)]
pub struct Drive {
    /// Top speed (m/s).
    pub speed: f64,
    /// Acceleration (m/s²); used by the trapezoid model.
    pub acceleration: f64,
}

impl Drive {
    /// Time to move a distance `d` (m) from rest to rest.
    pub fn time(&self, model: MotionModel, d: f64) -> f64 {
        let d = d.abs();
        match model {
            MotionModel::ConstantSpeed => d / self.speed,
            MotionModel::Trapezoid => {
                let (v, a) = (self.speed, self.acceleration);
                if d * a >= v * v {
                    d / v + v / a
                } else {
                    2.0 * (d / a).sqrt()
                }
            }
        }
    }

    /// Distance covered `t` seconds into a rest-to-rest move of length `d`.
    pub fn progress(&self, model: MotionModel, d: f64, t: f64) -> f64 {
        let total = self.time(model, d);
        if t <= 0.0 {
            return 0.0;
        }
        if t >= total {
            return d;
        }
        match model {
            MotionModel::ConstantSpeed => self.speed * t,
            MotionModel::Trapezoid => {
                let a = self.acceleration;
                let ramp = (self.speed / a).min(total / 2.0);
                let peak = a * ramp;
                if t <= ramp {
                    0.5 * a * t * t
                } else if t <= total - ramp {
                    0.5 * a * ramp * ramp + peak * (t - ramp)
                } else {
                    let r = total - t;
                    d - 0.5 * a * r * r
                }
            }
        }
    }

    /// Time at which a rest-to-rest move of length `d` has covered `s` (0 ≤ s ≤ d).
    pub fn time_at(&self, model: MotionModel, d: f64, s: f64) -> f64 {
        let total = self.time(model, d);
        if s <= 0.0 {
            return 0.0;
        }
        if s >= d {
            return total;
        }
        match model {
            MotionModel::ConstantSpeed => s / self.speed,
            MotionModel::Trapezoid => {
                let a = self.acceleration;
                let ramp = (self.speed / a).min(total / 2.0);
                let ramp_d = 0.5 * a * ramp * ramp;
                if s <= ramp_d {
                    (2.0 * s / a).sqrt()
                } else if s <= d - ramp_d {
                    ramp + (s - ramp_d) / (a * ramp)
                } else {
                    total - (2.0 * (d - s) / a).sqrt()
                }
            }
        }
    }
}

/// A placement robot: an X–Y gantry with a pick-and-place head.
#[derive(Clone, Debug, PartialEq, serde::Serialize, schemars::JsonSchema)]
pub struct Robot {
    /// Name.
    pub name: String,
    /// Drive.
    pub drive: Drive,
    /// Where it starts (m).
    pub home: [f64; 2],
    /// X travel (m), already narrowed so that it never reaches the other robot's feeder.
    pub x: [f64; 2],
    /// X travel as the cell gives it (m).
    pub x_given: [f64; 2],
    /// Y travel (m).
    pub y: [f64; 2],
}

/// A component delivery system: a carriage moving in Y at a fixed X, with bins at a pitch.
#[derive(Clone, Debug, PartialEq, serde::Serialize, schemars::JsonSchema)]
pub struct Feeder {
    /// Name.
    pub name: String,
    /// X of its pick line (m).
    pub x: f64,
    /// Travel of its carriage: the Y of bin 0 (m).
    pub travel: [f64; 2],
    /// Carriage position at the start (m).
    pub home: f64,
    /// Number of bins.
    pub bins: usize,
    /// Distance from one bin to the next, along +Y (m).
    pub pitch: f64,
    /// Drive.
    pub drive: Drive,
}

impl Feeder {
    /// Y of bin `slot` with the carriage at `carriage`.
    pub fn bin_y(&self, carriage: f64, slot: usize) -> f64 {
        carriage + slot as f64 * self.pitch
    }
}

/// The X–Y table carrying the board; its position is that of the board's origin.
#[derive(Clone, Debug, PartialEq, serde::Serialize, schemars::JsonSchema)]
pub struct Table {
    /// X travel of the board origin (m).
    pub x: [f64; 2],
    /// Y travel of the board origin (m).
    pub y: [f64; 2],
    /// Position at the start (m).
    pub home: [f64; 2],
    /// Drive.
    pub drive: Drive,
}

/// A component type: what a bin holds.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, schemars::JsonSchema)]
pub struct ComponentType {
    /// Footprint.
    pub footprint: String,
    /// Value.
    pub value: String,
}

/// A bin given in the cell (`[[process.bins]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct GivenBin {
    /// Feeder index.
    pub feeder: usize,
    /// Bin index.
    pub slot: usize,
    /// Type index.
    pub kind: usize,
}

/// A loaded PCB-assembly cell.
#[derive(Clone, Debug)]
pub struct PcbCell {
    /// Name for reports.
    pub name: String,
    /// The cell file.
    pub path: PathBuf,
    /// The board as read.
    pub board: board::Board,
    /// The components to place (board frame of the populated side).
    pub components: Vec<Component>,
    /// Component types, sorted.
    pub types: Vec<ComponentType>,
    /// Type of each component.
    pub type_of: Vec<usize>,
    /// One or two robots, left to right.
    pub robots: Vec<Robot>,
    /// The two feeders, left to right.
    pub feeders: [Feeder; 2],
    /// The table.
    pub table: Table,
    /// Pick time per component (s).
    pub pick_time: f64,
    /// Place time per component (s).
    pub place_time: f64,
    /// Smallest X distance between the two robots (m).
    pub safety_gap: f64,
    /// Whether two robots are kept apart (the paper's collision avoidance; off only to show
    /// what it costs — the verifier then reports the crossings).
    pub collision_avoidance: bool,
    /// The configuration `plan` uses.
    pub configuration: Configuration,
    /// The motion model.
    pub motion: MotionModel,
    /// Bins fixed by the cell (empty: the optimiser chooses).
    pub given_bins: Vec<GivenBin>,
}

impl PcbCell {
    /// Number of components.
    pub fn len(&self) -> usize {
        self.components.len()
    }

    /// Whether there is nothing to place.
    pub fn is_empty(&self) -> bool {
        self.components.is_empty()
    }

    /// The same cell run another way: with its first robot alone (`robots` = 1 on a two-robot
    /// cell, the robot then reaching both feeders), in another configuration or motion model.
    pub fn variant(
        &self,
        robots: usize,
        configuration: Configuration,
        motion: MotionModel,
    ) -> Result<PcbCell, String> {
        let mut cell = self.clone();
        match (robots, self.robots.len()) {
            (1, 2) => {
                cell.robots.truncate(1);
                cell.robots[0].x = cell.robots[0].x_given;
                cell.collision_avoidance = false;
            }
            (a, b) if a == b => {}
            (a, b) => {
                return Err(format!(
                    "the cell has {b} robot(s); it cannot be planned with {a}"
                ));
            }
        }
        cell.configuration = configuration;
        cell.motion = motion;
        cell.reachable()?;
        Ok(cell)
    }

    /// Every bin reachable by a robot that serves its feeder, every component placeable by
    /// some robot.
    pub fn reachable(&self) -> Result<(), String> {
        for f in 0..2 {
            for slot in 0..self.feeders[f].bins {
                if !(0..self.robots.len())
                    .any(|r| self.feeders_of(r).contains(&f) && self.pick_range(r, f, slot).is_some())
                {
                    return Err(format!(
                        "bin {slot} of feeder {} is out of the robots' reach",
                        self.feeders[f].name
                    ));
                }
            }
        }
        for c in 0..self.len() {
            if !(0..self.robots.len()).any(|r| self.place_box(r, c).is_some()) {
                return Err(format!(
                    "component {} cannot be brought under a robot",
                    self.components[c].reference
                ));
            }
        }
        Ok(())
    }

    /// The feeders robot `r` picks from (one robot: both; two: its own).
    pub fn feeders_of(&self, r: usize) -> Range<usize> {
        if self.robots.len() == 1 { 0..2 } else { r..r + 1 }
    }

    /// The table positions at which robot `r` can place component `c`: a box, or `None`.
    pub fn place_box(&self, r: usize, c: usize) -> Option<[[f64; 2]; 2]> {
        let b = self.components[c].position;
        let robot = &self.robots[r];
        let x = [
            self.table.x[0].max(robot.x[0] - b[0]),
            self.table.x[1].min(robot.x[1] - b[0]),
        ];
        let y = [
            self.table.y[0].max(robot.y[0] - b[1]),
            self.table.y[1].min(robot.y[1] - b[1]),
        ];
        (x[0] <= x[1] && y[0] <= y[1]).then_some([x, y])
    }

    /// The carriage positions at which robot `r` can pick from bin `slot` of feeder `f`.
    pub fn pick_range(&self, r: usize, f: usize, slot: usize) -> Option<[f64; 2]> {
        let feeder = &self.feeders[f];
        let robot = &self.robots[r];
        let off = slot as f64 * feeder.pitch;
        let lo = feeder.travel[0].max(robot.y[0] - off);
        let hi = feeder.travel[1].min(robot.y[1] - off);
        (lo <= hi && (robot.x[0]..=robot.x[1]).contains(&feeder.x)).then_some([lo, hi])
    }
}
