//! Loading a cell file: parse, apply units, resolve paths, load robots and meshes, build the
//! collision world, and refuse anything inconsistent with an error that names file and line.
use crate::cell::{Cell, Object, Planning, Source};
use crate::io::read_bounded;
use crate::pose::pose_from_spec;
use crate::process::{Process, ProcessInput, Registry, key_span};
use crate::robot::{BodyFrame, Robot, RobotId, Scratch, Tool};
use crate::self_pairs::{SelfPairs, cached_self_pairs, geometry_key, non_adjacent_pairs};
use crate::spec::{CellSpec, PlanningSpec, PoseSpec, ShapeEntry};
use crate::tasks::read_tasks;
use crate::{InputError, error::line_of};
use cellplan_geom::{BodyContact, CollisionWorld, DVec3, GroupBody, MeshError, Pose, ShapeSpec, load_mesh};
use cellplan_kin::RobotModel;
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

mod robot;
use robot::robot;

/// Largest cell file read (bytes).
pub const MAX_CELL_FILE: u64 = 16 << 20;

/// How to load a cell.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Folder for cached self-collision pair lists (`None`: no cache).
    pub cache_dir: Option<PathBuf>,
    /// Random configurations sampled to find the self-collision pairs.
    pub self_pair_samples: usize,
    /// Seed of that sampling.
    pub seed: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            cache_dir: None,
            self_pair_samples: 10_000,
            seed: 0,
        }
    }
}

impl LoadOptions {
    /// The usual cache folder: `$CELLPLAN_CACHE_DIR`, else `$XDG_CACHE_HOME/cellplan`, else
    /// `$HOME/.cache/cellplan`.
    pub fn default_cache_dir() -> Option<PathBuf> {
        let env = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(PathBuf::from);
        env("CELLPLAN_CACHE_DIR")
            .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("cellplan")))
            .or_else(|| env("HOME").map(|d| d.join(".cache/cellplan")))
    }
}

/// Time in which a joint reaches full speed when no acceleration limit is given (s).
pub const DEFAULT_ACCELERATION_TIME: f64 = 0.25;

struct Ctx<'a> {
    path: &'a Path,
    dir: PathBuf,
    text: &'a str,
    to_m: f64,
    to_rad: f64,
}

impl Ctx<'_> {
    /// An error at `span` of the cell file, with a general hint that callers may replace.
    fn err(&self, span: Range<usize>, msg: impl Into<String>) -> InputError {
        InputError::at_span(self.path, self.text, span, msg)
            .hint("docs/cell-format.md describes every key of the cell file, its unit and default")
    }

    /// The span of `key = ...` inside `within` (see [`key_span`]).
    fn key_span(&self, within: &Range<usize>, key: &str) -> Range<usize> {
        key_span(self.text, within, key)
    }

    fn resolve(&self, rel: &str) -> PathBuf {
        self.dir.join(rel)
    }

    fn pose(&self, spec: &Spanned<PoseSpec>) -> Result<Pose, InputError> {
        pose_from_spec(spec.get_ref(), self.to_m, self.to_rad).map_err(|e| {
            self.err(spec.span(), e.to_string()).hint(
                "a pose is { xyz = [x, y, z] } plus at most one of rpy = [r, p, y], quat = [x, y, z, w], matrix = [[..], [..], [..]] (rows)",
            )
        })
    }
}

