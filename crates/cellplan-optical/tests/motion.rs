//! Motion planning on the bundled autobody-4r cell: the radii bound, the clearance, straight
//! legs from home to measuring candidates and back, and a blocked leg solved by RRT-Connect —
//! every path re-checked densely (1 mm Cartesian steps) with `Robot::contact_at`.
use cellplan_core::candidates::generate;
use cellplan_core::motion::{
    RobotValidity, joint_space, plan_leg, plan_leg_with_margin, robot_roadmap, robot_validity,
};
use cellplan_model::robot::Scratch;
use cellplan_model::{Cell, LoadOptions, Robot, TaskId};
use cellplan_motion::plan::{PlanError, PlanSettings, Planner, StateValidity, Straight};
use cellplan_optical::load;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use std::sync::OnceLock;

struct Fixture {
    cell: Cell,
    /// First candidate of every task, per robot.
    candidates: Vec<Vec<Vec<f64>>>,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/autobody-4r/cell.toml");
        let cell = load(&path, &LoadOptions::default()).expect("example cell loads");
        let table = generate(&cell);
        let candidates = cell
            .robots
            .iter()
            .map(|r| {
                (0..cell.tasks.len())
                    .filter_map(|t| table.get(TaskId(t), r.id).candidates.first())
                    .map(|c| c.q.clone())
                    .collect()
            })
            .collect();
        Fixture { cell, candidates }
    })
}

fn margin(cell: &Cell) -> f64 {
    cell.planning.clearance
}

/// Dense independent re-check: every edge sampled so that no body point moves more than
/// 1 mm between samples, each sample checked with `Robot::contact_at` at the margin.
fn dense_contact_free(cell: &Cell, robot: &Robot, waypoints: &[Vec<f64>]) -> Result<(), String> {
    let space = joint_space(cell, robot);
    let mut scratch = Scratch::default();
    let mut q = Vec::new();
    for (e, w) in waypoints.windows(2).enumerate() {
        let n = (space.cartesian_bound(&w[0], &w[1]) / 1e-3).ceil().max(1.0) as usize;
        for k in 0..=n {
            space.interpolate(&w[0], &w[1], k as f64 / n as f64, &mut q);
            if !robot.within_limits(&q) {
                return Err(format!("edge {e} sample {k}/{n}: outside the limits"));
            }
            robot.body_poses(&q, &mut scratch);
            if let Some(c) = robot.contact_at(&cell.world, &scratch, margin(cell)) {
                return Err(format!("edge {e} sample {k}/{n}: {c:?}"));
            }
        }
    }
    Ok(())
}

fn random_q(robot: &Robot, rng: &mut ChaCha8Rng) -> Vec<f64> {
    robot
        .model
        .chain
        .joints
        .iter()
        .map(|j| rng.random_range(j.lower..j.upper))
        .collect()
}

#[test]
fn radii_bound_every_hull_vertex_displacement() {
    let f = fixture();
    let cell = &f.cell;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for robot in &cell.robots {
        let space = joint_space(cell, robot);
        assert_eq!(space.dim(), robot.dof());
        assert!(space.radii.iter().all(|&r| r > 0.0 && r.is_finite()));
        // Radii shrink towards the tip: each joint carries less.
        assert!(space.radii.windows(2).all(|w| w[0] >= w[1]));
        let hulls: Vec<_> = (0..robot.bodies.len())
            .map(|i| cell.world.body_hull(robot.group, i))
            .collect();
        let (mut sa, mut sb) = (Scratch::default(), Scratch::default());
        let mut worst: f64 = 0.0;
        for _ in 0..200 {
            let a = random_q(robot, &mut rng);
            let b = random_q(robot, &mut rng);
            robot.body_poses(&a, &mut sa);
            let mut q = Vec::new();
            for k in 1..=8 {
                space.interpolate(&a, &b, k as f64 / 8.0, &mut q);
                robot.body_poses(&q, &mut sb);
                let bound = space.cartesian_bound(&a, &q);
                for (i, hull) in hulls.iter().enumerate() {
                    let Some(hull) = hull else { continue };
                    for v in &hull.vertices {
                        let moved =
                            (sa.bodies[i].transform_point(*v) - sb.bodies[i].transform_point(*v)).length();
                        assert!(moved <= bound + 1e-9, "{moved} > {bound}");
                        worst = worst.max(moved / bound);
                    }
                }
            }
        }
        // The bound is not absurdly loose either.
        assert!(worst > 0.3, "{worst}");
    }
}

