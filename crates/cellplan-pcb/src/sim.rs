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
mod tests {
    use super::*;
    use crate::cell::Configuration;
    use crate::testing::random_cell;

    use crate::testing::random_decision;

    /// Paper 004 eq. 1–7 (one robot), literally: cycle by cycle, with the CDS off time of eq. 5
    /// and 6 and the table off time of eq. 4.
    fn paper_one_robot(cell: &PcbCell, d: &Decision) -> f64 {
        let v = cell.robots[0].drive.speed;
        let slot_of = slot_lookup(cell, d);
        let mut c_cycles: Vec<f64> = Vec::new();
        let mut place_part: Vec<f64> = Vec::new();
        let mut feeder_last: [Option<usize>; 2] = [None, None];
        let mut feeder_pos = [cell.feeders[0].home, cell.feeders[1].home];
        let mut robot = cell.robots[0].home;
        let mut table = cell.table.home;
        for (i, &c) in d.order.iter().enumerate() {
            let f = d.feeder[c];
            let slot = slot_of[f][cell.type_of[c]].unwrap();
            let k_pt = [cell.feeders[f].x, cell.feeders[f].bin_y(d.carriage[c], slot)];
            let p_pt = [
                d.table[c][0] + cell.components[c].position[0],
                d.table[c][1] + cell.components[c].position[1],
            ];
            let pk_r = dist(robot, k_pt) / v;
            let d_t = (d.carriage[c] - feeder_pos[f]).abs() / cell.feeders[f].drive.speed;
            let off_d = match feeder_last[f] {
                Some(k) if k + 1 == i => place_part[k],
                Some(k) => c_cycles[k + 1..i].iter().sum::<f64>() + place_part[k],
                None => c_cycles.iter().sum::<f64>(),
            };
            let pick_c = pk_r.max(d_t - off_d) + cell.pick_time;
            let off_t = pick_c;
            let pl_r = dist(k_pt, p_pt) / v;
            let t_t = dist(table, d.table[c]) / cell.table.drive.speed;
            let place_c = pl_r.max(t_t - off_t) + cell.place_time;
            c_cycles.push(pick_c + place_c);
            place_part.push(place_c);
            feeder_last[f] = Some(i);
            feeder_pos[f] = d.carriage[c];
            robot = p_pt;
            table = d.table[c];
        }
        c_cycles.iter().sum()
    }

    /// Paper 004 eq. 8–15 (two robots, no collision avoidance), literally.
    fn paper_two_robots(cell: &PcbCell, d: &Decision) -> f64 {
        let slot_of = slot_lookup(cell, d);
        let mut c_cycles: Vec<f64> = Vec::new();
        let mut first_part: Vec<f64> = Vec::new();
        let mut robot_last: [Option<usize>; 2] = [None, None];
        let mut feeder_last: [Option<usize>; 2] = [None, None];
        let mut feeder_pos = [cell.feeders[0].home, cell.feeders[1].home];
        let mut robot = [cell.robots[0].home, cell.robots[1].home];
        let mut table = cell.table.home;
        for (i, &c) in d.order.iter().enumerate() {
            let (r, f) = (d.robot[c], d.feeder[c]);
            let v = cell.robots[r].drive.speed;
            let slot = slot_of[f][cell.type_of[c]].unwrap();
            let k_pt = [cell.feeders[f].x, cell.feeders[f].bin_y(d.carriage[c], slot)];
            let p_pt = [
                d.table[c][0] + cell.components[c].position[0],
                d.table[c][1] + cell.components[c].position[1],
            ];
            let pk_t = dist(robot[r], k_pt) / v;
            // Eq. 10–11.
            let off_r = match robot_last[r] {
                Some(k) if k + 1 == i => 0.0,
                Some(k) => c_cycles[k + 1..i].iter().sum(),
                None => c_cycles.iter().sum(),
            };
            // Eq. 12–13.
            let d_t = (d.carriage[c] - feeder_pos[f]).abs() / cell.feeders[f].drive.speed;
            let off_d = match feeder_last[f] {
                Some(k) => c_cycles[k..i].iter().sum::<f64>() - first_part[k] - cell.pick_time,
                None => c_cycles.iter().sum(),
            };
            let first = (pk_t - off_r).max(d_t - off_d); // eq. 9
            let r_t = first + cell.pick_time + dist(k_pt, p_pt) / v; // eq. 15
            let t_t = dist(table, d.table[c]) / cell.table.drive.speed;
            c_cycles.push(r_t.max(t_t) + cell.place_time); // eq. 8
            first_part.push(first);
            robot_last[r] = Some(i);
            feeder_last[f] = Some(i);
            feeder_pos[f] = d.carriage[c];
            robot[r] = p_pt;
            table = d.table[c];
        }
        c_cycles.iter().sum()
    }