/// Loads and checks a cell file; its process is found in `registry` by `[process] kind`.
///
/// The steps: read and parse the file, find the process, read `[planning]`, the tools, the
/// static objects and the robots, put the robots' bodies into the collision world, read the
/// tasks and build the process, check that every robot stands clear at home, and find the
/// self-collision pairs.
pub fn load(path: &Path, registry: &Registry, opts: &LoadOptions) -> Result<Cell, InputError> {
    let (text, spec) = read_spec(path)?;
    let ctx = Ctx {
        path,
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        text: &text,
        to_m: spec.units.length.to_m(),
        to_rad: spec.units.angle.to_rad(),
    };

    let process_span = spec.process.span();
    let entry = registry.find(
        &spec.process.get_ref().kind,
        path,
        &text,
        ctx.key_span(&process_span, "kind"),
    )?;
    let planning = planning(&ctx, spec.planning.as_ref())?;
    let tools = tools(&ctx, &spec)?;
    let mut world = CollisionWorld::new();
    let objects = objects(&ctx, &spec, &mut world)?;
    let (mut robots, source) = robots(&ctx, &spec, &tools)?;
    add_robot_bodies(&mut world, &mut robots);
    exempt_robot_bases(&mut world, &robots);

    let tasks_path = ctx.resolve(&spec.tasks.get_ref().file);
    let tasks = read_tasks(&tasks_path, ctx.to_m, ctx.to_rad, entry.task_columns)?;
    let process: std::sync::Arc<dyn Process> = (entry.build)(&ProcessInput {
        path,
        text: &text,
        span: process_span,
        to_m: ctx.to_m,
        to_rad: ctx.to_rad,
        tasks: &tasks,
        tasks_path: &tasks_path,
    })?;

    check_homes(&ctx, &spec, &world, &robots, planning.clearance)?;
    let pending_cache = find_self_pairs(&mut world, &mut robots, opts);
    Ok(Cell {
        name: cell_name(&spec, path),
        path: path.to_path_buf(),
        units: spec.units,
        process,
        planning,
        robots,
        objects,
        tasks,
        world,
        tasks_path,
        source,
        pending_cache,
    })
}

/// The `[process] kind` of a cell file, read before anything else so that the binary can hand
/// cells whose machines are not robot arms (paper 004's gantries) to their own loader.
pub fn process_kind(path: &Path) -> Result<String, InputError> {
    #[derive(serde::Deserialize)]
    struct Head {
        process: Option<toml::Spanned<Kind>>,
    }
    #[derive(serde::Deserialize)]
    struct Kind {
        kind: Option<String>,
    }
    let text = read_bounded(path, MAX_CELL_FILE).map_err(|e| {
        InputError::new(path, format!("cannot read the cell file: {e}"))
            .hint("give the path of a cell TOML file, e.g. examples/autobody-4r/cell.toml")
    })?;
    let head: Head = toml::from_str(&text).map_err(|e| {
        InputError::at_span(
            path,
            &text,
            e.span().unwrap_or(0..0),
            format!("invalid cell file: {}", e.message().trim()),
        )
        .hint(parse_hint(&text, "docs/cell-format.md"))
    })?;
    let Some(process) = head.process else {
        return Err(InputError::new(path, "the cell file has no `[process]` table")
            .hint("add `[process]` with `kind = \"optical-inspection\"` or `kind = \"pcb-assembly\"` (docs/cell-format.md)"));
    };
    let span = process.span();
    process.into_inner().kind.ok_or_else(|| {
        InputError::at_span(path, &text, span, "`[process]` has no `kind`")
            .hint("add `kind = \"optical-inspection\"` or `kind = \"pcb-assembly\"` (docs/cell-format.md)")
    })
}

/// Reads the cell file (at most [`MAX_CELL_FILE`] bytes) and parses it as TOML.
fn read_spec(path: &Path) -> Result<(String, CellSpec), InputError> {
    read_cell_toml(path, "examples/autobody-4r/cell.toml", "docs/cell-format.md")
}

/// A cell file's text and its TOML read into `S` (any process's layout), at most 1 MiB; a
/// file that cannot be read or parsed is an error at its line, with `example` (a cell file to
/// point to) and `docs` (where the keys are listed) in the hints.
pub fn read_cell_toml<S: serde::de::DeserializeOwned>(
    path: &Path,
    example: &str,
    docs: &str,
) -> Result<(String, S), InputError> {
    let text = read_bounded(path, MAX_CELL_FILE).map_err(|e| {
        InputError::new(path, format!("cannot read the cell file: {e}"))
            .hint(format!("give the path of a cell TOML file, e.g. {example}"))
    })?;
    let spec: S = toml::from_str(&text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        InputError::at_span(
            path,
            &text,
            span,
            format!("invalid cell file: {}", e.message().trim()),
        )
        .hint(parse_hint(&text, docs))
    })?;
    Ok((text, spec))
}