/// The robot's body poses are the motion core's, bit for bit, and its TCP from the posed links
/// is `tcp_pose`'s (the candidates pose a configuration once, for its TCP, its process checks
/// and the checker), and the checker answers the same on the poses it is given as on its own —
/// at random configurations, valid and not, and outside the limits.
#[test]
fn the_checker_answers_the_same_on_poses_it_is_given() {
    let f = fixture();
    let cell = &f.cell;
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut scratch = Scratch::default();
    let (mut links, mut poses) = (Vec::new(), Vec::new());
    for robot in &cell.robots {
        let v = robot_validity(cell, robot, margin(cell));
        let arm = robot.arm(&cell.world);
        let (mut valid, mut invalid) = (0, 0);
        let mut one_invalid = None;
        for _ in 0..300 {
            let q = random_q(robot, &mut rng);
            robot.body_poses(&q, &mut scratch);
            arm.body_poses(&q, &mut links, &mut poses);
            assert_eq!(scratch.bodies, poses);
            assert_eq!(robot.tcp_from_links(&scratch), robot.tcp_pose(&q));
            let own = v.is_valid(&q);
            assert_eq!(v.is_valid_posed(&q, &scratch.bodies), own);
            valid += usize::from(own);
            invalid += usize::from(!own);
            if !own {
                one_invalid.get_or_insert(q);
            }
        }
        assert!(
            valid > 10 && invalid > 10,
            "{}: {valid} valid, {invalid} not",
            robot.name
        );
        let mut out = robot.home.clone();
        out[0] = robot.model.chain.joints[0].upper + 0.1;
        robot.body_poses(&out, &mut scratch);
        assert!(!v.is_valid_posed(&out, &scratch.bodies));
        // Poses of another length: the checker poses the arm itself.
        assert!(v.is_valid_posed(&robot.home, &[]));
        assert!(!v.is_valid_posed(&one_invalid.expect("some invalid"), &[]));
    }
}

#[test]
fn clearance_agrees_with_contact_checks() {
    let f = fixture();
    let cell = &f.cell;
    let robot = &cell.robots[0];
    let v = robot_validity(cell, robot, margin(cell));
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut scratch = Scratch::default();
    let (mut valid, mut invalid) = (0, 0);
    for _ in 0..400 {
        let q = random_q(robot, &mut rng);
        let c = v.clearance(&q);
        robot.body_poses(&q, &mut scratch);
        let contact = robot.contact_at(&cell.world, &scratch, margin(cell));
        if c > 0.0 {
            assert!(contact.is_none(), "clearance {c} but {contact:?}");
            valid += 1;
        }
        if contact.is_some() {
            assert!(c <= 1e-6, "{c}");
            invalid += 1;
        }
        assert!(c <= v.cap);
    }
    assert!(valid > 10 && invalid > 10, "{valid} {invalid}");
    // Outside the limits: invalid.
    let mut q = robot.home.clone();
    q[0] = robot.model.chain.joints[0].upper + 0.1;
    assert_eq!(v.clearance(&q), f64::NEG_INFINITY);
    let s = PlanSettings::default();
    assert!(matches!(
        plan_leg(cell, robot, &q, &robot.home, &s),
        Err(PlanError::StartInvalid { .. })
    ));
}

