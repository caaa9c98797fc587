//! Blends: after coordination, legs without a wait on the way run through their corners
//! without stopping (`cellplan_core::coord::blend`). On the crossing cell of the coordination
//! tests: blended plans verify, are never longer, and the verifier re-checks the curves.
use cellplan_core::coord::blend::{blend_controls, curve_clear};
use cellplan_core::coord::{self, Coordination};
use cellplan_core::document as output;
use cellplan_motion::plan::StateValidity;
use cellplan_optical::testing::{document, fixture};
use cellplan_verify::{VerifySettings, ViolationKind, verify};
use proptest::prelude::*;

mod faults;

/// A disc of radius `r` about `o` in a two-joint space; the clearance of `q` is its distance
/// from the disc (radii of 1 per joint: `Σ_j |Δq_j|` bounds the motion of a "point").
struct Disc {
    o: [f64; 2],
    r: f64,
}

impl StateValidity for Disc {
    fn is_valid(&self, q: &[f64]) -> bool {
        self.clearance(q) > 0.0
    }
    fn clearance(&self, q: &[f64]) -> f64 {
        ((q[0] - self.o[0]).powi(2) + (q[1] - self.o[1]).powi(2)).sqrt() - self.r
    }
}

fn bezier(a: &[f64], p: &[f64], c: &[f64], s: f64) -> Vec<f64> {
    (0..a.len())
        .map(|j| (1.0 - s) * (1.0 - s) * a[j] + 2.0 * s * (1.0 - s) * p[j] + s * s * c[j])
        .collect()
}

#[test]
fn a_blend_that_cuts_into_an_obstacle_is_refused() {
    // An L-shaped path around a disc inside its corner: (0, 0) → (1, 0) → (1, 1), the disc
    // centred at (0.9, 0.1) with radius 0.08 (both segments pass 0.02 from it).
    let path = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]];
    let disc = Disc {
        o: [0.9, 0.1],
        r: 0.08,
    };
    let radii = [1.0, 1.0];
    // A small blend stays clear, a large one passes through the disc.
    let (a, c) = blend_controls(&path, 1, 0.05);
    assert!(curve_clear(&disc, &radii, &a, &path[1], &c));
    let (a, c) = blend_controls(&path, 1, 0.45);
    assert!(!curve_clear(&disc, &radii, &a, &path[1], &c));
    assert!((0..=100).any(|k| disc.clearance(&bezier(&a, &path[1], &c, k as f64 / 100.0)) < 0.0));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Whenever the check accepts a curve, the curve keeps off the disc at every point.
    #[test]
    fn an_accepted_curve_keeps_clear(
        a in prop::array::uniform2(-1.0f64..1.0),
        p in prop::array::uniform2(-1.0f64..1.0),
        c in prop::array::uniform2(-1.0f64..1.0),
        o in prop::array::uniform2(-1.0f64..1.0),
        r in 0.01f64..0.5,
    ) {
        let disc = Disc { o, r };
        if curve_clear(&disc, &[1.0, 1.0], &a, &p, &c) {
            for k in 0..=2000 {
                let q = bezier(&a, &p, &c, k as f64 / 2000.0);
                prop_assert!(disc.clearance(&q) > 0.0, "{q:?}");
            }
        }
    }
}

/// The crossing cell coordinated by `strategy` without blends.
fn unblended(strategy: Coordination) -> output::Plan {
    let f = fixture();
    let c = coord::coordinate_outcome(
        &f.cell,
        &f.table,
        &f.outcome,
        &coord::CoordSettings {
            strategy,
            blend_deviation: 0.0,
            ..coord::CoordSettings::default()
        },
    )
    .unwrap();
    assert_eq!(c.blended_corners, 0);
    cellplan_core::document::build(&f.cell, &f.table, &f.outcome, &c, &f.settings, 0.0, 0.0)
}

#[test]
fn blended_plans_verify_and_are_never_longer() {
    let f = fixture();
    let mut corners = 0;
    for strategy in Coordination::RESOLVING {
        let (doc, c) = document(strategy);
        let report = verify(&f.cell, &doc, &VerifySettings::default());
        assert!(report.ok, "{strategy}: {:#?}", report.violations);
        let stated: usize = doc
            .robots
            .iter()
            .flat_map(|r| &r.legs)
            .map(|l| l.blends.len())
            .sum();
        assert_eq!(stated, c.blended_corners, "{strategy}");
        corners += stated;
        let plain = unblended(strategy);
        assert!(
            plain
                .robots
                .iter()
                .flat_map(|r| &r.legs)
                .all(|l| l.blends.is_empty())
        );
        // Every robot ends no later, and moves no longer.
        for (b, p) in doc.robots.iter().zip(&plain.robots) {
            assert!(
                b.motion_s <= p.motion_s + 1e-9,
                "{strategy}: {} {} > {}",
                b.name,
                b.motion_s,
                p.motion_s
            );
        }
        assert!(
            doc.cycle_time_s <= plain.cycle_time_s + 1e-9,
            "{strategy}: {} > {}",
            doc.cycle_time_s,
            plain.cycle_time_s
        );
        // No blended leg has a wait on the way.
        for rp in &doc.robots {
            for w in rp.waits.iter().filter(|w| w.waypoint > 0) {
                assert!(rp.legs[w.leg].blends.is_empty());
            }
        }
    }
    assert!(corners > 0, "nothing was blended on the crossing cell");
}