/// What to do about a cell file that does not parse (`docs`: the page of its format): a file
/// that starts like JSON was most likely a plan given where the cell goes.
fn parse_hint(text: &str, docs: &str) -> String {
    if text.trim_start().starts_with('{') {
        "this file is JSON, not a cell file's TOML: is it a plan? Commands that take both take the plan first, then the cell (`cellplan verify PLAN CELL`)".to_string()
    } else {
        format!("{docs} lists every key and its type")
    }
}

/// Reads `[tools]`: each tool's TCP and shapes, by name.
fn tools(ctx: &Ctx, spec: &CellSpec) -> Result<BTreeMap<String, Tool>, InputError> {
    let mut tools = BTreeMap::new();
    for (name, tool) in &spec.tools {
        let tcp = ctx.pose(&tool.get_ref().tcp)?;
        let mut shapes = Vec::new();
        for entry in &tool.get_ref().shapes {
            shapes.push(shape(ctx, entry, tool.span(), &format!("tool `{name}`"))?);
        }
        tools.insert(
            name.clone(),
            Tool {
                name: name.clone(),
                tcp,
                shapes,
            },
        );
    }
    Ok(tools)
}

/// Reads `[[objects]]` (named, each name once) and adds each to `world` as a static body.
fn objects(ctx: &Ctx, spec: &CellSpec, world: &mut CollisionWorld) -> Result<Vec<Object>, InputError> {
    let mut objects: Vec<Object> = Vec::new();
    for entry in &spec.objects {
        let span = entry.span();
        let e = entry.get_ref();
        let name = e
            .name
            .clone()
            .ok_or_else(|| ctx.err(span.clone(), "an object needs a `name`"))?;
        if objects.iter().any(|o| o.name == name) {
            return Err(ctx.err(
                ctx.key_span(&span, "name"),
                format!("object name `{name}` is used twice"),
            ));
        }
        let (shape, local) = shape(ctx, e, span, &format!("object `{name}`"))?;
        let id = world.add_static(&name, &shape, local);
        objects.push(Object {
            name,
            shape,
            pose: local,
            id,
        });
    }
    Ok(objects)
}

/// Reads `[[robots]]` (at least one; URDF models shared by robots that name the same one), with
/// the cell file's text and the span of each robot's `base`.
fn robots(
    ctx: &Ctx,
    spec: &CellSpec,
    tools: &BTreeMap<String, Tool>,
) -> Result<(Vec<Robot>, Source), InputError> {
    let mut models: HashMap<String, Arc<RobotModel>> = HashMap::new();
    let mut robots: Vec<Robot> = Vec::new();
    let mut source = Source {
        text: ctx.text.to_string(),
        ..Source::default()
    };
    for entry in &spec.robots {
        let robot = robot(ctx, entry, RobotId(robots.len()), tools, &mut models, &robots)?;
        source.robot_base.push(entry.get_ref().base.span());
        robots.push(robot);
    }
    if robots.is_empty() {
        return Err(InputError::new(ctx.path, "the cell has no robots").hint("add a [[robots]] table"));
    }
    Ok((robots, source))
}

/// Adds each robot to `world` as a group: one body per collision shape (so that no hull spans
/// parts that are apart, such as a gripper's fingers), the links' shapes in chain order, then
/// the tool's. A body is named after the URDF link its shape belongs to (or `tool:NAME`), with
/// `#k` when that link has several shapes.
fn add_robot_bodies(world: &mut CollisionWorld, robots: &mut [Robot]) {
    for robot in robots {
        let tip = robot.model.chain.links.len().saturating_sub(1);
        let mut bodies = Vec::new();
        let mut frames = Vec::new();
        let mut links = Vec::new();
        let mut shapes_of = Vec::new();
        let mut push = |name: String, shape: &(ShapeSpec, Pose), frame: BodyFrame, link: usize| {
            bodies.push(GroupBody {
                name,
                shapes: vec![shape.clone()],
            });
            frames.push(frame);
            links.push(link);
            shapes_of.push(shape.clone());
        };
        for (i, shapes) in robot.model.collision.iter().enumerate() {
            let names = robot.model.collision_links.get(i);
            for (k, shape) in shapes.iter().enumerate() {
                let source = names
                    .and_then(|n| n.get(k))
                    .cloned()
                    .unwrap_or_else(|| robot.model.chain.links[i].name.clone());
                let siblings = names.map_or(0, |n| n.iter().filter(|m| **m == source).count());
                let nth = names.map_or(0, |n| n[..k].iter().filter(|m| **m == source).count());
                let name = if siblings > 1 {
                    format!("{source}#{nth}")
                } else {
                    source
                };
                push(name, shape, BodyFrame::Link(i), i);
            }
        }
        let several = robot.tool.shapes.len() > 1;
        for (k, shape) in robot.tool.shapes.iter().enumerate() {
            let name = if several {
                format!("tool:{}#{k}", robot.tool.name)
            } else {
                format!("tool:{}", robot.tool.name)
            };
            push(name, shape, BodyFrame::Tool, tip);
        }
        robot.group = world.add_group(&robot.name, bodies);
        robot.bodies = frames;
        robot.body_links = links;
        robot.body_shapes = shapes_of;
    }
}