    #[test]
    fn resuming_one_robot_simulations_from_a_state_gives_the_same_time() {
        for seed in 0..10 {
            for conf in Configuration::ALL {
                let cell = random_cell(20, 5, 1, conf, seed);
                let mut d = random_decision(&cell, seed);
                let _ = crate::search::fix_devices(&cell, &mut d, None);
                let slot_of = slot_lookup(&cell, &d);
                for greedy in [false, true] {
                    let full = if greedy {
                        simulate(&cell, &d, &mut crate::rendezvous::Greedy, DelayRule::Off).makespan
                    } else {
                        simulate(&cell, &d, &mut Given(&d), DelayRule::Off).makespan
                    };
                    let mut states = vec![blank_state(); d.order.len() + 1];
                    let least = least_cycles(&cell);
                    let run = |states: &mut [State], from: usize, cutoff: f64| {
                        if greedy {
                            one_robot_from(
                                &cell,
                                &d,
                                &slot_of,
                                &mut crate::rendezvous::Greedy,
                                states,
                                from,
                                cutoff,
                                &least,
                            )
                        } else {
                            one_robot_from(&cell, &d, &slot_of, &mut Given(&d), states, from, cutoff, &least)
                        }
                    };
                    let whole = run(&mut states, 0, f64::INFINITY).unwrap();
                    assert!(
                        (whole - full).abs() < 1e-12,
                        "{conf:?} {greedy}: {whole} vs {full}"
                    );
                    let resumed = run(&mut states, 11, f64::INFINITY).unwrap();
                    assert!((resumed - full).abs() < 1e-12);
                    assert_eq!(run(&mut states, 0, full - 1e-6), None, "the cutoff stops it");
                    assert!(run(&mut states, 0, full + 1e-9).is_some());
                }
            }
        }
    }

    #[test]
    fn event_simulation_is_the_papers_equations() {
        for seed in 0..20 {
            let cell = random_cell(15, 4, 1, Configuration::AllMoving, seed);
            let d = random_decision(&cell, seed);
            let s = simulate(&cell, &d, &mut Given(&d), DelayRule::Off);
            let paper = paper_one_robot(&cell, &d);
            assert!(
                (s.makespan - paper).abs() < 1e-9,
                "one robot, seed {seed}: {} vs {paper}",
                s.makespan
            );
            let cell = random_cell(15, 4, 2, Configuration::AllMoving, seed);
            let d = random_decision(&cell, seed + 100);
            let s = simulate(&cell, &d, &mut Given(&d), DelayRule::Off);
            let paper = paper_two_robots(&cell, &d);
            assert!(
                (s.makespan - paper).abs() < 1e-9,
                "two robots, seed {seed}: {} vs {paper}",
                s.makespan
            );
        }
    }

