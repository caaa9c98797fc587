//! A plan replayed from its document: what each robot does when, where its joints and probe
//! are at any time. Shared by the HTML report, the glTF export and the CSV export.
use super::scene::SceneRobot;
use cellplan_core::document::RobotPlan;

/// What a robot is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Doing {
    /// Moving (on a leg).
    Moving,
    /// Measuring an MP (index into the robot's `tasks`).
    Measuring(usize),
    /// Standing still for another robot (index into the robot's `waits`).
    Waiting(usize),
}

impl Doing {
    /// `moving`, `measuring` or `waiting`.
    pub fn word(self) -> &'static str {
        match self {
            Doing::Moving => "moving",
            Doing::Measuring(_) => "measuring",
            Doing::Waiting(_) => "waiting",
        }
    }
}

/// A stretch of time in which a robot does one thing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Start (s).
    pub start: f64,
    /// End (s).
    pub end: f64,
    /// What.
    pub doing: Doing,
}

/// A robot's time from its start to its end, cut into moving, measuring and waiting intervals:
/// measuring from each MP's arrival to its departure, waiting as the plan's waits state, moving
/// the rest. Intervals are in time order, do not overlap, and cover `[start_s, end_s]`; where a
/// wait and a measurement overlap (not in a verified plan), the later one starts when the
/// earlier ends.
pub fn intervals(rp: &RobotPlan) -> Vec<Interval> {
    let mut fixed: Vec<Interval> = rp
        .tasks
        .iter()
        .enumerate()
        .map(|(k, v)| Interval {
            start: v.arrive_s,
            end: v.depart_s,
            doing: Doing::Measuring(k),
        })
        .chain(rp.waits.iter().enumerate().map(|(k, w)| Interval {
            start: w.start_s,
            end: w.start_s + w.duration_s,
            doing: Doing::Waiting(k),
        }))
        .filter(|i| i.end > i.start)
        .collect();
    fixed.sort_by(|a, b| a.start.total_cmp(&b.start));
    let mut out = Vec::with_capacity(2 * fixed.len() + 1);
    let mut at = rp.start_s;
    for i in fixed {
        let start = i.start.max(at);
        if start > at + 1e-9 {
            out.push(Interval {
                start: at,
                end: start,
                doing: Doing::Moving,
            });
        }
        if i.end > start {
            out.push(Interval { start, ..i });
            at = i.end;
        }
    }
    if rp.end_s > at + 1e-9 {
        out.push(Interval {
            start: at,
            end: rp.end_s,
            doing: Doing::Moving,
        });
    }
    out
}

/// The joint values at time `t`, interpolated linearly between the trajectory's samples (held
/// at the ends).
pub fn q_at(rp: &RobotPlan, t: f64) -> Vec<f64> {
    let s = &rp.trajectory;
    let Some(first) = s.first() else {
        return rp.home.clone();
    };
    let k = s.partition_point(|x| x.t <= t);
    if k == 0 {
        return first.q.clone();
    }
    if k == s.len() {
        return s[k - 1].q.clone();
    }
    let (a, b) = (&s[k - 1], &s[k]);
    let f = if b.t > a.t { (t - a.t) / (b.t - a.t) } else { 0.0 };
    a.q.iter().zip(&b.q).map(|(x, y)| x + f * (y - x)).collect()
}

/// The probe (TCP) position at every trajectory sample: `(t, xyz)`.
pub fn probe_track(robot: &SceneRobot, rp: &RobotPlan) -> Vec<(f64, [f64; 3])> {
    rp.trajectory
        .iter()
        .map(|s| {
            let p = robot.tcp_pose(&s.q).translation;
            (s.t, [p.x, p.y, p.z])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_core::document::{PoseOut, Sample, Visit, WaitOut};

    fn robot() -> RobotPlan {
        let visit = |task: &str, a: f64, d: f64| Visit {
            task: task.into(),
            candidate: 0,
            q: vec![0.0],
            tcp: PoseOut {
                xyz: [0.0; 3],
                quat: [0.0, 0.0, 0.0, 1.0],
            },
            figures: Default::default(),
            perturbation_rad: None,
            arrive_s: a,
            depart_s: d,
        };
        RobotPlan {
            name: "R".into(),
            joints: vec!["j".into()],
            home: vec![0.0],
            tasks: vec![visit("A", 2.0, 3.5), visit("B", 6.0, 7.5)],
            start_s: 0.0,
            end_s: 10.0,
            motion_s: 5.0,
            measuring_s: 3.0,
            waiting_s: 1.0,
            total_s: 10.0,
            waits: vec![WaitOut {
                leg: 1,
                waypoint: 0,
                start_s: 3.5,
                duration_s: 1.0,
                reason: cellplan_core::coord::WaitReason::GiveWay,
                for_robot: Some("S".into()),
            }],
            legs: Vec::new(),
            trajectory: vec![
                Sample { t: 0.0, q: vec![0.0] },
                Sample { t: 1.0, q: vec![1.0] },
                Sample { t: 2.0, q: vec![3.0] },
            ],
        }
    }

    #[test]
    fn intervals_cover_the_program_in_order() {
        let iv = intervals(&robot());
        let kinds: Vec<&str> = iv.iter().map(|i| i.doing.word()).collect();
        assert_eq!(
            kinds,
            ["moving", "measuring", "waiting", "moving", "measuring", "moving"]
        );
        assert_eq!(iv[0].start, 0.0);
        assert_eq!(iv.last().unwrap().end, 10.0);
        for w in iv.windows(2) {
            assert!((w[0].end - w[1].start).abs() < 1e-12);
        }
        assert_eq!(iv[2].doing, Doing::Waiting(0));
        assert_eq!(iv[4].doing, Doing::Measuring(1));
    }

    #[test]
    fn q_at_interpolates_and_holds_at_the_ends() {
        let r = robot();
        assert_eq!(q_at(&r, -1.0), vec![0.0]);
        assert_eq!(q_at(&r, 0.5), vec![0.5]);
        assert_eq!(q_at(&r, 1.5), vec![2.0]);
        assert_eq!(q_at(&r, 9.0), vec![3.0]);
    }
}
