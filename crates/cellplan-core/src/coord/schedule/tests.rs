//! The scheduler's tests: small diagrams with known answers, brute force, random diagrams.
use super::*;

fn track(robot: usize, len: f64, rests: &[f64]) -> Track {
    Track {
        robot,
        len,
        rests: rests.to_vec(),
    }
}

fn boxed(robots: (usize, usize), a: (f64, f64), b: (f64, f64)) -> ConflictBox {
    ConflictBox {
        robots,
        a,
        b,
        open: [false; 4],
    }
}

/// Where robot `r` is at time `t` under the schedule (position), and when it ends.
fn position(t: &Track, waits: &[(f64, Option<usize>)], time: f64) -> f64 {
    let mut clock = 0.0;
    for (k, &at) in t.rests.iter().enumerate() {
        if k > 0 {
            let d = at - t.rests[k - 1];
            if time < clock + d {
                return t.rests[k - 1] + (time - clock);
            }
            clock += d;
        }
        if time < clock + waits[k].0 {
            return at;
        }
        clock += waits[k].0;
    }
    (t.rests.last().unwrap() + time - clock).min(t.len)
}

/// The schedule keeps every pair of positions out of every box (sampled every 1 ms).
fn assert_clear(tracks: &[Track], boxes: &[ConflictBox], s: &Schedule) {
    let mut time = 0.0;
    while time <= s.makespan + 1e-9 {
        for b in boxes {
            let pa = position(&tracks[b.robots.0], &s.waits[b.robots.0], time);
            let pb = position(&tracks[b.robots.1], &s.waits[b.robots.1], time);
            let inside = pa > b.a.0 + 1e-6 && pa < b.a.1 - 1e-6 && pb > b.b.0 + 1e-6 && pb < b.b.1 - 1e-6;
            assert!(!inside, "at {time}: {pa} and {pb} in {b:?}");
        }
        time += 1e-3;
    }
}

/// Two robots crossing one region: the shorter wait is taken (b waits for a to leave,
/// 1 s, rather than a for b, 3 s), at the last rest before the region (a rest on the
/// region's edge is in it).
#[test]
fn one_box_waits_the_shorter_way() {
    let tracks = [track(0, 10.0, &[0.0, 2.0, 4.0]), track(1, 10.0, &[0.0, 3.0, 5.0])];
    // a in the region over [4, 6], b over [5, 7].
    let boxes = [boxed((0, 1), (4.0, 6.0), (5.0, 7.0))];
    let s = schedule(&tracks, &boxes, 1000, 0.05).unwrap();
    assert!(s.proven);
    // a first: b reaches 5 at 6 (waits 1 s at its rest 5); b first: a waits until b is
    // past 7 (at 7): 3 s.
    assert!((s.makespan - 11.0).abs() < 1e-9, "{s:?}");
    assert_eq!(s.waits[0].iter().map(|w| w.0).sum::<f64>(), 0.0);
    assert!((s.waits[1][1].0 - 1.0).abs() < 1e-9, "{s:?}");
    assert_eq!(s.waits[1][1].1, Some(0));
    assert_eq!(s.waits[1][2].0, 0.0);
    assert_clear(&tracks, &boxes, &s);
}

