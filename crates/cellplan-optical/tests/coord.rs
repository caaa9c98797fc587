//! Coordination on a two-robot cell built so that the robots' paths cross: the bundled
//! two-robot example with the second robot moved to 0.9 m from the first, and its first 12 MPs
//! (`cellplan_optical::testing`, shared with the report's tests).
//! Every strategy must give a plan the verifier accepts; the uncoordinated plan must be
//! rejected, naming the conflict; injected faults must be caught.
use cellplan_core::coord::{self, Coordination};
use cellplan_core::document as output;
use cellplan_model::LoadOptions;
use cellplan_optical::load;
use cellplan_optical::testing::{crossing_cell, document, fixture, on_threads};
use cellplan_verify::{VerifySettings, ViolationKind, verify};

mod faults;

#[test]
fn the_uncoordinated_plan_has_a_conflict_and_the_verifier_names_it() {
    let f = fixture();
    let (doc, c) = document(Coordination::None);
    assert!(!c.after.is_empty(), "the robots of this cell must meet");
    let first = &doc.coordination.conflicts_after[0];
    assert_eq!(first.robots, ["R1".to_string(), "R2".to_string()]);
    assert!(first.end_s > first.start_s);
    // Scenario 1 exactly when both probes are measuring.
    let measuring = first
        .activity
        .iter()
        .all(|a| matches!(a, output::ActivityOut::Working { .. }));
    assert_eq!(first.scenario == 1, measuring, "{first:?}");
    let report = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(!report.ok);
    let rr: Vec<_> = report
        .violations
        .iter()
        .filter(|v| v.kind == ViolationKind::RobotRobot)
        .collect();
    assert!(!rr.is_empty(), "{:#?}", report.violations);
    assert_eq!(rr[0].robot.as_deref(), Some("R1"));
    assert_eq!(rr[0].other.as_deref(), Some("R2"));
    // The verifier sees the contact where the planner's search found it (within its step).
    let t = rr[0].time_s.unwrap();
    assert!(t <= first.end_s && t + 0.05 >= first.start_s, "{t} vs {first:?}");
}

#[test]
fn every_strategy_gives_a_verified_conflict_free_plan() {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    let free = coord::cycle_and_delta(&none.timed).0;
    for strategy in Coordination::RESOLVING {
        let (doc, c) = document(strategy);
        let report = verify(&f.cell, &doc, &VerifySettings::default());
        assert!(report.ok, "{}: {:#?}", strategy, report.violations);
        assert!(!c.before.is_empty(), "{}", strategy);
        assert!(c.after.is_empty());
        assert!(c.resolved >= 1);
        // Resolving costs time or nothing; never less than the robots passing through each other.
        assert!(doc.cycle_time_s >= free - 1e-9, "{}", strategy);
        // The waits are in the document where the strategy made them, none shorter than the
        // shortest allowed (a shorter one would not show between two trajectory samples).
        let waits: usize = doc.robots.iter().map(|r| r.waits.len()).sum();
        let min_wait = coord::CoordSettings::default().min_wait;
        for w in doc.robots.iter().flat_map(|r| &r.waits) {
            assert!(w.duration_s >= min_wait - 1e-9, "{}: {w:?}", strategy);
        }
        assert_eq!(waits > 0, c.programs.iter().any(|p| !p.waits.is_empty()));
        if strategy == Coordination::DelayStartup {
            assert!(
                doc.robots
                    .iter()
                    .flat_map(|r| &r.waits)
                    .all(|w| w.leg == 0 && w.waypoint == 0)
            );
        }
    }
}

/// The distance between R1 at `qa` and R2 at `qb` of the crossing cell (capped at 1 m).
fn distance(qa: &[f64], qb: &[f64]) -> f64 {
    let f = fixture();
    let (ra, rb) = (&f.cell.robots[0], &f.cell.robots[1]);
    let (mut sa, mut sb) = (Default::default(), Default::default());
    ra.body_poses(qa, &mut sa);
    rb.body_poses(qb, &mut sb);
    f.cell
        .world
        .group_group_distance(ra.group, &sa.bodies, rb.group, &sb.bodies, 1.0)
}

/// The uncoordinated plan of the crossing cell and its conflict boxes.
fn uncoordinated_boxes() -> (coord::Coordinated, Vec<coord::ConflictBox>) {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    let settings = coord::CoordSettings::default();
    let boxes = coord::conflict_boxes(&f.cell, &f.table, &none.programs, &settings).unwrap();
    (none, boxes)
}

