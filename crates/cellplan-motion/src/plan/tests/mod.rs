use super::*;
use proptest::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A point robot among disc (ball) obstacles: clearance = distance to the nearest disc surface
/// minus the margin. The point moves exactly as far as the joint segment is long, which the
/// unit radii bound (the 1-norm bounds the 2-norm).
struct Discs {
    discs: Vec<(Vec<f64>, f64)>,
    margin: f64,
    calls: AtomicUsize,
}

impl Discs {
    fn new(discs: Vec<(Vec<f64>, f64)>, margin: f64) -> Self {
        Discs {
            discs,
            margin,
            calls: AtomicUsize::new(0),
        }
    }
}

impl StateValidity for Discs {
    fn clearance(&self, q: &[f64]) -> f64 {
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.discs
            .iter()
            .map(|(c, r)| {
                let d2: f64 = c.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum();
                d2.sqrt() - r
            })
            .fold(f64::INFINITY, f64::min)
            - self.margin
    }
}

fn square(n: usize, size: f64) -> JointSpace {
    JointSpace::new(vec![0.0; n], vec![size; n], vec![1.0; n])
}

/// A wall of discs along x = 5 from y = 0 up to y = 8 in the square [0, 10]²: the way from
/// the left to the right goes around its top.
fn wall() -> Discs {
    let discs = (0..=20).map(|k| (vec![5.0, 0.4 * k as f64], 0.3)).collect();
    Discs::new(discs, 0.05)
}

/// Every edge sampled every `step` (in the 2-norm) is valid.
fn brute_force_valid(v: &dyn StateValidity, waypoints: &[Vec<f64>], step: f64) -> bool {
    let space = square(waypoints[0].len(), 1.0);
    let mut q = Vec::new();
    waypoints.windows(2).all(|w| {
        let len = w[0]
            .iter()
            .zip(&w[1])
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        let n = (len / step).ceil().max(1.0) as usize;
        (0..=n).all(|k| {
            space.interpolate(&w[0], &w[1], k as f64 / n as f64, &mut q);
            v.clearance(&q) > 0.0
        })
    })
}

fn settings(seed: u64) -> PlanSettings {
    PlanSettings {
        seed,
        ..PlanSettings::default()
    }
}

#[test]
fn straight_when_clear() {
    let space = square(2, 10.0);
    let v = wall();
    let path = plan_leg(&space, &v, &[1.0, 9.5], &[9.0, 9.5], &settings(1)).unwrap();
    assert!(path.straight);
    assert_eq!(path.waypoints, vec![vec![1.0, 9.5], vec![9.0, 9.5]]);
    assert_eq!(path.samples, 0);
    assert_eq!(path.validity_calls, v.calls.load(Ordering::Relaxed));
    assert!(brute_force_valid(&v, &path.waypoints, 1e-3));
    let direct = Straight
        .plan(&space, &v, &[1.0, 9.5], &[9.0, 9.5], &settings(1))
        .unwrap();
    assert_eq!(direct.waypoints.len(), 2);
}

#[test]
fn around_the_wall() {
    let space = square(2, 10.0);
    let v = wall();
    let (start, goal) = ([1.0, 1.0], [9.0, 1.0]);
    assert!(matches!(
        Straight.plan(&space, &v, &start, &goal, &settings(0)),
        Err(PlanError::NoPath { samples: 0, .. })
    ));
    for seed in 0..10 {
        let raw = RrtConnect::default()
            .plan(&space, &v, &start, &goal, &settings(seed))
            .unwrap();
        assert!(!raw.straight && raw.samples > 0);
        assert_eq!(raw.waypoints.first().unwrap(), &start.to_vec());
        assert_eq!(raw.waypoints.last().unwrap(), &goal.to_vec());
        assert!(brute_force_valid(&v, &raw.waypoints, 1e-3), "seed {seed}");
        let leg = plan_leg(&space, &v, &start, &goal, &settings(seed)).unwrap();
        assert!(!leg.straight);
        assert!(brute_force_valid(&v, &leg.waypoints, 1e-3), "seed {seed}");
        // It goes over the top of the wall (y > 8.3) and is not much longer than needed.
        assert!(leg.waypoints.iter().any(|q| q[1] > 8.3));
        let shortest = 2.0 * ((4.0f64).powi(2) + (7.35f64).powi(2)).sqrt();
        assert!(leg.length(&space) < 1.3 * shortest, "{}", leg.length(&space));
        assert!(leg.length(&space) <= raw.length(&space) + 1e-9);
    }
}