#[test]
fn the_verifier_rechecks_the_blends() {
    let good = faults::good_plan();
    let kinds = faults::kinds;
    let (r, l) = good
        .robots
        .iter()
        .enumerate()
        .find_map(|(r, rp)| rp.legs.iter().position(|l| !l.blends.is_empty()).map(|l| (r, l)))
        .expect("a blended leg");
    // A blend stated smaller than the one run: the trajectory leaves the stated curve.
    let mut shrunk = good.clone();
    shrunk.robots[r].legs[l].blends[0].radius *= 0.5;
    assert!(
        kinds(&shrunk).contains(&ViolationKind::OffPath),
        "{:?}",
        kinds(&shrunk)
    );
    // The blend dropped: the trajectory cuts a corner the leg says it stops at.
    let mut dropped = good.clone();
    dropped.robots[r].legs[l].blends.clear();
    assert!(
        kinds(&dropped).contains(&ViolationKind::OffPath),
        "{:?}",
        kinds(&dropped)
    );
    // A blend past the middle of its segments.
    let mut wide = good.clone();
    wide.robots[r].legs[l].blends[0].radius = 100.0;
    assert!(
        kinds(&wide).contains(&ViolationKind::Continuity),
        "{:?}",
        kinds(&wide)
    );
    // A blend at a waypoint the layout does not allow (the leg's end) is refused on reading.
    let mut misplaced = good.clone();
    let n = misplaced.robots[r].legs[l].waypoints.len();
    misplaced.robots[r].legs[l].blends[0].waypoint = n - 1;
    let text = serde_json::to_string(&misplaced).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plan.json");
    std::fs::write(&path, text).unwrap();
    let err = output::read(&path).unwrap_err().to_string();
    assert!(err.contains("blends[0]"), "{err}");
}

#[test]
fn a_needless_joint_swing_is_straightened_before_blending() {
    use cellplan_motion::plan::check_segment;
    let f = fixture();
    let mut outcome = f.outcome.clone();
    let robot = &f.cell.robots[0];
    let limits = cellplan_core::plan::graph::limits_of(robot);
    let space = cellplan_core::motion::joint_space(&f.cell, robot);
    let validity = cellplan_core::motion::robot_validity(&f.cell, robot, f.cell.planning.clearance);
    // Robot 0's first leg made to swing its last joint out and back on the way: a detour
    // nothing in the cell asks for (checked clear first, or the test proves nothing).
    let prog = &mut outcome.robots[0].program;
    let (a, b) = (
        prog.legs[0].waypoints[0].clone(),
        prog.legs[0].waypoints.last().unwrap().clone(),
    );
    let mut mid: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.5 * (x + y)).collect();
    let last = mid.len() - 1;
    mid[last] += 2.0;
    let swung = vec![a.clone(), mid, b.clone()];
    for w in swung.windows(2) {
        assert!(check_segment(&space, &validity, &w[0], &w[1], 1e-4).valid);
    }
    let swing = |w: &[Vec<f64>]| -> f64 {
        w.windows(2).map(|p| (p[1][last] - p[0][last]).abs()).sum::<f64>()
            - (w[w.len() - 1][last] - w[0][last]).abs()
    };
    let injected = swing(&swung);
    assert!(injected > 1.0, "{injected}");
    prog.legs[0] = coord::program::ProgramLeg::new(swung, false, &limits).unwrap();
    let settings = coord::CoordSettings::default();
    let c = coord::coordinate_outcome(&f.cell, &f.table, &outcome, &settings).unwrap();
    let leg = &c.programs[0].legs[0];
    assert!(
        swing(&leg.waypoints) < 0.25 * injected,
        "swing left: {} of {injected}",
        swing(&leg.waypoints)
    );
    // The straightened plan verifies, and the leg it runs is the straightened one.
    let doc = cellplan_core::document::build(&f.cell, &f.table, &outcome, &c, &f.settings, 0.0, 0.0);
    let report = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
    assert!(swing(&doc.robots[0].legs[0].waypoints) < 0.25 * injected);
}