/// A robot home for good in the other's way can only be passed before it gets there; one
/// still at home, only after it has left.
#[test]
fn homes_fix_the_order() {
    let tracks = [track(0, 6.0, &[0.0, 1.0]), track(1, 8.0, &[0.0, 2.0])];
    // Robot 0's end pose (6) blocks robot 1 over [3, 4]: robot 1 must be past 4 first.
    let boxes = [boxed((0, 1), (5.0, 6.0), (3.0, 4.0))];
    let s = schedule(&tracks, &boxes, 1000, 0.05).unwrap();
    // Robot 0 must not reach 5 before robot 1 is at 4 (time 4): it waits 3 s... at rest 1
    // (position 1, reached at 1): it leaves at 4 - 4 = 0 → no wait needed? 5 is reached
    // at 5 > 4: already clear.
    assert_eq!(s.decisions, 0);
    assert!((s.makespan - 8.0).abs() < 1e-9);
    assert_clear(&tracks, &boxes, &s);
    // Now robot 1 is late: it reaches 3 only at 6.
    let late = [track(0, 6.0, &[0.0, 1.0]), track(1, 8.0, &[0.0, 2.0]).clone()];
    let boxes = [boxed((0, 1), (5.0, 6.0), (3.0, 7.0))];
    let s = schedule(&late, &boxes, 1000, 0.05).unwrap();
    // Robot 1 passes first (robot 0 at its end blocks forever): robot 0 may reach 5 only
    // when robot 1 is past 7 (time 7): it waits 2 s at rest 1.
    assert!((s.waits[0][1].0 - 2.0).abs() < 1e-9, "{s:?}");
    assert!((s.makespan - 8.0).abs() < 1e-9);
    assert_clear(&late, &boxes, &s);
    // Robot 1's start home in robot 0's way: robot 1 leaves first.
    let boxes = [boxed((0, 1), (0.5, 2.0), (0.0, 1.0))];
    let s = schedule(&late, &boxes, 1000, 0.05).unwrap();
    assert!(
        (s.waits[0][1].0 - 0.0).abs() < 1e-9 && s.waits[0][0].0 > 0.0,
        "{s:?}"
    );
    assert_clear(&late, &boxes, &s);
    // Both end homes in each other's way: no order exists.
    let boxes = [boxed((0, 1), (5.0, 6.0), (7.0, 8.0))];
    assert!(schedule(&late, &boxes, 1000, 0.05).is_none());
}

/// Three robots, boxes chained so that the greedy choice at the first box is wrong: the
/// search finds the order a brute force over all orders finds.
/// A robot certified clear while standing at home (`open`) may let the other pass there,
/// at its start and at its end; without the certificate no order exists.
#[test]
fn a_robot_clear_at_home_may_wait_there() {
    let tracks = [track(0, 10.0, &[0.0]), track(1, 10.0, &[0.0])];
    // Both conflict while leaving home.
    let mut b = boxed((0, 1), (0.0, 3.0), (0.0, 3.0));
    assert!(schedule(&tracks, std::slice::from_ref(&b), 1000, 0.05).is_none());
    b.open = [true, false, false, false];
    let s = schedule(&tracks, std::slice::from_ref(&b), 1000, 0.05).unwrap();
    assert!((s.waits[0][0].0 - 3.0).abs() < 1e-9, "{s:?}");
    assert!((s.makespan - 13.0).abs() < 1e-9);
    assert_clear(&tracks, std::slice::from_ref(&b), &s);
    // Both conflict while coming home: robot 1, clear once home, may arrive first.
    let mut b = boxed((0, 1), (8.0, 10.0), (7.0, 10.0));
    assert!(schedule(&tracks, std::slice::from_ref(&b), 1000, 0.05).is_none());
    b.open = [false, false, false, true];
    let s = schedule(&tracks, std::slice::from_ref(&b), 1000, 0.05).unwrap();
    // Robot 0 may reach 8 only when robot 1 is home (10): a 2 s wait at home.
    assert!((s.waits[0][0].0 - 2.0).abs() < 1e-9, "{s:?}");
    assert_clear(&tracks, std::slice::from_ref(&b), &s);
}

