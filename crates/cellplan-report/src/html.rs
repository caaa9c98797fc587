//! The self-contained HTML report of a plan (and of a strategy comparison): summary, Gantt
//! chart, time–position charts before and after coordination (paper 000 Fig. 7/8), and the 3D
//! playback of the cell (the project's own WebGL2 viewer, `viewer.js`). One file with no
//! outside references: it opens offline in any browser.
use super::charts::{self, Marks, StrategyBar, Track};
use super::playback::{Doing, intervals, probe_track};
use super::scene::{Scene, robot_colour};
use crate::escape;
use base64::Engine;
use cellplan_core::document::Plan;
use cellplan_core::verify;
use cellplan_geom::{DVec3, Pose};
use cellplan_model::Cell;
use serde_json::{Value, json};
use std::fmt::Write;

const CSS: &str = include_str!("report.css");
const VIEWER: &str = include_str!("viewer.js");

/// Most points per robot in a time–position chart (the track is thinned evenly above that).
const CHART_POINTS: usize = 1500;

/// What a plan report shows.
pub struct PlanReport<'a> {
    /// The plan.
    pub plan: &'a Plan,
    /// The cell it was made for.
    pub cell: &'a Cell,
    /// The cell to draw.
    pub scene: &'a Scene,
    /// The verifier's verdict on the plan, when it was run for the report.
    pub verification: Option<&'a verify::Report>,
    /// The plan file's name, for the page.
    pub plan_file: Option<&'a str>,
}

fn b64<T: Copy>(values: &[T], bytes: impl Fn(T) -> [u8; 4]) -> String {
    let raw: Vec<u8> = values.iter().flat_map(|&v| bytes(v)).collect();
    base64::engine::general_purpose::STANDARD.encode(raw)
}

fn b64_f32(values: &[f32]) -> String {
    b64(values, f32::to_le_bytes)
}

fn b64_u32(values: &[u32]) -> String {
    b64(values, u32::to_le_bytes)
}

fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