#[test]
fn a_leg_via_fixed_exits_keeps_them_checked_and_its_ends() {
    let space = square(2, 10.0);
    let v = wall();
    // Leave the start straight up, arrive at the goal straight down.
    let exit = vec![vec![1.0, 1.0], vec![1.0, 2.0], vec![1.0, 3.0]];
    let entry = vec![vec![9.0, 3.0], vec![9.0, 2.0], vec![9.0, 1.0]];
    let leg = plan_leg_via(&space, &v, &exit, &entry, &settings(4)).unwrap();
    assert_eq!(leg.waypoints.first().unwrap(), &exit[0]);
    assert_eq!(leg.waypoints.last().unwrap(), &entry[2]);
    assert!(!leg.straight && leg.validity_calls > 0);
    assert!(brute_force_valid(&v, &leg.waypoints, 1e-3));
    assert!(leg.waypoints.iter().any(|q| q[1] > 8.3), "over the wall");
    // An exit through the wall fails the leg before any sampling.
    let through = vec![vec![1.0, 1.0], vec![9.0, 1.0]];
    assert!(matches!(
        plan_leg_via(&space, &v, &through, &entry, &settings(4)),
        Err(PlanError::NoPath { samples: 0, .. })
    ));
    // Empty polylines give no leg.
    assert!(plan_leg_via(&space, &v, &[], &entry, &settings(4)).is_err());
}

#[test]
fn invalid_ends_are_refused() {
    let space = square(2, 10.0);
    let v = wall();
    let s = settings(0);
    for planner in [&Straight as &dyn Planner, &RrtConnect::default()] {
        assert!(matches!(
            planner.plan(&space, &v, &[5.0, 2.0], &[9.0, 1.0], &s),
            Err(PlanError::StartInvalid { clearance }) if clearance < 0.0
        ));
        assert!(matches!(
            planner.plan(&space, &v, &[1.0, 1.0], &[5.0, 8.2], &s),
            Err(PlanError::GoalInvalid { .. })
        ));
        // Outside the joint limits.
        assert!(matches!(
            planner.plan(&space, &v, &[-1.0, 1.0], &[9.0, 1.0], &s),
            Err(PlanError::StartInvalid { clearance }) if clearance == f64::NEG_INFINITY
        ));
        assert!(matches!(
            planner.plan(&space, &v, &[1.0, 1.0], &[9.0, f64::NAN], &s),
            Err(PlanError::GoalInvalid { .. })
        ));
    }
    // Within the margin of a disc: invalid too.
    assert!(matches!(
        plan_leg(&space, &v, &[5.0, 8.32], &[9.0, 1.0], &s),
        Err(PlanError::StartInvalid { .. })
    ));
    assert!(
        PlanError::NoPath {
            samples: 3,
            validity_calls: 7
        }
        .to_string()
        .contains("3 samples")
    );
}

#[test]
fn enclosed_goal_gives_no_path() {
    let space = square(2, 10.0);
    // A ring of discs around (8, 8).
    let discs = (0..40)
        .map(|k| {
            let a = k as f64 / 40.0 * std::f64::consts::TAU;
            (vec![8.0 + 1.5 * a.cos(), 8.0 + 1.5 * a.sin()], 0.2)
        })
        .collect();
    let v = Discs::new(discs, 0.01);
    let s = PlanSettings {
        max_samples: 300,
        ..settings(3)
    };
    match plan_leg(&space, &v, &[1.0, 1.0], &[8.0, 8.0], &s) {
        Err(PlanError::NoPath {
            samples,
            validity_calls,
        }) => {
            assert_eq!(samples, 300);
            assert!(validity_calls > 300);
        }
        other => panic!("{other:?}"),
    }
    let s = PlanSettings {
        time_limit: Duration::ZERO,
        ..settings(3)
    };
    assert!(matches!(
        RrtConnect::default().plan(&space, &v, &[1.0, 1.0], &[8.0, 8.0], &s),
        Err(PlanError::NoPath { samples: 0, .. })
    ));
}

