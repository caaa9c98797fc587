//! The cycle-time model of paper 004 (§3.1 eq. 1–7 for one robot, §4.1–4.2 eq. 8–16 for two),
//! written as the event simulation it describes: every device leaves for its next rendezvous as
//! soon as it is free (the robot right after a placement, a feeder right after a pick, the table
//! right after a placement), a pick starts when robot and feeder are both there, a placement when
//! robot and table are. `tests::event_simulation_is_the_papers_equations` checks that this is the
//! same number as the paper's sums of cycle times.
//!
//! Two robots share one X axis ("walls", Fig. 7): before a robot leaves its pick for the
//! placement, it waits (the safety delay of eq. 16) until the other robot, as far as its motion is
//! known, has left every X level it is about to enter. [`DelayRule::Paper`] is the paper's rule —
//! wait until the other robot has left the whole overlap region before entering it —;
//! [`DelayRule::Exact`] the least delay that keeps the gap at every level (equal or shorter).
use crate::cell::{MotionModel, PcbCell};

mod resume;
pub use resume::{State, blank_state, least_cycles, one_robot_from};

/// Where the devices meet for one component, and who does it.
#[derive(Clone, Debug, PartialEq)]
pub struct Decision {
    /// Components in placement order.
    pub order: Vec<usize>,
    /// Robot of each component.
    pub robot: Vec<usize>,
    /// Feeder each component is picked from.
    pub feeder: Vec<usize>,
    /// Per feeder, per bin: the type it holds.
    pub slots: [Vec<Option<usize>>; 2],
    /// Per component: the feeder carriage position (Y of bin 0) at its pick (m).
    pub carriage: Vec<f64>,
    /// Per component: the table position at its placement (m).
    pub table: Vec<[f64; 2]>,
}

/// How the safety delay is found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DelayRule {
    /// No delay (collision avoidance off: the robots may cross).
    Off,
    /// Paper 004 §4.2: wait until the other robot has left the overlap region.
    Paper,
    /// The least wait that keeps the gap at every X level (constant-speed model; the trapezoid
    /// model uses the paper's rule).
    Exact,
}

/// One cycle as simulated.
#[derive(Clone, Debug, PartialEq)]
pub struct Cycle {
    /// Component.
    pub component: usize,
    /// Robot.
    pub robot: usize,
    /// Feeder.
    pub feeder: usize,
    /// Bin.
    pub slot: usize,
    /// Carriage position at the pick (m).
    pub carriage: f64,
    /// Table position at the placement (m).
    pub table: [f64; 2],
    /// Pick point (m).
    pub pick_point: [f64; 2],
    /// Place point (m).
    pub place_point: [f64; 2],
    /// When the robot left for the pick (its previous placement's end, or 0).
    pub robot_leaves: f64,
    /// When it arrived at the pick point.
    pub robot_at_pick: f64,
    /// When the feeder left for the pick (its previous pick's end, or 0).
    pub feeder_leaves: f64,
    /// When the bin arrived at the pick point.
    pub feeder_at_pick: f64,
    /// Pick start and end.
    pub pick: [f64; 2],
    /// Safety delay after the pick (eq. 16).
    pub safety_delay: f64,
    /// When the robot arrived at the place point.
    pub robot_at_place: f64,
    /// When the table left for this placement (the previous placement's end, or 0).
    pub table_leaves: f64,
    /// When it arrived.
    pub table_at_place: f64,
    /// Place start and end.
    pub place: [f64; 2],
}

/// The result of a simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Cycles in placement order.
    pub cycles: Vec<Cycle>,
    /// Assembly time: the end of the last placement (s).
    pub makespan: f64,
}

/// The devices' state before a cycle, for a rendezvous chooser.
#[derive(Clone, Copy, Debug)]
pub struct Now {
    /// Robot position and when it is free.
    pub robot: ([f64; 2], f64),
    /// Feeder carriage position and when it is free.
    pub feeder: (f64, f64),
    /// Table position and when it is free.
    pub table: ([f64; 2], f64),
}

/// Chooses the rendezvous of a cycle.
pub trait Rendezvous {
    /// Carriage position for the pick of `component` from `slot`, given the state.
    fn carriage(
        &mut self,
        cell: &PcbCell,
        component: usize,
        robot: usize,
        feeder: usize,
        slot: usize,
        now: &Now,
    ) -> f64;
    /// Table position for its placement, given the pick point and the pick's end.
    fn table(
        &mut self,
        cell: &PcbCell,
        component: usize,
        robot: usize,
        pick_point: [f64; 2],
        pick_end: f64,
        now: &Now,
    ) -> [f64; 2];
}

/// The rendezvous the decision states.
pub struct Given<'a>(pub &'a Decision);