/// Robot 0 must be past 2 before robot 1 reaches 4 (its home blocks robot 1 there) and
/// must not reach 3 before robot 1 is past 7 (its end home blocks robot 1 there): without
/// a rest between 2 and 3 no order exists, and the core is exactly those two boxes (the
/// third, far away, is not in it); with a rest at 2.5 robot 0 waits there (until 6.5:
/// it reaches 3 when robot 1 is past 7).
#[test]
fn the_infeasible_core_shows_where_a_stop_is_missing() {
    let boxes = [
        boxed((0, 1), (0.0, 2.0), (4.0, 6.0)),
        boxed((0, 1), (3.0, 10.0), (5.0, 7.0)),
        boxed((0, 2), (0.0, 1.0), (8.0, 9.0)),
    ];
    let tracks = [
        track(0, 10.0, &[0.0]),
        track(1, 10.0, &[0.0]),
        track(2, 10.0, &[0.0]),
    ];
    assert!(schedule(&tracks, &boxes, 1000, 0.05).is_none());
    assert_eq!(infeasible_core(&tracks, &boxes, 1000, 0.05), vec![0, 1]);
    let stopped = [
        track(0, 10.0, &[0.0, 2.5]),
        track(1, 10.0, &[0.0]),
        track(2, 10.0, &[0.0]),
    ];
    let s = schedule(&stopped, &boxes, 1000, 0.05).unwrap();
    assert!((s.waits[0][1].0 - 4.0).abs() < 1e-9, "{s:?}");
    assert_clear(&stopped, &boxes, &s);
    assert!(infeasible_core(&stopped, &boxes, 1000, 0.05).is_empty());
}

#[test]
fn the_search_matches_brute_force() {
    let tracks = [
        track(0, 10.0, &[0.0, 1.0, 3.0, 5.0, 7.0]),
        track(1, 10.0, &[0.0, 2.0, 4.0, 6.0]),
        track(2, 9.0, &[0.0, 1.5, 3.5, 6.5]),
    ];
    let boxes = [
        boxed((0, 1), (1.5, 3.0), (2.5, 4.5)),
        boxed((1, 2), (4.5, 6.5), (3.0, 5.0)),
        boxed((0, 2), (5.5, 8.0), (6.0, 8.5)),
        boxed((0, 1), (7.5, 9.0), (7.0, 8.0)),
    ];
    let s = schedule(&tracks, &boxes, 100_000, 0.0).unwrap();
    assert!(s.proven);
    assert_clear(&tracks, &boxes, &s);
    // Brute force: every order of the four boxes, longest paths by repeated relaxation.
    let mut best = f64::INFINITY;
    for mask in 0..16u32 {
        let mut search = Search::new(&tracks, &boxes, 1, 0.0);
        let mut x = search.initial();
        let mut ok = true;
        for (i, c) in search.choices.clone().iter().enumerate() {
            let e = if mask >> i & 1 == 0 { c.first_a } else { c.first_b };
            match e {
                Some(e) => ok &= search.add(e, &mut x),
                None => ok = false,
            }
        }
        if ok {
            best = best.min(search.makespan(&x));
        }
    }
    assert!((s.makespan - best).abs() < 1e-9, "{} vs {best}", s.makespan);
}

/// `robots` random tracks, each with a number of rests in `rests` (home included after the
/// first), 0.2–2 s apart, and 0.5–2 s of path after the last.
fn random_tracks(
    rng: &mut rand_chacha::ChaCha8Rng,
    robots: usize,
    rests: std::ops::Range<usize>,
) -> Vec<Track> {
    use rand::RngExt;
    (0..robots)
        .map(|r| {
            let mut at = vec![0.0];
            for _ in 0..rng.random_range(rests.clone()) {
                let last = *at.last().unwrap();
                at.push(last + rng.random_range(0.2..2.0));
            }
            track(r, at.last().unwrap() + rng.random_range(0.5..2.0), &at)
        })
        .collect()
}

/// Random boxes between the robots of `tracks` (as many as `count` draws), each robot's
/// interval drawn by `span` from its path's length.
fn random_boxes(
    rng: &mut rand_chacha::ChaCha8Rng,
    tracks: &[Track],
    count: std::ops::Range<usize>,
    span: impl Fn(&mut rand_chacha::ChaCha8Rng, f64) -> (f64, f64),
) -> Vec<ConflictBox> {
    use rand::RngExt;
    let m = tracks.len();
    (0..rng.random_range(count))
        .map(|_| {
            let (a, b) = (rng.random_range(0..m), rng.random_range(0..m - 1));
            let b = if b >= a { b + 1 } else { b };
            let (a, b) = (a.min(b), a.max(b));
            boxed((a, b), span(rng, tracks[a].len), span(rng, tracks[b].len))
        })
        .collect()
}