#[test]
fn deterministic_for_a_seed_in_3d() {
    let space = square(3, 4.0);
    // A slab of balls at z = 2 with one hole near a corner.
    let mut discs = Vec::new();
    for i in 0..=10 {
        for j in 0..=10 {
            if i >= 9 && j >= 9 {
                continue;
            }
            discs.push((vec![0.4 * i as f64, 0.4 * j as f64, 2.0], 0.3));
        }
    }
    let v = Discs::new(discs, 0.0);
    let (start, goal) = ([1.0, 1.0, 0.5], [1.0, 1.0, 3.5]);
    let a = plan_leg(&space, &v, &start, &goal, &settings(42)).unwrap();
    let b = plan_leg(&space, &v, &start, &goal, &settings(42)).unwrap();
    assert_eq!(a, b);
    assert!(!a.straight);
    assert!(brute_force_valid(&v, &a.waypoints, 1e-3));
    // It goes through the hole.
    assert!(
        a.waypoints
            .windows(2)
            .any(|w| (w[0][2] - 2.0) * (w[1][2] - 2.0) <= 0.0)
    );
    let c = plan_leg(&space, &v, &start, &goal, &settings(43)).unwrap();
    assert!(brute_force_valid(&v, &c.waypoints, 1e-3));
}

#[test]
fn a_segments_memo_is_made_once_and_only_for_its_owner() {
    let motion = SegmentMotion::new(&[1.0, 2.0], &[0.5, -0.25]);
    let made = AtomicUsize::new(0);
    let make = |x: f64| {
        made.fetch_add(1, Ordering::Relaxed);
        vec![x]
    };
    assert_eq!(&*motion.memo(7, || make(1.0)), &[1.0]);
    assert_eq!(&*motion.memo(7, || make(2.0)), &[1.0], "made again");
    assert_eq!(made.load(Ordering::Relaxed), 1);
    // Another owner gets its own values, made each time, and the first owner's stay.
    assert_eq!(&*motion.memo(8, || make(3.0)), &[3.0]);
    assert_eq!(&*motion.memo(7, || make(4.0)), &[1.0]);
    assert_eq!(made.load(Ordering::Relaxed), 2);
    // The memo is no part of the value.
    assert_eq!(motion, SegmentMotion::new(&[1.0, 2.0], &[0.5, -0.25]));
    assert_eq!(motion.total(), 1.0);
}

#[test]
fn segment_check_steps_by_clearance() {
    let space = square(2, 10.0);
    let v = Discs::new(vec![(vec![5.0, 5.0], 1.0)], 0.0);
    // Far from the disc: few calls; grazing it: more; through it: invalid.
    let far = check_segment(&space, &v, &[0.0, 0.0], &[10.0, 0.0], 1e-4);
    assert!(far.valid && far.calls - far.probes <= 6, "{far:?}");
    let near = check_segment(&space, &v, &[0.0, 3.9], &[10.0, 3.9], 1e-4);
    assert!(near.valid && near.calls > far.calls, "{near:?}");
    let through = check_segment(&space, &v, &[0.0, 5.0], &[10.0, 5.0], 1e-4);
    assert!(!through.valid);
    // The first probe, in the middle, finds the contact: no covering at all.
    assert_eq!((through.calls, through.probes), (1, 1), "{through:?}");
    // Weighted radii: a joint with a large radius is stepped finely.
    let heavy = JointSpace::new(vec![0.0; 2], vec![10.0; 2], vec![100.0, 1.0]);
    let fine = check_segment(&heavy, &v, &[0.0, 0.0], &[10.0, 0.0], 1e-4);
    assert!(fine.valid && fine.calls > far.calls);
    // A zero-length segment at a valid point.
    let point = check_segment(&space, &v, &[1.0, 1.0], &[1.0, 1.0], 1e-4);
    assert_eq!(
        point,
        SegmentCheck {
            valid: true,
            calls: 2,
            probes: 0
        }
    );
}