/// Leaves each robot's base (the bodies before its first joint) out of the static checks: it
/// never moves, standing on its floor or pedestal.
fn exempt_robot_bases(world: &mut CollisionWorld, robots: &[Robot]) {
    for robot in robots {
        let chain = &robot.model.chain;
        let first_moving = chain
            .links
            .iter()
            .position(|l| l.joint.is_some())
            .unwrap_or(chain.links.len());
        let fixed: Vec<usize> = robot
            .bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| matches!(b, BodyFrame::Link(l) if *l < first_moving))
            .map(|(i, _)| i)
            .collect();
        world.set_static_exempt(robot.group, &fixed);
    }
}

/// Refuses a robot that does not stand clear at home: of the scene (by the clearance), of
/// itself (every non-adjacent pair) and of the other robots.
fn check_homes(
    ctx: &Ctx,
    spec: &CellSpec,
    world: &CollisionWorld,
    robots: &[Robot],
    clearance: f64,
) -> Result<(), InputError> {
    let mut home_poses: Vec<Vec<Pose>> = Vec::new();
    for (i, robot) in robots.iter().enumerate() {
        let mut scratch = Scratch::default();
        robot.body_poses(&robot.home, &mut scratch);
        let entry = &spec.robots[i];
        let home_span = entry.get_ref().home.as_ref().map_or(entry.span(), |h| h.span());
        let self_contact = non_adjacent_pairs(robot)
            .into_iter()
            .find(|&(a, b)| world.bodies_within(robot.group, a, b, &scratch.bodies, 0.0))
            .map(|(a, b)| BodyContact::SelfPair(a, b));
        if let Some(contact) = world
            .group_vs_static(robot.group, &scratch.bodies, clearance)
            .or(self_contact)
        {
            let what = describe_contact(world, robot, None, contact);
            return Err(ctx
                .err(home_span, format!("robot `{}` collides at its home configuration: {what}", robot.name))
                .hint("move the robot's `base` or change its `home` so that it stands clear (by the `[planning] clearance` from static objects)"));
        }
        for (j, other) in robots[..i].iter().enumerate() {
            if let Some(contact) =
                world.group_vs_group(robot.group, &scratch.bodies, other.group, &home_poses[j], 0.0)
            {
                let what = describe_contact(world, robot, Some(other), contact);
                return Err(ctx
                    .err(
                        entry.get_ref().base.span(),
                        format!(
                            "robots `{}` and `{}` collide at home: {what}",
                            robot.name, other.name
                        ),
                    )
                    .hint("place the robots further apart or change their `home`"));
            }
        }
        home_poses.push(scratch.bodies.clone());
    }
    Ok(())
}