/// An interval inside a path, clear of both ends.
fn inner_span(rng: &mut rand_chacha::ChaCha8Rng, len: f64) -> (f64, f64) {
    use rand::RngExt;
    let a = rng.random_range(0.3..len - 0.3);
    (a, (a + rng.random_range(0.1..1.0)).min(len - 0.2))
}

/// The boxes still open after orders are chosen, found from the parent's open boxes and
/// the raised nodes, are those a scan of every box finds (random tracks and boxes, random
/// orders added one after another).
#[test]
fn open_boxes_are_kept_up_without_a_scan() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut checked = 0;
    for _ in 0..80 {
        let tracks = random_tracks(&mut rng, 4, 2..9);
        let span = |rng: &mut rand_chacha::ChaCha8Rng, len: f64| {
            let a = rng.random_range(0.0..len);
            (a, (a + rng.random_range(0.1..1.5)).min(len))
        };
        let boxes: Vec<ConflictBox> = (0..60)
            .map(|_| {
                let (a, b) = (rng.random_range(0..4), rng.random_range(0..3));
                let b = if b >= a { b + 1 } else { b };
                boxed(
                    (a, b),
                    span(&mut rng, tracks[a].len),
                    span(&mut rng, tracks[b].len),
                )
            })
            .collect();
        let mut search = Search::new(&tracks, &boxes, 1, 0.1);
        let mut x = search.initial();
        let mut open = search.all_open(&x);
        for _ in 0..20 {
            let Some(&i) = open.get(rng.random_range(0..open.len().max(1))) else {
                break;
            };
            let c = search.choices[i as usize];
            let Some(e) = (if rng.random_bool(0.5) {
                c.first_a
            } else {
                c.first_b
            })
            .or(c.first_a)
            .or(c.first_b) else {
                break;
            };
            let mut y = x.clone();
            if !search.add(e, &mut y) {
                break;
            }
            let raised = std::mem::take(&mut search.raised);
            let mut next = search.refresh(&open, &raised, &y);
            next.sort_unstable();
            assert_eq!(next, search.all_open(&y));
            assert!(!next.contains(&i), "the box just ordered is passed");
            (x, open) = (y, next);
            checked += 1;
        }
    }
    assert!(checked > 200, "{checked}");
}

/// Waits shorter than the shortest allowed are lengthened to it (and the boxes still
/// hold); with a budget of one node the first dive's schedule comes back, not proven.
#[test]
fn short_waits_are_lengthened_and_the_budget_binds() {
    let tracks = [track(0, 10.0, &[0.0, 2.0, 4.0]), track(1, 10.0, &[0.0, 3.0, 4.9])];
    let boxes = [boxed((0, 1), (4.0, 5.0), (5.0, 6.0))];
    // b reaches 5 at 5.0 ≥ a's exit at 5.0: no wait at all.
    let s = schedule(&tracks, &boxes, 1000, 0.2).unwrap();
    assert!(s.waits.iter().flatten().all(|w| w.0 == 0.0 || w.0 >= 0.2 - 1e-9));
    assert_clear(&tracks, &boxes, &s);
    let boxes = [boxed((0, 1), (4.0, 5.05), (5.0, 6.0))];
    let s = schedule(&tracks, &boxes, 1000, 0.2).unwrap();
    // 0.05 s would do; 0.2 s is the shortest allowed.
    let w: f64 = s.waits.iter().flatten().map(|w| w.0).sum();
    assert!((w - 0.2).abs() < 1e-9, "{s:?}");
    assert_clear(&tracks, &boxes, &s);
    let s = schedule(&tracks, &boxes, 1, 0.2).unwrap();
    assert!(!s.proven);
}