#[test]
fn shortcut_never_lengthens_and_stays_valid() {
    let space = square(2, 10.0);
    let v = wall();
    for seed in 0..20 {
        let raw = RrtConnect::default()
            .plan(&space, &v, &[1.0, 1.0], &[9.0, 1.0], &settings(seed))
            .unwrap();
        let before = path_length(&space, &raw.waypoints);
        let mut path = raw.waypoints.clone();
        let mut last = before;
        // Post-processing in several rounds, each never longer than the last.
        for round in 0..3 {
            let s = PlanSettings {
                shortcut_iterations: 20,
                ..settings(seed * 10 + round)
            };
            shortcut(&space, &v, &mut path, &s);
            let now = path_length(&space, &path);
            assert!(now <= last + 1e-9, "seed {seed}: {now} > {last}");
            assert!(brute_force_valid(&v, &path, 1e-3), "seed {seed}");
            assert_eq!(path.first(), raw.waypoints.first());
            assert_eq!(path.last(), raw.waypoints.last());
            last = now;
        }
        assert!(last < before || raw.waypoints.len() <= 3);
    }
}

/// A dense polyline (1 cm steps, as a retract is) over the wall's top: the redundant
/// waypoints go by galloping, for far fewer checks than growing each segment one waypoint
/// at a time (the same path or a shorter one), and the path stays valid with its ends.
#[test]
fn redundant_waypoints_of_a_dense_polyline_go_by_galloping() {
    let space = square(2, 10.0);
    let v = wall();
    let mut dense: Vec<Vec<f64>> = Vec::new();
    let corners = [[1.0, 1.0], [1.0, 9.0], [9.0, 9.0], [9.0, 1.0]];
    for w in corners.windows(2) {
        let n = (space.distance(&w[0], &w[1]) / 0.01).round() as usize;
        for k in 0..n {
            let t = k as f64 / n as f64;
            dense.push(vec![
                w[0][0] + t * (w[1][0] - w[0][0]),
                w[0][1] + t * (w[1][1] - w[0][1]),
            ]);
        }
    }
    dense.push(corners[3].to_vec());
    assert!(brute_force_valid(&v, &dense, 1e-3));
    // One waypoint at a time: from each kept waypoint, the segment grows while it is seen.
    let mut greedy = dense.clone();
    let mut greedy_calls = 0;
    let mut i = 0;
    while i + 2 < greedy.len() {
        let check = check_segment(&space, &v, &greedy[i], &greedy[i + 2], 1e-4);
        greedy_calls += check.calls;
        if check.valid {
            greedy.remove(i + 1);
        } else {
            i += 1;
        }
    }
    let mut path = dense.clone();
    let s = PlanSettings {
        shortcut_iterations: 0,
        ..settings(0)
    };
    let calls = shortcut(&space, &v, &mut path, &s);
    assert!(brute_force_valid(&v, &path, 1e-3));
    assert_eq!(path.first(), dense.first());
    assert_eq!(path.last(), dense.last());
    assert!(
        path.len() <= 6,
        "{} waypoints left of {}",
        path.len(),
        dense.len()
    );
    assert!(path_length(&space, &path) <= path_length(&space, &greedy) + 1e-9);
    assert!(
        calls * 5 < greedy_calls,
        "galloping {calls} calls against {greedy_calls} one waypoint at a time"
    );
}

#[test]
fn timed_shortcut_never_slows_the_path_and_stays_valid() {
    use crate::timing::{Limits, time_path_exact};
    let space = square(2, 10.0);
    let v = wall();
    // A slow joint 1: time and length disagree about where to cut.
    let limits = Limits::new(vec![2.0, 0.5], vec![4.0, 1.0]).unwrap();
    let time = |p: &[Vec<f64>]| time_path_exact(p, &limits).unwrap().trajectory.duration();
    let mut faster = 0;
    for seed in 0..20 {
        let raw = RrtConnect::default()
            .plan(&space, &v, &[1.0, 1.0], &[9.0, 1.0], &settings(seed))
            .unwrap();
        let mut path = raw.waypoints.clone();
        let mut last = time(&path);
        for round in 0..3 {
            let s = PlanSettings {
                shortcut_iterations: 20,
                ..settings(seed * 10 + round)
            };
            shortcut_timed(&space, &v, &mut path, &s, &limits);
            let now = time(&path);
            assert!(now <= last + 1e-9, "seed {seed}: {now} > {last}");
            assert!(brute_force_valid(&v, &path, 1e-3), "seed {seed}");
            assert_eq!(path.first(), raw.waypoints.first());
            assert_eq!(path.last(), raw.waypoints.last());
            last = now;
        }
        faster += usize::from(last < time(&raw.waypoints) - 1e-9);
    }
    // The planner's raw paths zigzag: most get faster.
    assert!(faster >= 15, "{faster} of 20 faster");
}