/// The pairs of positions (every 50 ms of each program: `ta` of R1, `tb` of R2 of the
/// crossing cell) at which the two robots come closer than the coordination's distance, with
/// that distance.
fn contacts(ta: &coord::Timed, tb: &coord::Timed) -> Vec<(f64, f64, f64)> {
    let margin = fixture().cell.planning.clearance + coord::REPLAY_SLACK;
    let mut out = Vec::new();
    let step = 0.05;
    let mut sa = 0.0;
    while sa <= ta.end() {
        let mut sb = 0.0;
        while sb <= tb.end() {
            let d = distance(&ta.trajectory.position(sa), &tb.trajectory.position(sb));
            if d <= margin {
                out.push((sa, sb, d));
            }
            sb += step;
        }
        sa += step;
    }
    out
}

/// The coordination diagram misses no contact: on a grid of position pairs (every 50 ms of
/// each program) every pair of configurations closer than the clearance lies in a box of that
/// robot pair, and so does every conflict the search on the clock found (both robots at the
/// conflict's start, the programs having no waits). The boxes are not the whole square either.
#[test]
fn the_coordination_diagram_covers_every_contact() {
    let (none, boxes) = uncoordinated_boxes();
    assert!(!boxes.is_empty());
    let inside = |a: usize, b: usize, sa: f64, sb: f64| {
        boxes.iter().any(|x| {
            x.robots == (a, b)
                && x.a.0 - 1e-9 <= sa
                && sa <= x.a.1 + 1e-9
                && x.b.0 - 1e-9 <= sb
                && sb <= x.b.1 + 1e-9
        })
    };
    for c in &none.after {
        assert!(inside(c.robots.0, c.robots.1, c.start, c.start), "{c:?}");
    }
    let (ta, tb) = (&none.timed[0], &none.timed[1]);
    let close = contacts(ta, tb);
    for &(sa, sb, d) in &close {
        assert!(inside(0, 1, sa, sb), "({sa}, {sb}) at {d} m is in no box");
    }
    assert!(!close.is_empty());
    let area: f64 = boxes.iter().map(|x| (x.a.1 - x.a.0) * (x.b.1 - x.b.0)).sum();
    assert!(area < 0.5 * ta.end() * tb.end(), "{area}");
}

/// The diagram as a certificate on the clock: with waits anywhere in the two programs, every
/// time (every 10 ms) at which the robots come closer than the coordination's distance lies in
/// a window the cover gives for the pair, and the windows are not the whole clock. (The exact
/// search on the clock looks only there.)
#[test]
fn the_diagrams_windows_on_the_clock_hold_every_contact() {
    let f = fixture();
    let (none, boxes) = uncoordinated_boxes();
    let cover = coord::Cover::new(2, &boxes);
    let margin = f.cell.planning.clearance + coord::REPLAY_SLACK;
    let limits: Vec<_> = f
        .cell
        .robots
        .iter()
        .map(cellplan_core::plan::graph::limits_of)
        .collect();
    let wait = |leg: usize, duration: f64| coord::Wait {
        leg,
        waypoint: 0,
        duration,
        reason: coord::WaitReason::GiveWay,
        for_robot: None,
    };
    let (mut contacts, mut covered, mut total) = (0, 0.0, 0.0);
    // Waits of either robot, at its start and between measurements.
    for (wa, wb) in [
        (vec![], vec![]),
        (vec![(0, 1.5)], vec![]),
        (vec![], vec![(2, 0.8), (5, 2.0)]),
        (vec![(3, 0.6)], vec![(0, 0.3)]),
    ] {
        let (mut pa, mut pb) = (none.programs[0].clone(), none.programs[1].clone());
        for (leg, d) in wa {
            pa.set_wait(wait(leg, d));
        }
        for (leg, d) in wb {
            pb.set_wait(wait(leg, d));
        }
        let (ta, tb) = (pa.timed(&limits[0]).unwrap(), pb.timed(&limits[1]).unwrap());
        let horizon = ta.end().max(tb.end());
        let windows = cover.windows(0, &ta, 1, &tb, 0.0, horizon).unwrap();
        covered += windows.iter().map(|w| w.1 - w.0).sum::<f64>();
        total += horizon;
        let mut t = 0.0;
        while t <= horizon {
            let d = distance(&ta.trajectory.position(t), &tb.trajectory.position(t));
            if d <= margin {
                contacts += 1;
                assert!(
                    windows.iter().any(|w| w.0 - 1e-9 <= t && t <= w.1 + 1e-9),
                    "contact at {t} s ({d} m) in no window: {windows:?}"
                );
            }
            t += 0.01;
        }
    }
    assert!(contacts > 0, "the robots of the crossing cell meet somewhere");
    assert!(covered < 0.5 * total, "windows {covered} s of {total} s");
}

