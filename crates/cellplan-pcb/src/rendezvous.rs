//! Our rendezvous rule for a given order, bins and robots: each meeting placed where it ends
//! soonest, as seen from the devices' state when it is chosen.
//!
//! - The pick: the carriage position `s` minimising "pick done, then straight to where the
//!   board point would be if the table stayed" — `max(robot arrives, bin arrives) + robot's
//!   move to the place` — a one-dimensional convex function under the constant-speed model,
//!   found by golden-section search over the carriage's reachable range.
//! - The placement: the table position on the segment between where the table is and where it
//!   would bring the board point onto the pick point (clipped to what the robot reaches), the
//!   one at which robot and table meet soonest — again one-dimensional.
use crate::cell::PcbCell;
use crate::sim::{Now, Rendezvous, dist};

/// Golden-section minimum of `f` on `[lo, hi]` (`iters` steps; exact for unimodal `f`).
pub fn golden(lo: f64, hi: f64, iters: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    if hi - lo <= 1e-12 {
        return lo;
    }
    const R: f64 = 0.618_033_988_749_894_9;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iters {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = f(d);
        }
    }
    // The ends too: the optimum often sits on a travel limit.
    let mid = 0.5 * (a + b);
    let mut best = (f(mid), mid);
    for x in [lo, hi] {
        let v = f(x);
        if v < best.0 {
            best = (v, x);
        }
    }
    best.1
}

/// The greedy rule (see the module).
#[derive(Clone, Copy, Debug, Default)]
pub struct Greedy;

fn clip(v: f64, r: [f64; 2]) -> f64 {
    v.clamp(r[0], r[1])
}

impl Rendezvous for Greedy {
    fn carriage(&mut self, cell: &PcbCell, c: usize, r: usize, f: usize, slot: usize, now: &Now) -> f64 {
        let Some(range) = cell.pick_range(r, f, slot) else {
            return cell.feeders[f].home;
        };
        let model = cell.motion;
        let robot = &cell.robots[r];
        let feeder = &cell.feeders[f];
        let b = cell.components[c].position;
        let place_guess = match cell.place_box(r, c) {
            Some(bx) => [
                clip(now.table.0[0], bx[0]) + b[0],
                clip(now.table.0[1], bx[1]) + b[1],
            ],
            None => [now.table.0[0] + b[0], now.table.0[1] + b[1]],
        };
        let (rpos, rfree) = now.robot;
        let (fpos, ffree) = now.feeder;
        let off = slot as f64 * feeder.pitch;
        golden(range[0], range[1], 28, |s| {
            let k = [feeder.x, s + off];
            let at = (rfree + robot.drive.time(model, dist(rpos, k)))
                .max(ffree + feeder.drive.time(model, s - fpos));
            at + robot.drive.time(model, dist(k, place_guess))
        })
    }

    fn table(
        &mut self,
        cell: &PcbCell,
        c: usize,
        r: usize,
        pick: [f64; 2],
        pick_end: f64,
        now: &Now,
    ) -> [f64; 2] {
        let model = cell.motion;
        let b = cell.components[c].position;
        let Some(bx) = cell.place_box(r, c) else {
            return now.table.0;
        };
        let (tpos, tfree) = now.table;
        let ideal = [pick[0] - b[0], pick[1] - b[1]];
        let at = |l: f64| {
            [
                clip(tpos[0] + l * (ideal[0] - tpos[0]), bx[0]),
                clip(tpos[1] + l * (ideal[1] - tpos[1]), bx[1]),
            ]
        };
        let robot = &cell.robots[r];
        let cost = |t: [f64; 2]| {
            let p = [t[0] + b[0], t[1] + b[1]];
            (pick_end + robot.drive.time(model, dist(pick, p)))
                .max(tfree + cell.table.drive.time(model, dist(tpos, t)))
        };
        let l = golden(0.0, 1.0, 28, |l| cost(at(l)));
        at(l)
    }
}
