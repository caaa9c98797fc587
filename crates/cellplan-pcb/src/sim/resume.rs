//! Resuming a one-robot simulation from the state between two cycles, and stopping it as
//! soon as it cannot end below a cutoff: the inner loop of our search.
use super::{Decision, Now, Rendezvous, dist};
use crate::cell::PcbCell;

/// The devices' state between two cycles of a one-robot cell: what
/// [`simulate`](super::simulate) carries from one cycle to the next. `states[k]` is the state
/// before cycle `k` (before its pick is chosen), so a decision that differs from another only
/// from position `k` of the order on can be simulated from `states[k]` on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    robot: ([f64; 2], f64),
    feeders: [(f64, f64); 2],
    table: ([f64; 2], f64),
}

/// [`simulate`](super::simulate)'s assembly time for a one-robot cell, from `states[from]` on
/// (filling `states[from + 1..]`), stopping with `None` as soon as the time cannot end at or
/// below `cutoff`: each component's cycle takes at least `least[c]` ([`least_cycles`]).
/// `states` must hold `order.len() + 1` entries; with `from = 0` the first is set here.
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