    /// Robot X at time `t` from the schedule alone (independent of the tracks).
    fn robot_x(cell: &PcbCell, s: &Schedule, r: usize, t: f64) -> f64 {
        let mut pos = cell.robots[r].home;
        let mut segments = Vec::new();
        let mine: Vec<&Cycle> = s.cycles.iter().filter(|c| c.robot == r).collect();
        for cy in &mine {
            segments.push((cy.robot_leaves, cy.robot_at_pick, pos, cy.pick_point));
            segments.push((
                cy.pick[1] + cy.safety_delay,
                cy.robot_at_place,
                cy.pick_point,
                cy.place_point,
            ));
            pos = cy.place_point;
        }
        if let Some(last) = mine.last() {
            let back = last.place[1] + dist(pos, cell.robots[r].home) / cell.robots[r].drive.speed;
            segments.push((last.place[1], back, pos, cell.robots[r].home));
        }
        let mut x = cell.robots[r].home[0];
        for (t0, t1, a, b) in segments {
            if t >= t1 {
                x = b[0];
            } else if t > t0 {
                let f = (t - t0) / (t1 - t0);
                x = a[0] + f * (b[0] - a[0]);
            }
        }
        x
    }

    #[test]
    fn safety_delays_keep_the_gap_and_the_exact_rule_waits_less() {
        let mut crossings_without = 0;
        for seed in 0..12 {
            let cell = random_cell(20, 5, 2, Configuration::AllMoving, seed);
            let d = random_decision(&cell, seed);
            for rule in [DelayRule::Off, DelayRule::Paper, DelayRule::Exact] {
                let s = simulate(&cell, &d, &mut Given(&d), rule);
                let end = s.makespan + 1.0;
                let mut worst = f64::INFINITY;
                let steps = 20_000;
                for k in 0..=steps {
                    let t = end * k as f64 / steps as f64;
                    worst = worst.min(robot_x(&cell, &s, 1, t) - robot_x(&cell, &s, 0, t));
                }
                if rule == DelayRule::Off {
                    crossings_without += usize::from(worst < cell.safety_gap - 1e-9);
                } else {
                    assert!(
                        worst >= cell.safety_gap - 1e-9,
                        "seed {seed} {rule:?}: gap {worst}"
                    );
                }
            }
            let paper = simulate(&cell, &d, &mut Given(&d), DelayRule::Paper);
            let exact = simulate(&cell, &d, &mut Given(&d), DelayRule::Exact);
            assert!(exact.cycles[0].safety_delay <= paper.cycles[0].safety_delay + 1e-12);
        }
        assert!(
            crossings_without > 0,
            "the random cells must need collision avoidance at all"
        );
    }
}

/// The devices' state between two cycles of a one-robot cell: what [`simulate`] carries from
/// one cycle to the next. `states[k]` is the state before cycle `k` (before its pick is
/// chosen), so a decision that differs from another only from position `k` of the order on
/// can be simulated from `states[k]` on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    robot: ([f64; 2], f64),
    feeders: [(f64, f64); 2],
    table: ([f64; 2], f64),
}

