//! Each device replayed from its moves: where it is at any time, whether it stands still, the
//! moves' own checks (start, full drive, continuity, travel), and the robots' X gap checked
//! exactly piece by piece.
use super::{POS_TOL, PcbViolation, PcbViolationKind, TIME_TOL, v};
use cellplan_pcb::PcbCell;
use cellplan_pcb::cell::{Drive, MotionModel};
use cellplan_pcb::document::{DeviceKind, DeviceOut};

pub(super) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

pub(super) fn near(a: [f64; 2], b: [f64; 2]) -> bool {
    dist(a, b) <= POS_TOL
}

/// A device's replay: where it is at any time.
pub(super) struct Replay<'a> {
    pub(super) dev: &'a DeviceOut,
    pub(super) drive: Drive,
    pub(super) model: MotionModel,
}

impl Replay<'_> {
    /// Position at `t`.
    pub(super) fn at(&self, t: f64) -> [f64; 2] {
        let mut pos = self.dev.start;
        for m in &self.dev.moves {
            if t >= m.t[1] {
                pos = m.to;
            } else if t > m.t[0] {
                let len = dist(m.from, m.to);
                let s = self.drive.progress(self.model, len, t - m.t[0]);
                let f = if len > 0.0 { s / len } else { 1.0 };
                return [
                    m.from[0] + f * (m.to[0] - m.from[0]),
                    m.from[1] + f * (m.to[1] - m.from[1]),
                ];
            } else {
                break;
            }
        }
        pos
    }

    /// Whether the device stands still at `p` throughout `[a, b]`.
    pub(super) fn still_at(&self, a: f64, b: f64, p: [f64; 2]) -> bool {
        let moving = self
            .dev
            .moves
            .iter()
            .any(|m| m.t[0] < b - TIME_TOL && m.t[1] > a + TIME_TOL);
        !moving && near(self.at(a), p)
    }

    /// Times at which the X motion changes form (move ends and trapezoid phase ends).
    fn breakpoints(&self, out: &mut Vec<f64>) {
        for m in &self.dev.moves {
            out.push(m.t[0]);
            out.push(m.t[1]);
            if self.model == MotionModel::Trapezoid {
                let len = dist(m.from, m.to);
                let total = self.drive.time(self.model, len);
                let ramp = (self.drive.speed / self.drive.acceleration).min(total / 2.0);
                out.push(m.t[0] + ramp);
                out.push(m.t[1] - ramp);
            }
        }
    }
}