#[test]
fn straightening_removes_a_joint_swing_the_obstacles_do_not_ask_for() {
    use crate::timing::{Limits, time_path_exact};
    // A third joint the wall (discs in the first two joints) does not see: a path around the
    // wall's top along which it swings up and down needlessly, and sets the segments' times
    // (at equal limits the joint that moves most does).
    let space = square(3, 30.0);
    let v = wall();
    let limits = Limits::uniform(3, 1.0, 2.0).unwrap();
    let time = |p: &[Vec<f64>]| time_path_exact(p, &limits).unwrap().trajectory.duration();
    let swing = |p: &[Vec<f64>]| -> f64 {
        p.windows(2).map(|w| (w[1][2] - w[0][2]).abs()).sum::<f64>() - (p[p.len() - 1][2] - p[0][2]).abs()
    };
    let path = vec![
        vec![1.0, 1.0, 1.0],
        vec![4.0, 9.0, 25.0],
        vec![6.0, 9.0, 0.5],
        vec![9.0, 1.0, 2.0],
    ];
    assert!(brute_force_valid(&v, &path, 1e-3));
    let mut straight = path.clone();
    let calls = straighten_joints_timed(&space, &v, &mut straight, (0, 40), 1e-4, &limits);
    assert!(calls > 0);
    assert_eq!(straight.len(), path.len());
    assert_eq!(straight.first(), path.first());
    assert_eq!(straight.last(), path.last());
    assert!(brute_force_valid(&v, &straight, 1e-3));
    // The first two joints keep their course (the wall needs it); the third no longer swings.
    for (a, b) in straight.iter().zip(&path) {
        assert_eq!(a[..2], b[..2]);
    }
    // 47 rad of needless swing: what is left no longer sets any segment's time.
    assert!(
        swing(&straight) < 2.0,
        "swing left {}: {straight:?}",
        swing(&straight)
    );
    assert!(
        time(&straight) < 0.5 * time(&path),
        "{} against {}",
        time(&straight),
        time(&path)
    );
}

#[test]
fn straightening_never_slows_a_path_and_keeps_it_valid() {
    use crate::timing::{Limits, time_path_exact};
    // Discs in all three joints: a joint's detour may be what keeps the path clear.
    let space = square(3, 10.0);
    let mut discs = Vec::new();
    for y in 0..=8 {
        for z in 0..=8 {
            if (y, z) != (4, 4) {
                discs.push((vec![5.0, 1.0 * y as f64 + 1.0, 1.0 * z as f64 + 1.0], 0.45));
            }
        }
    }
    let v = Discs::new(discs, 0.02);
    let limits = Limits::new(vec![1.0, 0.7, 1.5], vec![2.0, 1.0, 3.0]).unwrap();
    let time = |p: &[Vec<f64>]| time_path_exact(p, &limits).unwrap().trajectory.duration();
    let mut faster = 0;
    for seed in 0..20 {
        let raw = RrtConnect::default()
            .plan(&space, &v, &[1.0, 2.0, 8.0], &[9.0, 8.0, 2.0], &settings(seed))
            .unwrap();
        let mut path = raw.waypoints.clone();
        straighten_joints_timed(&space, &v, &mut path, (seed, 40), 1e-4, &limits);
        assert!(brute_force_valid(&v, &path, 1e-3), "seed {seed}");
        assert_eq!(path.len(), raw.waypoints.len());
        assert_eq!(path.first(), raw.waypoints.first());
        assert_eq!(path.last(), raw.waypoints.last());
        let (before, after) = (time(&raw.waypoints), time(&path));
        assert!(after <= before + 1e-9, "seed {seed}: {after} > {before}");
        faster += usize::from(after < before - 1e-9);
    }
    assert!(faster >= 10, "{faster} of 20 faster");
}

/// A joint that turns (`θ`, over two turns either way) and one that slides (`y`): the point
/// `(cos θ, sin θ, y)` among balls. A full turn of `θ` puts it where it was; it moves at most
/// `|Δθ| + |Δy|` along a segment (unit radii).
struct Pinwheel {
    balls: Vec<([f64; 3], f64)>,
}