#[test]
fn home_to_candidates_and_back() {
    let f = fixture();
    let cell = &f.cell;
    let s = PlanSettings::default();
    let mut legs = 0;
    for (robot, candidates) in cell.robots.iter().zip(&f.candidates) {
        let v = robot_validity(cell, robot, margin(cell));
        for goal in candidates
            .iter()
            .filter(|q| v.clearance(q) > s.min_clearance)
            .take(3)
        {
            for (a, b) in [(&robot.home, goal), (goal, &robot.home)] {
                let path = plan_leg(cell, robot, a, b, &s).expect("a path");
                assert_eq!(path.waypoints.first(), Some(a));
                assert_eq!(path.waypoints.last(), Some(b));
                assert!(path.waypoints.iter().all(|q| v.clearance(q) > 0.0));
                dense_contact_free(cell, robot, &path.waypoints).unwrap();
                legs += 1;
            }
        }
    }
    assert!(legs >= 16, "{legs}");
}

#[test]
fn blocked_leg_is_solved_by_rrt_connect() {
    let f = fixture();
    let cell = &f.cell;
    let s = PlanSettings {
        seed: 5,
        ..PlanSettings::default()
    };
    // The first leg from home to a candidate whose straight segment is blocked.
    let (robot, goal) = cell
        .robots
        .iter()
        .zip(&f.candidates)
        .find_map(|(robot, candidates)| {
            let space = joint_space(cell, robot);
            let v = robot_validity(cell, robot, margin(cell));
            candidates
                .iter()
                .filter(|q| v.clearance(q) > s.min_clearance)
                .find(|q| {
                    matches!(
                        Straight.plan(&space, &v, &robot.home, q, &s),
                        Err(PlanError::NoPath { .. })
                    )
                })
                .map(|q| (robot, q.clone()))
        })
        .expect("some candidate is not reachable in a straight line from home");
    let path = plan_leg(cell, robot, &robot.home, &goal, &s).expect("a path");
    assert!(!path.straight);
    assert!(path.waypoints.len() >= 3);
    assert!(path.samples > 0);
    dense_contact_free(cell, robot, &path.waypoints).unwrap();
    // Deterministic for the seed.
    let again = plan_leg(cell, robot, &robot.home, &goal, &s).unwrap();
    assert_eq!(path.waypoints, again.waypoints);
    assert_eq!(path.validity_calls, again.validity_calls);
    eprintln!(
        "{}: {} waypoints, {} samples, {} validity calls",
        robot.name,
        path.waypoints.len(),
        path.samples,
        path.validity_calls
    );
}

/// A leg the sampler gives up on (a budget of no samples: only the straight segment, which is
/// blocked) is found through the robot's shared roadmap, passes the dense re-check, and is the
/// same from a fresh roadmap as from one that other legs have used (their edge checks cached)
/// — the roadmap's answers do not depend on which legs were asked before, on which thread. The
/// cell's leg planner with the roadmap gives a valid leg too.
#[test]
fn a_leg_the_sampler_gives_up_on_goes_through_the_roadmap() {
    use cellplan_motion::plan::{plan_leg as sample_leg, roadmap_leg};
    let f = fixture();
    let cell = &f.cell;
    let s = PlanSettings {
        seed: 7,
        max_samples: 0,
        ..PlanSettings::default()
    };
    let mut solved = 0;
    for (robot, candidates) in cell.robots.iter().zip(&f.candidates) {
        let space = joint_space(cell, robot);
        let v = robot_validity(cell, robot, margin(cell));
        let goals: Vec<&Vec<f64>> = candidates
            .iter()
            .filter(|q| v.clearance(q) > s.min_clearance)
            .filter(|q| {
                matches!(
                    sample_leg(&space, &v, &robot.home, q, &s),
                    Err(PlanError::NoPath { .. })
                )
            })
            .take(3)
            .collect();
        let mut seeds = vec![robot.home.clone()];
        seeds.extend(candidates.iter().cloned());
        let warm = robot_roadmap(cell, robot, &seeds, 11);
        assert!(warm.len() > seeds.len() / 2, "{} nodes", warm.len());
        for goal in goals {
            let Ok(path) = roadmap_leg(&space, &v, &warm, &robot.home, goal, &s) else {
                continue;
            };
            assert_eq!(path.waypoints.first(), Some(&robot.home));
            assert_eq!(path.waypoints.last(), Some(goal));
            dense_contact_free(cell, robot, &path.waypoints).unwrap();
            let cold = robot_roadmap(cell, robot, &seeds, 11);
            let again = roadmap_leg(&space, &v, &cold, &robot.home, goal, &s).unwrap();
            assert_eq!(again.waypoints, path.waypoints);
            let get = || &warm;
            let leg =
                plan_leg_with_margin(cell, robot, &robot.home, goal, margin(cell), &s, Some(&get)).unwrap();
            dense_contact_free(cell, robot, &leg.waypoints).unwrap();
            solved += 1;
        }
    }
    assert!(solved >= 3, "{solved} legs through the roadmap");
}