/// Every robot's motion keeps the coordination's distance, and `HOME_STEP_SLACK` more, from
/// every other robot standing at home (sampled along the uncoordinated timelines): a robot at
/// home is never in another's way, with room for the timeline's conservative steps.
#[test]
fn robots_keep_more_than_the_coordination_distance_from_the_homes() {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    let need = f.cell.planning.clearance + coord::REPLAY_SLACK + cellplan_core::motion::HOME_STEP_SLACK;
    let mut at_home = Default::default();
    let mut moving = Default::default();
    let mut samples = 0;
    for (a, ta) in none.timed.iter().enumerate() {
        for (b, rb) in f.cell.robots.iter().enumerate() {
            if a == b {
                continue;
            }
            rb.body_poses(&rb.home, &mut at_home);
            let ra = &f.cell.robots[a];
            let mut t = 0.0;
            while t <= ta.end() {
                ra.body_poses(&ta.trajectory.position(t), &mut moving);
                let d = f.cell.world.group_group_distance(
                    ra.group,
                    &moving.bodies,
                    rb.group,
                    &at_home.bodies,
                    1.0,
                );
                assert!(
                    d >= need - 1e-6,
                    "{} at {t} s is {d} m from {} at home",
                    ra.name,
                    rb.name
                );
                samples += 1;
                t += 0.02;
            }
        }
    }
    assert!(samples > 100);
}

/// `best` is no worse than the baselines, to its tie rule: a cycle within a millisecond with a
/// smaller Δt counts as shorter (and `best` runs the fixed-priority competitor on the tours
/// in their canonical directions, the baseline on the tours as planned).
#[test]
fn best_is_no_worse_than_the_baselines_here() {
    let cycle = |s: Coordination| document(s).0.cycle_time_s;
    let best = cycle(Coordination::Best);
    for s in [Coordination::DelayStartup, Coordination::FixedPriority] {
        assert!(best <= cycle(s) + 1e-3, "best {best} vs {} {}", s, cycle(s));
    }
}

#[test]
fn coordination_does_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        on_threads(threads, || {
            let (mut doc, _) = document(Coordination::Best);
            doc.compute_s = output::ComputeTimes::default();
            doc
        })
    };
    assert_eq!(run(1), run(2));
}

/// The verifier checks legs, the robot–robot timeline and the lower bound's graphs in
/// parallel; its report — every violation, their order, the figures — is the same on one
/// thread as on two. The uncoordinated plan's robots meet, so the report has robot–robot
/// violations to order.
#[test]
fn the_verifier_says_the_same_on_one_thread_and_on_two() {
    let f = fixture();
    let (doc, _) = document(Coordination::None);
    let run = |threads| {
        on_threads(threads, || {
            format!("{:?}", verify(&f.cell, &doc, &VerifySettings::default()))
        })
    };
    let one = run(1);
    assert!(one.contains("RobotRobot"), "{one}");
    assert_eq!(one, run(2));
}