/// Sets each robot's self-collision pairs, sampled once per distinct robot geometry (or read
/// from the cache), and the tables of its close pairs (built once per geometry); returns the
/// cache entries still to be written.
fn find_self_pairs(
    world: &mut CollisionWorld,
    robots: &mut [Robot],
    opts: &LoadOptions,
) -> Vec<crate::self_pairs::PendingCache> {
    let mut sampled: HashMap<u64, SelfPairs> = HashMap::new();
    let mut tables_by_key: HashMap<u64, std::sync::Arc<cellplan_motion::arm::PairTables>> = HashMap::new();
    let mut pending_cache = Vec::new();
    for robot in robots {
        let key = geometry_key(robot, opts.self_pair_samples, opts.seed);
        let pairs = match sampled.get(&key) {
            Some(p) => p.clone(),
            None => {
                let (p, pending) = cached_self_pairs(
                    robot,
                    world,
                    opts.self_pair_samples,
                    opts.seed,
                    opts.cache_dir.as_deref(),
                );
                pending_cache.extend(pending);
                sampled.insert(key, p.clone());
                p
            }
        };
        world.set_self_pairs(robot.group, pairs.pairs.clone());
        robot.self_pairs = pairs.pairs;
        // The tables depend on the robot's geometry alone (the same key as its pairs).
        let tables = match tables_by_key.get(&key) {
            Some(t) => std::sync::Arc::clone(t),
            None => {
                let t = std::sync::Arc::new(cellplan_motion::arm::PairTables::build(&robot.arm(&*world)));
                tables_by_key.insert(key, std::sync::Arc::clone(&t));
                t
            }
        };
        robot.pair_tables = tables;
    }
    pending_cache
}

/// The cell's `name`, else the name of the folder holding the cell file, else `cell`.
fn cell_name(spec: &CellSpec, path: &Path) -> String {
    spec.name.clone().unwrap_or_else(|| {
        path.canonicalize()
            .ok()
            .and_then(|p| {
                p.parent()
                    .and_then(|d| d.file_name())
                    .map(|n| n.to_string_lossy().into_owned())
            })
            .unwrap_or_else(|| "cell".into())
    })
}

fn describe_contact(world: &CollisionWorld, robot: &Robot, other: Option<&Robot>, c: BodyContact) -> String {
    let body = |r: &Robot, i: usize| world.body_name(r.group, i).to_string();
    match c {
        BodyContact::Static { body: b, object } => {
            format!(
                "`{}` touches object `{}`",
                body(robot, b),
                world.static_name(object)
            )
        }
        BodyContact::SelfPair(a, b) => format!("`{}` touches `{}`", body(robot, a), body(robot, b)),
        BodyContact::Pair(a, b) => match other {
            Some(o) => format!("`{}` touches `{}` of `{}`", body(robot, a), body(o, b), o.name),
            None => format!("bodies {a} and {b}"),
        },
    }
}

fn positive(ctx: &Ctx, span: &Range<usize>, key: &str, v: f64) -> Result<f64, InputError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ctx.err(
            ctx.key_span(span, key),
            format!("`{key}` must be positive, not {}", crate::shown(v)),
        ))
    }
}

/// A shape's dimension `v` (file units): positive, and at most
/// [`crate::tasks::MAX_COORDINATE`] metres.
fn size(ctx: &Ctx, span: &Range<usize>, key: &str, v: f64) -> Result<f64, InputError> {
    let v = positive(ctx, span, key, v)?;
    if v * ctx.to_m > crate::tasks::MAX_COORDINATE {
        return Err(ctx
            .err(
                ctx.key_span(span, key),
                format!(
                    "`{key}` of {} m is beyond {} m",
                    crate::shown(v * ctx.to_m),
                    crate::tasks::MAX_COORDINATE
                ),
            )
            .hint("shape sizes are in the file's `units.length`"));
    }
    Ok(v)
}

/// Reads `[planning]` (defaults where absent).
fn planning(ctx: &Ctx, spec: Option<&Spanned<PlanningSpec>>) -> Result<Planning, InputError> {
    let mut out = Planning::default();
    let Some(spec) = spec else { return Ok(out) };
    let span = spec.span();
    let p = spec.get_ref();
    if let Some(v) = p.clearance {
        if !(v.is_finite() && v >= 0.0) {
            return Err(ctx.err(
                ctx.key_span(&span, "clearance"),
                format!("`clearance` must be ≥ 0, not {}", crate::shown(v)),
            ));
        }
        out.clearance = v * ctx.to_m;
        if out.clearance > MAX_CLEARANCE {
            return Err(ctx
                .err(ctx.key_span(&span, "clearance"), format!("`clearance` of {} m is beyond {MAX_CLEARANCE} m", crate::shown(out.clearance)))
                .hint("the clearance is the gap kept between robots and objects, a few millimetres to centimetres; check `units.length`"));
        }
    }
    if let Some(v) = p.task_cap {
        if v == 0 || v > MAX_TASK_CAP {
            return Err(ctx
                .err(
                    ctx.key_span(&span, "task_cap"),
                    format!("`task_cap` must be between 1 and {MAX_TASK_CAP}, not {v}"),
                )
                .hint("φ is the most tasks one robot may be given"));
        }
        out.task_cap = v;
    }
    if let Some(v) = p.balance_limit {
        let v = positive(ctx, &span, "balance_limit", v)?;
        if v > MAX_BALANCE_LIMIT {
            return Err(ctx
                .err(
                    ctx.key_span(&span, "balance_limit"),
                    format!("`balance_limit` of {} s is beyond {MAX_BALANCE_LIMIT} s", crate::shown(v)),
                )
                .hint("γ is the most the robots' cycle times may differ, in seconds; leave `balance_limit` out for no limit"));
        }
        out.balance_limit = Some(v);
    }
    Ok(out)
}