#[test]
fn accepted_segments_pass_the_dense_recheck() {
    let f = fixture();
    let cell = &f.cell;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let s = PlanSettings::default();
    let (mut accepted, mut refused) = (0, 0);
    for robot in &cell.robots {
        let space = joint_space(cell, robot);
        let v = robot_validity(cell, robot, margin(cell));
        // From home or a candidate to a random valid configuration.
        let mut starts = vec![robot.home.clone()];
        starts.extend(f.candidates[robot.id.0].iter().take(4).cloned());
        for a in &starts {
            for _ in 0..6 {
                let b = random_q(robot, &mut rng);
                if v.clearance(&b) <= s.min_clearance || v.clearance(a) <= s.min_clearance {
                    continue;
                }
                let check = cellplan_motion::plan::check_segment(&space, &v, a, &b, s.min_clearance);
                if check.valid {
                    dense_contact_free(cell, robot, &[a.clone(), b]).unwrap();
                    accepted += 1;
                } else {
                    refused += 1;
                }
            }
        }
    }
    assert!(accepted >= 5 && refused >= 5, "{accepted} {refused}");
}

/// The robot's capped `segment_step` agrees with the default built on `clearances`: the same
/// contact verdict, a step never longer (up to GJK's tolerance) and, where a part was taken at
/// a cover bound that is enough (`ENOUGH_SHARE` in cellplan-motion's arm.rs), shorter but not by
/// much over all (its exact queries stop within a tenth, `STEP_SHARE`) — at candidates (close to the body) and at random configurations, for random
/// segment bounds.
#[test]
fn capped_segment_step_agrees_with_the_default() {
    struct Plain<'a>(&'a RobotValidity<'a>);
    impl StateValidity for Plain<'_> {
        fn clearance(&self, q: &[f64]) -> f64 {
            self.0.clearance(q)
        }
        fn clearances(&self, q: &[f64], out: &mut Vec<cellplan_motion::plan::Clearance>) {
            self.0.clearances(q, out)
        }
    }
    let f = fixture();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut checked, mut shorter, mut fast_sum, mut slow_sum) = (0, 0, 0.0, 0.0);
    for robot in &f.cell.robots {
        let mut v = robot_validity(&f.cell, robot, margin(&f.cell));
        // The default steps by the space's radii alone: so must the capped one here.
        v.own_radii = false;
        v.posed_radii = false;
        let plain = Plain(&v);
        let mut qs = f.candidates[robot.id.0].clone();
        qs.extend((0..40).map(|_| random_q(robot, &mut rng)));
        for q in &qs {
            let per_joint: Vec<f64> = (0..q.len()).map(|_| rng.random_range(0.0..3.0)).collect();
            let motion = cellplan_motion::plan::SegmentMotion::new(&vec![1.0; q.len()], &per_joint);
            let floor = 1e-4;
            let limit = rng.random_range(0.05..1.0);
            let fast = v.segment_step(q, &motion, floor, limit);
            let slow = plain.segment_step(q, &motion, floor, limit);
            match (fast, slow) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    // GJK stops at a tolerance that depends on the cap: the two distances may
                    // differ by a few µm·1e-3, far inside the 1 µm slack taken off every one.
                    assert!(
                        a > 0.0 && a <= b + 1e-5 * b + 1e-9,
                        "capped step {a}, default {b}"
                    );
                    checked += 1;
                    // Its exact queries stop within a tenth of the distance above the floor
                    // (`STEP_SHARE`): shorter than that only where a cover bound was taken.
                    shorter += usize::from(a < 0.9 * b - 1e-5 * b - 1e-9);
                    fast_sum += a;
                    slow_sum += b;
                }
                other => panic!("verdicts differ at {q:?}: {other:?}"),
            }
        }
    }
    assert!(checked > 100, "only {checked} valid configurations compared");
    // Most steps are the same; the shorter ones cost little length over all.
    assert!(shorter * 4 < checked, "{shorter} of {checked} shorter");
    assert!(fast_sum >= 0.8 * slow_sum, "steps {fast_sum} against {slow_sum}");
}

