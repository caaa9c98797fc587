//! A robot of the cell file: its URDF model, IK solver, home, tool, limits and reach, each
//! value checked with an error that names the file and line.
use super::{Ctx, DEFAULT_ACCELERATION_TIME};
use crate::io::read_bounded;
use crate::robot::{IkKind, Robot, RobotId, Tool};
use crate::spec::{OpwSpec, RobotSpec};
use crate::{InputError, error::line_of, shown};
use cellplan_geom::Pose;
use cellplan_kin::{
    Chain, DlsIk, DlsParams, IkSolver, JointKind, KinError, OpwIk, OpwParameters, ParallelIk, RobotModel,
    TrackIk, load_urdf,
};
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;
use toml::Spanned;

fn kin_error(ctx: &Ctx, span: Range<usize>, robot: &str, e: KinError) -> InputError {
    let at = format!(
        "robot `{robot}` ({}:{})",
        ctx.path.display(),
        line_of(ctx.text, span.start)
    );
    match e {
        KinError::Urdf {
            path,
            line,
            message,
            hint,
        } => InputError::at_line(&path, line, message).hint(format!("{hint} (used by {at})")),
        KinError::Mesh {
            urdf,
            line,
            link,
            source,
        } => InputError::at_line(&urdf, line, format!("link `{link}`: {source}"))
            .hint(format!("check the mesh file and the `packages` of {at}")),
        KinError::Io { path, source } => InputError::new(&path, format!("cannot read: {source}"))
            .hint(format!("check the path given for {at}")),
        KinError::Opw { path, line, message } => {
            InputError::at_line(&path, line, message).hint(format!("check the `opw` parameters of {at}"))
        }
    }
}

/// Reads one `[[robots]]` entry in named steps: its name (once in the cell), URDF model, inverse
/// kinematics, base, home, tool, joint velocity and acceleration limits, and reach.
pub(super) fn robot(
    ctx: &Ctx,
    entry: &Spanned<RobotSpec>,
    id: RobotId,
    tools: &BTreeMap<String, Tool>,
    models: &mut HashMap<String, Arc<RobotModel>>,
    earlier: &[Robot],
) -> Result<Robot, InputError> {
    let span = entry.span();
    let r = entry.get_ref();
    if earlier.iter().any(|o| o.name == r.name) {
        return Err(ctx.err(
            ctx.key_span(&span, "name"),
            format!("robot name `{}` is used twice", r.name),
        ));
    }
    let model = robot_model(ctx, entry, models)?;
    let chain = &model.chain;
    let (ik, ik_kind) = ik_solver(ctx, entry, &model)?;
    let base = ctx.pose(&r.base)?;
    let home = home(ctx, r, chain)?;
    let tool = robot_tool(ctx, r, tools)?;
    let max_velocity = max_velocity(ctx, entry, chain)?;
    let max_acceleration = match joint_limits(ctx, r, chain, &r.max_acceleration, true)? {
        Some(a) => a,
        None => max_velocity
            .iter()
            .map(|v| v / DEFAULT_ACCELERATION_TIME)
            .collect(),
    };
    let reach = reach(chain, &tool);
    Ok(Robot {
        id,
        name: r.name.clone(),
        model,
        base,
        home,
        tool,
        ik,
        ik_kind,
        max_velocity,
        max_acceleration,
        group: cellplan_geom::GroupId(u32::MAX),
        bodies: Vec::new(),
        body_links: Vec::new(),
        body_shapes: Vec::new(),
        self_pairs: Vec::new(),
        pair_tables: Default::default(),
        reach,
    })
}

