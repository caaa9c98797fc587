//! The coordination diagram as a certificate on the clock: where two robots may meet.
//!
//! Every pair of positions outside a pair's conflict boxes is certified clear (the diagram
//! proves the robots farther apart than the margin there, whatever the clock). A program with
//! waits moves along the same path: its position at time `t` is `t` less the waits begun
//! before (a robot waiting holds its position). So two robots on the clock can only meet while
//! both positions lie in one box at once, and the exact search on the clock
//! ([`super::timeline::PairProbe`]) need only look at those windows of time. The answers are
//! those of the exact search over the whole interval: outside the windows it could not find a
//! contact (it steps on distances the diagram bounds from below).
//!
//! A cover holds only for the paths its boxes were built on: a robot whose path changes (other
//! poses, other legs) is marked, and its pairs are searched over the whole interval again.
use super::diagram::ConflictBox;
use super::program::{Activity, Timed};

/// Positions are compared with this slack (s): a program's times with waits add up in another
/// order than without them.
const SLACK: f64 = 1e-6;

/// The conflict boxes of every robot pair, by pair, for the paths they were built on.
#[derive(Clone, Debug)]
pub struct Cover {
    /// Per robot pair `(a, b)`, `a < b` (cell indices), at `a * m + b`: the boxes as
    /// `[a from, a to, b from, b to]` (positions, s).
    boxes: Vec<Vec<[f64; 4]>>,
    /// Robots (cell indices).
    m: usize,
    /// Per robot: whether its path is still the one the boxes were built on.
    valid: Vec<bool>,
}

impl Cover {
    /// The cover of `m` robots' paths by `boxes` (every box of every pair of those paths).
    pub fn new(m: usize, boxes: &[ConflictBox]) -> Cover {
        let mut by_pair = vec![Vec::new(); m * m];
        for b in boxes {
            let (x, y) = b.robots;
            if x < y && y < m {
                by_pair[x * m + y].push([b.a.0, b.a.1, b.b.0, b.b.1]);
            }
        }
        Cover {
            boxes: by_pair,
            m,
            valid: vec![true; m],
        }
    }

    /// Robot `r`'s path is no longer the one the boxes were built on.
    pub fn invalidate(&mut self, r: usize) {
        if let Some(v) = self.valid.get_mut(r) {
            *v = false;
        }
    }

    /// The windows of `[from, until]` (merged, in order) in which robots `x` and `y`, on the
    /// clock as `tx` and `ty`, have positions inside one box of their pair; `None` when the
    /// cover does not hold for one of them (then every time may be a contact).
    pub fn windows(
        &self,
        x: usize,
        tx: &Timed,
        y: usize,
        ty: &Timed,
        from: f64,
        until: f64,
    ) -> Option<Vec<(f64, f64)>> {
        if x == y || x >= self.m || y >= self.m || !self.valid[x] || !self.valid[y] {
            return None;
        }
        let (a, b, ta, tb) = if x < y { (x, y, tx, ty) } else { (y, x, ty, tx) };
        let (ca, cb) = (Clock::new(ta), Clock::new(tb));
        let mut out: Vec<(f64, f64)> = self.boxes[a * self.m + b]
            .iter()
            .filter_map(|&[a0, a1, b0, b1]| {
                let lo = ca.first_at(a0 - SLACK).max(cb.first_at(b0 - SLACK)).max(from);
                let hi = ca.last_at(a1 + SLACK).min(cb.last_at(b1 + SLACK)).min(until);
                (lo <= hi).then_some((lo, hi))
            })
            .collect();
        out.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.total_cmp(&q.1)));
        let mut merged: Vec<(f64, f64)> = Vec::with_capacity(out.len());
        for (lo, hi) in out {
            match merged.last_mut() {
                Some(last) if lo <= last.1 => last.1 = last.1.max(hi),
                _ => merged.push((lo, hi)),
            }
        }
        Some(merged)
    }
}

/// A program's position (its time without waits) against the clock: non-decreasing and
/// continuous, rising one to one except while the robot waits; at its end it stays (home).
struct Clock {
    /// (time, position) at the start and at the end of every span.
    knots: Vec<(f64, f64)>,
}

impl Clock {
    fn new(timed: &Timed) -> Clock {
        let mut knots = Vec::with_capacity(timed.spans.len() + 1);
        let mut s = 0.0;
        knots.push((0.0, 0.0));
        for span in &timed.spans {
            if !matches!(span.what, Activity::Wait { .. }) {
                s += span.end - span.start;
            }
            knots.push((span.end, s));
        }
        Clock { knots }
    }