/// The pairs' floor is a lower bound (never above the proven shortest schedule of all the
/// robots), often the shortest itself; the search with it ends with the same makespan as
/// without it, and on a small budget (6 nodes) it proves schedules shortest that the search alone cannot
/// (random diagrams of four robots).
#[test]
fn the_pairs_floor_bounds_and_ends_the_search_early() {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let (mut compared, mut reached, mut more_proven) = (0, 0, 0);
    for _ in 0..80 {
        let tracks = random_tracks(&mut rng, 4, 3..10);
        let boxes = random_boxes(&mut rng, &tracks, 4..24, inner_span);
        let (plain, _) = search(&tracks, &boxes, 200_000, 0.05, false);
        let (floored, _) = search(&tracks, &boxes, 200_000, 0.05, true);
        let (lb, _) = floor(&tracks, &boxes, 200_000, 0.05);
        match (plain, floored) {
            (Found::Schedule(p), Found::Schedule(f)) => {
                assert!(p.proven && f.proven);
                assert!(
                    (p.makespan - f.makespan).abs() < 1e-9,
                    "{} vs {}",
                    p.makespan,
                    f.makespan
                );
                assert_clear(&tracks, &boxes, &f);
                let lb = lb.expect("a schedule exists, so every pair has one");
                assert!(
                    lb <= p.makespan + 1e-9,
                    "floor {lb} above the shortest {}",
                    p.makespan
                );
                compared += 1;
                reached += usize::from(lb >= p.makespan - 1e-9);
                // On a small budget: proven with the floor only when it is the shortest.
                let (Found::Schedule(cut), _) = search(&tracks, &boxes, 6, 0.05, false) else {
                    continue;
                };
                if let (Found::Schedule(c), _) = search(&tracks, &boxes, 6, 0.05, true)
                    && c.proven
                {
                    assert!((c.makespan - p.makespan).abs() < 1e-9);
                    more_proven += usize::from(!cut.proven);
                }
            }
            (Found::Infeasible, Found::Infeasible) => {}
            (p, f) => panic!("{p:?} against {f:?}"),
        }
    }
    assert!(compared > 40, "{compared}");
    assert!(reached > compared / 3, "{reached} of {compared}");
    assert!(more_proven > 0, "{more_proven} of {compared}");
}

/// A complete selection of orders by a fixed priority of the robots gives a schedule
/// that passes every box whenever it holds, so a search of one node already has one; the
/// search never ends above it, and a full search proves it the shortest on some diagrams
/// (random diagrams of five robots).
#[test]
fn complete_selections_give_the_search_a_schedule_at_once() {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let (mut held, mut shortest, mut tried) = (0, 0, 0);
    for _ in 0..60 {
        let tracks = random_tracks(&mut rng, 5, 3..12);
        let boxes = random_boxes(&mut rng, &tracks, 5..40, inner_span);
        tried += 1;
        let Some((at_once, ..)) = Search::new(&tracks, &boxes, 1, 0.05).incumbent() else {
            continue;
        };
        held += 1;
        let (Found::Schedule(one), nodes) = search(&tracks, &boxes, 1, 0.05, false) else {
            panic!("a selection holds, so a search of one node has a schedule");
        };
        assert!(nodes <= NO_SCHEDULE_FACTOR + 1, "{nodes}");
        assert!(one.makespan <= at_once + 1e-9, "{} above {at_once}", one.makespan);
        assert_clear(&tracks, &boxes, &one);
        let (Found::Schedule(full), _) = search(&tracks, &boxes, 200_000, 0.05, true) else {
            panic!("a selection holds, so the full search has a schedule");
        };
        assert!(full.proven && full.makespan <= at_once + 1e-9);
        assert_clear(&tracks, &boxes, &full);
        shortest += usize::from(full.makespan >= at_once - 1e-9);
    }
    assert!(held > tried / 2, "{held} of {tried}");
    assert!(shortest > 0 && shortest < held, "{shortest} of {held}");
}

