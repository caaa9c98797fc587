//! A loaded stud-weld cell as the planner and the verifier use it: the one robot, its
//! dynamics (URDF inertials, the gun lumped into the tip link, gravity in the base frame), its
//! limits, and the process parameters.
use crate::process::StudWeld;
use cellplan_geom::DVec3;
use cellplan_kin::dynamics::{Dynamics, LinkInertia};
use cellplan_model::{Cell, InputError, Robot};

/// The robot and process of a stud-weld cell, checked.
pub struct WeldCell<'a> {
    /// The cell.
    pub cell: &'a Cell,
    /// Its robot.
    pub robot: &'a Robot,
    /// The process.
    pub process: &'a StudWeld,
    /// The robot's dynamics with the gun.
    pub dynamics: Dynamics,
    /// Joint limits.
    pub q_bounds: Vec<[f64; 2]>,
    /// Joint speed limits (rad/s).
    pub v_max: Vec<f64>,
}

/// The stud-weld process of a cell, if it is one.
pub fn process_of(cell: &Cell) -> Option<&StudWeld> {
    cell.process.as_any().downcast_ref()
}

/// The dynamics of `robot` carrying a gun of `mass` (kg) at `com` (tip-link frame, m), with
/// gravity along −z of the world expressed in the robot's root frame. Every link a joint moves
/// must have a URDF `<inertial>`: the error names the first that has none.
pub fn robot_dynamics(robot: &Robot, mass: f64, com: DVec3) -> Result<Dynamics, String> {
    let model = &robot.model;
    let chain = &model.chain;
    let joints_to = chain.joints_to();
    // A link moved by a joint that carries nothing, while a later link does, is a URDF whose
    // inertials were left out; massless frames at the end (flange, tool0) are normal.
    let first_moving = chain.links.iter().position(|l| l.joint.is_some());
    if let Some(first) = first_moving {
        for (i, l) in chain.links.iter().enumerate().skip(first) {
            let moved = joints_to.get(i).copied().unwrap_or(0) > 0;
            if moved && l.joint.is_some() && model.inertia.get(i).copied().flatten().is_none() {
                return Err(format!(
                    "link `{}` of `{}` has no <inertial> (mass, centre of mass, inertia): the stud-weld process needs the robot's dynamics",
                    l.name,
                    model.path.display()
                ));
            }
        }
    }
    let mut inertia = model.inertia.clone();
    if mass > 0.0
        && let Some(tip) = inertia.last_mut()
    {
        let gun = LinkInertia {
            mass,
            com,
            inertia: glam::DMat3::ZERO,
        };
        *tip = Some(tip.unwrap_or(LinkInertia::ZERO).combined(&gun));
    }
    let mut d = Dynamics::new(chain, &inertia);
    d.gravity = robot.base.rotation.inverse() * DVec3::new(0.0, 0.0, -9.81);
    Ok(d)
}

impl<'a> WeldCell<'a> {
    /// Checks that the cell is a stud-weld cell with one robot whose joints have torque limits
    /// and whose links have inertials.
    #[allow(clippy::result_large_err)]
    pub fn new(cell: &'a Cell) -> Result<Self, InputError> {
        let process = process_of(cell).ok_or_else(|| {
            InputError::new(
                &cell.path,
                "not a stud-weld cell (`[process] kind = \"stud-weld\"`)",
            )
        })?;
        let [robot] = cell.robots.as_slice() else {
            return Err(InputError::new(
                &cell.path,
                format!(
                    "a stud-weld cell has one robot, this one has {}",
                    cell.robots.len()
                ),
            )
            .hint("paper 002's station: one robot welds every stud"));
        };
        let dof = robot.dof();
        if process.max_torque.len() != dof {
            return Err(InputError::at_line(
                &cell.path,
                process.max_torque_line,
                format!(
                    "`max_torque` gives {} values, robot `{}` has {dof} joints",
                    process.max_torque.len(),
                    robot.name
                ),
            )
            .hint("one torque limit (N·m) per joint, in chain order"));
        }
        let dynamics = robot_dynamics(robot, process.gun_mass, process.gun_com).map_err(|m| {
            InputError::new(&robot.model.path, m)
                .hint("give every moving link an <inertial>, or use a URDF that has them")
        })?;
        let q_bounds = robot
            .model
            .chain
            .joints
            .iter()
            .map(|j| [j.lower, j.upper])
            .collect();
        Ok(WeldCell {
            cell,
            robot,
            process,
            dynamics,
            q_bounds,
            v_max: robot.max_velocity.clone(),
        })
    }
}