#[test]
fn the_verifier_catches_injected_faults() {
    let f = fixture();
    let good = faults::good_plan();
    let settings = VerifySettings::default();
    let kinds = faults::kinds;
    // The cell as built differs from the plan: R2 stands 5 cm closer to R1. Where the plan
    // passes the robots by each other with little room, they now meet.
    let moved_path = crossing_cell().with_file_name("moved.toml");
    let text = std::fs::read_to_string(crossing_cell())
        .unwrap()
        .replace("xyz = [3100, -200, 0]", "xyz = [3100, -250, 0]");
    std::fs::write(&moved_path, text).unwrap();
    let moved = load(&moved_path, &LoadOptions::default()).unwrap();
    let k: Vec<ViolationKind> = verify(&moved, &good, &settings)
        .violations
        .iter()
        .map(|v| v.kind)
        .collect();
    assert!(k.contains(&ViolationKind::RobotRobot), "{k:?}");
    // A joint-limit breach.
    let mut breach = good.clone();
    let n = breach.robots[0].trajectory.len();
    breach.robots[0].trajectory[n / 2].q[0] = 10.0;
    assert!(kinds(&breach).contains(&ViolationKind::JointLimit));
    // A skipped MP.
    let mut skipped = good.clone();
    let busy = skipped.robots.iter().position(|r| !r.tasks.is_empty()).unwrap();
    skipped.robots[busy].tasks.remove(0);
    assert!(kinds(&skipped).contains(&ViolationKind::MissingTask));
    // Legs that no longer describe the motion: a via point of a sampled leg dropped, so the
    // trajectory leaves the joint path the scene was checked along.
    let mut rerouted = good.clone();
    let (r, l) = rerouted
        .robots
        .iter()
        .enumerate()
        .find_map(|(r, rp)| {
            rp.legs
                .iter()
                .position(|l| l.waypoints.len() >= 3)
                .map(|l| (r, l))
        })
        .expect("a leg with a via point");
    rerouted.robots[r].legs[l].waypoints.remove(1);
    rerouted.robots[r].legs[l].blends.clear();
    assert!(
        kinds(&rerouted).contains(&ViolationKind::OffPath),
        "{:?}",
        kinds(&rerouted)
    );
    // A wait removed from the trajectory: the robots meet again.
    let mut hurried = good.clone();
    let (_, none) = document(Coordination::None);
    let doc_none = output::build(&f.cell, &f.table, &f.outcome, &none, &f.settings, 0.0, 0.0);
    for (r, rn) in hurried.robots.iter_mut().zip(&doc_none.robots) {
        r.trajectory = rn.trajectory.clone();
        r.total_s = rn.total_s;
    }
    hurried.cycle_time_s = doc_none.cycle_time_s;
    hurried.delta_t_s = doc_none.delta_t_s;
    assert!(kinds(&hurried).contains(&ViolationKind::RobotRobot));
    // A robot's waits list deleted (the exported program would lose its wait): the clock
    // no longer adds up, nor does the waiting time.
    let waiter = good
        .robots
        .iter()
        .position(|r| !r.waits.is_empty())
        .expect("a robot that waits");
    let mut unwaited = good.clone();
    unwaited.robots[waiter].waits.clear();
    let k = kinds(&unwaited);
    assert!(
        k.contains(&ViolationKind::Continuity) && k.contains(&ViolationKind::Totals),
        "{k:?}"
    );
    // A wait moved to another time: not a standstill there.
    let mut moved_wait = good.clone();
    let w = &mut moved_wait.robots[waiter].waits[0];
    w.start_s += 0.5 * w.duration_s.max(0.2) + 0.3;
    assert!(kinds(&moved_wait).contains(&ViolationKind::Continuity));
    // The priority order named with a robot the plan does not have.
    let mut stranger = good.clone();
    stranger.coordination.priority = vec!["R9".into()];
    assert!(kinds(&stranger).contains(&ViolationKind::Totals));
}

/// The plan records each robot's probe track before coordination: from home to home, as long
/// as the uncoordinated program, and with the waits gone (so shorter than the plan's).
#[test]
fn the_plan_keeps_the_probe_tracks_before_coordination() {
    let f = fixture();
    let (doc, c) = document(Coordination::FixedPriority);
    let tracks = &doc.coordination.uncoordinated_probe;
    assert_eq!(tracks.len(), doc.robots.len());
    for ((tr, rp), prog) in tracks.iter().zip(&doc.robots).zip(&f.outcome.robots) {
        assert_eq!(tr.robot, rp.name);
        let robot = f.cell.robot(&rp.name).unwrap();
        let home = robot.tcp_pose(&rp.home).translation;
        for end in [tr.xyz.first().unwrap(), tr.xyz.last().unwrap()] {
            assert!((cellplan_geom::DVec3::from(*end) - home).length() < 1e-3);
        }
        let length = prog.program.duration();
        assert_eq!(tr.xyz.len(), (length / tr.dt_s).ceil() as usize + 1);
        // Longer than the plan's program only by what blending its legs saved.
        let saved = prog.program.motion() - rp.motion_s;
        assert!(saved >= -1e-9, "blending made the legs slower: {saved}");
        assert!(length <= rp.total_s + saved + 1e-9);
    }
    let waited: f64 = doc.robots.iter().map(|r| r.waiting_s).sum();
    assert!(waited > 0.0 && c.waits > 0);
}

