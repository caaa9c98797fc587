//! PCB-assembly plans (paper 004) through the independent verifier: every configuration and
//! both optimisers on the six-component example pass; every kind of fault injected into a plan
//! document is caught; plans do not depend on the thread count.
use cellplan_pcb::PcbCell;
use cellplan_pcb::cell::Configuration;
use cellplan_pcb::document::{DeviceKind, MoveOut, PcbPlan};
use cellplan_pcb::plan::{Optimizer, Request, run};
use cellplan_verify::pcb::{PcbVerifySettings, PcbViolationKind, verify_pcb};
use std::path::Path;

fn example() -> PcbCell {
    cellplan_pcb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/pcb-paper-6/cell.toml"))
        .unwrap()
}

fn plan(cell: &PcbCell, optimizer: Optimizer, evaluations: usize, seed: u64) -> PcbPlan {
    run(
        cell,
        &Request {
            optimizer,
            evaluations,
            seed,
            deadline: None,
        },
    )
    .plan
}

fn kinds(base: &PcbCell, plan: &PcbPlan) -> Vec<PcbViolationKind> {
    verify_pcb(base, plan, &PcbVerifySettings::default())
        .violations
        .iter()
        .map(|v| v.kind)
        .collect()
}

#[test]
fn every_configuration_and_optimiser_verifies_and_the_numbers_are_rederived() {
    let base = example();
    let mut cases: Vec<PcbCell> = Configuration::ALL
        .iter()
        .map(|&c| base.variant(1, c, base.motion).unwrap())
        .collect();
    cases.push(base.clone());
    let mut trapezoid = base.clone();
    trapezoid.motion = cellplan_pcb::MotionModel::Trapezoid;
    cases.push(
        trapezoid
            .variant(1, Configuration::AllMoving, trapezoid.motion)
            .unwrap(),
    );
    cases.push(trapezoid);
    for cell in &cases {
        for optimizer in [Optimizer::Ga, Optimizer::Best] {
            let p = plan(cell, optimizer, 3000, 1);
            let r = verify_pcb(&base, &p, &PcbVerifySettings::default());
            assert!(
                r.ok,
                "{:?} {} {:?}: {:?}",
                cell.configuration,
                cell.robots.len(),
                optimizer,
                r.violations
            );
            assert!((r.cycle_time_s - p.cycle_time_s).abs() < 1e-9);
            assert!(
                r.lower_bound_s <= p.cycle_time_s + 1e-9,
                "bound {} above the plan {}",
                r.lower_bound_s,
                p.cycle_time_s
            );
            assert_eq!(p.placements.len(), 6);
        }
    }
}