pub(super) fn check_device(cell: &PcbCell, dev: &DeviceOut, drive: Drive, out: &mut Vec<PcbViolation>) {
    let name = Some(dev.name.as_str());
    let model = cell.motion;
    let (lo, hi, fixed, home): ([f64; 2], [f64; 2], bool, [f64; 2]) = match dev.kind {
        DeviceKind::Robot => {
            let r = cell
                .robots
                .iter()
                .find(|r| r.name == dev.name)
                .map_or(&cell.robots[0], |r| r);
            ([r.x[0], r.y[0]], [r.x[1], r.y[1]], false, r.home)
        }
        DeviceKind::Feeder => {
            let f = cell
                .feeders
                .iter()
                .find(|f| f.name == dev.name)
                .map_or(&cell.feeders[0], |f| f);
            (
                [f.x, f.travel[0]],
                [f.x, f.travel[1]],
                !cell.configuration.feeders_move(),
                [f.x, f.home],
            )
        }
        DeviceKind::Table => (
            [cell.table.x[0], cell.table.y[0]],
            [cell.table.x[1], cell.table.y[1]],
            !cell.configuration.table_moves(),
            cell.table.home,
        ),
    };
    let inside =
        |p: [f64; 2]| (0..2).all(|a| p[a].is_finite() && p[a] >= lo[a] - POS_TOL && p[a] <= hi[a] + POS_TOL);
    if fixed {
        if !inside(dev.start) {
            out.push(v(
                PcbViolationKind::Start,
                name,
                None,
                Some(0.0),
                format!("fixed at {:?}, outside its travel", dev.start),
            ));
        }
        if !dev.moves.is_empty() {
            out.push(v(
                PcbViolationKind::FixedMoved,
                name,
                None,
                Some(dev.moves[0].t[0]),
                format!("a fixed device with {} move(s)", dev.moves.len()),
            ));
        }
        return;
    }
    if !near(dev.start, home) {
        out.push(v(
            PcbViolationKind::Start,
            name,
            None,
            Some(0.0),
            format!("starts at {:?}, not at its home {:?}", dev.start, home),
        ));
    }
    let mut pos = dev.start;
    let mut free = 0.0f64;
    for m in &dev.moves {
        let t0 = m.t[0];
        if t0 < -TIME_TOL {
            out.push(v(
                PcbViolationKind::Motion,
                name,
                None,
                Some(t0),
                "a move before time 0".into(),
            ));
            return;
        }
        if !(m.t[0].is_finite() && m.t[1].is_finite()) || t0 < free - TIME_TOL {
            out.push(v(
                PcbViolationKind::Motion,
                name,
                None,
                Some(t0),
                "a move that starts before the previous one ended (or at no finite time)".into(),
            ));
            return;
        }
        if !near(m.from, pos) {
            out.push(v(
                PcbViolationKind::Motion,
                name,
                None,
                Some(t0),
                format!("a move from {:?}, but the device is at {:?}", m.from, pos),
            ));
        }
        if !inside(m.to) {
            out.push(v(
                PcbViolationKind::Motion,
                name,
                None,
                Some(m.t[1]),
                format!("moves to {:?}, outside its travel", m.to),
            ));
        }
        let need = drive.time(model, dist(m.from, m.to));
        if (m.t[1] - m.t[0] - need).abs() > TIME_TOL.max(1e-9 * need) {
            out.push(v(
                PcbViolationKind::Motion,
                name,
                None,
                Some(t0),
                format!(
                    "a move of {:.6} m lasting {:.6} s; at full drive it takes {:.6} s",
                    dist(m.from, m.to),
                    m.t[1] - m.t[0],
                    need
                ),
            ));
        }
        pos = m.to;
        free = m.t[1];
    }
}

/// Smallest X distance between two robots over their whole motion (robot `a` left), and the
/// number of maximal time intervals closer than `gap`.
pub(super) fn robot_gap(a: &Replay, b: &Replay, gap: f64) -> (f64, usize) {
    let mut times = vec![0.0];
    a.breakpoints(&mut times);
    b.breakpoints(&mut times);
    times.retain(|t| t.is_finite());
    times.sort_by(f64::total_cmp);
    times.dedup();
    let f = |t: f64| b.at(t)[0] - a.at(t)[0];
    let mut closest = f64::INFINITY;
    let mut crossings = 0;
    let mut inside = false;
    let check = |value: f64, closest: &mut f64, crossings: &mut usize, inside: &mut bool| {
        *closest = closest.min(value);
        let bad = value < gap - 1e-9;
        if bad && !*inside {
            *crossings += 1;
        }
        *inside = bad;
    };
    for w in times.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let (f0, f1, fm) = (f(t0), f(t1), f(0.5 * (t0 + t1)));
        check(f0, &mut closest, &mut crossings, &mut inside);
        // On this piece the gap is quadratic (or linear): its vertex from three values.
        let curv = f0 + f1 - 2.0 * fm;
        if curv.abs() > 1e-15 {
            // The vertex of the parabola through (0, f0), (½, fm), (1, f1), s in [0, 1].
            let a2 = 2.0 * curv;
            let b1 = f1 - f0 - a2;
            let sv = (-b1 / (2.0 * a2)).clamp(0.0, 1.0);
            check(f(t0 + sv * (t1 - t0)), &mut closest, &mut crossings, &mut inside);
        }
        check(f1, &mut closest, &mut crossings, &mut inside);
    }
    if times.len() == 1 {
        closest = f(0.0);
        crossings = usize::from(closest < gap - 1e-9);
    }
    (closest, crossings)
}