/// A stop (what `best` adds where a robot has no rest to let another pass) splits a moving
/// segment at the configuration the robot has there: the joint path is the same, the robot
/// comes to rest there once more, and the program gets longer; inside a measurement there is
/// nothing to split.
#[test]
fn a_stop_splits_a_segment_on_the_same_joint_path() {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    let robot = &f.cell.robots[0];
    let limits = cellplan_core::plan::graph::limits_of(robot);
    let program = none.programs[0].clone();
    let timed = &none.timed[0];
    let span = timed
        .spans
        .iter()
        .find(|s| matches!(s.what, coord::Activity::Move { .. }) && s.end - s.start > 0.2)
        .expect("a segment to split");
    let coord::Activity::Move { leg, segment } = span.what else {
        unreachable!()
    };
    let at = 0.5 * (span.start + span.end);
    let mut stopped = program.clone();
    assert!(stopped.stop_at(timed, at, &limits).unwrap());
    let (old, new) = (&program.legs[leg].waypoints, &stopped.legs[leg].waypoints);
    assert_eq!(new.len(), old.len() + 1);
    let (a, b, m) = (&old[segment], &old[segment + 1], &new[segment + 1]);
    assert_eq!(m, &timed.trajectory.position(at));
    // On the segment: m = a + λ (b − a), 0 < λ < 1, in every joint.
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| y - x).collect();
    let k = (0..d.len())
        .max_by(|&i, &j| d[i].abs().total_cmp(&d[j].abs()))
        .unwrap();
    let lambda = (m[k] - a[k]) / d[k];
    assert!(lambda > 0.0 && lambda < 1.0, "{lambda}");
    for j in 0..d.len() {
        assert!((a[j] + lambda * d[j] - m[j]).abs() < 1e-9, "joint {j}");
    }
    assert!(!stopped.legs[leg].straight);
    let again = stopped.timed(&limits).unwrap();
    assert!(again.end() > timed.end() + 1e-6, "a stop costs time");
    // Every configuration of the new program lies on the old joint path of that leg.
    let on_old = |q: &[f64]| {
        old.windows(2).any(|w| {
            let d: Vec<f64> = w[0].iter().zip(&w[1]).map(|(x, y)| y - x).collect();
            let len2: f64 = d.iter().map(|x| x * x).sum();
            let t = if len2 > 0.0 {
                (q.iter()
                    .zip(&w[0])
                    .zip(&d)
                    .map(|((q, a), d)| (q - a) * d)
                    .sum::<f64>()
                    / len2)
                    .clamp(0.0, 1.0)
            } else {
                0.0
            };
            q.iter()
                .zip(&w[0])
                .zip(&d)
                .all(|((q, a), d)| (a + t * d - q).abs() < 1e-7)
        })
    };
    for s in again
        .spans
        .iter()
        .filter(|s| matches!(s.what, coord::Activity::Move { leg: l, .. } if l == leg))
    {
        for i in 0..=10 {
            let q = again
                .trajectory
                .position(s.start + (s.end - s.start) * i as f64 / 10.0);
            assert!(on_old(&q), "{q:?} is off the leg's path");
        }
    }
    // Inside a measurement: nothing to split.
    let (arrive, depart) = timed.visits[0];
    let mut same = program.clone();
    assert!(!same.stop_at(timed, 0.5 * (arrive + depart), &limits).unwrap());
    assert_eq!(same, program);
}