    /// The time on the rising piece from knot `i - 1` to knot `i` at which the position is `s`.
    fn on_piece(&self, i: usize, s: f64) -> f64 {
        let ((t0, s0), (t1, s1)) = (self.knots[i - 1], self.knots[i]);
        (t0 + (t1 - t0) * ((s - s0) / (s1 - s0))).clamp(t0, t1)
    }

    /// The earliest time at which the position is at least `s` (infinity: never).
    fn first_at(&self, s: f64) -> f64 {
        let i = self.knots.partition_point(|k| k.1 < s);
        match i {
            0 => self.knots[0].0,
            i if i == self.knots.len() => f64::INFINITY,
            i => self.on_piece(i, s),
        }
    }

    /// The latest time at which the position is at most `s` (infinity: always, as at home
    /// after the end; minus infinity: never).
    fn last_at(&self, s: f64) -> f64 {
        let i = self.knots.partition_point(|k| k.1 <= s);
        match i {
            0 => f64::NEG_INFINITY,
            i if i == self.knots.len() => f64::INFINITY,
            i => self.on_piece(i, s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coord::program::Span;
    use cellplan_motion::timing::Trajectory;

    fn span(start: f64, end: f64, what: Activity) -> Span {
        Span { start, end, what }
    }

    /// Move 0–1, wait 1–3, measure 3–4, move 4–5: positions 0–1, 1, 1–2, 2–3, then 3 (home).
    fn timed() -> Timed {
        let mv = Activity::Move { leg: 0, segment: 0 };
        Timed {
            trajectory: Trajectory::dwell(&[0.0], 5.0),
            spans: vec![
                span(0.0, 1.0, mv),
                span(1.0, 3.0, Activity::Wait { leg: 0, waypoint: 1 }),
                span(3.0, 4.0, Activity::Measure { visit: 0 }),
                span(4.0, 5.0, mv),
            ],
            visits: vec![(3.0, 4.0)],
            wait_starts: vec![1.0],
            arrivals: vec![vec![0.0, 1.0]],
            idle: false,
        }
    }

    /// The clock's position rises one to one, holds while the robot waits, and holds at the
    /// end for ever; first and last times at a position are the ends of where it is there.
    #[test]
    fn the_clock_holds_the_position_while_the_robot_waits() {
        let c = Clock::new(&timed());
        assert_eq!(c.first_at(-1.0), 0.0);
        assert_eq!(c.first_at(0.5), 0.5);
        assert_eq!(c.first_at(1.0), 1.0);
        assert_eq!(c.last_at(1.0), 3.0);
        assert_eq!(c.first_at(1.5), 3.5);
        assert_eq!(c.last_at(2.5), 4.5);
        assert_eq!(c.last_at(3.0), f64::INFINITY);
        assert_eq!(c.first_at(3.5), f64::INFINITY);
        assert_eq!(c.last_at(-0.5), f64::NEG_INFINITY);
    }

    /// A box of positions becomes the window of time in which both robots are inside it, cut
    /// to the interval asked; windows that touch are merged; a robot whose path changed has no
    /// windows (every time may be a contact).
    #[test]
    fn boxes_become_windows_of_time() {
        let boxes = [
            ConflictBox {
                robots: (0, 1),
                a: (0.5, 1.5),
                b: (0.0, 0.25),
                open: [false; 4],
            },
            ConflictBox {
                robots: (0, 1),
                a: (2.5, 2.75),
                b: (2.0, 3.0),
                open: [false; 4],
            },
        ];
        let mut cover = Cover::new(2, &boxes);
        let (ta, tb) = (timed(), timed());
        // First box: robot 0 in [0.5, 3.5] s, robot 1 in [0, 0.25] s: [0.5, 0.25] is empty.
        // Second: robot 0 in [4.5, 4.75] s, robot 1 in [4, inf): [4.5, 4.75].
        let w = cover.windows(0, &ta, 1, &tb, 0.0, 10.0).unwrap();
        assert_eq!(w.len(), 1);
        assert!(
            (w[0].0 - 4.5).abs() < 1e-5 && (w[0].1 - 4.75).abs() < 1e-5,
            "{w:?}"
        );
        // Asked the other way round, the same.
        assert_eq!(cover.windows(1, &tb, 0, &ta, 0.0, 10.0).unwrap(), w);
        // Cut to what is asked.
        assert!(cover.windows(0, &ta, 1, &tb, 0.0, 4.0).unwrap().is_empty());
        cover.invalidate(1);
        assert!(cover.windows(0, &ta, 1, &tb, 0.0, 10.0).is_none());
    }
}