impl Rendezvous for Given<'_> {
    fn carriage(&mut self, _: &PcbCell, c: usize, _: usize, _: usize, _: usize, _: &Now) -> f64 {
        self.0.carriage[c]
    }
    fn table(&mut self, _: &PcbCell, c: usize, _: usize, _: [f64; 2], _: f64, _: &Now) -> [f64; 2] {
        self.0.table[c]
    }
}

pub(crate) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Tolerance of the X levels of the safety delay (m).
const LEVEL_TOL: f64 = 1e-9;

/// One straight move of a robot, as the X track sees it.
#[derive(Clone, Copy, Debug)]
struct Piece {
    t0: f64,
    t1: f64,
    x0: f64,
    x1: f64,
    /// Path length of the move (0 for a stay).
    len: f64,
}

/// A robot's X over time, as far as it is known, and where it stays afterwards.
#[derive(Clone, Debug, Default)]
struct Track {
    pieces: Vec<Piece>,
}

impl Track {
    /// The last time at or after `from` at which the robot (in mirrored coordinates where it
    /// stands right of the other) is at or left of `level`; `None` if never (as known).
    fn last_at_or_below(
        &self,
        level: f64,
        from: f64,
        drive: &crate::cell::Drive,
        model: MotionModel,
    ) -> Option<f64> {
        let start = self.pieces.partition_point(|p| p.t1 < from);
        let mut last: Option<f64> = None;
        // Levels are computed as `x − gap + gap`, which rounding may leave a hair below `x`:
        // positions up to LEVEL_TOL above the level count as at it (conservative).
        let up = level + LEVEL_TOL;
        for p in &self.pieces[start..] {
            let t = if p.t1.is_infinite() {
                // The last known stay, at the robot's own feeder or home: a conflict only if it
                // is strictly inside the gap (which the cell's travel limits rule out).
                (p.x1 < level - LEVEL_TOL).then_some(f64::INFINITY)
            } else if p.x1 <= up {
                Some(p.t1)
            } else if p.x0 <= up {
                // Moving away (x1 > level ≥ x0): the crossing.
                let frac = ((up - p.x0) / (p.x1 - p.x0)).clamp(0.0, 1.0);
                Some(p.t0 + drive.time_at(model, p.len, frac * p.len))
            } else {
                None
            };
            if let Some(t) = t {
                last = Some(last.map_or(t, |l: f64| l.max(t)));
            }
        }
        last
    }