impl StateValidity for Pinwheel {
    fn clearance(&self, q: &[f64]) -> f64 {
        let p = [q[0].cos(), q[0].sin(), q[1]];
        self.balls
            .iter()
            .map(|(c, r)| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt() - r)
            .fold(f64::INFINITY, f64::min)
    }
}

fn pinwheel_space() -> JointSpace {
    let tau = std::f64::consts::TAU;
    JointSpace::new(vec![-tau, 0.0], vec![tau, 10.0], vec![1.0, 1.0]).with_turns(vec![true, false])
}

/// A path whose middle waypoints stand nearly a full turn of `θ` from both ends: each of its
/// outer segments turns `θ` almost all the way round.
fn wound_path() -> Vec<Vec<f64>> {
    vec![vec![0.0, 1.0], vec![6.0, 3.0], vec![6.2, 5.0], vec![0.5, 7.0]]
}

#[test]
fn unwinding_takes_back_the_turns_a_path_need_not_make() {
    let tau = std::f64::consts::TAU;
    let space = pinwheel_space();
    // A ball far from the circle: everything is clear.
    let v = Pinwheel {
        balls: vec![([5.0, 5.0, 5.0], 0.5)],
    };
    let path = wound_path();
    assert!(brute_force_valid(&v, &path, 1e-3));
    let mut unwound = path.clone();
    let length = |p: &[Vec<f64>]| path_length(&space, p);
    let calls = super::simplify::unwind(&space, &v, &mut unwound, 1e-4, &length);
    // The two middle waypoints stand where they stood, a turn lower: θ moves 1.06 rad, not 11.9.
    assert!(calls > 0);
    assert_eq!(unwound[0], path[0]);
    assert_eq!(unwound[3], path[3]);
    for k in 1..3 {
        assert_eq!(unwound[k][1], path[k][1]);
        assert!((unwound[k][0] - (path[k][0] - tau)).abs() < 1e-12, "{unwound:?}");
    }
    assert!(brute_force_valid(&v, &unwound, 1e-3));
    assert!(length(&unwound) < 0.5 * length(&path));
    // A joint that does not turn, or a space that does not say so, is left alone.
    let mut same = path.clone();
    let plain = JointSpace::new(vec![-tau, 0.0], vec![tau, 10.0], vec![1.0, 1.0]);
    assert_eq!(super::simplify::unwind(&plain, &v, &mut same, 1e-4, &length), 0);
    assert_eq!(same, path);
}

#[test]
fn unwinding_keeps_the_long_way_round_where_the_short_one_is_blocked() {
    let space = pinwheel_space();
    // A ball on the short arc between θ = 0 and the first middle waypoint (θ = 6.0, a turn
    // less -0.28), at the height that segment passes it; the long way round (θ from 0 up to 6)
    // passes that height at θ = 3, on the other side of the circle.
    let v = Pinwheel {
        balls: vec![([(-0.14f64).cos(), (-0.14f64).sin(), 2.0], 0.05)],
    };
    let path = wound_path();
    assert!(brute_force_valid(&v, &path, 1e-3));
    let short = vec![path[0].clone(), vec![6.0 - std::f64::consts::TAU, 3.0]];
    assert!(!brute_force_valid(&v, &short, 1e-3));
    let mut kept = path.clone();
    let length = |p: &[Vec<f64>]| path_length(&space, p);
    let calls = super::simplify::unwind(&space, &v, &mut kept, 1e-4, &length);
    assert!(calls > 0);
    // Held at the first middle waypoint, the second cannot do better than where it is either.
    assert_eq!(kept, path);
    assert!(brute_force_valid(&v, &kept, 1e-3));
}

/// A wrist that turns over two turns either way (`θ`) and carries a point 5 cm off its axis,
/// on a point that slides in the plane (`x`, `y`) around [`wall`]: `θ` hardly matters to the
/// wall, so the sampler leaves it wherever its draws put it.
struct Wrist(Discs);

impl StateValidity for Wrist {
    fn clearance(&self, q: &[f64]) -> f64 {
        self.0
            .clearance(&[q[1] + 0.05 * q[0].cos(), q[2] + 0.05 * q[0].sin()])
    }
}

