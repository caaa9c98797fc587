use super::*;
use crate::cell::Configuration;
use crate::testing::random_cell;

use crate::testing::random_decision;

/// Paper 004 eq. 1–7 (one robot), literally: cycle by cycle, with the CDS off time of eq. 5
/// and 6 and the table off time of eq. 4.
fn paper_one_robot(cell: &PcbCell, d: &Decision) -> f64 {
    let v = cell.robots[0].drive.speed;
    let slot_of = slot_lookup(cell, d);
    let mut c_cycles: Vec<f64> = Vec::new();
    let mut place_part: Vec<f64> = Vec::new();
    let mut feeder_last: [Option<usize>; 2] = [None, None];
    let mut feeder_pos = [cell.feeders[0].home, cell.feeders[1].home];
    let mut robot = cell.robots[0].home;
    let mut table = cell.table.home;
    for (i, &c) in d.order.iter().enumerate() {
        let f = d.feeder[c];
        let slot = slot_of[f][cell.type_of[c]].unwrap();
        let k_pt = [cell.feeders[f].x, cell.feeders[f].bin_y(d.carriage[c], slot)];
        let p_pt = [
            d.table[c][0] + cell.components[c].position[0],
            d.table[c][1] + cell.components[c].position[1],
        ];
        let pk_r = dist(robot, k_pt) / v;
        let d_t = (d.carriage[c] - feeder_pos[f]).abs() / cell.feeders[f].drive.speed;
        let off_d = match feeder_last[f] {
            Some(k) if k + 1 == i => place_part[k],
            Some(k) => c_cycles[k + 1..i].iter().sum::<f64>() + place_part[k],
            None => c_cycles.iter().sum::<f64>(),
        };
        let pick_c = pk_r.max(d_t - off_d) + cell.pick_time;
        let off_t = pick_c;
        let pl_r = dist(k_pt, p_pt) / v;
        let t_t = dist(table, d.table[c]) / cell.table.drive.speed;
        let place_c = pl_r.max(t_t - off_t) + cell.place_time;
        c_cycles.push(pick_c + place_c);
        place_part.push(place_c);
        feeder_last[f] = Some(i);
        feeder_pos[f] = d.carriage[c];
        robot = p_pt;
        table = d.table[c];
    }
    c_cycles.iter().sum()
}

/// Paper 004 eq. 8–15 (two robots, no collision avoidance), literally.
fn paper_two_robots(cell: &PcbCell, d: &Decision) -> f64 {
    let slot_of = slot_lookup(cell, d);
    let mut c_cycles: Vec<f64> = Vec::new();
    let mut first_part: Vec<f64> = Vec::new();
    let mut robot_last: [Option<usize>; 2] = [None, None];
    let mut feeder_last: [Option<usize>; 2] = [None, None];
    let mut feeder_pos = [cell.feeders[0].home, cell.feeders[1].home];
    let mut robot = [cell.robots[0].home, cell.robots[1].home];
    let mut table = cell.table.home;
    for (i, &c) in d.order.iter().enumerate() {
        let (r, f) = (d.robot[c], d.feeder[c]);
        let v = cell.robots[r].drive.speed;
        let slot = slot_of[f][cell.type_of[c]].unwrap();
        let k_pt = [cell.feeders[f].x, cell.feeders[f].bin_y(d.carriage[c], slot)];
        let p_pt = [
            d.table[c][0] + cell.components[c].position[0],
            d.table[c][1] + cell.components[c].position[1],
        ];
        let pk_t = dist(robot[r], k_pt) / v;
        // Eq. 10–11.
        let off_r = match robot_last[r] {
            Some(k) if k + 1 == i => 0.0,
            Some(k) => c_cycles[k + 1..i].iter().sum(),
            None => c_cycles.iter().sum(),
        };
        // Eq. 12–13.
        let d_t = (d.carriage[c] - feeder_pos[f]).abs() / cell.feeders[f].drive.speed;
        let off_d = match feeder_last[f] {
            Some(k) => c_cycles[k..i].iter().sum::<f64>() - first_part[k] - cell.pick_time,
            None => c_cycles.iter().sum(),
        };
        let first = (pk_t - off_r).max(d_t - off_d); // eq. 9
        let r_t = first + cell.pick_time + dist(k_pt, p_pt) / v; // eq. 15
        let t_t = dist(table, d.table[c]) / cell.table.drive.speed;
        c_cycles.push(r_t.max(t_t) + cell.place_time); // eq. 8
        first_part.push(first);
        robot_last[r] = Some(i);
        feeder_last[f] = Some(i);
        feeder_pos[f] = d.carriage[c];
        robot[r] = p_pt;
        table = d.table[c];
    }
    c_cycles.iter().sum()
}