/// A leg whose middle waypoints stand a full turn of the wrist's last joint from where the
/// ends have it (as a path through samples drawn over the joint's ±2π range can): straightening
/// with no one-joint shortcut (so that only the unwinding acts) unwinds it on the R-2000iC in
/// the car-body cell — the middle waypoints stand a turn back, every other joint where it was,
/// the joint moves a turn less each way, the leg takes less time, and the dense re-check finds
/// it clear.
#[test]
fn straightening_unwinds_a_wrist_turned_round_on_the_real_robot() {
    use cellplan_core::plan::graph::limits_of;
    use cellplan_motion::plan::{check_segment, straighten_joints_timed};
    use cellplan_motion::timing::time_path_exact;
    let f = fixture();
    let cell = &f.cell;
    let tau = std::f64::consts::TAU;
    let robot = &cell.robots[0];
    let space = joint_space(cell, robot);
    let v = robot_validity(cell, robot, margin(cell));
    let limits = limits_of(robot);
    let last = robot.dof() - 1;
    assert!(space.winds(last), "joint 6 of the R-2000iC turns over ±2π");
    let home = robot.home.clone();
    let mut tried = 0;
    for goal in &f.candidates[0] {
        // Two middle waypoints, a third and two thirds of the way, turned a full turn.
        let mut path = vec![home.clone()];
        for t in [1.0 / 3.0, 2.0 / 3.0] {
            let mut q = Vec::new();
            space.interpolate(&home, goal, t, &mut q);
            q[last] += if q[last] > 0.0 { -tau } else { tau };
            path.push(q);
        }
        path.push(goal.clone());
        if !path.iter().all(|q| space.contains(q))
            || !path
                .windows(2)
                .all(|w| check_segment(&space, &v, &w[0], &w[1], 1e-4).valid)
        {
            continue;
        }
        tried += 1;
        let time = |p: &[Vec<f64>]| time_path_exact(p, &limits).unwrap().trajectory.duration();
        let turned = |p: &[Vec<f64>]| p.windows(2).map(|w| (w[1][last] - w[0][last]).abs()).sum::<f64>();
        let mut straight = path.clone();
        straighten_joints_timed(&space, &v, &mut straight, (3, 0), 1e-4, &limits);
        assert_eq!(straight.first(), path.first());
        assert_eq!(straight.last(), path.last());
        for k in 1..3 {
            assert_eq!(straight[k][..last], path[k][..last]);
            assert!(
                (straight[k][last] - path[k][last]).abs() > tau - 1e-9,
                "{straight:?}"
            );
        }
        assert!(
            turned(&straight) < turned(&path) - tau,
            "joint 6 turned {} rad before, {} after",
            turned(&path),
            turned(&straight)
        );
        assert!(time(&straight) < time(&path));
        dense_contact_free(cell, robot, &straight).unwrap();
        if tried == 3 {
            break;
        }
    }
    assert_eq!(
        tried, 3,
        "three legs home → candidate clear with the wrist turned round"
    );
}