/// A tour run the other way round is the same joint path backwards on the clock: at position
/// `len − s` it is where the tour is at `s`, it takes as long, and reversing it twice gives
/// the tour back.
#[test]
fn a_reversed_tour_is_the_same_path_backwards() {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    for (p, t) in none.programs.iter().zip(&none.timed) {
        let limits = cellplan_core::plan::graph::limits_of(&f.cell.robots[p.robot]);
        let back = p.reversed(&limits).unwrap();
        assert_eq!(back.reversed(&limits).unwrap(), *p);
        assert_eq!(
            back.visits.iter().map(|v| v.task).collect::<Vec<_>>(),
            p.visits.iter().rev().map(|v| v.task).collect::<Vec<_>>()
        );
        let tb = back.timed(&limits).unwrap();
        let len = t.end();
        assert!((tb.end() - len).abs() < 1e-9, "{} vs {len}", tb.end());
        let mut s = 0.0;
        while s <= len {
            let (x, y) = (t.trajectory.position(s), tb.trajectory.position(len - s));
            for (a, b) in x.iter().zip(&y) {
                assert!((a - b).abs() < 1e-7, "at {s}: {x:?} vs {y:?}");
            }
            s += 0.01;
        }
    }
}

/// The diagram of a pair with one tour reversed is the pair's diagram mirrored along that
/// robot's positions (what `best`'s choice of directions relies on): every pair of positions
/// at which the reversed tour comes closer than the clearance to the other lies in a mirrored
/// box, and the mirrored boxes are the boxes built for the reversed tour, to rounding.
#[test]
fn the_diagram_of_a_reversed_tour_is_the_mirrored_diagram() {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    let settings = coord::CoordSettings::default();
    let boxes = coord::conflict_boxes(&f.cell, &f.table, &none.programs, &settings).unwrap();
    let len = none.timed[1].end();
    let mirrored: Vec<coord::ConflictBox> = boxes
        .iter()
        .map(|b| coord::ConflictBox {
            b: (len - b.b.1, len - b.b.0),
            open: [b.open[0], b.open[1], b.open[3], b.open[2]],
            ..b.clone()
        })
        .collect();
    let limits = cellplan_core::plan::graph::limits_of(&f.cell.robots[1]);
    let programs = vec![
        none.programs[0].clone(),
        none.programs[1].reversed(&limits).unwrap(),
    ];
    let direct = coord::conflict_boxes(&f.cell, &f.table, &programs, &settings).unwrap();
    let key = |b: &coord::ConflictBox| {
        let r = |x: f64| (x * 1e6).round() as i64;
        (r(b.a.0), r(b.a.1), r(b.b.0), r(b.b.1), b.open)
    };
    let mut x: Vec<_> = mirrored.iter().map(key).collect();
    let mut y: Vec<_> = direct.iter().map(key).collect();
    x.sort();
    y.sort();
    assert_eq!(x, y);
    // And they cover every contact of the reversed tour.
    let close = contacts(&none.timed[0], &programs[1].timed(&limits).unwrap());
    for &(sa, sb, d) in &close {
        let inside = mirrored
            .iter()
            .any(|x| x.a.0 - 1e-9 <= sa && sa <= x.a.1 + 1e-9 && x.b.0 - 1e-9 <= sb && sb <= x.b.1 + 1e-9);
        assert!(inside, "({sa}, {sb}) at {d} m is in no mirrored box");
    }
    assert!(!close.is_empty());
}

/// `best` chooses each tour's direction: given robot R2's tour the other way round, it ends
/// at the same cycle time as from the tour as planned (directions count from a canonical one,
/// not from the way the sequencer wrote the tour), and either plan verifies — with the tours,
/// the tracks before coordination and the conflicts before it in the directions run.
#[test]
fn best_chooses_the_tour_directions() {
    let f = fixture();
    // Without blends: with them, `best` also runs the baselines on the tours as given.
    let settings = coord::CoordSettings {
        blend_deviation: 0.0,
        ..coord::CoordSettings::default()
    };
    let limits = cellplan_core::plan::graph::limits_of(&f.cell.robots[1]);
    let mut turned = f.outcome.clone();
    turned.robots[1].program = f.outcome.robots[1].program.reversed(&limits).unwrap();
    let mut cycles = Vec::new();
    for outcome in [&f.outcome, &turned] {
        let c = coord::coordinate_outcome(&f.cell, &f.table, outcome, &settings).unwrap();
        let doc = cellplan_core::document::build(&f.cell, &f.table, outcome, &c, &f.settings, 0.0, 0.0);
        let report = verify(&f.cell, &doc, &VerifySettings::default());
        assert!(report.ok, "{:#?}", report.violations);
        // Reversed tours come only from the schedule (not from the fixed-priority
        // competitor, nor when nothing conflicts), which the document then reports.
        let flipped = c.reversed.iter().filter(|&&r| r).count();
        assert_eq!(doc.stats.passage_search.map_or(0, |s| s.reversed), flipped);
        // The tour run is the one given, or that one reversed.
        let given: Vec<_> = outcome.robots[1].program.visits.iter().map(|v| v.task).collect();
        let mut run: Vec<_> = c.programs[1].visits.iter().map(|v| v.task).collect();
        if c.reversed.get(1).copied().unwrap_or(false) {
            run.reverse();
        }
        assert_eq!(run, given);
        cycles.push(doc.cycle_time_s);
    }
    assert!((cycles[0] - cycles[1]).abs() < 1e-9, "{cycles:?}");
}