#[test]
fn straightening_unwinds_and_keeps_paths_valid_where_a_joint_turns() {
    use crate::timing::{Limits, time_path_exact};
    let tau = std::f64::consts::TAU;
    let (lower, upper, radii) = (vec![-tau, 0.0, 0.0], vec![tau, 10.0, 10.0], vec![0.05, 1.0, 1.0]);
    let space =
        JointSpace::new(lower.clone(), upper.clone(), radii.clone()).with_turns(vec![true, false, false]);
    let plain = JointSpace::new(lower, upper, radii);
    let v = Wrist(wall());
    // A slow wrist: its turns set the segments' times.
    let limits = Limits::new(vec![0.5, 2.0, 2.0], vec![1.0, 4.0, 4.0]).unwrap();
    let time = |p: &[Vec<f64>]| time_path_exact(p, &limits).unwrap().trajectory.duration();
    // How far θ turns beyond the ends' difference.
    let excess = |p: &[Vec<f64>]| -> f64 {
        p.windows(2).map(|w| (w[1][0] - w[0][0]).abs()).sum::<f64>() - (p[p.len() - 1][0] - p[0][0]).abs()
    };
    let (mut with, mut without, mut faster) = (0.0, 0.0, 0);
    for seed in 0..20 {
        let raw = RrtConnect::default()
            .plan(&space, &v, &[0.2, 1.0, 1.0], &[2.9, 9.0, 1.0], &settings(seed))
            .unwrap();
        let mut shortcut_path = raw.waypoints.clone();
        shortcut(&space, &v, &mut shortcut_path, &settings(seed));
        let mut path = shortcut_path.clone();
        straighten_joints_timed(&space, &v, &mut path, (seed, 40), 1e-4, &limits);
        assert!(brute_force_valid(&v, &path, 1e-3), "seed {seed}");
        assert_eq!(path.len(), shortcut_path.len());
        assert_eq!(path.first(), raw.waypoints.first());
        assert_eq!(path.last(), raw.waypoints.last());
        assert!(path.iter().all(|q| space.contains(q)));
        assert!(time(&path) <= time(&shortcut_path) + 1e-9, "seed {seed}");
        // Without turns the same straightening can only take θ back along the way it came.
        let mut wound = shortcut_path.clone();
        straighten_joints_timed(&plain, &v, &mut wound, (seed, 40), 1e-4, &limits);
        // The path straightened without unwinding is one of the two tried: never slower.
        assert!(time(&path) <= time(&wound) + 1e-9, "seed {seed}");
        with += excess(&path);
        without += excess(&wound);
        faster += usize::from(time(&path) < time(&wound) - 1e-9);
    }
    assert!(
        with < 0.5 * without,
        "θ turned {with} rad beyond the ends with unwinding, {without} without"
    );
    // Where the turns set the time and the straightening alone cannot take them back (13.7 s
    // against 17.7 s and 10.2 s against 28.6 s here).
    assert!(faster >= 2, "{faster} of 20 paths faster for unwinding");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The conservative check never accepts a segment in which a dense sampling finds a
    /// contact, in 2-D and 3-D, with unit or larger radii.
    #[test]
    fn conservative_check_never_accepts_a_colliding_segment(
        dim in 2usize..=3,
        discs in prop::collection::vec(
            (prop::collection::vec(0.0..4.0f64, 3), 0.05..0.8f64), 1..6),
        a in prop::collection::vec(0.0..4.0f64, 3),
        b in prop::collection::vec(0.0..4.0f64, 3),
        margin in 0.0..0.1f64,
        radius_scale in 1.0..3.0f64,
    ) {
        let discs: Vec<(Vec<f64>, f64)> =
            discs.into_iter().map(|(c, r)| (c[..dim].to_vec(), r)).collect();
        let v = Discs::new(discs, margin);
        let space = JointSpace::new(vec![0.0; dim], vec![4.0; dim], vec![radius_scale; dim]);
        let (a, b) = (&a[..dim], &b[..dim]);
        let check = check_segment(&space, &v, a, b, 1e-4);
        if check.valid {
            let n = 20_000;
            let mut q = Vec::new();
            for k in 0..=n {
                space.interpolate(a, b, k as f64 / n as f64, &mut q);
                prop_assert!(v.clearance(&q) > 0.0, "contact at {:?}", q);
            }
        }
        prop_assert!(check.calls >= 1);
    }
}