/// Backjumping leaves the search exact: on random diagrams of five robots with few rests
/// (where orders chosen early close cycles late), it ends with the same shortest makespan, or
/// the same proof that there is none, as chronological backtracking, in no more nodes, and in
/// fewer on some.
#[test]
fn backjumping_keeps_the_search_exact_in_fewer_nodes() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
    let (mut fewer, mut infeasible, mut same) = (0, 0, 0);
    let (mut with, mut without) = (0, 0);
    for _ in 0..120 {
        let tracks = random_tracks(&mut rng, 5, 1..4);
        // Now and then a box from home or to the end (a robot at home in another's way).
        let span = |rng: &mut rand_chacha::ChaCha8Rng, len: f64| {
            let a = if rng.random_bool(0.03) {
                0.0
            } else {
                rng.random_range(0.1..len - 0.1)
            };
            let b = if rng.random_bool(0.03) {
                len
            } else {
                (a + rng.random_range(0.2..1.5)).min(len - 0.05)
            };
            (a, b)
        };
        let boxes = random_boxes(&mut rng, &tracks, 20..80, span);
        let (jumped, n_jump) = search_with(&tracks, &boxes, 200_000, 0.05, false, true, false);
        let (plain, n_plain) = search_with(&tracks, &boxes, 200_000, 0.05, false, false, false);
        assert!(n_jump <= n_plain, "{n_jump} > {n_plain}");
        (with, without) = (with + n_jump, without + n_plain);
        fewer += usize::from(n_jump < n_plain);
        match (jumped, plain) {
            (Found::Schedule(j), Found::Schedule(p)) => {
                assert!(j.proven && p.proven);
                assert!(
                    (j.makespan - p.makespan).abs() < 1e-9,
                    "{} vs {}",
                    j.makespan,
                    p.makespan
                );
                assert_clear(&tracks, &boxes, &j);
                same += 1;
            }
            (Found::Infeasible, Found::Infeasible) => infeasible += 1,
            (j, p) => panic!("{j:?} against {p:?}"),
        }
    }
    assert!(
        same > 20 && infeasible > 5,
        "{same} schedules, {infeasible} infeasible"
    );
    assert!(
        fewer > 5 && with < without,
        "{fewer}: {with} against {without} nodes"
    );
}

/// The neighbourhood search after an unproven search ([`Search::improve`]) keeps every
/// schedule clear of the boxes, never ends above the search without it nor below the proven
/// shortest, and shortens some: on random diagrams of six robots searched with a budget far
/// too small to prove anything (21 of 60 shorter when written).
#[test]
fn putting_each_robot_back_through_the_others_shortens_unproven_schedules() {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    let (mut compared, mut shorter) = (0, 0);
    for _ in 0..60 {
        let tracks = random_tracks(&mut rng, 6, 1..4);
        let boxes = random_boxes(&mut rng, &tracks, 40..120, inner_span);
        let (Found::Schedule(plain), _) = search_with(&tracks, &boxes, 30, 0.05, false, true, false) else {
            continue;
        };
        if plain.proven {
            continue;
        }
        let (Found::Schedule(lns), _) = search_with(&tracks, &boxes, 30, 0.05, false, true, true) else {
            panic!("the neighbourhood search starts from a schedule and keeps one");
        };
        assert_clear(&tracks, &boxes, &lns);
        assert!(
            lns.makespan <= plain.makespan + 1e-9,
            "{} above {}",
            lns.makespan,
            plain.makespan
        );
        if let (Found::Schedule(full), _) = search(&tracks, &boxes, 400_000, 0.05, true)
            && full.proven
        {
            assert!(
                lns.makespan >= full.makespan - 1e-9,
                "{} below {}",
                lns.makespan,
                full.makespan
            );
        }
        compared += 1;
        shorter += usize::from(lns.makespan < plain.makespan - 1e-9);
    }
    assert!(compared >= 40 && shorter >= 10, "{shorter} shorter of {compared}");
}