#[test]
fn contacts_shorter_than_the_time_step_are_caught() {
    // The robot–robot check proves clearance between the instants it measures (conservative
    // advancement on the robots' travel), so a coarse time step only coarsens how a contact's
    // interval is reported: every conflict of the uncoordinated plan is still found, even those
    // shorter than the step, which sampling at that step could pass over.
    let f = fixture();
    let (doc, _) = document(Coordination::None);
    let coarse = VerifySettings {
        time_step: 1.0,
        ..VerifySettings::default()
    };
    let report = verify(&f.cell, &doc, &coarse);
    let found: Vec<_> = report
        .violations
        .iter()
        .filter(|v| v.kind == ViolationKind::RobotRobot)
        .collect();
    let conflicts = &doc.coordination.conflicts_after;
    assert!(
        conflicts.iter().any(|c| c.end_s - c.start_s < coarse.time_step),
        "the plan must have a conflict shorter than the step: {conflicts:?}"
    );
    for c in conflicts {
        // Reported at a first instant within the conflict (the planner's interval holds the
        // distance below the clearance plus its replay slack, so a contact starts no sooner).
        assert!(
            found.iter().any(|v| {
                let t = v.time_s.unwrap();
                v.robot.as_deref() == Some(c.robots[0].as_str())
                    && v.other.as_deref() == Some(c.robots[1].as_str())
                    && t >= c.start_s - 1e-6
                    && t <= c.end_s + 1e-6
            }),
            "{c:?} not among {found:#?}"
        );
    }
}

#[test]
fn the_robot_robot_check_is_proven_between_its_instants() {
    // The uncoordinated plan with R2's trajectory started later by random delays (R2 waits at
    // home first): some delays keep the robots apart, some not. Checked here every 1 ms: a plan
    // the verifier passes keeps the clearance less its tolerance at every one of those times,
    // and one that comes closer at any of them is reported.
    use rand::{RngExt, SeedableRng};
    let f = fixture();
    let (good, _) = document(Coordination::None);
    let clearance = f.cell.planning.clearance;
    let floor = clearance - cellplan_verify::PROOF_TOLERANCE;
    let position = |tr: &[output::Sample], t: f64| -> Vec<f64> {
        let i = tr.partition_point(|s| s.t <= t);
        if i == 0 {
            return tr[0].q.clone();
        }
        let Some(b) = tr.get(i) else {
            return tr[tr.len() - 1].q.clone();
        };
        let a = &tr[i - 1];
        let w = if b.t > a.t { (t - a.t) / (b.t - a.t) } else { 0.0 };
        a.q.iter().zip(&b.q).map(|(x, y)| x + w * (y - x)).collect()
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let (mut passed, mut caught) = (0, 0);
    for case in 0..12 {
        let mut doc = good.clone();
        let delay = rng.random_range(0.0..12.0);
        for s in &mut doc.robots[1].trajectory {
            s.t += delay;
        }
        let (a, b) = (&doc.robots[0].trajectory, &doc.robots[1].trajectory);
        let horizon = a.last().unwrap().t.max(b.last().unwrap().t);
        let steps = (horizon / 1e-3).ceil() as usize;
        let bad = (0..=steps).any(|k| {
            let t = k as f64 * 1e-3;
            distance(&position(a, t), &position(b, t)) < floor
        });
        let found = verify(&f.cell, &doc, &VerifySettings::default())
            .violations
            .iter()
            .any(|v| v.kind == ViolationKind::RobotRobot);
        if bad {
            assert!(
                found,
                "case {case} (delay {delay:.3} s): within {floor} m and passed"
            );
            caught += 1;
        } else if !found {
            passed += 1;
        }
    }
    assert!(passed > 0 && caught > 0, "{passed} passed, {caught} caught");
}