/// `[x, y, z, qx, qy, qz, qw]`.
fn pose_json(p: &Pose) -> Value {
    let (t, q) = (p.translation, p.rotation);
    json!([t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(round6))
}

/// The horizontal axis along which the cell is longest (robots and MPs): 0 for x, 1 for y.
pub fn long_axis(cell: &Cell) -> usize {
    let points: Vec<DVec3> = cell
        .tasks
        .iter()
        .map(|t| t.position)
        .chain(cell.robots.iter().map(|r| r.base.translation))
        .collect();
    let extent = |i: usize| {
        let v = points.iter().map(|p| p[i]);
        v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
    };
    if extent(1) > extent(0) { 1 } else { 0 }
}

/// The report page of a plan.
///
/// Fails (with a sentence) when the plan does not fit the cell: a robot missing, or other
/// joints.
pub fn plan_html(rep: &PlanReport) -> Result<String, String> {
    let (plan, cell, scene) = (rep.plan, rep.cell, rep.scene);
    let order = scene.match_plan(plan)?;
    let axis = long_axis(cell);
    let axis_name = ["x", "y"][axis];
    let t_end = charts::time_range(plan);

    // Probe tracks of the plan, thinned for the charts.
    let tracks_full: Vec<Vec<(f64, [f64; 3])>> = plan
        .robots
        .iter()
        .zip(&order)
        .map(|(rp, &k)| probe_track(&scene.robots[k], rp))
        .collect();
    let thin = |points: &[(f64, f64)]| -> Vec<(f64, f64)> {
        let step = points.len().div_ceil(CHART_POINTS).max(1);
        let mut v: Vec<(f64, f64)> = points.iter().step_by(step).copied().collect();
        if let Some(&last) = points.last()
            && v.last() != Some(&last)
        {
            v.push(last);
        }
        v
    };
    let after: Vec<Track> = plan
        .robots
        .iter()
        .enumerate()
        .map(|(r, rp)| Track {
            robot: r,
            name: &rp.name,
            points: thin(
                &tracks_full[r]
                    .iter()
                    .map(|&(t, p)| (t, p[axis]))
                    .collect::<Vec<_>>(),
            ),
        })
        .collect();
    let before: Vec<Track> = plan
        .coordination
        .uncoordinated_probe
        .iter()
        .filter_map(|b| {
            let r = plan.robots.iter().position(|rp| rp.name == b.robot)?;
            let points: Vec<(f64, f64)> = b
                .xyz
                .iter()
                .enumerate()
                .map(|(k, p)| (k as f64 * b.dt_s, p[axis]))
                .collect();
            Some(Track {
                robot: r,
                name: &plan.robots[r].name,
                points: thin(&points),
            })
        })
        .collect();

    let mut page = String::with_capacity(1 << 20);
    let title = format!("cellplan — {}", plan.cell);
    let _ = write!(
        page,
        r#"<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1"><title>{}</title><style>{CSS}</style></head><body><main>"#,
        escape(&title)
    );
    let _ = write!(
        page,
        r#"<h1>{}</h1><p class="sub">Plan of cell <b>{}</b> ({}){} — {} allocation, {} coordination, seed {}.</p>"#,
        escape(&title),
        escape(&plan.cell),
        escape(&plan.cell_file),
        rep.plan_file
            .map(|f| format!(", plan <code>{}</code>", escape(f)))
            .unwrap_or_default(),
        escape(&json_word(&plan.settings.allocation)),
        escape(&json_word(&plan.settings.coordination)),
        plan.settings.seed
    );
    summary(&mut page, rep);

    // 3D playback.
    let _ = write!(
        page,
        r#"<section id="viewer-section"><h2>Playback</h2><div class="viewer"><canvas id="view" aria-label="3D view of the cell"></canvas><div id="viewer-msg"></div></div><div class="controls"><button id="play" type="button">▶ play</button><input id="time" type="range" min="0" max="{t_end}" step="0.01" value="0" aria-label="time"><span id="clock">0.00 s</span><label>speed <select id="speed"><option value="0.5">0.5×</option><option value="1" selected>1×</option><option value="2">2×</option><option value="4">4×</option></select></label></div><div class="controls"><label><input type="checkbox" id="show-paths"> probe paths</label><label><input type="checkbox" id="show-before"> paths before coordination</label><label><input type="checkbox" id="show-conflicts"> conflicts before coordination</label><label><input type="checkbox" id="show-normals"> MPs and normals</label><button id="reset-view" type="button">reset view</button></div><div id="status"></div><p class="hint">Drag to turn, shift-drag or right-drag to pan, wheel to zoom; space plays and pauses; click a chart to jump to that time. MPs and paths are coloured by robot; red: unmeasured MPs and where conflicts were before coordination.</p></section>"#
    );

    let _ = write!(
        page,
        r#"<section id="gantt-section"><h2>Gantt chart</h2>{}</section>"#,
        charts::gantt(plan)
    );
    let conflicts = if plan.coordination.conflicts_after.is_empty() {
        &plan.coordination.conflicts_before
    } else {
        &plan.coordination.conflicts_after
    };
    let _ = write!(
        page,
        r#"<section id="timepos-section"><h2>Probe position over time (paper 000 Fig. 7/8)</h2>"#
    );
    if !before.is_empty() {
        page.push_str(&charts::time_position(
            "timepos-before",
            &format!(
                "Before coordination: {} conflict(s), cycle {:.2} s",
                plan.coordination.conflicts_before.len(),
                plan.coordination.uncoordinated_cycle_time_s
            ),
            &before,
            axis_name,
            axis,
            Marks::Conflicts(&plan.coordination.conflicts_before),
            t_end,
        ));
    }
    let after_title = if plan.coordination.conflicts_after.is_empty() {
        format!(
            "After coordination ({}): {} wait(s), {} pose(s) changed, cycle {:.2} s",
            json_word(&plan.coordination.strategy),
            plan.coordination.waits,
            plan.coordination.poses_changed,
            plan.cycle_time_s
        )
    } else {
        format!(
            "Not coordinated: {} conflict(s) left, cycle {:.2} s",
            plan.coordination.conflicts_after.len(),
            plan.cycle_time_s
        )
    };
    page.push_str(&charts::time_position(
        "timepos-after",
        &after_title,
        &after,
        axis_name,
        axis,
        if plan.coordination.conflicts_after.is_empty() {
            Marks::Resolution(plan)
        } else {
            Marks::Conflicts(&plan.coordination.conflicts_after)
        },
        t_end,
    ));
    page.push_str("</section>");
    details(&mut page, plan);

    let _ = write!(
        page,
        r#"<footer>Written by cellplan {} from the plan document (format {} v{}); the 3D view is drawn with the project's own WebGL2 code, from the cell's meshes ({} distinct, {} triangles drawn).</footer></main>"#,
        env!("CARGO_PKG_VERSION"),
        escape(&plan.format),
        plan.version,
        scene.geometries.len(),
        scene.drawn_triangles()
    );
    let data = viewer_data(plan, cell, scene, &order, &tracks_full, conflicts, t_end);
    // Names come from the cell file: `<`, `>` and `&` only occur inside JSON strings, where
    // their \u escapes read the same, and keep the HTML parser out of the script element's
    // text (`</script>`, `<!--`).
    let data = data
        .to_string()
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026");
    let _ = write!(
        page,
        r#"<script id="cellplan-data" type="application/json">{data}</script><script>{VIEWER}</script></body></html>"#
    );
    Ok(page)
}

/// A serde enum's wire name (`"balanced"`, `"pose-perturbation"`).
fn json_word<T: serde::Serialize>(v: &T) -> String {
    match serde_json::to_value(v) {
        Ok(Value::String(s)) => s,
        Ok(other) => other.to_string(),
        Err(_) => String::new(),
    }
}

fn figure(page: &mut String, value: &str, label: &str, class: &str) {
    let _ = write!(
        page,
        r#"<div class="figure"><b class="{class}">{value}</b><span>{label}</span></div>"#
    );
}

fn summary(page: &mut String, rep: &PlanReport) {
    let plan = rep.plan;
    page.push_str(r#"<section id="summary"><h2>Summary</h2><div class="figures">"#);
    figure(page, &format!("{:.2} s", plan.cycle_time_s), "cycle time", "");
    figure(
        page,
        &format!("{:.2} s", plan.delta_t_s),
        "Δt (longest − shortest)",
        "",
    );
    figure(
        page,
        &format!("{:.2} s", plan.lower_bound_s),
        &format!("lower bound (cycle ×{:.2})", plan.ratio_to_lower_bound),
        "",
    );
    figure(
        page,
        &format!("{:.2} s", plan.coordination.uncoordinated_cycle_time_s),
        "cycle before coordination",
        "",
    );
    figure(
        page,
        &format!(
            "{} / {}",
            plan.coordination.conflicts_before.len(),
            plan.stats.conflicts_resolved
        ),
        "conflicts found / resolved",
        "",
    );
    figure(
        page,
        &format!(
            "{} / {}",
            plan.coordination.waits, plan.coordination.poses_changed
        ),
        "waits / poses changed",
        "",
    );
    let (verdict, class, label) = match rep.verification {
        Some(v) if v.ok => ("verified".to_string(), "ok", "cellplan verify, now".to_string()),
        Some(v) => (
            format!("{} violation(s)", v.violations.len()),
            "bad",
            "cellplan verify, now".to_string(),
        ),
        None if plan.verified => ("verified".into(), "ok", "when planned".into()),
        None => ("not verified".into(), "bad", "written with --no-verify".into()),
    };
    figure(page, &verdict, &label, class);
    figure(page, &format!("{:.1} s", plan.compute_s.total), "compute", "");
    page.push_str("</div>");
    page.push_str(
        r#"<table id="robots"><tr><th>robot</th><th>MPs</th><th>moving s</th><th>measuring s</th><th>waiting s</th><th>total s</th><th class="text">MPs in order</th></tr>"#,
    );
    for (r, rp) in plan.robots.iter().enumerate() {
        let c = robot_colour(r).map(|x| (x * 255.0).round() as u8);
        let _ = write!(
            page,
            r#"<tr><td><span class="swatch" style="background:rgb({},{},{})"></span>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td class="text">{}</td></tr>"#,
            c[0],
            c[1],
            c[2],
            escape(&rp.name),
            rp.tasks.len(),
            rp.motion_s,
            rp.measuring_s,
            rp.waiting_s,
            rp.total_s,
            escape(
                &rp.tasks
                    .iter()
                    .map(|v| v.task.as_str())
                    .collect::<Vec<_>>()
                    .join(" → ")
            )
        );
    }
    page.push_str("</table>");
    if let Some(v) = rep.verification
        && !v.ok
    {
        page.push_str(r#"<h3 class="bad">Violations</h3><table><tr><th>what</th><th>robots</th><th>time s</th><th>MP</th><th class="text">detail</th></tr>"#);
        for x in &v.violations {
            let _ = write!(
                page,
                r#"<tr><td>{:?}</td><td>{}</td><td>{}</td><td>{}</td><td class="text">{}</td></tr>"#,
                x.kind,
                escape(
                    &[x.robot.as_deref(), x.other.as_deref()]
                        .into_iter()
                        .flatten()
                        .collect::<Vec<_>>()
                        .join(" & ")
                ),
                x.time_s.map(|t| format!("{t:.2}")).unwrap_or_default(),
                escape(x.task.as_deref().unwrap_or("")),
                escape(&x.detail)
            );
        }
        page.push_str("</table>");
    }
    page.push_str("</section>");
}

fn details(page: &mut String, plan: &Plan) {
    let c = &plan.coordination;
    page.push_str(r#"<section id="coordination"><h2>Coordination</h2>"#);
    let _ = write!(
        page,
        "<p>Strategy <b>{}</b>{}; {} conflict(s) in the programs before coordination, {} resolution(s), {:.1} s of compute.</p>",
        escape(&json_word(&c.strategy)),
        if c.priority.is_empty() {
            String::new()
        } else {
            format!(", priority {}", escape(&c.priority.join(" > ")))
        },
        c.conflicts_before.len(),
        plan.stats.conflicts_resolved,
        plan.compute_s.coordination
    );
    let list = if c.conflicts_after.is_empty() {
        &c.conflicts_before
    } else {
        &c.conflicts_after
    };
    if !list.is_empty() {
        page.push_str(r#"<table id="conflicts"><tr><th>#</th><th>robots</th><th>from s</th><th>to s</th><th>scenario</th><th class="text">what they were doing</th></tr>"#);
        for (k, x) in list.iter().enumerate() {
            let _ = write!(
                page,
                r#"<tr><td>C{}</td><td>{} &amp; {}</td><td>{:.2}</td><td>{:.2}</td><td>{}</td><td class="text">{}: {}; {}: {}</td></tr>"#,
                k + 1,
                escape(&x.robots[0]),
                escape(&x.robots[1]),
                x.start_s,
                x.end_s,
                if x.scenario == 1 {
                    "1: both measuring"
                } else {
                    "2: moving"
                },
                escape(&x.robots[0]),
                escape(&x.activity[0].text("measuring")),
                escape(&x.robots[1]),
                escape(&x.activity[1].text("measuring"))
            );
        }
        page.push_str("</table>");
    }
    let waits: Vec<_> = plan
        .robots
        .iter()
        .flat_map(|r| r.waits.iter().map(move |w| (r, w)))
        .collect();
    if !waits.is_empty() {
        page.push_str(r#"<table id="waits"><tr><th>robot</th><th class="text">where</th><th>from s</th><th>for s</th><th>reason</th><th>lets pass</th></tr>"#);
        for (r, w) in waits {
            let _ = write!(
                page,
                r#"<tr><td>{}</td><td class="text">{}</td><td>{:.2}</td><td>{:.2}</td><td>{}</td><td>{}</td></tr>"#,
                escape(&r.name),
                escape(&r.wait_place(w)),
                w.start_s,
                w.duration_s,
                w.reason,
                escape(w.for_robot.as_deref().unwrap_or(""))
            );
        }
        page.push_str("</table>");
    }
    page.push_str("</section>");
    if !plan.unmeasured.is_empty() {
        page.push_str(r#"<section id="unmeasured"><h2 class="bad">Unmeasured MPs</h2><table><tr><th>MP</th><th class="text">furthest check any probe pose passed</th></tr>"#);
        for u in &plan.unmeasured {
            let _ = write!(
                page,
                r#"<tr><td>{}</td><td class="text">{}</td></tr>"#,
                escape(&u.task),
                escape(&u.reason)
            );
        }
        page.push_str("</table></section>");
    }
    page.push_str(r#"<section id="settings"><h2>Settings</h2><table>"#);
    if let Ok(Value::Object(map)) = serde_json::to_value(&plan.settings) {
        for (k, v) in map {
            let v = match v {
                Value::String(s) => s,
                Value::Null => "—".into(),
                other => other.to_string(),
            };
            let _ = write!(
                page,
                r#"<tr><td>{}</td><td class="text">{}</td></tr>"#,
                escape(&k),
                escape(&v)
            );
        }
    }
    page.push_str("</table></section>");
}

fn viewer_data(
    plan: &Plan,
    cell: &Cell,
    scene: &Scene,
    order: &[usize],
    tracks: &[Vec<(f64, [f64; 3])>],
    conflicts: &[cellplan_core::document::ConflictOut],
    t_end: f64,
) -> Value {
    let geometries: Vec<Value> = scene
        .geometries
        .iter()
        .map(|g| {
            let flat: Vec<f32> = g.positions.iter().flatten().copied().collect();
            json!({"p": b64_f32(&flat), "i": b64_u32(&g.indices)})
        })
        .collect();
    let statics: Vec<Value> = scene
        .statics
        .iter()
        .map(|s| json!({"name": s.name, "g": s.placed.geometry, "pose": pose_json(&s.placed.pose), "colour": s.colour}))
        .collect();
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let mut grow = |p: DVec3| {
        lo = lo.min(p);
        hi = hi.max(p);
    };
    let robots: Vec<Value> = plan
        .robots
        .iter()
        .zip(order)
        .enumerate()
        .map(|(r, (rp, &k))| {
            let sr = &scene.robots[k];
            grow(sr.base.translation);
            let times: Vec<f32> = rp.trajectory.iter().map(|s| s.t as f32).collect();
            let q: Vec<f32> = rp
                .trajectory
                .iter()
                .flat_map(|s| s.q.iter().map(|&v| v as f32))
                .collect();
            let path: Vec<f32> = tracks[r]
                .iter()
                .flat_map(|(_, p)| {
                    grow(DVec3::from(*p));
                    p.map(|v| v as f32)
                })
                .collect();
            let before: Vec<f32> = plan
                .coordination
                .uncoordinated_probe
                .iter()
                .find(|b| b.robot == rp.name)
                .map(|b| b.xyz.iter().flat_map(|p| p.map(|v| v as f32)).collect())
                .unwrap_or_default();
            let links: Vec<Value> = sr
                .parts
                .iter()
                .enumerate()
                .map(|(i, parts)| {
                    let joint = sr.joint_of(i);
                    let axis = joint.map_or(cellplan_geom::DVec3::Z, |(_, jt)| jt.axis);
                    json!({
                        "o": pose_json(&sr.model.chain.links[i].origin),
                        "j": joint.map_or(-1, |(j, _)| j as i64),
                        "axis": [axis.x, axis.y, axis.z],
                        "prismatic": joint.is_some_and(|(_, jt)| !jt.is_rotational()),
                        "parts": parts.iter().map(|p| json!({"g": p.geometry, "pose": pose_json(&p.pose)})).collect::<Vec<_>>(),
                    })
                })
                .collect();
            let iv: Vec<Value> = intervals(rp)
                .iter()
                .map(|i| {
                    let what = match i.doing {
                        Doing::Moving => "moving".to_string(),
                        Doing::Measuring(v) => format!("measuring {}", rp.tasks[v].task),
                        Doing::Waiting(w) => format!(
                            "waiting{}",
                            rp.waits[w]
                                .for_robot
                                .as_deref()
                                .map(|f| format!(" for {f}"))
                                .unwrap_or_default()
                        ),
                    };
                    json!([round6(i.start), round6(i.end), what])
                })
                .collect();
            json!({
                "name": rp.name,
                "colour": robot_colour(r),
                "base": pose_json(&sr.base),
                "tcp": pose_json(&sr.tcp),
                "links": links,
                "dof": rp.joints.len(),
                "t": b64_f32(&times),
                "q": b64_f32(&q),
                "path": b64_f32(&path),
                "before": b64_f32(&before),
                "intervals": iv,
            })
        })
        .collect();
    let robot_of = |name: &str| {
        plan.robots
            .iter()
            .position(|rp| rp.tasks.iter().any(|v| v.task == name))
            .map_or(-1, |r| r as i64)
    };
    let tasks: Vec<Value> = cell
        .tasks
        .iter()
        .map(|t| {
            grow(t.position);
            let p = [t.position.x, t.position.y, t.position.z].map(round6);
            let n = [t.normal.x, t.normal.y, t.normal.z].map(round6);
            json!({
                "name": t.name,
                "p": p,
                "n": n,
                "r": robot_of(&t.name),
            })
        })
        .collect();
    let conflicts: Vec<Value> = conflicts
        .iter()
        .map(|c| json!({"robots": c.robots, "start": c.start_s, "end": c.end_s, "p": c.probe_xyz}))
        .collect();
    if !lo.is_finite() {
        (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
    }
    lo = lo.min(DVec3::new(lo.x, lo.y, 0.0)) - DVec3::splat(0.3);
    hi += DVec3::splat(0.3);
    // Look from the robots' side of the MPs, a little from the front.
    let centroid = |v: &mut dyn Iterator<Item = DVec3>| {
        let (s, n) = v.fold((DVec3::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
        s / n.max(1) as f64
    };
    let from = centroid(&mut cell.robots.iter().map(|r| r.base.translation))
        - centroid(&mut cell.tasks.iter().map(|t| t.position));
    let azimuth = if from.x.hypot(from.y) > 1e-6 {
        from.y.atan2(from.x) - 0.55
    } else {
        0.8
    };
    json!({
        "t_end": t_end,
        "cycle": plan.cycle_time_s,
        "geometries": geometries,
        "statics": statics,
        "robots": robots,
        "tasks": tasks,
        "conflicts": conflicts,
        "bounds": [[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]],
        "camera_azimuth": azimuth,
    })
}

/// One strategy's row in a comparison report.
pub struct CompareRow {
    /// Cells of the table row, as text.
    pub cells: Vec<String>,
    /// Whether it is our method's row (drawn bold).
    pub ours: bool,
}

/// The report page of `cellplan compare`: the strategy table and the bar chart of paper 000
/// Fig. 10.
pub fn compare_html(
    title: &str,
    intro: &str,
    header: &[String],
    rows: &[CompareRow],
    bars: &[StrategyBar],
    bound: Option<f64>,
) -> String {
    let mut page = String::new();
    let _ = write!(
        page,
        r#"<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1"><title>{}</title><style>{CSS}</style></head><body><main><h1>{}</h1><p class="sub">{}</p><section id="bars-section"><h2>Time per robot and cycle time (paper 000 Fig. 10)</h2>{}</section><section id="table-section"><h2>Strategies (paper 000 Table 3)</h2><table id="strategies"><tr>"#,
        escape(title),
        escape(title),
        escape(intro),
        charts::strategy_bars(bars, bound)
    );
    for (k, h) in header.iter().enumerate() {
        let _ = write!(
            page,
            "<th{}>{}</th>",
            if k == 0 { r#" class="text""# } else { "" },
            escape(h)
        );
    }
    page.push_str("</tr>");
    for row in rows {
        page.push_str("<tr>");
        for (k, c) in row.cells.iter().enumerate() {
            let text = if row.ours {
                format!("<b>{}</b>", escape(c))
            } else {
                escape(c)
            };
            let _ = write!(
                page,
                "<td{}>{text}</td>",
                if k == 0 { r#" class="text""# } else { "" }
            );
        }
        page.push_str("</tr>");
    }
    let _ = write!(
        page,
        r#"</table></section><footer>Written by cellplan {}.</footer></main></body></html>"#,
        env!("CARGO_PKG_VERSION")
    );
    page
}