    /// Lowest X (mirrored) the robot occupies at or after `from`.
    fn lowest_after(&self, from: f64) -> f64 {
        let start = self.pieces.partition_point(|p| p.t1 < from);
        self.pieces[start..]
            .iter()
            .map(|p| p.x0.min(p.x1))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Simulates a decision with the rendezvous `rv` chooses.
///
/// A robot's next pick is chosen when its previous placement ends (or at the start), since it
/// leaves for it at once; with two robots each feeder belongs to one robot, so the feeder's
/// state is already final then. The table position is chosen at the pick's end.
pub fn simulate(cell: &PcbCell, d: &Decision, rv: &mut dyn Rendezvous, rule: DelayRule) -> Schedule {
    let model = cell.motion;
    let n_robots = cell.robots.len();
    let fixed_feeders = !cell.configuration.feeders_move();
    let fixed_table = !cell.configuration.table_moves();
    let mut robot_pos: Vec<[f64; 2]> = cell.robots.iter().map(|r| r.home).collect();
    let mut robot_free = vec![0.0; n_robots];
    let mut feeder_pos = [cell.feeders[0].home, cell.feeders[1].home];
    let mut table_pos = cell.table.home;
    // A fixed feeder or table stands where the decision puts it from the start.
    if fixed_feeders {
        for (f, pos) in feeder_pos.iter_mut().enumerate() {
            if let Some(&c) = d.order.iter().find(|&&c| d.feeder[c] == f) {
                *pos = d.carriage[c];
            }
        }
    }
    if fixed_table && let Some(&c) = d.order.first() {
        table_pos = d.table[c];
    }
    let mut feeder_free = [0.0f64; 2];
    let mut table_free = 0.0f64;
    let slot_of = slot_lookup(cell, d);
    let next_of = next_of_robot(d, n_robots);
    // Each robot's next pick: (carriage, pick point), chosen when it leaves for it.
    let mut next_pick: Vec<Option<(f64, [f64; 2])>> = vec![None; n_robots];
    // Mirrored X tracks, stored as the other robot sees them (this robot to its right).
    let mut tracks: Vec<Track> = vec![Track::default(); n_robots];
    let choose = |rv: &mut dyn Rendezvous, c: usize, r: usize, now: &Now, feeder_pos: &[f64; 2]| {
        let f = d.feeder[c];
        let slot = slot_of[f][cell.type_of[c]].unwrap_or(0);
        let carriage = if fixed_feeders {
            feeder_pos[f]
        } else {
            rv.carriage(cell, c, r, f, slot, now)
        };
        (
            carriage,
            [cell.feeders[f].x, cell.feeders[f].bin_y(carriage, slot)],
        )
    };
    let mirror = |r: usize, x: f64| if r == 0 { -x } else { x };
    for r in 0..n_robots {
        let first = d.order.iter().copied().find(|&c| d.robot[c] == r);
        let target = match first {
            Some(c) => {
                let f = d.feeder[c];
                let now = Now {
                    robot: (robot_pos[r], 0.0),
                    feeder: (feeder_pos[f], 0.0),
                    table: (table_pos, 0.0),
                };
                let pick = choose(rv, c, r, &now, &feeder_pos);
                next_pick[r] = Some(pick);
                pick.1
            }
            None => robot_pos[r],
        };
        if n_robots == 2 {
            let home = robot_pos[r];
            let arrive = cell.robots[r].drive.time(model, dist(home, target));
            let t = &mut tracks[r];
            t.pieces.push(Piece {
                t0: 0.0,
                t1: arrive,
                x0: mirror(r, home[0]),
                x1: mirror(r, target[0]),
                len: dist(home, target),
            });
            t.pieces.push(Piece {
                t0: arrive,
                t1: f64::INFINITY,
                x0: mirror(r, target[0]),
                x1: mirror(r, target[0]),
                len: 0.0,
            });
        }
    }
    let mut cycles = Vec::with_capacity(d.order.len());
    for (i, &c) in d.order.iter().enumerate() {
        let r = d.robot[c];
        let f = d.feeder[c];
        let slot = slot_of[f][cell.type_of[c]].unwrap_or(0);
        let feeder = &cell.feeders[f];
        let robot = &cell.robots[r];
        let (carriage, pick_point) = next_pick[r].take().unwrap_or_else(|| {
            let now = Now {
                robot: (robot_pos[r], robot_free[r]),
                feeder: (feeder_pos[f], feeder_free[f]),
                table: (table_pos, table_free),
            };
            choose(rv, c, r, &now, &feeder_pos)
        });
        let robot_leaves = robot_free[r];
        let robot_at_pick = robot_leaves + robot.drive.time(model, dist(robot_pos[r], pick_point));
        let feeder_leaves = feeder_free[f];
        let feeder_at_pick = feeder_leaves + feeder.drive.time(model, carriage - feeder_pos[f]);
        let pick_start = robot_at_pick.max(feeder_at_pick);
        let pick_end = pick_start + cell.pick_time;
        let now = Now {
            robot: (pick_point, pick_end),
            feeder: (carriage, pick_end),
            table: (table_pos, table_free),
        };
        let table = if fixed_table {
            table_pos
        } else {
            rv.table(cell, c, r, pick_point, pick_end, &now)
        };
        let b = cell.components[c].position;
        let place_point = [table[0] + b[0], table[1] + b[1]];
        let move_len = dist(pick_point, place_point);
        let move_time = robot.drive.time(model, move_len);
        let delay = if n_robots == 2 && rule != DelayRule::Off {
            let o = 1 - r;
            // In the other robot's frame this robot is the left one: its own track is stored
            // mirrored for the other, so negate back.
            let xa = -mirror(r, pick_point[0]);
            let xb = -mirror(r, place_point[0]);
            safety_delay(
                &tracks[o],
                xa,
                xb,
                pick_end,
                move_len,
                &robot.drive,
                &cell.robots[o].drive,
                model,
                cell.safety_gap,
                rule,
            )
        } else {
            0.0
        };
        let leave_pick = pick_end + delay;
        let robot_at_place = leave_pick + move_time;
        let table_leaves = table_free;
        let table_at_place = table_leaves + cell.table.drive.time(model, dist(table_pos, table));
        let place_start = robot_at_place.max(table_at_place);
        let place_end = place_start + cell.place_time;
        robot_pos[r] = place_point;
        robot_free[r] = place_end;
        feeder_pos[f] = carriage;
        feeder_free[f] = pick_end;
        table_pos = table;
        table_free = place_end;
        // The robot leaves at once for its next pick (or home).
        let target = match next_of[i] {
            Some(nc) => {
                let nf = d.feeder[nc];
                let now = Now {
                    robot: (place_point, place_end),
                    feeder: (feeder_pos[nf], feeder_free[nf]),
                    table: (table_pos, table_free),
                };
                let pick = choose(rv, nc, r, &now, &feeder_pos);
                next_pick[r] = Some(pick);
                pick.1
            }
            None => robot.home,
        };
        if n_robots == 2 {
            let t = &mut tracks[r];
            // Close the open stay at the pick, then the move to the place, the stay there, the
            // return and a new open stay.
            if let Some(last) = t.pieces.last_mut() {
                last.t1 = leave_pick;
            }
            let back = place_end + robot.drive.time(model, dist(place_point, target));
            let (xa, xp, xt) = (
                mirror(r, pick_point[0]),
                mirror(r, place_point[0]),
                mirror(r, target[0]),
            );
            t.pieces.push(Piece {
                t0: leave_pick,
                t1: robot_at_place,
                x0: xa,
                x1: xp,
                len: move_len,
            });
            t.pieces.push(Piece {
                t0: robot_at_place,
                t1: place_end,
                x0: xp,
                x1: xp,
                len: 0.0,
            });
            t.pieces.push(Piece {
                t0: place_end,
                t1: back,
                x0: xp,
                x1: xt,
                len: dist(place_point, target),
            });
            t.pieces.push(Piece {
                t0: back,
                t1: f64::INFINITY,
                x0: xt,
                x1: xt,
                len: 0.0,
            });
        }
        cycles.push(Cycle {
            component: c,
            robot: r,
            feeder: f,
            slot,
            carriage,
            table,
            pick_point,
            place_point,
            robot_leaves,
            robot_at_pick,
            feeder_leaves,
            feeder_at_pick,
            pick: [pick_start, pick_end],
            safety_delay: delay,
            robot_at_place,
            table_leaves,
            table_at_place,
            place: [place_start, place_end],
        });
    }
    let makespan = cycles.last().map_or(0.0, |c| c.place[1]);
    Schedule { cycles, makespan }
}

/// Per feeder, per type: the first bin holding it.
pub fn slot_lookup(cell: &PcbCell, d: &Decision) -> [Vec<Option<usize>>; 2] {
    let mut out = [vec![None; cell.types.len()], vec![None; cell.types.len()]];
    for (slots, found) in d.slots.iter().zip(out.iter_mut()) {
        for (s, t) in slots.iter().enumerate() {
            if let Some(t) = *t
                && t < cell.types.len()
                && found[t].is_none()
            {
                found[t] = Some(s);
            }
        }
    }
    out
}

fn next_of_robot(d: &Decision, n_robots: usize) -> Vec<Option<usize>> {
    let mut next = vec![None; d.order.len()];
    let mut upcoming: Vec<Option<usize>> = vec![None; n_robots];
    for (i, &c) in d.order.iter().enumerate().rev() {
        let r = d.robot[c];
        next[i] = upcoming[r];
        upcoming[r] = Some(c);
    }
    next
}

/// The safety delay of a robot that leaves its pick at `from` (at mirrored X `xa`) for a place
/// at mirrored X `xb`, against the other robot's mirrored track (standing right of it).
#[allow(clippy::too_many_arguments)]
fn safety_delay(
    other: &Track,
    xa: f64,
    xb: f64,
    from: f64,
    len: f64,
    drive: &crate::cell::Drive,
    other_drive: &crate::cell::Drive,
    model: MotionModel,
    gap: f64,
    rule: DelayRule,
) -> f64 {
    if xb <= xa || other.pieces.is_empty() {
        // Moving back toward its own side only widens the gap.
        return 0.0;
    }
    // τ(level): when the robot reaches mirrored X `level` on its way (undelayed).
    let tau = |level: f64| from + drive.time_at(model, len, (level - xa) / (xb - xa) * len);
    let rule = if model == MotionModel::Trapezoid && rule == DelayRule::Exact {
        DelayRule::Paper
    } else {
        rule
    };
    match rule {
        DelayRule::Off => 0.0,
        DelayRule::Paper => {
            let Some(leave) = other.last_at_or_below(xb + gap, from, other_drive, model) else {
                return 0.0;
            };
            let enter = (other.lowest_after(from) - gap).max(xa);
            if enter > xb {
                return 0.0;
            }
            (leave - tau(enter)).max(0.0)
        }
        DelayRule::Exact => {
            let start = other.pieces.partition_point(|p| p.t1 < from);
            let mut levels = vec![xa, xb];
            for p in &other.pieces[start..] {
                for x in [p.x0 - gap, p.x1 - gap] {
                    if x > xa && x < xb {
                        levels.push(x);
                    }
                }
            }
            let mut delay = 0.0f64;
            for level in levels {
                if let Some(last) = other.last_at_or_below(level + gap, from, other_drive, model) {
                    delay = delay.max(last - tau(level));
                }
            }
            delay
        }
    }
}

#[cfg(test)]
mod tests;
