//! The exact re-check of joint paths sees a motion problem's tool (bench/motion's car-body scene,
//! whose robot carries the README cell's probe).
use cellplan_geom::{Pose, ShapeSpec};
use cellplan_motion::problem::{ArmSetup, read_problems};
use cellplan_verify::motion::{ExactObstacle, ExactRobot};
use std::path::Path;

#[test]
fn the_exact_recheck_checks_the_tool() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/motion/autobody-r2000/autobody.json");
    let set = read_problems(&path).unwrap();
    let mut bare = set.clone();
    bare.robot.tool = None;
    let with = ArmSetup::load(&set).unwrap();
    let without = ArmSetup::load(&bare).unwrap();
    let robot = ExactRobot::new(&with.model, with.base, &with.link_pairs());
    let bare_robot = ExactRobot::new(&without.model, without.base, &without.link_pairs());
    assert_eq!(robot.part_count(), bare_robot.part_count() + 2);
    // A ball where the probe's housing is at the start: a path standing there touches it with
    // the tool, and only with the tool.
    let q = with.to_chain(&set.problems[0].start);
    let tool = set.robot.tool.as_ref().unwrap();
    let housing = set.robot.base * with.model.chain.fk_tip(&q) * tool.shapes[1].1;
    let ball = ExactObstacle::new(
        "ball",
        &ShapeSpec::Sphere { radius: 0.02 },
        Pose::from_translation(housing.translation),
    )
    .unwrap();
    let path = [q.clone(), q.clone()];
    let hit = robot.check_path(&path, std::slice::from_ref(&ball), 0.0, 1e-3);
    assert!(!hit.valid);
    let (_, _, what) = hit.contact.unwrap();
    assert!(what.contains("(probe) with obstacle ball"), "{what}");
    assert!(
        bare_robot
            .check_path(&path, std::slice::from_ref(&ball), 0.0, 1e-3)
            .valid
    );
    // The problems as given are clear with the tool too (start and goals).
    for p in &set.problems {
        let obstacles: Vec<ExactObstacle> = p
            .obstacles
            .iter()
            .filter_map(|o| ExactObstacle::new(&o.name, &o.shape, o.pose))
            .collect();
        for c in std::iter::once(&p.start).chain(&p.goals) {
            let c = with.to_chain(c);
            let check = robot.check_path(&[c.clone(), c], &obstacles, p.margin, 1e-3);
            assert!(check.valid, "{}: {:?}", p.name, check.contact);
        }
    }
}
