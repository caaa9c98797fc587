//! CMM plans (paper 003) through the independent verifier: whole plans, both reuse strategies on
//! random subsets, re-planned subsets, and tampered plans, each fault caught.
use cellplan_cmm::cell::CmmCell;
use cellplan_cmm::document::{CmmPlan, Strategy};
use cellplan_cmm::plan::{Request, document, reuse, run};
use cellplan_solve::GtspMethod;
use cellplan_verify::cmm::{CmmViolationKind, verify_cmm};
use std::path::Path;
use std::sync::OnceLock;

fn cell() -> &'static CmmCell {
    static CELL: OnceLock<CmmCell> = OnceLock::new();
    CELL.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cmm-block/cell.toml");
        cellplan_cmm::cell::load(&path).unwrap_or_else(|e| panic!("{e}"))
    })
}

fn request(order: GtspMethod, seed: u64) -> Request {
    Request {
        order,
        classification: None,
        seed,
        subset: None,
    }
}

fn planned() -> &'static CmmPlan {
    static PLAN: OnceLock<CmmPlan> = OnceLock::new();
    PLAN.get_or_init(|| {
        let req = request(GtspMethod::Ils, 0);
        let out = run(cell(), &req).unwrap();
        document(cell(), &out, &req, Strategy::Plan)
    })
}

fn kinds(plan: &CmmPlan) -> Vec<CmmViolationKind> {
    verify_cmm(cell(), plan)
        .violations
        .iter()
        .map(|v| v.kind)
        .collect()
}

#[test]
fn whole_plans_by_both_orderings_verify_and_measure_every_mp() {
    for order in [GtspMethod::Ga, GtspMethod::Ils] {
        let req = request(order, 3);
        let out = run(cell(), &req).unwrap();
        let doc = document(cell(), &out, &req, Strategy::Plan);
        let r = verify_cmm(cell(), &doc);
        assert!(r.ok, "{order:?}: {:?}", r.violations);
        assert_eq!(doc.tasks.len(), 39);
        assert!(doc.unmeasured.is_empty());
        assert!((r.motion_time_s - doc.motion_time_s).abs() < 1e-9);
        assert!(r.closest_m >= cell().clearance);
    }
}

#[test]
fn the_same_seed_gives_the_same_plan() {
    let req = request(GtspMethod::Ils, 5);
    let a = document(cell(), &run(cell(), &req).unwrap(), &req, Strategy::Plan);
    let b = document(cell(), &run(cell(), &req).unwrap(), &req, Strategy::Plan);
    assert_eq!(CmmPlan { compute_s: 0.0, ..a }, CmmPlan { compute_s: 0.0, ..b });
}

#[test]
fn reuse_of_random_subsets_verifies_and_beats_walking_the_initial_path() {
    use rand::{RngExt, SeedableRng};
    let plan = planned();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for _ in 0..8 {
        let size = rng.random_range(3..=20);
        let mut subset: Vec<usize> = (0..39).collect();
        for i in (1..subset.len()).rev() {
            subset.swap(i, rng.random_range(0..=i));
        }
        subset.truncate(size);
        let roots = reuse(cell(), plan, &subset, Strategy::ReuseRoots).unwrap();
        let initial = reuse(cell(), plan, &subset, Strategy::ReuseInitialPath).unwrap();
        for doc in [&roots, &initial] {
            let r = verify_cmm(cell(), doc);
            assert!(r.ok, "{:?}: {:?}", doc.strategy, r.violations);
            let mut got: Vec<usize> = doc.tasks.iter().map(|id| cell().mp(id).unwrap()).collect();
            got.sort_unstable();
            let mut want = subset.clone();
            want.sort_unstable();
            assert_eq!(got, want);
        }
        assert!(roots.motion_time_s < initial.motion_time_s);
        // A reuse plan is itself reusable.
        let again = reuse(cell(), &roots, &subset[..2], Strategy::ReuseRoots).unwrap();
        assert!(verify_cmm(cell(), &again).ok);
    }
}

#[test]
fn a_replanned_subset_verifies() {
    let req = Request {
        subset: Some(vec![0, 12, 20, 33]),
        ..request(GtspMethod::Ils, 0)
    };
    let out = run(cell(), &req).unwrap();
    let doc = document(cell(), &out, &req, Strategy::Replan);
    let r = verify_cmm(cell(), &doc);
    assert!(r.ok, "{:?}", r.violations);
    assert_eq!(doc.tasks.len(), 4);
}