#[test]
fn resuming_one_robot_simulations_from_a_state_gives_the_same_time() {
    for seed in 0..10 {
        for conf in Configuration::ALL {
            let cell = random_cell(20, 5, 1, conf, seed);
            let mut d = random_decision(&cell, seed);
            let _ = crate::search::fix_devices(&cell, &mut d, None);
            let slot_of = slot_lookup(&cell, &d);
            for greedy in [false, true] {
                let full = if greedy {
                    simulate(&cell, &d, &mut crate::rendezvous::Greedy, DelayRule::Off).makespan
                } else {
                    simulate(&cell, &d, &mut Given(&d), DelayRule::Off).makespan
                };
                let mut states = vec![blank_state(); d.order.len() + 1];
                let least = least_cycles(&cell);
                let run = |states: &mut [State], from: usize, cutoff: f64| {
                    if greedy {
                        one_robot_from(
                            &cell,
                            &d,
                            &slot_of,
                            &mut crate::rendezvous::Greedy,
                            states,
                            from,
                            cutoff,
                            &least,
                        )
                    } else {
                        one_robot_from(&cell, &d, &slot_of, &mut Given(&d), states, from, cutoff, &least)
                    }
                };
                let whole = run(&mut states, 0, f64::INFINITY).unwrap();
                assert!(
                    (whole - full).abs() < 1e-12,
                    "{conf:?} {greedy}: {whole} vs {full}"
                );
                let resumed = run(&mut states, 11, f64::INFINITY).unwrap();
                assert!((resumed - full).abs() < 1e-12);
                assert_eq!(run(&mut states, 0, full - 1e-6), None, "the cutoff stops it");
                assert!(run(&mut states, 0, full + 1e-9).is_some());
            }
        }
    }
}

#[test]
fn event_simulation_is_the_papers_equations() {
    for seed in 0..20 {
        let cell = random_cell(15, 4, 1, Configuration::AllMoving, seed);
        let d = random_decision(&cell, seed);
        let s = simulate(&cell, &d, &mut Given(&d), DelayRule::Off);
        let paper = paper_one_robot(&cell, &d);
        assert!(
            (s.makespan - paper).abs() < 1e-9,
            "one robot, seed {seed}: {} vs {paper}",
            s.makespan
        );
        let cell = random_cell(15, 4, 2, Configuration::AllMoving, seed);
        let d = random_decision(&cell, seed + 100);
        let s = simulate(&cell, &d, &mut Given(&d), DelayRule::Off);
        let paper = paper_two_robots(&cell, &d);
        assert!(
            (s.makespan - paper).abs() < 1e-9,
            "two robots, seed {seed}: {} vs {paper}",
            s.makespan
        );
    }
}

/// Robot X at time `t` from the schedule alone (independent of the tracks).
fn robot_x(cell: &PcbCell, s: &Schedule, r: usize, t: f64) -> f64 {
    let mut pos = cell.robots[r].home;
    let mut segments = Vec::new();
    let mine: Vec<&Cycle> = s.cycles.iter().filter(|c| c.robot == r).collect();
    for cy in &mine {
        segments.push((cy.robot_leaves, cy.robot_at_pick, pos, cy.pick_point));
        segments.push((
            cy.pick[1] + cy.safety_delay,
            cy.robot_at_place,
            cy.pick_point,
            cy.place_point,
        ));
        pos = cy.place_point;
    }
    if let Some(last) = mine.last() {
        let back = last.place[1] + dist(pos, cell.robots[r].home) / cell.robots[r].drive.speed;
        segments.push((last.place[1], back, pos, cell.robots[r].home));
    }
    let mut x = cell.robots[r].home[0];
    for (t0, t1, a, b) in segments {
        if t >= t1 {
            x = b[0];
        } else if t > t0 {
            let f = (t - t0) / (t1 - t0);
            x = a[0] + f * (b[0] - a[0]);
        }
    }
    x
}

#[test]
fn safety_delays_keep_the_gap_and_the_exact_rule_waits_less() {
    let mut crossings_without = 0;
    let mut compared = 0;
    for seed in 0..12 {
        let cell = random_cell(20, 5, 2, Configuration::AllMoving, seed);
        let d = random_decision(&cell, seed);
        for rule in [DelayRule::Off, DelayRule::Paper, DelayRule::Exact] {
            let s = simulate(&cell, &d, &mut Given(&d), rule);
            let end = s.makespan + 1.0;
            let mut worst = f64::INFINITY;
            let steps = 20_000;
            for k in 0..=steps {
                let t = end * k as f64 / steps as f64;
                worst = worst.min(robot_x(&cell, &s, 1, t) - robot_x(&cell, &s, 0, t));
            }
            if rule == DelayRule::Off {
                crossings_without += usize::from(worst < cell.safety_gap - 1e-9);
            } else {
                assert!(
                    worst >= cell.safety_gap - 1e-9,
                    "seed {seed} {rule:?}: gap {worst}"
                );
            }
        }
        let paper = simulate(&cell, &d, &mut Given(&d), DelayRule::Paper);
        let exact = simulate(&cell, &d, &mut Given(&d), DelayRule::Exact);
        // Up to the first delay both rules share their history: there the exact one waits no
        // longer than the paper's.
        if let Some(i) = (0..exact.cycles.len())
            .find(|&i| exact.cycles[i].safety_delay > 1e-12 || paper.cycles[i].safety_delay > 1e-12)
        {
            assert!(
                exact.cycles[i].safety_delay <= paper.cycles[i].safety_delay + 1e-12,
                "seed {seed}"
            );
            compared += 1;
        }
    }
    assert!(compared > 0, "some random cell must need a safety delay");
    assert!(
        crossings_without > 0,
        "the random cells must need collision avoidance at all"
    );
}
