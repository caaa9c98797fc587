//! Reading and checking a CMM cell file and its task CSV: units applied, every value in range,
//! every MP within the machine's reach and its cone a true cone.
use super::*;
use crate::part::MpFeature;
use cellplan_geom::DVec3;
use cellplan_model::InputError;
use cellplan_model::io::read_bounded;
use cellplan_model::spec::{LengthUnit, ShapeEntry};
use serde::Deserialize;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// Largest task file read.
const MAX_TASK_FILE: u64 = 16 << 20;
/// Largest length anywhere in the cell (m).
const MAX_LENGTH: f64 = 100.0;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    name: Option<String>,
    #[serde(default)]
    units: Units,
    process: Spanned<ProcessSpec>,
    machine: Spanned<MachineSpec>,
    #[serde(default)]
    head: Option<Spanned<HeadSpec>>,
    #[serde(default)]
    stylus: Option<Spanned<StylusSpec>>,
    part: Spanned<ShapeEntry>,
    #[serde(default)]
    fixtures: Vec<Spanned<ShapeEntry>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Units {
    #[serde(default = "mm")]
    length: LengthUnit,
}

fn mm() -> LengthUnit {
    LengthUnit::Mm
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProcessSpec {
    #[allow(dead_code)]
    kind: String,
    tasks: Spanned<String>,
    clearance: Option<Spanned<f64>>,
    touch_clearance: Option<Spanned<f64>>,
    pretouch: Option<Spanned<f64>>,
    inspection_time: Option<Spanned<f64>>,
    orientation_step: Option<Spanned<f64>>,
    classification: Option<Spanned<String>>,
    adjacent: Option<Spanned<Vec<[String; 2]>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineSpec {
    x: [f64; 2],
    y: [f64; 2],
    z: [f64; 2],
    home: [f64; 3],
    speed: Option<f64>,
    rotation_speed: Option<f64>,
    acceleration: Option<f64>,
    rotation_acceleration: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeadSpec {
    a: Option<[f64; 2]>,
    b: Option<[f64; 2]>,
    index_step: Option<f64>,
    diameter: Option<f64>,
    height: Option<f64>,
    ram: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StylusSpec {
    l1: Option<f64>,
    l2: Option<f64>,
    ball: Option<f64>,
    stem_diameter: Option<f64>,
    extension_diameter: Option<f64>,
}

struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
    to_m: f64,
}

impl Ctx<'_> {
    fn err(&self, span: Range<usize>, msg: impl Into<String>) -> InputError {
        InputError::at_span(self.path, self.text, span, msg)
            .hint("docs/cell-format.md (CMM inspection) lists every key, its unit and default")
    }

    fn key(&self, within: &Range<usize>, key: &str) -> Range<usize> {
        cellplan_model::process::key_span(self.text, within, key)
    }

    /// A length above 0 (file units → m).
    fn positive(&self, span: &Range<usize>, key: &str, v: f64) -> Result<f64, InputError> {
        if !(v.is_finite() && v > 0.0 && v * self.to_m <= MAX_LENGTH) {
            return Err(self.err(
                self.key(span, key),
                format!(
                    "`{key}` = {} must be a length above 0 and within {MAX_LENGTH} m",
                    cellplan_model::shown(v)
                ),
            ));
        }
        Ok(v * self.to_m)
    }

    fn range(&self, span: &Range<usize>, key: &str, r: [f64; 2]) -> Result<[f64; 2], InputError> {
        let ok = r
            .iter()
            .all(|v| v.is_finite() && v.abs() * self.to_m <= MAX_LENGTH)
            && r[0] < r[1];
        if !ok {
            return Err(self.err(
                self.key(span, key),
                format!(
                    "`{key}` = [{}, {}] must be two finite numbers, low < high, within {MAX_LENGTH} m",
                    r[0], r[1]
                ),
            ));
        }
        Ok([r[0] * self.to_m, r[1] * self.to_m])
    }

    /// An angle range in degrees → rad, within `limit` degrees either way.
    fn angles(
        &self,
        span: &Range<usize>,
        key: &str,
        r: [f64; 2],
        limit: f64,
    ) -> Result<[f64; 2], InputError> {
        if !(r.iter().all(|v| v.is_finite() && v.abs() <= limit) && r[0] <= r[1]) {
            return Err(self.err(
                self.key(span, key),
                format!(
                    "`{key}` = [{}, {}] must be two angles in degrees, low ≤ high, within ±{limit}°",
                    r[0], r[1]
                ),
            ));
        }
        Ok([r[0].to_radians(), r[1].to_radians()])
    }
}

fn positive_opt(
    ctx: &Ctx,
    span: &Range<usize>,
    key: &str,
    v: Option<f64>,
    default: f64,
) -> Result<f64, InputError> {
    v.map_or(Ok(default), |v| ctx.positive(span, key, v))
}

/// Loads a CMM-inspection cell file, its part and fixtures, and its MPs.
pub fn load(path: &Path) -> Result<CmmCell, InputError> {
    let (text, spec): (String, Spec) = cellplan_model::load::read_cell_toml(
        path,
        "examples/cmm-block/cell.toml",
        "docs/cell-format.md (CMM inspection)",
    )?;
    let ctx = Ctx {
        path,
        text: &text,
        to_m: spec.units.length.to_m(),
    };
    let to_m = ctx.to_m;
    let deg = std::f64::consts::PI / 180.0;

    // The machine.
    let ms = spec.machine.span();
    let m = spec.machine.get_ref();
    let travel = Travel {
        x: ctx.range(&ms, "x", m.x)?,
        y: ctx.range(&ms, "y", m.y)?,
        z: ctx.range(&ms, "z", m.z)?,
    };
    let movement = positive_opt(&ctx, &ms, "speed", m.speed, 0.085)?;
    let rotation = match m.rotation_speed {
        None => 1.0,
        Some(v) if v.is_finite() && v > 0.0 && v <= 3600.0 => v * deg,
        Some(v) => {
            return Err(ctx.err(
                ctx.key(&ms, "rotation_speed"),
                format!(
                    "`rotation_speed` = {} must be above 0 and at most 3600 °/s",
                    cellplan_model::shown(v)
                ),
            ));
        }
    };
    let acceleration = match (m.acceleration, m.rotation_acceleration) {
        (None, None) => None,
        (Some(a), Some(r)) => {
            let a = ctx.positive(&ms, "acceleration", a)?;
            if !(r.is_finite() && r > 0.0 && r <= 1e5) {
                return Err(ctx.err(
                    ctx.key(&ms, "rotation_acceleration"),
                    format!("`rotation_acceleration` = {r} must be above 0 and at most 100000 °/s²"),
                ));
            }
            Some((a, r * deg))
        }
        _ => {
            return Err(ctx
                .err(ms.clone(), "give both `acceleration` and `rotation_acceleration`, or neither")
                .hint("with both, moves and turns follow a trapezoidal profile; with neither, full speed at once (paper 003)"));
        }
    };
    let speeds = CmmSpeeds {
        movement,
        rotation,
        acceleration,
    };

    // The head and stylus.
    let paper = CmmHead::paper();
    let pbodies = ProbeBodies::paper();
    let (head_span, h) = match &spec.head {
        Some(h) => (h.span(), Some(h.get_ref())),
        None => (0..0, None),
    };
    let a_range = match h.and_then(|h| h.a) {
        Some(r) => ctx.angles(&head_span, "a", r, 180.0)?,
        None => paper.a_range,
    };
    let b_range = match h.and_then(|h| h.b) {
        Some(r) => ctx.angles(&head_span, "b", r, 360.0)?,
        None => paper.b_range,
    };
    let index_step = match h.and_then(|h| h.index_step) {
        None => None,
        Some(s) if s.is_finite() && (0.1..=90.0).contains(&s) => Some(s * deg),
        Some(s) => {
            return Err(ctx.err(
                ctx.key(&head_span, "index_step"),
                format!("`index_step` = {s} must be between 0.1° and 90°"),
            ));
        }
    };
    let head_d = positive_opt(
        &ctx,
        &head_span,
        "diameter",
        h.and_then(|h| h.diameter),
        pbodies.head.0 / to_m,
    )?;
    let head_h = positive_opt(
        &ctx,
        &head_span,
        "height",
        h.and_then(|h| h.height),
        pbodies.head.1 / to_m,
    )?;
    let ram = match h.and_then(|h| h.ram) {
        Some([side, height]) => (
            ctx.positive(&head_span, "ram", side)?,
            ctx.positive(&head_span, "ram", height)?,
        ),
        None => pbodies.ram,
    };
    let (stylus_span, st) = match &spec.stylus {
        Some(s) => (s.span(), Some(s.get_ref())),
        None => (0..0, None),
    };
    let l1 = positive_opt(&ctx, &stylus_span, "l1", st.and_then(|s| s.l1), paper.l1 / to_m)?;
    let l2 = positive_opt(&ctx, &stylus_span, "l2", st.and_then(|s| s.l2), paper.l2 / to_m)?;
    let ball = positive_opt(
        &ctx,
        &stylus_span,
        "ball",
        st.and_then(|s| s.ball),
        paper.ball_diameter / to_m,
    )?;
    let stem_d = positive_opt(
        &ctx,
        &stylus_span,
        "stem_diameter",
        st.and_then(|s| s.stem_diameter),
        pbodies.stem_diameter / to_m,
    )?;
    let ext_d = positive_opt(
        &ctx,
        &stylus_span,
        "extension_diameter",
        st.and_then(|s| s.extension_diameter),
        pbodies.extension_diameter / to_m,
    )?;
    if stem_d >= ball {
        return Err(ctx
            .err(
                ctx.key(&stylus_span, "stem_diameter"),
                "the stem must be thinner than the ball, or the stem would touch first",
            )
            .hint("a 3 mm ball usually carries a 1.5–2 mm stem"));
    }
    let head = CmmHead {
        l1,
        l2,
        ball_diameter: ball,
        a_range,
        b_range,
        index_step,
    };
    let z_travel = travel.z[1] - travel.z[0];
    if head.reach() + ball / 2.0 >= z_travel {
        let span = if spec.stylus.is_some() {
            stylus_span
        } else {
            ms.clone()
        };
        return Err(ctx
            .err(
                span,
                format!(
                    "the probe reaches {:.1} mm (L1 + L2 + ball radius) but the Z travel is {:.1} mm: it could never lift the stylus off the part",
                    (head.reach() + ball / 2.0) * 1e3,
                    z_travel * 1e3
                ),
            )
            .hint("use a shorter stylus or give the machine a longer `z` travel"));
    }
    let bodies = ProbeBodies {
        stem_diameter: stem_d,
        extension_diameter: ext_d,
        head: (head_d, head_h),
        ram,
        stem_start: (ball / 2.0 + 0.0025).max(ball),
    };

    // Home.
    let home = [
        m.home[0] * to_m,
        m.home[1] * to_m,
        m.home[2] * to_m,
        a_range[0].max(0.0).min(a_range[1]),
        0f64.clamp(b_range[0], b_range[1]),
    ];
    let inside = |v: f64, r: [f64; 2]| v.is_finite() && (r[0]..=r[1]).contains(&v);
    if !(inside(home[0], travel.x) && inside(home[1], travel.y) && inside(home[2], travel.z)) {
        return Err(ctx.err(
            ctx.key(&ms, "home"),
            "the machine's `home` lies outside its travel",
        ));
    }

    // Process.
    let p = spec.process.get_ref();
    let length_or =
        |v: &Option<Spanned<f64>>, key: &str, default: f64, zero_ok: bool| -> Result<f64, InputError> {
            match v {
                None => Ok(default),
                Some(s) => {
                    let x = *s.get_ref();
                    if !(x.is_finite() && (x > 0.0 || zero_ok && x == 0.0) && x * to_m <= 1.0) {
                        return Err(ctx.err(
                            s.span(),
                            format!(
                                "`{key}` = {x} must be {} and at most 1 m",
                                if zero_ok { "0 or more" } else { "above 0" }
                            ),
                        ));
                    }
                    Ok(x * to_m)
                }
            }
        };
    let clearance = length_or(&p.clearance, "clearance", 0.002, true)?;
    let touch_clearance = length_or(&p.touch_clearance, "touch_clearance", 0.001, true)?;
    let pretouch = length_or(&p.pretouch, "pretouch", 0.005, false)?;
    let inspection_s = match &p.inspection_time {
        None => 1.0,
        Some(s) if s.get_ref().is_finite() && (0.0..=3600.0).contains(s.get_ref()) => *s.get_ref(),
        Some(s) => {
            return Err(ctx.err(
                s.span(),
                format!("`inspection_time` = {} must be between 0 and 3600 s", s.get_ref()),
            ));
        }
    };
    let orientation_step = match &p.orientation_step {
        None => 7.5 * deg,
        Some(s) if s.get_ref().is_finite() && (1.0..=45.0).contains(s.get_ref()) => s.get_ref() * deg,
        Some(s) => {
            return Err(ctx
                .err(
                    s.span(),
                    format!("`orientation_step` = {} must be between 1° and 45°", s.get_ref()),
                )
                .hint("the candidate orientations of a continuous head lie on this grid"));
        }
    };
    let classification = match p
        .classification
        .as_ref()
        .map(|s| (s.get_ref().as_str(), s.span()))
    {
        None | Some(("exact", _)) => Method::Exact,
        Some(("greedy", _)) => Method::Greedy,
        Some((other, span)) => {
            return Err(ctx
                .err(span, format!("unknown `classification` \"{other}\""))
                .hint("\"exact\" (fewest groups) or \"greedy\" (paper 003's rule)"));
        }
    };

    // The part and the fixtures.
    let part_span = spec.part.span();
    let part_entry = spec.part.get_ref();
    if part_entry.mesh.is_none() {
        return Err(ctx
            .err(part_span, "the `[part]` needs a `mesh` (STL or OBJ)")
            .hint("the MPs are given in the mesh's frame; `pose` places both on the machine"));
    }
    let (part_shape, part_pose) =
        cellplan_model::load::shape_entry(path, &text, part_entry, part_span.clone(), "the part", to_m, deg)?;
    let part_file = (
        path.parent()
            .unwrap_or(Path::new(""))
            .join(part_entry.mesh.as_deref().unwrap_or_default()),
        part_entry.mesh_units.map_or(to_m, |u| u.to_m()),
    );
    let part_name = part_entry.name.clone().unwrap_or_else(|| "part".to_string());
    let mut statics = vec![(part_name, part_shape, part_pose)];
    for (i, f) in spec.fixtures.iter().enumerate() {
        let owner = format!("fixture {}", i + 1);
        let (shape, pose) =
            cellplan_model::load::shape_entry(path, &text, f.get_ref(), f.span(), &owner, to_m, deg)?;
        let name = f.get_ref().name.clone().unwrap_or(owner);
        statics.push((name, shape, pose));
    }

    // The MPs.
    let tasks_file = path.parent().unwrap_or(Path::new("")).join(p.tasks.get_ref());
    if !tasks_file.exists() {
        return Err(ctx
            .err(
                p.tasks.span(),
                format!("the task file {} does not exist", tasks_file.display()),
            )
            .hint("`tasks` is a path relative to the cell file, to a CSV `id,x,y,z,nx,ny,nz,feature,theta[,face]`"));
    }
    let (mut mps, mp_lines, faces) = read_mps(&tasks_file, to_m)?;
    for mp in &mut mps {
        mp.position = part_pose.transform_point(mp.position);
        mp.normal = part_pose.rotation * mp.normal;
    }
    // Every MP within reach of the travel box.
    let reach = head.reach();
    for (mp, &line) in mps.iter().zip(&mp_lines) {
        let ball = mp.position + mp.normal * (ball / 2.0);
        let c = DVec3::new(
            ball.x.clamp(travel.x[0], travel.x[1]),
            ball.y.clamp(travel.y[0], travel.y[1]),
            ball.z.clamp(travel.z[0], travel.z[1]),
        );
        if (c - ball).length() > reach + 1e-9 {
            return Err(InputError::at_line(
                &tasks_file,
                Some(line),
                format!(
                    "MP {} at ({:.1}, {:.1}, {:.1}) mm (machine frame) lies outside the machine's range: {:.1} mm from its travel, and the probe reaches {:.1} mm",
                    mp.name,
                    mp.position.x * 1e3,
                    mp.position.y * 1e3,
                    mp.position.z * 1e3,
                    (c - ball).length() * 1e3,
                    reach * 1e3
                ),
            )
            .hint(format!(
                "move the part (its `pose` in {}) or widen the machine's travel",
                path.display()
            )));
        }
    }
    // Adjacency.
    let adjacent = match &p.adjacent {
        None => None,
        Some(list) => {
            let mut pairs = Vec::new();
            for [a, b] in list.get_ref() {
                let find = |n: &str| faces.iter().position(|f| f == n);
                match (find(a), find(b)) {
                    (Some(x), Some(y)) if x != y => pairs.push((x, y)),
                    (Some(_), Some(_)) => {
                        return Err(
                            ctx.err(list.span(), format!("face `{a}` is listed as adjacent to itself"))
                        );
                    }
                    _ => {
                        let unknown = if find(a).is_none() { a } else { b };
                        return Err(ctx
                            .err(
                                list.span(),
                                format!("`adjacent` names face `{unknown}`, which no MP lies on"),
                            )
                            .hint(format!(
                                "the faces are the task file's `face` column: {}",
                                faces.join(", ")
                            )));
                    }
                }
            }
            Some(pairs)
        }
    };
    let name = spec.name.clone().unwrap_or_else(|| {
        path.parent()
            .and_then(|d| d.file_name())
            .map_or("cmm".to_string(), |n| n.to_string_lossy().into_owned())
    });
    let cell = CmmCell {
        name,
        path: path.to_path_buf(),
        statics,
        part_file,
        mps,
        tasks_file,
        mp_lines,
        faces,
        adjacent,
        head,
        bodies,
        travel,
        home,
        speeds,
        inspection_s,
        clearance,
        touch_clearance,
        pretouch,
        orientation_step,
        classification,
    };
    // Home must be clear.
    let probe = cell.probe();
    if probe.distance(&cell.home, 1.0) <= cell.clearance {
        return Err(ctx
            .err(
                ctx.key(&ms, "home"),
                "at `home` (probe straight down) the probe is not clear of the part and fixtures",
            )
            .hint("put `home` high above the part"));
    }
    Ok(cell)
}

/// The MPs, each one's line, and the face names.
pub(crate) type MpFile = (Vec<Mp>, Vec<usize>, Vec<String>);

/// Reads the MP CSV: `id,x,y,z,nx,ny,nz,feature,theta[,face]` (lengths in the cell's unit, θ in
/// degrees). Without a `face` column, MPs with the same normal on the same plane share a face.
pub(crate) fn read_mps(path: &Path, to_m: f64) -> Result<MpFile, InputError> {
    let text = read_bounded(path, MAX_TASK_FILE).map_err(|e| {
        InputError::new(path, format!("cannot read the task file: {e}"))
            .hint("a CSV `id,x,y,z,nx,ny,nz,feature,theta[,face]`, at most 16 MiB")
    })?;
    let hint = "columns id,x,y,z,nx,ny,nz,feature,theta[,face]: mm (the cell's length unit), a normal, surface|hole|edge|stud, the cone half-angle in degrees";
    let mut lines = text.lines().enumerate().filter(|(_, l)| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('#')
    });
    let Some((hl, header)) = lines.next() else {
        return Err(InputError::new(path, "the task file has no header and no MPs").hint(hint));
    };
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_ascii_lowercase()).collect();
    let col = |name: &str| cols.iter().position(|c| c == name);
    let needed = ["id", "x", "y", "z", "nx", "ny", "nz", "feature", "theta"];
    let mut idx = [0usize; 9];
    for (k, n) in needed.iter().enumerate() {
        idx[k] = col(n).ok_or_else(|| {
            InputError::at_line(path, Some(hl + 1), format!("the header lacks the column `{n}`")).hint(hint)
        })?;
    }
    let face_col = col("face");
    let mut mps = Vec::new();
    let mut mp_lines = Vec::new();
    let mut faces: Vec<String> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (i, line) in lines {
        let ln = i + 1;
        let at = |msg: String| InputError::at_line(path, Some(ln), msg).hint(hint);
        if mps.len() >= MAX_MPS {
            return Err(at(format!(
                "more than {MAX_MPS} MPs: split the inspection into several jobs"
            )));
        }
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != cols.len() {
            return Err(at(format!("{} fields, the header has {}", f.len(), cols.len())));
        }
        let num = |k: usize| -> Result<f64, InputError> {
            let s = f[idx[k]];
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| at(format!("`{}` = \"{s}\" is not a finite number", needed[k])))
        };
        let id = f[idx[0]].to_string();
        if id.is_empty() {
            return Err(at("an MP without an id".into()));
        }
        if !seen.insert(id.clone()) {
            return Err(at(format!("MP id `{id}` appears twice")));
        }
        let p = DVec3::new(num(1)?, num(2)?, num(3)?);
        if p.abs().max_element() * to_m > MAX_LENGTH {
            return Err(at(format!(
                "MP {id} lies more than {MAX_LENGTH} m from the origin"
            )));
        }
        let n = DVec3::new(num(4)?, num(5)?, num(6)?);
        if n.length() < 1e-9 {
            return Err(at(format!("MP {id} has a zero normal")));
        }
        let feature = match f[idx[7]].to_ascii_lowercase().as_str() {
            "surface" | "plane" => MpFeature::Plane,
            "hole" | "bore" => MpFeature::BoreWall,
            "edge" | "rim" => MpFeature::HoleEdge,
            "stud" | "boss" => MpFeature::Boss,
            other => return Err(at(format!("unknown feature `{other}`"))),
        };
        let theta = num(8)?;
        if !(theta > 0.0 && theta < 90.0) {
            return Err(at(format!(
                "MP {id}: cone half-angle θ = {theta}° must lie strictly between 0° and 90°"
            ))
            .hint("θ is the largest angle between the probe's axis and the surface normal at which the MP may be touched (paper 003 §3.1)"));
        }
        let face_name = match face_col {
            Some(c) if !f[c].is_empty() => f[c].to_string(),
            _ => {
                // Same normal, same plane: one face.
                let n = n.normalize();
                let off = n.dot(p) * to_m;
                format!("plane({:.3},{:.3},{:.3})@{:.4}", n.x, n.y, n.z, off)
            }
        };
        let face = match faces.iter().position(|x| *x == face_name) {
            Some(k) => k,
            None => {
                faces.push(face_name);
                faces.len() - 1
            }
        };
        mps.push(Mp {
            name: id,
            position: p * to_m,
            normal: n.normalize(),
            feature,
            theta_deg: theta,
            face,
        });
        mp_lines.push(ln);
    }
    if mps.is_empty() {
        return Err(InputError::new(path, "the task file lists no MPs").hint(hint));
    }
    Ok((mps, mp_lines, faces))
}