/// The robot's URDF model (loaded once per file, packages and tip, and shared through
/// `models`); refuses a missing file and a chain without a movable joint.
fn robot_model(
    ctx: &Ctx,
    entry: &Spanned<RobotSpec>,
    models: &mut HashMap<String, Arc<RobotModel>>,
) -> Result<Arc<RobotModel>, InputError> {
    let r = entry.get_ref();
    let urdf = ctx.resolve(r.urdf.get_ref());
    let packages: BTreeMap<String, PathBuf> = r
        .packages
        .iter()
        .map(|(k, v)| (k.clone(), ctx.resolve(v)))
        .collect();
    let key = format!("{}|{:?}|{:?}", urdf.display(), packages, r.tip);
    let model = match models.get(&key) {
        Some(m) => m.clone(),
        None => {
            if !urdf.exists() {
                return Err(ctx
                    .err(
                        r.urdf.span(),
                        format!("URDF file {} does not exist", urdf.display()),
                    )
                    .hint("`urdf` is relative to the cell file"));
            }
            let m = Arc::new(
                load_urdf(&urdf, &packages, r.tip.as_deref())
                    .map_err(|e| kin_error(ctx, entry.span(), &r.name, e))?,
            );
            models.insert(key, m.clone());
            m
        }
    };
    if model.chain.dof() == 0 {
        return Err(ctx
            .err(
                r.urdf.span(),
                format!("the chain of robot `{}` has no movable joint", r.name),
            )
            .hint(
                "check the URDF and the robot's `tip`: the chain runs from the URDF root to the tip link",
            ));
    }
    Ok(model)
}

/// Factor from file units to SI for joint `j`: the length unit for a prismatic joint, else the
/// angle unit.
fn joint_scale(ctx: &Ctx, chain: &Chain, j: usize) -> f64 {
    match chain.joints[j].kind {
        JointKind::Prismatic => ctx.to_m,
        _ => ctx.to_rad,
    }
}

/// The robot's inverse kinematics: analytic OPW with the parameters `opw` gives (a 6-joint arm
/// only); without them, OPW with the parameters read off the URDF where the chain is an
/// ortho-parallel arm with a spherical wrist (checked against the chain, see
/// [`OpwIk::derive`]), the closed form of three parallel axes where it is a Universal Robots
/// kind of arm ([`ParallelIk::derive`]), sampled track positions with the arm's closed form
/// where it is such an arm on a linear track ([`TrackIk::derive`]), else the numeric solver.
fn ik_solver(
    ctx: &Ctx,
    entry: &Spanned<RobotSpec>,
    model: &Arc<RobotModel>,
) -> Result<(Arc<dyn IkSolver>, IkKind), InputError> {
    let r = entry.get_ref();
    let dof = model.chain.dof();
    let Some(opw) = &r.opw else {
        if let Some(derived) = OpwIk::derive(&model.chain) {
            return Ok((Arc::new(derived), IkKind::OpwDerived));
        }
        if let Some(parallel) = ParallelIk::derive(&model.chain) {
            return Ok((Arc::new(parallel), IkKind::Parallel));
        }
        if let Some(track) = TrackIk::derive(&model.chain) {
            return Ok((Arc::new(track), IkKind::Track));
        }
        return Ok((
            Arc::new(DlsIk::new(&model.chain, DlsParams::default())),
            IkKind::Numeric,
        ));
    };
    let params = opw_parameters(ctx, opw)?;
    if dof != 6 {
        return Err(ctx
            .err(
                opw.span(),
                format!(
                    "OPW needs a 6-joint arm; the chain of `{}` has {dof} joints",
                    r.name
                ),
            )
            .hint("remove `opw` to use the numeric IK"));
    }
    let solver = OpwIk::for_robot(model, params).map_err(|e| match e {
        KinError::Opw { message, .. } => ctx
            .err(opw.span(), format!("robot `{}`: {message}", r.name))
            .hint("the OPW parameters must describe this URDF (same robot model and tip link)"),
        other => kin_error(ctx, entry.span(), &r.name, other),
    })?;
    Ok((Arc::new(solver), IkKind::Opw))
}

