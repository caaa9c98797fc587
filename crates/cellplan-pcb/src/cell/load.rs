//! Reading and checking the cell file: the TOML as written, units applied, every value in range,
//! the board read and its components selected, and what the machine must be able to reach.
use super::*;
use crate::board::{Mount, Selection, Side};
use cellplan_model::InputError;
use cellplan_model::spec::LengthUnit;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    name: Option<String>,
    #[serde(default)]
    units: Units,
    process: Spanned<ProcessSpec>,
    robots: Vec<Spanned<RobotSpec>>,
    feeders: Vec<Spanned<FeederSpec>>,
    table: Spanned<TableSpec>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Units {
    #[serde(default = "mm")]
    length: LengthUnit,
    #[allow(dead_code)]
    angle: Option<String>,
}

fn mm() -> LengthUnit {
    LengthUnit::Mm
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProcessSpec {
    #[allow(dead_code)]
    kind: String,
    board: Spanned<String>,
    #[serde(default)]
    side: Option<Spanned<String>>,
    #[serde(default)]
    mounts: Option<Spanned<Vec<String>>>,
    #[serde(default)]
    components: Option<Spanned<Vec<String>>>,
    #[serde(default)]
    configuration: Option<Configuration>,
    #[serde(default)]
    motion: Option<MotionModel>,
    pick_time: Option<Spanned<f64>>,
    place_time: Option<Spanned<f64>>,
    safety_gap: Option<Spanned<f64>>,
    collision_avoidance: Option<bool>,
    #[serde(default)]
    bins: Vec<Spanned<BinSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BinSpec {
    feeder: String,
    bin: usize,
    footprint: String,
    value: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotSpec {
    name: String,
    speed: Option<f64>,
    acceleration: Option<f64>,
    home: [f64; 2],
    x: [f64; 2],
    y: [f64; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FeederSpec {
    name: String,
    x: f64,
    travel: [f64; 2],
    home: f64,
    bins: usize,
    pitch: f64,
    speed: Option<f64>,
    acceleration: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TableSpec {
    x: [f64; 2],
    y: [f64; 2],
    home: [f64; 2],
    speed: Option<f64>,
    acceleration: Option<f64>,
}

/// Paper 004 §3.3's speeds (m/s).
pub const ROBOT_SPEED: f64 = 2.0;
/// Table speed (m/s).
pub const TABLE_SPEED: f64 = 0.5;
/// Feeder speed (m/s).
pub const FEEDER_SPEED: f64 = 1.0;
/// Acceleration where none is given, for the trapezoid model (m/s²).
pub const DEFAULT_ACCELERATION: f64 = 10.0;

struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
    to_m: f64,
}

impl Ctx<'_> {
    fn err(&self, span: Range<usize>, msg: impl Into<String>) -> InputError {
        InputError::at_span(self.path, self.text, span, msg)
            .hint("docs/cell-format.md (PCB assembly) lists every key, its unit and default")
    }

    fn key(&self, within: &Range<usize>, key: &str) -> Range<usize> {
        cellplan_model::process::key_span(self.text, within, key)
    }

    fn drive(
        &self,
        span: &Range<usize>,
        speed: Option<f64>,
        acc: Option<f64>,
        default: f64,
    ) -> Result<Drive, InputError> {
        let speed = match speed {
            None => default,
            Some(v) if v.is_finite() && v > 0.0 && v * self.to_m <= 100.0 => v * self.to_m,
            Some(v) => {
                return Err(self
                    .err(
                        self.key(span, "speed"),
                        format!(
                            "speed {} must be above 0 and at most 100 m/s",
                            cellplan_model::shown(v)
                        ),
                    )
                    .hint("speeds are in length units per second (mm/s with units.length = \"mm\")"));
            }
        };
        let acceleration = match acc {
            None => DEFAULT_ACCELERATION,
            Some(a) if a.is_finite() && a > 0.0 && a * self.to_m <= 1e4 => a * self.to_m,
            Some(a) => {
                return Err(self.err(
                    self.key(span, "acceleration"),
                    format!("acceleration {a} must be above 0 and at most 10,000 m/s²"),
                ));
            }
        };
        Ok(Drive { speed, acceleration })
    }

    fn range(&self, span: &Range<usize>, key: &str, r: [f64; 2]) -> Result<[f64; 2], InputError> {
        let ok = r.iter().all(|v| v.is_finite() && v.abs() * self.to_m <= 100.0) && r[0] <= r[1];
        if !ok {
            return Err(self.err(
                self.key(span, key),
                format!(
                    "`{key}` = [{}, {}] must be two finite numbers, low ≤ high, within 100 m",
                    r[0], r[1]
                ),
            ));
        }
        Ok([r[0] * self.to_m, r[1] * self.to_m])
    }

    fn length(&self, span: &Range<usize>, key: &str, v: f64) -> Result<f64, InputError> {
        if !(v.is_finite() && v.abs() * self.to_m <= 100.0) {
            return Err(self.err(
                self.key(span, key),
                format!(
                    "`{key}` = {} must be a finite length within 100 m",
                    cellplan_model::shown(v)
                ),
            ));
        }
        Ok(v * self.to_m)
    }

    fn seconds(&self, v: Option<&Spanned<f64>>, default: f64, key: &str) -> Result<f64, InputError> {
        match v {
            None => Ok(default),
            Some(s) if s.get_ref().is_finite() && (0.0..=3600.0).contains(s.get_ref()) => Ok(*s.get_ref()),
            Some(s) => Err(self.err(
                s.span(),
                format!("`{key}` = {} must be between 0 and 3600 s", s.get_ref()),
            )),
        }
    }
}

/// Loads a PCB-assembly cell file and its board.
pub fn load(path: &Path) -> Result<PcbCell, InputError> {
    let (text, spec): (String, Spec) = cellplan_model::load::read_cell_toml(
        path,
        "examples/pcb-bitsy-1r/cell.toml",
        "docs/cell-format.md (PCB assembly)",
    )?;
    let ctx = Ctx {
        path,
        text: &text,
        to_m: spec.units.length.to_m(),
    };
    let p = spec.process.get_ref();
    let pspan = spec.process.span();

    // Robots.
    if spec.robots.is_empty() || spec.robots.len() > 2 {
        let span = spec.robots.first().map_or(0..0, |r| r.span());
        return Err(ctx.err(
            span,
            format!(
                "{} robots: a PCB cell has one or two placement robots",
                spec.robots.len()
            ),
        ));
    }
    let mut robots = Vec::new();
    for r in &spec.robots {
        let s = r.span();
        let r = r.get_ref();
        robots.push(Robot {
            name: r.name.clone(),
            drive: ctx.drive(&s, r.speed, r.acceleration, ROBOT_SPEED)?,
            home: [
                ctx.length(&s, "home", r.home[0])?,
                ctx.length(&s, "home", r.home[1])?,
            ],
            x: ctx.range(&s, "x", r.x)?,
            x_given: ctx.range(&s, "x", r.x)?,
            y: ctx.range(&s, "y", r.y)?,
        });
    }
    // Feeders.
    if spec.feeders.len() != 2 {
        let span = spec.feeders.first().map_or(0..0, |f| f.span());
        return Err(ctx
            .err(
                span,
                format!(
                    "{} feeders: a PCB cell has two (`[[feeders]]`, left then right)",
                    spec.feeders.len()
                ),
            )
            .hint("give two [[feeders]] entries; docs/cell-format.md shows one"));
    }
    let mut feeders = Vec::new();
    for f in &spec.feeders {
        let s = f.span();
        let f = f.get_ref();
        if f.bins == 0 || f.bins > MAX_BINS {
            return Err(ctx.err(
                ctx.key(&s, "bins"),
                format!("`bins` = {} must be between 1 and {MAX_BINS}", f.bins),
            ));
        }
        let pitch = ctx.length(&s, "pitch", f.pitch)?;
        if pitch <= 0.0 {
            return Err(ctx.err(ctx.key(&s, "pitch"), "`pitch` must be above 0"));
        }
        let travel = ctx.range(&s, "travel", f.travel)?;
        let home = ctx.length(&s, "home", f.home)?;
        if !(travel[0]..=travel[1]).contains(&home) {
            return Err(ctx.err(
                ctx.key(&s, "home"),
                "the feeder's `home` lies outside its `travel`",
            ));
        }
        feeders.push(Feeder {
            name: f.name.clone(),
            x: ctx.length(&s, "x", f.x)?,
            travel,
            home,
            bins: f.bins,
            pitch,
            drive: ctx.drive(&s, f.speed, f.acceleration, FEEDER_SPEED)?,
        });
    }
    let feeders: [Feeder; 2] = [feeders[0].clone(), feeders[1].clone()];
    if feeders[0].x >= feeders[1].x {
        return Err(ctx.err(
            spec.feeders[1].span(),
            "the second feeder must stand right of the first (larger `x`)",
        ));
    }
    // Table.
    let ts = spec.table.span();
    let t = spec.table.get_ref();
    let table = Table {
        x: ctx.range(&ts, "x", t.x)?,
        y: ctx.range(&ts, "y", t.y)?,
        home: [
            ctx.length(&ts, "home", t.home[0])?,
            ctx.length(&ts, "home", t.home[1])?,
        ],
        drive: ctx.drive(&ts, t.speed, t.acceleration, TABLE_SPEED)?,
    };
    if !(table.x[0]..=table.x[1]).contains(&table.home[0])
        || !(table.y[0]..=table.y[1]).contains(&table.home[1])
    {
        return Err(ctx.err(ctx.key(&ts, "home"), "the table's `home` lies outside its travel"));
    }
    // Process.
    let safety_gap = match &p.safety_gap {
        None => 0.05,
        Some(g) => {
            let v = ctx.length(&g.span(), "safety_gap", *g.get_ref())?;
            if v < 0.0 {
                return Err(ctx.err(g.span(), "`safety_gap` must not be negative"));
            }
            v
        }
    };
    if robots.len() == 1 {
        if let Some(g) = &p.safety_gap {
            return Err(ctx
                .err(
                    g.span(),
                    "`safety_gap` is a two-robot option, and this cell has one robot",
                )
                .hint("remove `safety_gap`, or add the second robot"));
        }
        if p.collision_avoidance.is_some() {
            return Err(ctx
                .err(
                    ctx.key(&pspan, "collision_avoidance"),
                    "`collision_avoidance` is a two-robot option, and this cell has one robot",
                )
                .hint("remove `collision_avoidance`, or add the second robot"));
        }
    }
    for (r, spec_r) in robots.iter().zip(&spec.robots) {
        if !(r.x[0]..=r.x[1]).contains(&r.home[0]) || !(r.y[0]..=r.y[1]).contains(&r.home[1]) {
            return Err(ctx.err(
                ctx.key(&spec_r.span(), "home"),
                format!("robot {}'s `home` lies outside its travel", r.name),
            ));
        }
    }
    if robots.len() == 2 {
        // Robot 1 never reaches within the gap of feeder 2's pick line, robot 2 of feeder 1's;
        // each starts at or beyond its own feeder, so that a robot at its own feeder never
        // stands in the other's way.
        let (x1, x2) = (feeders[0].x, feeders[1].x);
        if x1 + safety_gap > x2 - safety_gap {
            return Err(ctx.err(spec.feeders[1].span(), "the feeders stand closer than twice the safety gap: the robots could not pass each other's picks")
                .hint("move the feeders apart or reduce `safety_gap`"));
        }
        robots[0].x[1] = robots[0].x[1].min(x2 - safety_gap);
        robots[1].x[0] = robots[1].x[0].max(x1 + safety_gap);
        if robots[0].home[0] > x1 {
            return Err(ctx.err(
                ctx.key(&spec.robots[0].span(), "home"),
                "robot 1 must start at or left of feeder 1's pick line (home x ≤ feeder 1 x)",
            ));
        }
        if robots[1].home[0] < x2 {
            return Err(ctx.err(
                ctx.key(&spec.robots[1].span(), "home"),
                "robot 2 must start at or right of feeder 2's pick line (home x ≥ feeder 2 x)",
            ));
        }
        if robots[0].x[0] > robots[0].x[1] || robots[1].x[0] > robots[1].x[1] {
            return Err(ctx.err(
                spec.robots[0].span(),
                "a robot's X travel is empty once the other robot's feeder and the gap are kept clear",
            ));
        }
    }

    // The board.
    let board_path = path.parent().unwrap_or(Path::new("")).join(p.board.get_ref());
    let board = board::read(&board_path).map_err(|e| {
        if e.line.is_none() && !board_path.exists() {
            ctx.err(
                p.board.span(),
                format!("the board file {} does not exist", board_path.display()),
            )
            .hint("`board` is a path relative to the cell file, to a .kicad_pcb or a KiCad position CSV")
        } else {
            e
        }
    })?;
    let side = match p.side.as_ref().map(|s| s.get_ref().as_str()) {
        None | Some("front") | Some("top") => Side::Front,
        Some("back") | Some("bottom") => Side::Back,
        Some(other) => {
            return Err(ctx.err(
                p.side.as_ref().map_or(0..0, |s| s.span()),
                format!("side `{other}`: expected `front` or `back`"),
            ));
        }
    };
    let mounts = match &p.mounts {
        None => vec![Mount::Smd],
        Some(m) => {
            let mut out = Vec::new();
            for name in m.get_ref() {
                out.push(match name.as_str() {
                    "smd" => Mount::Smd,
                    "through-hole" | "through_hole" => Mount::ThroughHole,
                    "unspecified" => Mount::Unspecified,
                    other => {
                        return Err(ctx.err(
                            m.span(),
                            format!("mounting `{other}`: expected `smd`, `through-hole` or `unspecified`"),
                        ));
                    }
                });
            }
            out
        }
    };
    let only = p
        .components
        .as_ref()
        .map(|c| c.get_ref().clone())
        .unwrap_or_default();
    if let Some(c) = &p.components {
        for r in c.get_ref() {
            if !board.components.iter().any(|b| &b.reference == r) {
                return Err(ctx.err(
                    c.span(),
                    format!("component `{r}` is not on the board {}", board_path.display()),
                ));
            }
        }
    }
    let sel = Selection { side, mounts, only };
    let components = board::select(&board, &sel);
    if components.is_empty() {
        return Err(ctx
            .err(p.board.span(), format!("nothing to place: no footprint of {} is on the {side:?} side with a mounting placed here", board_path.display()))
            .hint("set `side`, `mounts` (e.g. [\"smd\", \"through-hole\"]) or `components`"));
    }
    let mut seen: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for c in &components {
        if let Some(first) = seen.insert(c.reference.as_str(), c.line) {
            return Err(InputError::at_line(&board_path, Some(c.line), format!(
                "two footprints to place are both `{}` (the other on line {first})",
                c.reference
            ))
            .hint("annotate the board in KiCad so that every placed footprint has its own reference, or leave these out with `mounts` or `components`"));
        }
        if c.reference.is_empty() {
            return Err(
                InputError::at_line(&board_path, Some(c.line), "a footprint without a reference")
                    .hint("annotate the board in KiCad (every placed footprint needs a reference)"),
            );
        }
    }
    let mut types: Vec<ComponentType> = components
        .iter()
        .map(|c| ComponentType {
            footprint: c.footprint.clone(),
            value: c.value.clone(),
        })
        .collect();
    types.sort();
    types.dedup();
    let type_of: Vec<usize> = components
        .iter()
        .map(|c| {
            let t = ComponentType {
                footprint: c.footprint.clone(),
                value: c.value.clone(),
            };
            types.binary_search(&t).unwrap_or(0)
        })
        .collect();

    // Bins given in the cell.
    let mut given_bins = Vec::new();
    for b in &p.bins {
        let s = b.span();
        let b = b.get_ref();
        let feeder = feeders
            .iter()
            .position(|f| f.name == b.feeder)
            .ok_or_else(|| ctx.err(s.clone(), format!("bin of unknown feeder `{}`", b.feeder)))?;
        if b.bin >= feeders[feeder].bins {
            return Err(ctx.err(
                s,
                format!(
                    "bin {} of feeder {}, which has {} bins (0 to {})",
                    b.bin,
                    b.feeder,
                    feeders[feeder].bins,
                    feeders[feeder].bins - 1
                ),
            ));
        }
        let t = ComponentType {
            footprint: b.footprint.clone(),
            value: b.value.clone(),
        };
        let kind = types.binary_search(&t).map_err(|_| {
            ctx.err(
                s.clone(),
                format!(
                    "bin holds `{}` `{}`, which no placed component is",
                    b.footprint, b.value
                ),
            )
        })?;
        if given_bins
            .iter()
            .any(|g: &GivenBin| g.feeder == feeder && g.slot == b.bin)
        {
            return Err(ctx.err(s, format!("bin {} of feeder {} is given twice", b.bin, b.feeder)));
        }
        given_bins.push(GivenBin {
            feeder,
            slot: b.bin,
            kind,
        });
    }
    let robots_n = robots.len();
    let cell = PcbCell {
        name: spec.name.clone().unwrap_or_else(|| {
            path.parent()
                .and_then(|d| d.file_name())
                .map_or("pcb".into(), |n| n.to_string_lossy().into_owned())
        }),
        path: path.to_path_buf(),
        board,
        components,
        types,
        type_of,
        robots,
        feeders,
        table,
        pick_time: ctx.seconds(p.pick_time.as_ref(), 0.05, "pick_time")?,
        place_time: ctx.seconds(p.place_time.as_ref(), 0.05, "place_time")?,
        safety_gap,
        collision_avoidance: p.collision_avoidance.unwrap_or(true),
        configuration: p.configuration.unwrap_or(Configuration::AllMoving),
        motion: p.motion.unwrap_or(MotionModel::ConstantSpeed),
        given_bins,
    };
    check_feasible(&ctx, &cell, &spec, robots_n, &board_path)?;
    Ok(cell)
}

/// Every type has a bin (given or possible), every bin a carriage position a robot reaches,
/// every component a table position at which a robot places it.
fn check_feasible(
    ctx: &Ctx,
    cell: &PcbCell,
    spec: &Spec,
    robots: usize,
    board_path: &Path,
) -> Result<(), InputError> {
    if !cell.given_bins.is_empty() {
        for (t, ty) in cell.types.iter().enumerate() {
            if !cell.given_bins.iter().any(|b| b.kind == t) {
                let line = cell.components[cell.type_of.iter().position(|&k| k == t).unwrap_or(0)].line;
                return Err(InputError::at_line(board_path, Some(line), format!(
                    "component type `{}` `{}` has no bin: `[[process.bins]]` in {} stocks every other type",
                    ty.footprint, ty.value, ctx.path.display()
                ))
                .hint("add a [[process.bins]] entry for it, or remove all of them and let the optimiser place the types"));
            }
        }
        if robots == 2 {
            for (c, &t) in cell.type_of.iter().enumerate() {
                let served = (0..2).any(|r| {
                    cell.place_box(r, c).is_some()
                        && cell.given_bins.iter().any(|b| b.kind == t && b.feeder == r)
                });
                if !served {
                    return Err(InputError::at_line(board_path, Some(cell.components[c].line), format!(
                        "component {} can be placed only by a robot whose feeder does not stock its type `{}` `{}`",
                        cell.components[c].reference, cell.types[t].footprint, cell.types[t].value
                    ))
                    .hint("stock the type in the feeder of a robot that reaches the component ([[process.bins]])"));
                }
            }
        }
    } else {
        let total: usize = cell.feeders.iter().map(|f| f.bins).sum();
        if total < cell.types.len() {
            return Err(ctx
                .err(
                    spec.feeders[0].span(),
                    format!(
                        "{} component types but only {total} bins in the two feeders",
                        cell.types.len()
                    ),
                )
                .hint("give the feeders more `bins`, or place fewer types (`components`, `mounts`)"));
        }
    }
    for f in 0..2 {
        for slot in 0..cell.feeders[f].bins {
            let reachable =
                (0..robots).any(|r| cell.feeders_of(r).contains(&f) && cell.pick_range(r, f, slot).is_some());
            if !reachable {
                return Err(ctx
                    .err(spec.feeders[f].span(), format!(
                        "bin {slot} of feeder {} cannot be brought within reach of the robot that serves it",
                        cell.feeders[f].name
                    ))
                    .hint("widen the robot's `y`/`x` travel or the feeder's `travel`, or use fewer bins"));
            }
        }
    }
    for (c, comp) in cell.components.iter().enumerate() {
        if !(0..robots).any(|r| cell.place_box(r, c).is_some()) {
            return Err(ctx
                .err(spec.table.span(), format!(
                    "the board is larger than the table's reach: component {} at ({:.1}, {:.1}) mm on the board cannot be brought under any robot",
                    comp.reference, comp.position[0] * 1e3, comp.position[1] * 1e3
                ))
                .hint("widen the table's `x`/`y` travel or the robots' travel"));
        }
    }
    Ok(())
}