/// [`simulate`]'s assembly time for a one-robot cell, from `states[from]` on (filling
/// `states[from + 1..]`), stopping with `None` as soon as the time cannot end at or below
/// `cutoff`: each component's cycle takes at least `least[c]` ([`least_cycles`]). `states`
/// must hold `order.len() + 1` entries; with `from = 0` the first is set here.
#[allow(clippy::too_many_arguments)]
pub fn one_robot_from(
    cell: &PcbCell,
    d: &Decision,
    slot_of: &[Vec<Option<usize>>; 2],
    rv: &mut dyn Rendezvous,
    states: &mut [State],
    from: usize,
    cutoff: f64,
    least: &[f64],
) -> Option<f64> {
    let mut rest: f64 = if cutoff.is_finite() {
        d.order[from..].iter().map(|&c| least[c]).sum()
    } else {
        0.0
    };
    let model = cell.motion;
    let n = d.order.len();
    let fixed_feeders = !cell.configuration.feeders_move();
    let fixed_table = !cell.configuration.table_moves();
    if from == 0 {
        let mut feeders = [(cell.feeders[0].home, 0.0), (cell.feeders[1].home, 0.0)];
        if fixed_feeders {
            for (f, slot) in feeders.iter_mut().enumerate() {
                if let Some(&c) = d.order.iter().find(|&&c| d.feeder[c] == f) {
                    slot.0 = d.carriage[c];
                }
            }
        }
        let mut table = cell.table.home;
        if fixed_table && let Some(&c) = d.order.first() {
            table = d.table[c];
        }
        states[0] = State {
            robot: (cell.robots[0].home, 0.0),
            feeders,
            table: (table, 0.0),
        };
    }
    let robot = &cell.robots[0];
    let mut s = states[from];
    for (k, &c) in d.order.iter().enumerate().skip(from) {
        let f = d.feeder[c];
        let slot = slot_of[f][cell.type_of[c]].unwrap_or(0);
        let feeder = &cell.feeders[f];
        let now = Now {
            robot: s.robot,
            feeder: s.feeders[f],
            table: s.table,
        };
        let carriage = if fixed_feeders {
            s.feeders[f].0
        } else {
            rv.carriage(cell, c, 0, f, slot, &now)
        };
        let pick_point = [feeder.x, feeder.bin_y(carriage, slot)];
        let robot_at_pick = s.robot.1 + robot.drive.time(model, dist(s.robot.0, pick_point));
        let feeder_at_pick = s.feeders[f].1 + feeder.drive.time(model, carriage - s.feeders[f].0);
        let pick_end = robot_at_pick.max(feeder_at_pick) + cell.pick_time;
        let now = Now {
            robot: (pick_point, pick_end),
            feeder: (carriage, pick_end),
            table: s.table,
        };
        let table = if fixed_table {
            s.table.0
        } else {
            rv.table(cell, c, 0, pick_point, pick_end, &now)
        };
        let b = cell.components[c].position;
        let place_point = [table[0] + b[0], table[1] + b[1]];
        let robot_at_place = pick_end + robot.drive.time(model, dist(pick_point, place_point));
        let table_at_place = s.table.1 + cell.table.drive.time(model, dist(s.table.0, table));
        let place_end = robot_at_place.max(table_at_place) + cell.place_time;
        s.robot = (place_point, place_end);
        s.feeders[f] = (carriage, pick_end);
        s.table = (table, place_end);
        states[k + 1] = s;
        rest -= least[c];
        if place_end + rest.max(0.0) * (1.0 - 1e-12) > cutoff {
            return None;
        }
    }
    Some(s.robot.1.max(if n == 0 { 0.0 } else { s.table.1 }))
}

/// Per component, a least time of its cycle in a one-robot cell: pick, place, and the move
/// from its pick line to where it is placed (at least the X distance from the nearer feeder
/// line to the component's reachable place points).
pub fn least_cycles(cell: &PcbCell) -> Vec<f64> {
    let v = cell.robots[0].drive.speed;
    (0..cell.len())
        .map(|c| {
            let b = cell.components[c].position[0];
            let m = cell.place_box(0, c).map_or(0.0, |bx| {
                let (lo, hi) = (bx[0][0] + b, bx[0][1] + b);
                cell.feeders
                    .iter()
                    .map(|f| {
                        if f.x < lo {
                            lo - f.x
                        } else if f.x > hi {
                            f.x - hi
                        } else {
                            0.0
                        }
                    })
                    .fold(f64::INFINITY, f64::min)
            });
            cell.pick_time + cell.place_time + m / v
        })
        .collect()
}

/// An empty state (to size buffers for [`one_robot_from`]).
pub fn blank_state() -> State {
    State {
        robot: ([0.0; 2], 0.0),
        feeders: [(0.0, 0.0); 2],
        table: ([0.0; 2], 0.0),
    }
}
