//! What the planning tests share: the reduced two-robot example (its first 8 MPs), the plan
//! document of a run, and the independent re-check of a plan — every MP measured exactly once
//! at a pose that meets the probe constraints, every leg re-sampled finely (joint steps of
//! 1 mrad) against the static scene at the margin, joint position, velocity and acceleration
//! limits from the written samples, the document's totals recomputed — and the verifier.
// Each test file uses some of these.
#![allow(dead_code)]
use cellplan_core::candidates::{CandidateTable, generate};
use cellplan_core::coord::{self, CoordSettings};
use cellplan_core::document as output;
use cellplan_core::plan::{self, Allocation, PlanSettings};
use cellplan_model::robot::Scratch;
use cellplan_model::{Cell, LoadOptions};
use cellplan_optical::load;
use cellplan_optical::testing::{example_copy, repo_root};
use cellplan_verify::{VerifySettings, verify};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::OnceLock;
/// The two-robot example with only its first `n` MPs, written to a temporary folder.
pub fn small_cell(n: usize) -> PathBuf {
    example_copy(&format!("plan-test-{n}"), "autobody-2r-small", n, |text| text)
}

pub struct Fixture {
    pub cell: Cell,
    pub table: CandidateTable,
}

pub fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let cell = load(&small_cell(8), &LoadOptions::default()).expect("the reduced cell loads");
        let table = generate(&cell);
        Fixture { cell, table }
    })
}

pub fn settings(allocation: Allocation) -> PlanSettings {
    PlanSettings {
        allocation,
        alternatives: 8,
        balanced_iterations: 60,
        // Never cut by the clock: the plan must depend only on the input and the seed.
        time_limit: std::time::Duration::from_secs(3600),
        ..PlanSettings::default()
    }
}

pub fn make(allocation: Allocation) -> output::Plan {
    let f = fixture();
    let s = settings(allocation);
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).expect("the reduced cell plans");
    let doc = build(&f.cell, &f.table, &outcome, &s);
    // The document survives its own JSON.
    let text = serde_json::to_string(&doc).unwrap();
    let back: output::Plan = serde_json::from_str(&text).unwrap();
    assert_eq!(serde_json::to_string(&back).unwrap(), text);
    check_plan(&f.cell, &doc);
    verified(&f.cell, &doc);
    doc
}

/// The plan document of a run, coordinated by `best`.
pub fn build(cell: &Cell, table: &CandidateTable, outcome: &plan::Outcome, s: &PlanSettings) -> output::Plan {
    let c = coord::coordinate_outcome(cell, table, outcome, &CoordSettings::default())
        .expect("coordination succeeds");
    output::build(cell, table, outcome, &c, s, 0.0, 0.0)
}

/// The plan document of a run ([`build`]), re-checked ([`check_plan`]) and verified
/// ([`verified`]).
pub fn build_checked(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &plan::Outcome,
    s: &PlanSettings,
) -> output::Plan {
    let doc = build(cell, table, outcome, s);
    check_plan(cell, &doc);
    verified(cell, &doc);
    doc
}