/// A constant tight clearance that only joint 1 can reduce (a tool beside the wrist that
/// carries it), and a point robot on joint 0 far from anything.
struct TightWrist;

impl StateValidity for TightWrist {
    fn clearance(&self, _q: &[f64]) -> f64 {
        0.01
    }
    fn clearances(&self, _q: &[f64], out: &mut Vec<Clearance>) {
        out.clear();
        out.push(Clearance {
            distance: 0.01,
            joints: 1..2,
        });
        out.push(Clearance {
            distance: 1.0,
            joints: 0..2,
        });
    }
}

fn tight(_: &[f64]) -> f64 {
    0.01
}

#[test]
fn structured_clearances_step_by_the_joints_that_matter() {
    let space = square(2, 10.0);
    // Joint 0 moves 10, joint 1 does not: the tight clearance cannot shrink.
    let fine = check_segment(&space, &tight, &[0.0, 1.0], &[10.0, 1.0], 1e-4);
    let coarse = check_segment(&space, &TightWrist, &[0.0, 1.0], &[10.0, 1.0], 1e-4);
    assert!(fine.valid && coarse.valid);
    // Each sample proves at most 0.01 / 10 of the parameter either side: at least 500 samples.
    assert!(fine.calls >= 500, "{fine:?}");
    assert!(coarse.calls - coarse.probes < 15, "{coarse:?}");
    // Joint 1 moving by 1: each sample proves 0.01 either side, at least 50 samples.
    let wrist = check_segment(&space, &TightWrist, &[0.0, 1.0], &[0.0, 2.0], 1e-4);
    assert!(wrist.valid && wrist.calls >= 50, "{wrist:?}");
    // A clearance below the floor is a contact whatever its joints.
    let floor = check_segment(&space, &TightWrist, &[0.0, 1.0], &[1.0, 1.0], 0.02);
    assert!(!floor.valid);
}

mod planners;
mod probes;

/// [`SegmentMotion::bound_at`] on a planar arm of two unit links, folded so that its tip sits
/// on the first axis: turning the first joint far and the second a little carries the tip away
/// from that axis, and the first joint then sweeps it around. The bound holds (the tip's path
/// measured in small pieces) only with the growth of the tip's distance from the first axis
/// counted; at the sample alone that distance is 0.
#[test]
fn a_posed_bound_counts_how_far_a_reach_grows() {
    let tip = |q: &[f64]| {
        let (a, b) = (q[0], q[0] + q[1]);
        (a.cos() + b.cos(), a.sin() + b.sin())
    };
    let q = [0.3, std::f64::consts::PI];
    let delta = [10.0, 0.1];
    // Radii that hold everywhere: the tip lies within 2 of the first axis, 1 of the second.
    let motion = SegmentMotion::new(&[2.0, 1.0], &delta);
    let at = tip(&q);
    // The tip's distance from each axis at the sample: the first axis is at the origin, the
    // second at the elbow.
    let elbow = (q[0].cos(), q[0].sin());
    let reach = |j: usize| match j {
        0 => at.0.hypot(at.1),
        _ => (at.0 - elbow.0).hypot(at.1 - elbow.1),
    };
    assert!(reach(0) < 1e-12);
    for t in [0.05, 0.2, 1.0] {
        let bound = motion.bound_at(&(0..2), reach, motion.drift_with(&(0..2), &[]), t);
        let mut path = 0.0;
        let mut prev = at;
        for k in 1..=10_000 {
            let s = t * k as f64 / 10_000.0;
            let p = tip(&[q[0] + s * delta[0], q[1] + s * delta[1]]);
            path += (p.0 - prev.0).hypot(p.1 - prev.1);
            prev = p;
        }
        assert!(path <= t * bound + 1e-9, "t {t}: path {path} > {}", t * bound);
        // The reach at the sample alone would not do: the drift is needed.
        assert!(
            path > t * motion.bound_at(&(0..2), reach, 0.0, t),
            "t {t}: path {path}"
        );
        // It is also tighter than the bound that holds everywhere, for short steps.
        if t <= 0.05 {
            assert!(bound < 0.5 * motion.bound(&(0..2)), "{bound}");
        }
    }
}