/// The OPW parameters: read from a ROS-Industrial yaml file, or inline in file units.
fn opw_parameters(ctx: &Ctx, opw: &Spanned<OpwSpec>) -> Result<OpwParameters, InputError> {
    Ok(match opw.get_ref() {
        OpwSpec::File(rel) => {
            let file = ctx.resolve(rel);
            let text = read_bounded(&file, 1 << 20).map_err(|e| {
                ctx.err(
                    opw.span(),
                    format!("cannot read OPW parameters {}: {e}", file.display()),
                )
                .hint("`opw` is a path relative to the cell file, or an inline table")
            })?;
            OpwParameters::from_ros_yaml(&text).map_err(|(line, m)| {
                InputError::at_line(&file, line, m).hint("expected a ROS-Industrial opw_parameters yaml")
            })?
        }
        OpwSpec::Inline(p) => OpwParameters {
            a1: p.a1 * ctx.to_m,
            a2: p.a2 * ctx.to_m,
            b: p.b * ctx.to_m,
            c1: p.c1 * ctx.to_m,
            c2: p.c2 * ctx.to_m,
            c3: p.c3 * ctx.to_m,
            c4: p.c4 * ctx.to_m,
            offsets: p.offsets.map(|o| o * ctx.to_rad),
            sign_corrections: p.sign_corrections,
        },
    })
}

/// The home configuration: given (one value per joint, within limits), else zero where that is
/// within limits, else mid-range.
fn home(ctx: &Ctx, r: &RobotSpec, chain: &Chain) -> Result<Vec<f64>, InputError> {
    let dof = chain.dof();
    let Some(h) = &r.home else {
        return Ok(chain
            .joints
            .iter()
            .map(|j| {
                if j.lower <= 0.0 && 0.0 <= j.upper {
                    0.0
                } else {
                    (j.lower + j.upper) / 2.0
                }
            })
            .collect());
    };
    if h.get_ref().len() != dof {
        return Err(ctx.err(
            h.span(),
            format!(
                "`home` has {} values but `{}` has {dof} joints",
                h.get_ref().len(),
                r.name
            ),
        ));
    }
    let q: Vec<f64> = h
        .get_ref()
        .iter()
        .enumerate()
        .map(|(j, v)| v * joint_scale(ctx, chain, j))
        .collect();
    for (j, joint) in chain.joints.iter().enumerate() {
        if !(joint.lower - 1e-9..=joint.upper + 1e-9).contains(&q[j]) {
            return Err(ctx
                .err(
                    h.span(),
                    format!("`home` puts joint `{}` outside its limits", joint.name),
                )
                .hint(format!(
                    "its range is [{:.4}, {:.4}] in file units",
                    joint.lower / joint_scale(ctx, chain, j),
                    joint.upper / joint_scale(ctx, chain, j)
                )));
        }
    }
    Ok(q)
}

/// The robot's tool from `[tools]` by name, else the bare flange.
fn robot_tool(ctx: &Ctx, r: &RobotSpec, tools: &BTreeMap<String, Tool>) -> Result<Tool, InputError> {
    let Some(name) = &r.tool else {
        return Ok(Tool {
            name: "flange".into(),
            tcp: Pose::IDENTITY,
            shapes: Vec::new(),
        });
    };
    tools.get(name.get_ref()).cloned().ok_or_else(|| {
        let known: Vec<&str> = tools.keys().map(String::as_str).collect();
        ctx.err(name.span(), format!("no tool named `{}`", name.get_ref()))
            .hint(format!(
                "tools defined under [tools]: {}",
                if known.is_empty() {
                    "none".into()
                } else {
                    known.join(", ")
                }
            ))
    })
}

