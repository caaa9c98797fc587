use super::super::{check_limits, move_time, move_time_instant, move_trajectory};
use super::*;
use proptest::prelude::*;

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// Euclidean distance from `q` to the polyline.
fn dist_to_polyline(q: &[f64], path: &[Vec<f64>]) -> f64 {
    if path.len() == 1 {
        return dist(q, &path[0]);
    }
    path.windows(2)
        .map(|w| {
            let d: Vec<f64> = w[0].iter().zip(&w[1]).map(|(a, b)| b - a).collect();
            let dd: f64 = d.iter().map(|x| x * x).sum();
            let t = if dd > 0.0 {
                (q.iter()
                    .zip(&w[0])
                    .zip(&d)
                    .map(|((q, a), d)| (q - a) * d)
                    .sum::<f64>()
                    / dd)
                    .clamp(0.0, 1.0)
            } else {
                0.0
            };
            let p: Vec<f64> = w[0].iter().zip(&d).map(|(a, d)| a + t * d).collect();
            dist(q, &p)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn single_segment_is_a_synchronised_trapezoid() {
    let l = Limits::uniform(1, 1.0, 2.0).unwrap();
    let t = time_path_exact(&[vec![0.0], vec![2.0]], &l).unwrap();
    assert!((t.trajectory.duration() - 2.5).abs() < 1e-12);
    assert_eq!(t.trajectory.pieces().len(), 3);
    assert!(close(&t.trajectory.position(1.25), &[1.0], 1e-12));
    assert!(close(&t.trajectory.velocity(1.0), &[1.0], 1e-12));
    // triangle
    let t = time_path_exact(&[vec![0.0], vec![0.125]], &l).unwrap();
    assert!((t.trajectory.duration() - 0.5).abs() < 1e-12);
    assert_eq!(t.trajectory.pieces().len(), 2);
}

#[test]
fn straight_line_time_vs_move_time() {
    // joint 0 bound by velocity, joint 1 by acceleration: the straight line is slower.
    let l = Limits::new(vec![1.0, 10.0], vec![100.0, 1.0]).unwrap();
    let (a, b) = (vec![0.0, 0.0], vec![2.0, 1.0]);
    let mt = move_time(&a, &b, &l);
    let line = time_path_exact(&[a.clone(), b.clone()], &l)
        .unwrap()
        .trajectory
        .duration();
    assert!(line >= mt - 1e-12);
    // one binding joint: equal
    let l = Limits::uniform(2, 1.0, 2.0).unwrap();
    let line = time_path_exact(&[a.clone(), b.clone()], &l)
        .unwrap()
        .trajectory
        .duration();
    assert!((line - move_time(&a, &b, &l)).abs() < 1e-12);
}

#[test]
fn collinear_waypoints_are_crossed_at_speed_and_duplicates_dropped() {
    let l = Limits::uniform(2, 1.0, 1.0).unwrap();
    let path = vec![
        vec![0.0, 0.0],
        vec![1.0, 1.0],
        vec![1.0, 1.0],
        vec![3.0, 3.0],
        vec![4.0, 4.0],
    ];
    let t = time_path_exact(&path, &l).unwrap();
    let direct = time_path_exact(&[path[0].clone(), path[4].clone()], &l).unwrap();
    assert!((t.trajectory.duration() - direct.trajectory.duration()).abs() < 1e-12);
    assert_eq!(t.waypoint_times[1], t.waypoint_times[2]);
    for (w, &time) in path.iter().zip(&t.waypoint_times) {
        assert!(close(&t.trajectory.position(time), w, 1e-9), "{w:?} at {time}");
    }
    // crossing (1,1) at speed: moving there
    assert!(t.trajectory.velocity(t.waypoint_times[1])[0] > 0.5);
    // a reversal is a corner: stop
    let back = vec![vec![0.0, 0.0], vec![1.0, 1.0], vec![0.0, 0.0]];
    let t = time_path_exact(&back, &l).unwrap();
    assert!(close(
        &t.trajectory.velocity(t.waypoint_times[1]),
        &[0.0, 0.0],
        1e-12
    ));
}

#[test]
fn degenerate_paths() {
    let l = Limits::uniform(2, 1.0, 1.0).unwrap();
    let t = time_path_exact(&[vec![1.0, 2.0]], &l).unwrap();
    assert_eq!(t.trajectory.duration(), 0.0);
    assert_eq!(t.trajectory.end_position(), vec![1.0, 2.0]);
    assert_eq!(t.waypoint_times, vec![0.0]);
    let t = time_path_exact(&[vec![1.0, 2.0], vec![1.0, 2.0]], &l).unwrap();
    assert_eq!(t.trajectory.duration(), 0.0);
    assert_eq!(t.waypoint_times, vec![0.0, 0.0]);
    let b = time_path_blended(&[vec![1.0, 2.0]], &l, &[0.1]).unwrap();
    assert_eq!(b.trajectory.duration(), 0.0);
    assert!(matches!(time_path_exact(&[], &l), Err(TimingError::Empty(_))));
    assert!(matches!(
        time_path_exact(&[vec![0.0, 0.0], vec![1.0]], &l),
        Err(TimingError::DimensionMismatch { .. })
    ));
    assert!(matches!(
        time_path_exact(&[vec![0.0, f64::NAN]], &l),
        Err(TimingError::NonFinite(_))
    ));
    let p = vec![vec![0.0, 0.0], vec![1.0, 0.0]];
    assert!(matches!(
        time_path_blended(&p, &l, &[0.1, 0.1, 0.1]),
        Err(TimingError::DimensionMismatch { .. })
    ));
    assert!(matches!(
        time_path_blended(&p, &l, &[-0.1]),
        Err(TimingError::InvalidDeviation { joint: 0, .. })
    ));
}

#[test]
fn blend_by_hand() {
    // v = a = 1; L-shaped path of two 10 rad segments. β = 1, corner speed c = 1 (velocity
    // bound), blend of 1 s starting 0.5 rad before the corner; deviation 1·1·1/8 per joint.
    // Time: 1 (accelerate) + 9 (cruise) + 1 (blend) + 9 (cruise) + 1 (stop) = 21 s vs 22 s.
    let l = Limits::uniform(2, 1.0, 1.0).unwrap();
    let path = vec![vec![0.0, 0.0], vec![10.0, 0.0], vec![10.0, 10.0]];
    let b = time_path_blended(&path, &l, &[10.0]).unwrap();
    assert!((b.trajectory.duration() - 21.0).abs() < 1e-9);
    assert_eq!(b.blends.len(), 1);
    let blend = &b.blends[0];
    assert_eq!(blend.waypoint, 1);
    assert!((blend.start_time - 10.0).abs() < 1e-9);
    assert!((blend.duration - 1.0).abs() < 1e-9);
    assert!((blend.radius - 0.5).abs() < 1e-9);
    assert!(close(&blend.deviation, &[0.125, 0.125], 1e-9));
    // middle of the blend: corner + Δv·b/8
    assert!(close(&b.trajectory.position(10.5), &[9.875, 0.125], 1e-9));
    assert!((time_path_exact(&path, &l).unwrap().trajectory.duration() - 22.0).abs() < 1e-9);
    // a tight bound shrinks the blend: c² ≤ 8δ/(|Δu|·β) = 0.08, deviation exactly δ.
    let b = time_path_blended(&path, &l, &[0.01]).unwrap();
    assert!(close(&b.deviation, &[0.01, 0.01], 1e-9));
    assert!((b.blends[0].speed - 0.08f64.sqrt()).abs() < 1e-9);
    // zero deviation: exact timing
    let b = time_path_blended(&path, &l, &[0.0]).unwrap();
    assert!(b.blends.is_empty());
    assert!((b.trajectory.duration() - 22.0).abs() < 1e-9);
}

#[test]
fn reversal_is_not_blended_when_stopping_is_faster() {
    let l = Limits::uniform(1, 1.0, 1.0).unwrap();
    let path = vec![vec![0.0], vec![5.0], vec![0.0]];
    let b = time_path_blended(&path, &l, &[10.0]).unwrap();
    let e = time_path_exact(&path, &l).unwrap();
    assert!(b.trajectory.duration() <= e.trajectory.duration() + 1e-12);
    assert!(check_limits(&b.trajectory, &l, 1e-9).is_ok());
}

fn limits_and_path() -> impl Strategy<Value = (Limits, Vec<Vec<f64>>, Vec<f64>)> {
    (1usize..=6).prop_flat_map(|dof| {
        (
            prop::collection::vec(0.2f64..3.0, dof),
            prop::collection::vec(0.5f64..10.0, dof),
            prop::collection::vec((prop::collection::vec(-3.0f64..3.0, dof), 0u8..10), 1..=8),
            prop::collection::vec(0.0f64..0.5, dof),
        )
            .prop_map(|(v, a, raw, dev)| {
                // sometimes repeat a waypoint, continue in the same direction, or move one joint
                let mut path: Vec<Vec<f64>> = Vec::new();
                for (w, kind) in raw {
                    let n = path.len();
                    if kind == 0 && n >= 1 {
                        path.push(path[n - 1].clone());
                    } else if kind == 1 && n >= 2 {
                        let ext = path[n - 1]
                            .iter()
                            .zip(&path[n - 2])
                            .map(|(b, a)| 2.0 * b - a)
                            .collect();
                        path.push(ext);
                    } else if kind == 2 && n >= 1 {
                        let mut q = path[n - 1].clone();
                        q[0] = w[0];
                        path.push(q);
                    } else {
                        path.push(w);
                    }
                }
                (Limits::new(v, a).unwrap(), path, dev)
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn instant_is_optimistic_and_move_time_is_reached((l, path, _) in limits_and_path()) {
        let (a, b) = (&path[0], &path[path.len() - 1]);
        let mi = move_time_instant(a, b, &l);
        let mt = move_time(a, b, &l);
        prop_assert!(mi <= mt);
        let max_va = l.velocity.iter().zip(&l.acceleration).map(|(v, a)| v / a).fold(0.0, f64::max);
        prop_assert!(mt <= mi + max_va + 1e-12);
        // move_trajectory realises move_time within the limits
        let t = move_trajectory(a, b, &l);
        prop_assert!((t.duration() - mt).abs() <= 1e-12 * (1.0 + mt));
        prop_assert!(check_limits(&t, &l, 1e-9).is_ok(), "{:?}", check_limits(&t, &l, 1e-9));
        prop_assert!(close(&t.end_position(), b, 1e-9));
        prop_assert!(close(&t.velocity(t.duration()), &vec![0.0; l.dof()], 1e-9));
    }

    #[test]
    fn exact_follows_the_path((l, path, _) in limits_and_path()) {
        let t = time_path_exact(&path, &l).unwrap();
        let tr = &t.trajectory;
        prop_assert!(check_limits(tr, &l, 1e-9).is_ok(), "{:?}", check_limits(tr, &l, 1e-9));
        prop_assert!(close(&tr.start_position(), &path[0], 1e-9));
        prop_assert!(close(&tr.end_position(), &path[path.len() - 1], 1e-9));
        prop_assert!(close(&tr.velocity(0.0), &vec![0.0; l.dof()], 1e-9));
        prop_assert!(close(&tr.velocity(tr.duration()), &vec![0.0; l.dof()], 1e-9));
        prop_assert_eq!(t.waypoint_times.len(), path.len());
        prop_assert!(t.waypoint_times.windows(2).all(|w| w[0] <= w[1] + 1e-12));
        for (w, &time) in path.iter().zip(&t.waypoint_times) {
            prop_assert!(close(&tr.position(time), w, 1e-7), "{:?} vs {:?}", tr.position(time), w);
        }
        // every sample on the polyline
        for (_, q) in tr.sample(tr.duration() / 97.0 + 1e-6) {
            prop_assert!(dist_to_polyline(&q, &path) <= 1e-7);
        }
        // no motion from rest to rest is faster than move_time
        let mt = move_time(&path[0], &path[path.len() - 1], &l);
        prop_assert!(tr.duration() >= mt - 1e-9);
    }

    #[test]
    fn blended_is_faster_and_close((l, path, dev) in limits_and_path()) {
        let e = time_path_exact(&path, &l).unwrap();
        let b = time_path_blended(&path, &l, &dev).unwrap();
        let tr = &b.trajectory;
        prop_assert!(check_limits(tr, &l, 1e-9).is_ok(), "{:?}", check_limits(tr, &l, 1e-9));
        prop_assert!(close(&tr.start_position(), &path[0], 1e-9));
        prop_assert!(close(&tr.end_position(), &path[path.len() - 1], 1e-9));
        prop_assert!(close(&tr.velocity(0.0), &vec![0.0; l.dof()], 1e-9));
        prop_assert!(close(&tr.velocity(tr.duration()), &vec![0.0; l.dof()], 1e-9));
        prop_assert!(tr.duration() <= e.trajectory.duration() + 1e-9);
        for (d, m) in b.deviation.iter().zip(&dev) {
            prop_assert!(*d <= m + 1e-12);
        }
        let bound = dev.iter().map(|d| d * d).sum::<f64>().sqrt();
        for (_, q) in tr.sample(tr.duration() / 211.0 + 1e-6) {
            prop_assert!(dist_to_polyline(&q, &path) <= bound + 1e-7);
        }
        // per joint, within the blend's deviation of the polyline timed at the corner speed
        for bl in &b.blends {
            let corner = &path[bl.waypoint];
            let v_in = tr.velocity(bl.start_time);
            let v_out = tr.velocity(bl.start_time + bl.duration);
            let mid = bl.start_time + 0.5 * bl.duration;
            for i in 0..=10 {
                let t = bl.start_time + bl.duration * i as f64 / 10.0;
                let v = if t < mid { &v_in } else { &v_out };
                let q = tr.position(t);
                for j in 0..l.dof() {
                    let nominal = corner[j] + (t - mid) * v[j];
                    prop_assert!((q[j] - nominal).abs() <= bl.deviation[j] + 1e-9);
                }
            }
        }
        // blends in time order, not overlapping
        prop_assert!(b.blends.windows(2).all(|w| w[0].start_time + w[0].duration <= w[1].start_time + 1e-9));
    }

    #[test]
    fn sample_is_monotone_and_ends_at_duration((l, path, dev) in limits_and_path(), dt in 0.01f64..2.0) {
        let tr = time_path_blended(&path, &l, &dev).unwrap().trajectory;
        let s = tr.sample(dt);
        prop_assert!(s.windows(2).all(|w| w[0].0 < w[1].0));
        prop_assert_eq!(s[0].0, 0.0);
        prop_assert_eq!(s.last().unwrap().0, tr.duration());
        prop_assert!(close(&s.last().unwrap().1, &path[path.len() - 1], 1e-9));
    }

    #[test]
    fn append_keeps_continuity((l, path, dev) in limits_and_path(), wait in 0.0f64..2.0) {
        let mut tr = time_path_exact(&path, &l).unwrap().trajectory;
        let end = tr.end_position();
        let d0 = tr.duration();
        tr.append(&Trajectory::dwell(&end, wait));
        let back: Vec<Vec<f64>> = path.iter().rev().cloned().collect();
        tr.append(&time_path_blended(&back, &l, &dev).unwrap().trajectory);
        prop_assert!(check_limits(&tr, &l, 1e-9).is_ok(), "{:?}", check_limits(&tr, &l, 1e-9));
        prop_assert!(close(&tr.position(d0 + wait / 2.0), &end, 1e-9));
        prop_assert!(close(&tr.end_position(), &path[0], 1e-9));
    }
}

#[test]
fn blended_waypoint_times_and_scaled_corners() {
    // The L-shaped path of `blend_by_hand` with a collinear waypoint on its first segment.
    let l = Limits::uniform(2, 1.0, 1.0).unwrap();
    let path = vec![vec![0.0, 0.0], vec![5.0, 0.0], vec![10.0, 0.0], vec![10.0, 10.0]];
    let b = time_path_blended(&path, &l, &[10.0]).unwrap();
    assert!((b.trajectory.duration() - 21.0).abs() < 1e-9);
    // 0 at the start; the collinear waypoint at 0.5 + 4.5 s (cruising at 1 after 0.5 rad);
    // the corner at the middle of its blend (10.5 s); the end.
    let want = [0.0, 5.5, 10.5, 21.0];
    assert_eq!(b.waypoint_times.len(), 4);
    for (got, want) in b.waypoint_times.iter().zip(want) {
        assert!((got - want).abs() < 1e-9, "{:?}", b.waypoint_times);
    }
    assert!(close(&b.trajectory.position(5.5), &[5.0, 0.0], 1e-9));
    // A scale of 0 at the corner stops there, as the exact timing does.
    let stopped = time_path_blended_scaled(&path, &l, &[10.0], &[1.0, 1.0, 0.0, 1.0]).unwrap();
    assert!(stopped.blends.is_empty());
    assert!((stopped.trajectory.duration() - 22.0).abs() < 1e-9);
    assert!((stopped.waypoint_times[2] - 11.0).abs() < 1e-9);
    // A quarter of the bound: a smaller blend, slower than the full one, faster than stopping.
    let small = time_path_blended_scaled(&path, &l, &[0.04], &[1.0, 1.0, 0.25, 1.0]).unwrap();
    assert!(small.deviation.iter().all(|&d| d <= 0.01 + 1e-12));
    let full = time_path_blended(&path, &l, &[0.04]).unwrap();
    assert!(full.trajectory.duration() < small.trajectory.duration());
    assert!(small.trajectory.duration() < 22.0);
    assert!(matches!(
        time_path_blended_scaled(&path, &l, &[0.1], &[1.0, -1.0]),
        Err(TimingError::InvalidScale { waypoint: 1, .. })
    ));
}