#[test]
fn tampered_plans_are_caught() {
    let plan = planned();
    assert!(verify_cmm(cell(), plan).ok);
    // A waypoint pushed into the part (the middle of the deck, 10 cm down).
    let mut p = plan.clone();
    let i = p.path.iter().position(|w| w.touch.is_some()).unwrap();
    p.path[i + 1].q[2] -= 0.25;
    assert!(
        kinds(&p).contains(&CmmViolationKind::Collision),
        "{:?}",
        kinds(&p)
    );
    // A touch off its MP.
    let mut p = plan.clone();
    let w = &mut p.path[i];
    w.q[0] += 0.001;
    assert!(kinds(&p).contains(&CmmViolationKind::Touch));
    // A touch of another MP.
    let mut p = plan.clone();
    let j = p.path.iter().rposition(|w| w.touch.is_some()).unwrap();
    p.path[j].touch = p.path[i].touch.clone();
    assert!(kinds(&p).contains(&CmmViolationKind::Task));
    // An MP dropped silently.
    let mut p = plan.clone();
    p.path[j].touch = None;
    p.tasks.pop();
    let k = kinds(&p);
    assert!(
        k.contains(&CmmViolationKind::Task) && k.contains(&CmmViolationKind::Total),
        "{k:?}"
    );
    // `tasks` out of order.
    let mut p = plan.clone();
    p.tasks.swap(0, 1);
    assert!(kinds(&p).contains(&CmmViolationKind::Task));
    // A time understated.
    let mut p = plan.clone();
    p.movement_s -= 0.5;
    assert!(kinds(&p).contains(&CmmViolationKind::Total));
    // A head angle beyond its range.
    let mut p = plan.clone();
    p.path[1].q[3] = -0.2;
    assert!(kinds(&p).contains(&CmmViolationKind::Range));
    // Outside the travel.
    let mut p = plan.clone();
    p.path[1].q[0] = 0.8;
    assert!(kinds(&p).contains(&CmmViolationKind::Range));
    // A stored root moved into the part: reuse would trust it.
    let mut p = plan.clone();
    p.groups[0].roots[0][2] = 0.15;
    assert!(kinds(&p).contains(&CmmViolationKind::Stored));
    // A turn height too low.
    let mut p = plan.clone();
    p.turn_height_m = 0.35;
    assert!(kinds(&p).contains(&CmmViolationKind::Stored));
    // Not starting at home.
    let mut p = plan.clone();
    p.path.remove(0);
    assert!(kinds(&p).contains(&CmmViolationKind::Format));
}

#[test]
fn a_path_through_a_thin_wall_between_two_clear_waypoints_is_caught() {
    // Two configurations either side of the block at deck height, both clear: the straight
    // move between them crosses the part.
    let plan = planned();
    let mut p = plan.clone();
    let home = p.path[0].q;
    let a = [0.1, 0.5, 0.2, 0.0, 0.0];
    let b = [0.62, 0.5, 0.2, 0.0, 0.0];
    let up = |q: [f64; 5]| [q[0], q[1], home[2], 0.0, 0.0];
    let extra = [up(a), a, b, up(b)].map(|q| cellplan_cmm::document::Waypoint { q, touch: None });
    p.path.splice(
        1..1,
        extra
            .into_iter()
            .chain([cellplan_cmm::document::Waypoint { q: home, touch: None }]),
    );
    let k = kinds(&p);
    assert!(k.contains(&CmmViolationKind::Collision), "{k:?}");
}

#[test]
fn the_second_example_the_housing_is_planned_whole_and_verifies() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cmm-housing/cell.toml");
    let cell = cellplan_cmm::cell::load(&path).unwrap_or_else(|e| panic!("{e}"));
    // The cell's adjacency is the generator's.
    for (f, a) in cell.faces.iter().enumerate() {
        for (g, b) in cell.faces.iter().enumerate() {
            let i = cellplan_cmm::housing::HOUSING_FACES
                .iter()
                .position(|x| x == a)
                .unwrap();
            let j = cellplan_cmm::housing::HOUSING_FACES
                .iter()
                .position(|x| x == b)
                .unwrap();
            assert_eq!(
                cell.adjacent(f, g),
                cellplan_cmm::housing::housing_adjacent(i, j),
                "{a} {b}"
            );
        }
    }
    let req = request(GtspMethod::Ils, 0);
    let out = run(&cell, &req).unwrap();
    let doc = document(&cell, &out, &req, Strategy::Plan);
    let r = verify_cmm(&cell, &doc);
    assert!(r.ok, "{:?}", r.violations);
    assert_eq!(doc.tasks.len(), 40, "unmeasured: {:?}", doc.unmeasured);
    let subset: Vec<usize> = (0..40).step_by(3).collect();
    let again = reuse(&cell, &doc, &subset, Strategy::ReuseRoots).unwrap();
    assert!(verify_cmm(&cell, &again).ok);
}