/// Per-joint limits given under `max_acceleration` (with `acceleration`) or `max_velocity`
/// (one positive value per joint, in file units, at most [`MAX_JOINT_ACCELERATION`] or
/// [`MAX_JOINT_SPEED`] in SI), in SI.
fn joint_limits(
    ctx: &Ctx,
    r: &RobotSpec,
    chain: &Chain,
    given: &Option<Spanned<Vec<f64>>>,
    acceleration: bool,
) -> Result<Option<Vec<f64>>, InputError> {
    let (key, most) = if acceleration {
        ("max_acceleration", MAX_JOINT_ACCELERATION)
    } else {
        ("max_velocity", MAX_JOINT_SPEED)
    };
    let dof = chain.dof();
    let Some(v) = given else { return Ok(None) };
    if v.get_ref().len() != dof {
        return Err(ctx.err(
            v.span(),
            format!(
                "`{key}` has {} values but `{}` has {dof} joints",
                v.get_ref().len(),
                r.name
            ),
        ));
    }
    v.get_ref()
        .iter()
        .enumerate()
        .map(|(j, &x)| {
            if !(x.is_finite() && x > 0.0) {
                return Err(ctx.err(v.span(), format!("`{key}` values must be positive")));
            }
            let si = x * joint_scale(ctx, chain, j);
            if si > most {
                let unit = si_unit(chain, j, acceleration);
                return Err(ctx
                    .err(
                        v.span(),
                        format!(
                            "`{key}` of joint `{}`, {}, is {si:.3e} {unit}: beyond {} {unit}",
                            chain.joints[j].name,
                            shown(x),
                            shown(most)
                        ),
                    )
                    .hint("check the values and the cell's units (`units.angle`, `units.length`)"));
            }
            Ok(si)
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// Fastest joint a robot may have (rad/s, or m/s for a prismatic joint): beyond, a limit is
/// refused as a mistake (the fastest wrists turn at about 35 rad/s). The verifier samples the
/// timeline at its time step, which means something only at speeds of this order.
pub const MAX_JOINT_SPEED: f64 = 100.0;

/// Largest joint acceleration a robot may have (rad/s², or m/s²), as [`MAX_JOINT_SPEED`].
pub const MAX_JOINT_ACCELERATION: f64 = 10_000.0;

/// The SI unit of joint `j`'s speed (or acceleration).
fn si_unit(chain: &Chain, j: usize, acceleration: bool) -> &'static str {
    match (chain.joints[j].kind, acceleration) {
        (JointKind::Prismatic, false) => "m/s",
        (JointKind::Prismatic, true) => "m/s²",
        (_, false) => "rad/s",
        (_, true) => "rad/s²",
    }
}

/// Joint velocity limits: `max_velocity`, else the URDF's (refused where a joint has none).
fn max_velocity(ctx: &Ctx, entry: &Spanned<RobotSpec>, chain: &Chain) -> Result<Vec<f64>, InputError> {
    let r = entry.get_ref();
    if let Some(v) = joint_limits(ctx, r, chain, &r.max_velocity, false)? {
        return Ok(v);
    }
    if let Some(j) = chain
        .joints
        .iter()
        .find(|j| !(j.max_velocity.is_finite() && j.max_velocity > 0.0))
    {
        return Err(ctx
            .err(
                ctx.key_span(&entry.span(), "urdf"),
                format!("joint `{}` has no velocity limit in the URDF", j.name),
            )
            .hint("give `max_velocity` for the robot in the cell file"));
    }
    if let Some((j, joint)) = chain
        .joints
        .iter()
        .enumerate()
        .find(|(_, j)| j.max_velocity > MAX_JOINT_SPEED)
    {
        let unit = si_unit(chain, j, false);
        return Err(ctx
            .err(
                ctx.key_span(&entry.span(), "urdf"),
                format!(
                    "joint `{}` has a velocity limit of {} {unit} in the URDF, beyond {} {unit}",
                    joint.name,
                    shown(joint.max_velocity),
                    shown(MAX_JOINT_SPEED)
                ),
            )
            .hint("fix the joint's <limit velocity> (rad/s, m/s for a prismatic joint), or give `max_velocity` for the robot in the cell file"));
    }
    Ok(chain.joints.iter().map(|j| j.max_velocity).collect())
}

/// Upper bound of the TCP's distance from the base: link offsets, prismatic strokes, TCP.
fn reach(chain: &Chain, tool: &Tool) -> f64 {
    chain
        .links
        .iter()
        .map(|l| l.origin.translation.length())
        .sum::<f64>()
        + chain
            .joints
            .iter()
            .filter(|j| j.kind == JointKind::Prismatic)
            .map(|j| j.lower.abs().max(j.upper.abs()))
            .sum::<f64>()
        + tool.tcp.translation.length()
}
