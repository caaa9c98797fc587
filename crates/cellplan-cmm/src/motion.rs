//! The CMM in the shared motion core: its configuration space `[x, y, z, a, b]` as a
//! [`JointSpace`] and the probe's clearance to the part as a [`StateValidity`], so that every
//! planner of `cellplan_motion::plan` (and the segment check that misses no contact between
//! samples) works on it unchanged.
use crate::classify::Probe;
use cellplan_kin::cmm::CmmQ;
use cellplan_motion::plan::{JointSpace, StateValidity};

/// The machine's travel: X, Y, Z of the A-axis centre (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Travel {
    /// X range.
    pub x: [f64; 2],
    /// Y range.
    pub y: [f64; 2],
    /// Z range.
    pub z: [f64; 2],
}

/// The configuration space: the travel and the head's angle ranges; per joint a bound on how
/// far any point of the probe moves per unit of it (1 for the linear axes; for the head axes the
/// farthest probe point from the axis: the ball, `L1 + L2` out, or the head's own radius).
pub fn space(probe: &Probe, travel: &Travel) -> JointSpace {
    let head = probe.head();
    let r = head.reach() + head.ball_diameter / 2.0;
    JointSpace::new(
        vec![
            travel.x[0],
            travel.y[0],
            travel.z[0],
            head.a_range[0],
            head.b_range[0],
        ],
        vec![
            travel.x[1],
            travel.y[1],
            travel.z[1],
            head.a_range[1],
            head.b_range[1],
        ],
        vec![1.0, 1.0, 1.0, r, r.max(0.05)],
    )
}

/// The probe's clearance to the part and fixtures, less `margin`.
pub struct CmmValidity<'a> {
    /// The probe and the scene.
    pub probe: &'a Probe,
    /// Distance to keep (m).
    pub margin: f64,
}

/// Distances beyond this are not measured exactly (m): every clearance threshold compared with
/// [`StateValidity::clearance`] (the group start's 5 cm, RRT-MRNC's safety) must stay below it.
pub const CAP: f64 = 0.1;

impl StateValidity for CmmValidity<'_> {
    fn clearance(&self, q: &[f64]) -> f64 {
        let Ok(q): Result<CmmQ, _> = q.try_into() else {
            return f64::NAN;
        };
        self.probe.distance(&q, CAP + self.margin) - self.margin
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::part::Mp;
    use crate::scene::block as setup;
    use cellplan_geom::DVec3;
    use cellplan_kin::cmm::CmmHead;
    use cellplan_motion::plan::{PlanSettings, plan_leg};

    /// The configuration 5 mm off `mp` along its normal, the probe along `d`.
    fn approach(probe: &Probe, mp: &Mp, d: DVec3) -> CmmQ {
        let head = probe.head();
        let ball = mp.position + mp.normal * (head.ball_diameter / 2.0 + 0.005);
        head.inverse(ball, d, 0.0)[0]
    }

    #[test]
    fn a_path_from_the_deck_to_the_side_is_planned_and_clear_everywhere() {
        let (mps, probe) = setup();
        let travel = Travel {
            x: [-0.3, 0.7],
            y: [-0.4, 0.6],
            z: [0.0, 1.0],
        };
        let space = space(&probe, &travel);
        let validity = CmmValidity {
            probe: &probe,
            margin: 0.002,
        };
        let deck = &mps[0];
        let side = mps.iter().find(|m| m.name == "S4").unwrap();
        let start = approach(&probe, deck, -DVec3::Z);
        // The side y = 0 faces −Y: the probe tilted 75° toward +Y.
        let goal = approach(
            &probe,
            side,
            CmmHead::direction(75f64.to_radians(), 90f64.to_radians()),
        );
        assert!(validity.clearance(&start) > 0.0 && validity.clearance(&goal) > 0.0);
        // Straight across would cut through the block's edge.
        let mid: Vec<f64> = start.iter().zip(&goal).map(|(a, b)| 0.5 * (a + b)).collect();
        assert!(
            validity.clearance(&mid) <= 0.0,
            "the direct move must be blocked for the test to mean something"
        );
        let path = plan_leg(
            &space,
            &validity,
            &start,
            &goal,
            &PlanSettings {
                seed: 1,
                ..PlanSettings::default()
            },
        )
        .unwrap();
        assert!(!path.straight && path.waypoints.len() > 2);
        // Every millimetre (and every 1 mrad of the head) of the path is clear.
        for w in path.waypoints.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let lin = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
            let ang = (a[3] - b[3]).abs().max((a[4] - b[4]).abs());
            let steps = ((lin / 0.001).max(ang / 0.001)).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let t = k as f64 / steps as f64;
                let q: Vec<f64> = a.iter().zip(b.iter()).map(|(x, y)| x + t * (y - x)).collect();
                assert!(validity.clearance(&q) > 0.0, "contact at {q:?}");
            }
        }
    }
}