/// The verifier accepts the plan, robot–robot clearance included.
pub fn verified(cell: &Cell, doc: &output::Plan) {
    let report = verify(cell, doc, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
    assert!(report.configurations_checked > 0);
    // Every robot pair walked, from its first instant on.
    let n = doc.robots.len();
    assert!(report.pair_instants_checked >= n * n.saturating_sub(1) / 2);
}

/// The independent re-check of a plan.
pub fn check_plan(cell: &Cell, doc: &output::Plan) {
    let process = cellplan_optical::of(cell).expect("an optical cell");
    assert_eq!(doc.format, output::FORMAT);
    assert_eq!(doc.robots.len(), cell.robots.len());
    let by_name: BTreeMap<&str, usize> = cell.tasks.iter().map(|t| (t.name.as_str(), t.id.0)).collect();
    let mut measured = vec![0usize; cell.tasks.len()];
    let mut scratch = Scratch::default();
    let mut times = Vec::new();
    for (robot, rp) in cell.robots.iter().zip(&doc.robots) {
        assert_eq!(rp.name, robot.name);
        assert!(
            rp.tasks.len() <= cell.planning.task_cap,
            "{} over its cap",
            rp.name
        );
        for v in &rp.tasks {
            let t = &cell.tasks[by_name[v.task.as_str()]];
            measured[t.id.0] += 1;
            assert!(robot.within_limits(&v.q));
            let tcp = robot.tcp_pose(&v.q);
            assert!((tcp.translation - glam::DVec3::from(v.tcp.xyz)).length() < 1e-6);
            let angle = process
                .measurement(t, &tcp)
                .unwrap_or_else(|r| panic!("{} does not measure {} from its pose: {r:?}", rp.name, v.task));
            assert!((angle - v.figures["view_angle_rad"]).abs() < 1e-6);
            robot.body_poses(&v.q, &mut scratch);
            assert!(
                robot
                    .contact_at(&cell.world, &scratch, cell.planning.clearance - 1e-6)
                    .is_none()
            );
            assert!(v.depart_s - v.arrive_s >= process.measure_time - 1e-9);
        }
        // Legs: chained home → … → home, re-sampled at 1 mrad per joint step.
        assert_eq!(rp.legs.len(), rp.tasks.len() + 1);
        let mut at = rp.home.clone();
        for (i, leg) in rp.legs.iter().enumerate() {
            let to = rp.tasks.get(i).map_or(&rp.home, |v| &v.q);
            assert!(
                dist(&leg.waypoints[0], &at) < 1e-9,
                "{} leg {i} starts elsewhere",
                rp.name
            );
            assert!(
                dist(leg.waypoints.last().unwrap(), to) < 1e-9,
                "{} leg {i} ends elsewhere",
                rp.name
            );
            for w in leg.waypoints.windows(2) {
                let steps = (dist(&w[0], &w[1]) / 1e-3).ceil().max(1.0) as usize;
                for s in 0..=steps {
                    let f = s as f64 / steps as f64;
                    let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(a, b)| a + f * (b - a)).collect();
                    assert!(
                        robot.within_limits(&q),
                        "{} leg {i} leaves the joint limits",
                        rp.name
                    );
                    robot.body_poses(&q, &mut scratch);
                    assert!(
                        robot
                            .contact_at(&cell.world, &scratch, cell.planning.clearance - 1e-6)
                            .is_none(),
                        "{} leg {i} ({} → {}) comes closer than the clearance at {q:?}",
                        rp.name,
                        leg.from,
                        leg.to
                    );
                }
            }
            at = to.clone();
        }
        // Samples: within limits; finite differences bound the mean velocity and acceleration.
        let tr = &rp.trajectory;
        assert!(tr.first().unwrap().t.abs() < 1e-12);
        assert!((tr.last().unwrap().t - rp.total_s).abs() < 1e-9);
        assert!(dist(&tr.first().unwrap().q, &rp.home) < 1e-9);
        assert!(dist(&tr.last().unwrap().q, &rp.home) < 1e-9);
        for s in tr {
            assert!(robot.within_limits(&s.q));
        }
        for w in tr.windows(3) {
            let (h1, h2) = (w[1].t - w[0].t, w[2].t - w[1].t);
            for j in 0..robot.dof() {
                let v = (w[1].q[j] - w[0].q[j]) / h1;
                assert!(
                    v.abs() <= robot.max_velocity[j] * (1.0 + 1e-6),
                    "{} joint {j} too fast",
                    rp.name
                );
                if (h1 - h2).abs() < 1e-9 {
                    let a = (w[2].q[j] - 2.0 * w[1].q[j] + w[0].q[j]) / (h1 * h1);
                    assert!(
                        a.abs() <= robot.max_acceleration[j] * (1.0 + 1e-6),
                        "{} joint {j} accelerates too hard",
                        rp.name
                    );
                }
            }
        }
        times.push(rp.total_s);
    }
    // Every measurable MP exactly once; the others listed as unmeasured.
    let unmeasured: Vec<&str> = doc.unmeasured.iter().map(|u| u.task.as_str()).collect();
    for t in &cell.tasks {
        let want = usize::from(!unmeasured.contains(&t.name.as_str()));
        assert_eq!(
            measured[t.id.0], want,
            "MP {} measured {} times",
            t.name, measured[t.id.0]
        );
    }
    let cycle = times.iter().copied().fold(0.0, f64::max);
    assert!((doc.cycle_time_s - cycle).abs() < 1e-9);
    let spread = cycle - times.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((doc.delta_t_s - spread).abs() < 1e-9);
    assert!(
        doc.lower_bound_s > 0.0 && doc.lower_bound_s <= doc.cycle_time_s + 1e-9,
        "lower bound {} above the cycle time {} ({} unmeasured)",
        doc.lower_bound_s,
        doc.cycle_time_s,
        doc.unmeasured.len()
    );
}

pub fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

/// `base` rebalanced with `settings`, its score and ends taken as its uncoordinated ones,
/// every hand-over allowed by the work budget, `judge` judging: see
/// [`plan::rebalance::rebalance`].
pub fn rebalanced(
    cell: &Cell,
    table: &CandidateTable,
    base: &plan::Outcome,
    settings: &PlanSettings,
    cache: &mut plan::PlanCache,
    judge: &mut plan::rebalance::Judge<'_, ()>,
) -> (Option<plan::rebalance::Rebalanced<()>>, bool) {
    use plan::rebalance::{Waits, ends, makespan, rebalance};
    rebalance(
        cell,
        table,
        (base, makespan(base), &ends(base), &Waits::default()),
        settings,
        cache,
        &|_| true,
        (judge, &|_| Waits::default()),
    )
    .unwrap()
}

/// A cell of the repository (path from its root), loaded.
pub fn repo_cell(rel: &str) -> cellplan_model::Cell {
    load(&repo_root().join(rel), &LoadOptions::default()).unwrap()
}

/// The README cell planned with the nearest-robot allocation: the cell, its candidates, the
/// settings, the leg cache and the plan.
pub fn readme_nearest() -> (Cell, CandidateTable, PlanSettings, plan::PlanCache, plan::Outcome) {
    let cell = repo_cell("examples/autobody-4r/cell.toml");
    let table = generate(&cell);
    let s = settings(Allocation::Proximity);
    let mut cache = plan::PlanCache::default();
    let base = plan::plan_cached(&cell, &table, &s, &|_| {}, &mut cache).unwrap();
    (cell, table, s, cache, base)
}

/// The robot that ends last by `end` (the higher index on a tie, as `rebalance` takes it).
pub fn last_robot(end: &[f64]) -> usize {
    (0..end.len())
        .max_by(|&a, &b| end[a].total_cmp(&end[b]).then(b.cmp(&a)))
        .expect("robots")
}