#[test]
fn faults_injected_into_a_plan_are_caught() {
    let base = example();
    let good = plan(&base, Optimizer::Best, 3000, 0);
    assert!(kinds(&base, &good).is_empty());
    type Fault = (&'static str, fn(&mut PcbPlan), PcbViolationKind);
    let faults: Vec<Fault> = vec![
        (
            "place point off by 1 mm",
            |p| p.placements[0].place.point[0] += 1e-3,
            PcbViolationKind::Place,
        ),
        (
            "a pick too short",
            |p| p.placements[2].pick.t[1] = p.placements[2].pick.t[0] + 0.01,
            PcbViolationKind::Pick,
        ),
        (
            "wrong rotation",
            |p| p.placements[1].rotation_rad += 0.1,
            PcbViolationKind::Place,
        ),
        (
            "a component left out",
            |p| {
                p.placements.pop();
            },
            PcbViolationKind::Component,
        ),
        (
            "a component twice",
            |p| {
                let x = p.placements[0].clone();
                p.placements.push(x);
            },
            PcbViolationKind::Component,
        ),
        (
            "a pick from the wrong bin",
            |p| p.placements[0].bin = (p.placements[0].bin + 1) % 4,
            PcbViolationKind::Bin,
        ),
        (
            "a move faster than the drive",
            |p| {
                let m = &mut p.devices[0].moves[0];
                m.t[1] = m.t[0] + 0.5 * (m.t[1] - m.t[0]);
            },
            PcbViolationKind::Motion,
        ),
        (
            "a move out of travel",
            |p| {
                let d = p
                    .devices
                    .iter_mut()
                    .find(|d| d.kind == DeviceKind::Table)
                    .unwrap();
                d.moves[0].to[0] = 5.0;
            },
            PcbViolationKind::Motion,
        ),
        (
            "a robot starting away from home",
            |p| p.devices[0].start[1] += 0.01,
            PcbViolationKind::Start,
        ),
        (
            "the stated assembly time",
            |p| p.cycle_time_s -= 0.01,
            PcbViolationKind::Total,
        ),
        (
            "the stated lower bound",
            |p| p.lower_bound_s += 0.01,
            PcbViolationKind::Total,
        ),
        (
            "a robot's totals",
            |p| p.robots[0].waiting_s += 0.01,
            PcbViolationKind::Total,
        ),
    ];
    for (name, fault, kind) in faults {
        let mut p = good.clone();
        fault(&mut p);
        let found = kinds(&base, &p);
        assert!(
            found.contains(&kind),
            "{name}: expected {kind:?}, found {found:?}"
        );
    }
    // Every time shifted before 0.
    let mut p = good.clone();
    for d in &mut p.devices {
        for m in &mut d.moves {
            m.t = [m.t[0] - 0.05, m.t[1] - 0.05];
        }
    }
    for pl in &mut p.placements {
        pl.pick.t = [pl.pick.t[0] - 0.05, pl.pick.t[1] - 0.05];
        pl.place.t = [pl.place.t[0] - 0.05, pl.place.t[1] - 0.05];
    }
    let found = verify_pcb(&base, &p, &PcbVerifySettings::default()).violations;
    assert!(
        found.iter().any(|v| v.detail.contains("before time 0")),
        "{found:?}"
    );
    // A plan claiming collision avoidance off on a cell that has it on.
    let mut p = good.clone();
    p.collision_avoidance = false;
    assert!(kinds(&base, &p).contains(&PcbViolationKind::Format));
    // Two placements at once (the paper places one after the other, on the one table).
    let mut p = good.clone();
    let k = (1..p.placements.len())
        .find(|&k| p.placements[k].robot != p.placements[k - 1].robot)
        .unwrap();
    p.placements[k].place.t = p.placements[k - 1].place.t;
    let found = verify_pcb(&base, &p, &PcbVerifySettings::default()).violations;
    assert!(
        found.iter().any(|v| v.detail.contains("one placement at a time")),
        "{found:?}"
    );
    // Bins the cell fixes: a plan may not stock others.
    let mut given = base.clone();
    for b in &good.bins {
        let feeder = given.feeders.iter().position(|f| f.name == b.feeder).unwrap();
        let kind = given
            .types
            .iter()
            .position(|t| t.footprint == b.footprint && t.value == b.value)
            .unwrap();
        given.given_bins.push(cellplan_pcb::cell::GivenBin {
            feeder,
            slot: b.bin,
            kind,
        });
    }
    let mut p = good.clone();
    p.lower_bound_s = cellplan_pcb::bound::lower_bound(&given);
    assert!(kinds(&given, &p).is_empty(), "{:?}", kinds(&given, &p));
    let mut extra = p.bins[0].clone();
    extra.bin = (0..4)
        .find(|b| !p.bins.iter().any(|x| x.feeder == extra.feeder && x.bin == *b))
        .unwrap();
    p.bins.push(extra);
    assert!(kinds(&given, &p).contains(&PcbViolationKind::Bin));
    // A fixed table that moves.
    let fixed = base.variant(1, Configuration::AllFixed, base.motion).unwrap();
    let mut p = plan(&fixed, Optimizer::Best, 2000, 0);
    assert!(kinds(&base, &p).is_empty());
    let table = p
        .devices
        .iter_mut()
        .find(|d| d.kind == DeviceKind::Table)
        .unwrap();
    let at = table.start;
    table.moves.push(MoveOut {
        t: [100.0, 100.0 + 0.002 / 0.5],
        from: at,
        to: [at[0] + 0.002, at[1]],
    });
    assert!(kinds(&base, &p).contains(&PcbViolationKind::FixedMoved));
}

#[test]
fn crossing_robots_are_caught_and_collision_avoidance_prevents_them() {
    // Random two-robot cells where, without the safety delays, the robots cross.
    let mut crossed = 0;
    for seed in 0..6 {
        let mut cell = cellplan_pcb::testing::random_cell(24, 5, 2, Configuration::AllMoving, seed);
        cell.collision_avoidance = false;
        let loose = plan(&cell, Optimizer::Ga, 400, seed);
        let r = verify_pcb(&cell, &loose, &PcbVerifySettings::default());
        if r.crossings > 0 {
            crossed += 1;
            assert!(
                r.violations
                    .iter()
                    .any(|v| v.kind == PcbViolationKind::RobotRobot)
            );
            let lenient = verify_pcb(&cell, &loose, &PcbVerifySettings { robot_robot: false });
            assert!(lenient.ok, "{:?}", lenient.violations);
        }
        cell.collision_avoidance = true;
        for optimizer in [Optimizer::Ga, Optimizer::Best] {
            let safe = plan(&cell, optimizer, 1500, seed);
            let r = verify_pcb(&cell, &safe, &PcbVerifySettings::default());
            assert!(
                r.ok && r.crossings == 0,
                "seed {seed} {optimizer:?}: {:?}",
                r.violations
            );
            assert!(r.closest_robots_m >= cell.safety_gap - 1e-9);
        }
    }
    assert!(
        crossed > 0,
        "some random cell must cross without collision avoidance"
    );
}

#[test]
fn plans_do_not_depend_on_the_thread_count() {
    let base = example();
    for optimizer in [Optimizer::Ga, Optimizer::Best] {
        let mut a = plan(&base, optimizer, 4000, 7);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let mut b = pool.install(|| plan(&base, optimizer, 4000, 7));
        a.compute_s = 0.0;
        b.compute_s = 0.0;
        assert_eq!(a, b, "{optimizer:?}");
    }
}

#[test]
fn safety_delays_of_both_rules_keep_the_gap_exactly_on_random_schedules() {
    use cellplan_pcb::document::{RunInfo, build};
    use cellplan_pcb::sim::{DelayRule, Given, simulate};
    for seed in 0..60 {
        let mut cell = cellplan_pcb::testing::random_cell(30, 6, 2, Configuration::AllMoving, seed);
        if seed % 2 == 1 {
            cell.motion = cellplan_pcb::MotionModel::Trapezoid;
        }
        let d = cellplan_pcb::testing::random_decision(&cell, seed + 1000);
        for rule in [DelayRule::Paper, DelayRule::Exact] {
            let s = simulate(&cell, &d, &mut Given(&d), rule);
            let info = RunInfo {
                optimizer: "best".into(),
                seed,
                compute_s: 0.0,
                evaluations: 0,
                lower_bound_s: cellplan_pcb::bound::lower_bound(&cell),
            };
            let doc = build(&cell, &d, &s, &info);
            let r = verify_pcb(&cell, &doc, &PcbVerifySettings::default());
            assert!(r.ok, "seed {seed} {rule:?}: {:?}", r.violations);
        }
    }
}

#[test]
fn the_bound_holds_when_a_type_is_in_both_feeders() {
    // One robot, a fixed table: two types stocked in both feeders, components near each
    // feeder; picking each component from the nearer feeder beats any one-feeder-per-type plan.
    for seed in 0..8 {
        let mut cell = cellplan_pcb::testing::random_cell(12, 2, 1, Configuration::AllFixed, seed);
        for (feeder, slot, kind) in [(0, 3, 0), (0, 5, 1), (1, 3, 0), (1, 5, 1)] {
            cell.given_bins
                .push(cellplan_pcb::cell::GivenBin { feeder, slot, kind });
        }
        for optimizer in [Optimizer::Ga, Optimizer::Best] {
            let p = plan(&cell, optimizer, 4000, seed);
            let r = verify_pcb(&cell, &p, &PcbVerifySettings::default());
            assert!(r.ok, "seed {seed} {optimizer:?}: {:?}", r.violations);
            assert!(r.lower_bound_s <= p.cycle_time_s + 1e-9);
            // Both feeders are used for one type somewhere (the nearer one per component).
            let used: std::collections::HashSet<&str> =
                p.placements.iter().map(|x| x.feeder.as_str()).collect();
            assert_eq!(used.len(), 2, "seed {seed} {optimizer:?}");
        }
    }
}