/// Largest `[planning] clearance` (m).
pub const MAX_CLEARANCE: f64 = 1.0;
/// Largest `[planning] balance_limit` (s): a day.
pub const MAX_BALANCE_LIMIT: f64 = 86_400.0;
/// Largest `[planning] task_cap`.
pub const MAX_TASK_CAP: usize = 100_000;

fn shape(
    ctx: &Ctx,
    e: &ShapeEntry,
    span: Range<usize>,
    owner: &str,
) -> Result<(ShapeSpec, Pose), InputError> {
    let given = [
        e.box_size.is_some(),
        e.cylinder.is_some(),
        e.sphere.is_some(),
        e.mesh.is_some(),
    ]
    .iter()
    .filter(|&&b| b)
    .count();
    if given != 1 {
        return Err(ctx.err(
            span,
            format!("{owner} needs exactly one of `box`, `cylinder`, `sphere`, `mesh` (found {given})"),
        ));
    }
    let pose = ctx.pose(&e.pose)?;
    let m = ctx.to_m;
    let shape = if let Some(b) = e.box_size {
        for v in b {
            size(ctx, &span, "box", v)?;
        }
        ShapeSpec::Box {
            half_extents: DVec3::from_array(b) * (m / 2.0),
        }
    } else if let Some(c) = e.cylinder {
        ShapeSpec::Cylinder {
            radius: size(ctx, &span, "cylinder", c.radius)? * m,
            half_height: size(ctx, &span, "cylinder", c.length)? * m / 2.0,
        }
    } else if let Some(r) = e.sphere {
        ShapeSpec::Sphere {
            radius: size(ctx, &span, "sphere", r)? * m,
        }
    } else {
        let rel = e.mesh.as_deref().unwrap_or_default();
        let file = ctx.resolve(rel);
        let mesh = load_mesh(&file).map_err(|err| match err {
            MeshError::Parse { path, line, message } => {
                InputError::at_line(&path, line, message).hint(format!(
                    "the mesh of {owner} ({}:{}); fix or re-export the file",
                    ctx.path.display(),
                    line_of(ctx.text, span.start)
                ))
            }
            other => ctx
                .err(ctx.key_span(&span, "mesh"), format!("{owner}: {other}"))
                .hint("mesh paths are relative to the cell file; STL (binary or ASCII) and OBJ are read"),
        })?;
        let factor = e.mesh_units.map_or(m, |u| u.to_m());
        ShapeSpec::Mesh(Arc::new(mesh.scaled(factor)))
    };
    Ok((shape, pose))
}

/// One shape entry (`box`, `cylinder`, `sphere` or `mesh`, with its pose) of another process's
/// cell file at `path` (text `text`, the entry at `span`): the same rules and errors as the
/// objects of an arm cell. Mesh paths are relative to the cell file; `to_m` and `to_rad` are the
/// file's units.
pub fn shape_entry(
    path: &Path,
    text: &str,
    entry: &ShapeEntry,
    span: Range<usize>,
    owner: &str,
    to_m: f64,
    to_rad: f64,
) -> Result<(ShapeSpec, Pose), InputError> {
    let ctx = Ctx {
        path,
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        text,
        to_m,
        to_rad,
    };
    shape(&ctx, entry, span, owner)
}
