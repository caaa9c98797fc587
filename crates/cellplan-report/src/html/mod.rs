//! The self-contained HTML report of a plan (and of a strategy comparison): summary, Gantt
//! chart, time–position charts before and after coordination (paper 000 Fig. 7/8), and the 3D
//! playback of the cell (the project's own WebGL2 viewer, `viewer.js`). One file with no
//! outside references: it opens offline in any browser.
//!
//! The pages are [`maud`] templates (like the SVG charts of [`charts`]), which escape every
//! spliced value; only the report's own style sheet and script and the embedded JSON data
//! (escaped for a script element) go in as they are.
use super::charts::{self, Marks, StrategyBar, Track};
use super::playback::probe_track;
use super::scene::{Scene, robot_colour};
use cellplan_core::document::{ConflictOut, Plan};
use cellplan_geom::DVec3;
use cellplan_model::Cell;
use cellplan_verify as verify;
use maud::{DOCTYPE, Markup, PreEscaped, html};
use serde_json::Value;

mod viewer;
use viewer::viewer_data;

const CSS: &str = include_str!("../report.css");
const VIEWER: &str = include_str!("../viewer.js");

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

/// `<head>` of every page: the title and the report's style sheet.
pub(crate) fn head(title: &str) -> Markup {
    html! {
        head {
            meta charset="utf-8";
            meta name="viewport" content="width=device-width, initial-scale=1";
            title { (title) }
            style { (PreEscaped(CSS)) }
        }
    }
}

/// The chart tracks of a plan: each robot's probe position along `axis` over time, thinned
/// for the charts.
struct ChartTracks<'a> {
    /// The probe tracks before coordination (robots the plan recorded them for).
    before: Vec<Track<'a>>,
    /// The probe tracks of the plan.
    after: Vec<Track<'a>>,
}

/// At most [`CHART_POINTS`] of `points`, evenly, always keeping the last.
fn thin(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let step = points.len().div_ceil(CHART_POINTS).max(1);
    let mut v: Vec<(f64, f64)> = points.iter().step_by(step).copied().collect();
    if let Some(&last) = points.last()
        && v.last() != Some(&last)
    {
        v.push(last);
    }
    v
}

fn chart_tracks<'a>(plan: &'a Plan, tracks_full: &[Vec<(f64, [f64; 3])>], axis: usize) -> ChartTracks<'a> {
    let after = plan
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
    let before = plan
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
    ChartTracks { before, after }
}

/// The conflicts the page marks: those left after coordination, else those found before it.
fn shown_conflicts(plan: &Plan) -> &[ConflictOut] {
    let c = &plan.coordination;
    if c.conflicts_after.is_empty() {
        &c.conflicts_before
    } else {
        &c.conflicts_after
    }
}

/// The report page of a plan.
///
/// Fails (with a sentence) when the plan does not fit the cell: a robot missing, or other
/// joints.
pub fn plan_html(rep: &PlanReport) -> Result<String, crate::scene::Mismatch> {
    let (plan, cell, scene) = (rep.plan, rep.cell, rep.scene);
    let order = scene.match_plan(plan)?;
    let axis = long_axis(cell);
    let t_end = charts::time_range(plan);
    let tracks_full: Vec<Vec<(f64, [f64; 3])>> = plan
        .robots
        .iter()
        .zip(&order)
        .map(|(rp, &k)| probe_track(&scene.robots[k], rp))
        .collect();
    let tracks = chart_tracks(plan, &tracks_full, axis);
    let data = viewer_data(plan, cell, scene, &order, &tracks_full, t_end);
    let title = format!("cellplan — {}", plan.cell);
    let page = html! {
        (DOCTYPE)
        html lang="en" {
            (head(&title))
            body {
                main {
                    (heading(rep, &title))
                    (summary(rep))
                    (playback_section(t_end))
                    section id="gantt-section" {
                        h2 { "Gantt chart" }
                        (charts::gantt(plan))
                    }
                    (time_position_section(plan, &tracks, axis, t_end))
                    (coordination_section(plan))
                    (unmeasured_section(plan))
                    (settings_section(plan))
                    (plan_footer(plan, scene))
                }
                script id="cellplan-data" type="application/json" { (PreEscaped(script_json(&data))) }
                script { (PreEscaped(VIEWER)) }
            }
        }
    };
    Ok(page.into_string())
}

/// JSON to embed in a `<script>` element. Names come from the cell file: `<`, `>` and `&` only
/// occur inside JSON strings, where their \u escapes read the same, and keep the HTML parser
/// out of the script element's text (`</script>`, `<!--`).
fn script_json(data: &Value) -> String {
    data.to_string()
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026")
}

/// The page's title and the line under it: cell, plan file and settings.
fn heading(rep: &PlanReport, title: &str) -> Markup {
    let plan = rep.plan;
    html! {
        h1 { (title) }
        p class="sub" {
            "Plan of cell " b { (plan.cell) } " (" (plan.cell_file) ")"
            @if let Some(file) = rep.plan_file {
                ", plan " code { (file) }
            }
            " — " (plan.settings.allocation) " allocation, "
            (plan.settings.coordination) " coordination, seed "
            (plan.settings.seed) "."
        }
    }
}

/// The 3D view with its time slider, speed, layer switches and hint.
fn playback_section(t_end: f64) -> Markup {
    html! {
        section id="viewer-section" {
            h2 { "Playback" }
            div class="viewer" {
                canvas id="view" aria-label="3D view of the cell" {}
                div id="viewer-msg" {}
            }
            div class="controls" {
                button id="play" type="button" { "▶ play" }
                input id="time" type="range" min="0" max=(t_end) step="0.01" value="0" aria-label="time";
                span id="clock" { "0.00 s" }
                label {
                    "speed "
                    select id="speed" {
                        option value="0.5" { "0.5×" }
                        option value="1" selected { "1×" }
                        option value="2" { "2×" }
                        option value="4" { "4×" }
                    }
                }
            }
            div class="controls" {
                label { input type="checkbox" id="show-paths"; " probe paths" }
                label { input type="checkbox" id="show-before"; " paths before coordination" }
                label { input type="checkbox" id="show-conflicts"; " conflicts before coordination" }
                label { input type="checkbox" id="show-normals"; " MPs and normals" }
                button id="reset-view" type="button" { "reset view" }
            }
            div id="status" {}
            p class="hint" {
                "Drag to turn, shift-drag or right-drag to pan, wheel to zoom; space plays and \
                 pauses; click a chart to jump to that time. MPs and paths are coloured by robot; \
                 red: unmeasured MPs and where conflicts were before coordination."
            }
        }
    }
}

/// The time–position charts before (when the plan kept the tracks) and after coordination.
fn time_position_section(plan: &Plan, tracks: &ChartTracks, axis: usize, t_end: f64) -> Markup {
    let c = &plan.coordination;
    let axis_name = ["x", "y"][axis];
    let before_title = format!(
        "Before coordination: {} conflict(s), cycle {:.2} s",
        c.conflicts_before.len(),
        c.uncoordinated_cycle_time_s
    );
    let (after_title, after_marks) = if c.conflicts_after.is_empty() {
        let title = format!(
            "After coordination ({}): {} wait(s), {} pose(s) changed, cycle {:.2} s",
            c.strategy, c.waits, c.poses_changed, plan.cycle_time_s
        );
        (title, Marks::Resolution(plan))
    } else {
        let title = format!(
            "Not coordinated: {} conflict(s) left, cycle {:.2} s",
            c.conflicts_after.len(),
            plan.cycle_time_s
        );
        (title, Marks::Conflicts(&c.conflicts_after))
    };
    let chart = |id, title: &str, tracks: &[Track], marks| {
        charts::time_position(id, title, tracks, axis_name, axis, marks, t_end)
    };
    html! {
        section id="timepos-section" {
            h2 { "Probe position over time (paper 000 Fig. 7/8)" }
            @if !tracks.before.is_empty() {
                (chart("timepos-before", &before_title, &tracks.before, Marks::Conflicts(&c.conflicts_before)))
            }
            (chart("timepos-after", &after_title, &tracks.after, after_marks))
        }
    }
}

/// The page's last line: version, document format and what the 3D view draws.
fn plan_footer(plan: &Plan, scene: &Scene) -> Markup {
    html! {
        footer {
            "Written by cellplan " (env!("CARGO_PKG_VERSION")) " from the plan document (format "
            (plan.format) " v" (plan.version) "); the 3D view is drawn with the project's own \
            WebGL2 code, from the cell's meshes (" (scene.geometries.len()) " distinct, "
            (scene.drawn_triangles()) " triangles drawn)."
        }
    }
}

/// One headline figure: a value over its label.
fn figure(value: impl maud::Render, label: impl maud::Render, class: &str) -> Markup {
    html! {
        div class="figure" { b class=(class) { (value) } span { (label) } }
    }
}

/// The summary: headline figures, the robot table, and the verifier's violations if any.
fn summary(rep: &PlanReport) -> Markup {
    html! {
        section id="summary" {
            h2 { "Summary" }
            (figures(rep))
            (robot_table(rep.plan))
            @if let Some(v) = rep.verification && !v.ok {
                (violation_table(v))
            }
        }
    }
}

/// The verifier's verdict as a figure: its value, class and label.
fn verdict(rep: &PlanReport) -> (String, &'static str, &'static str) {
    match rep.verification {
        Some(v) if v.ok => ("verified".into(), "ok", "cellplan verify, now"),
        Some(v) => (
            format!("{} violation(s)", v.violations.len()),
            "bad",
            "cellplan verify, now",
        ),
        None if rep.plan.verified => ("verified".into(), "ok", "when planned"),
        None => ("not verified".into(), "bad", "written with --no-verify"),
    }
}

fn figures(rep: &PlanReport) -> Markup {
    let plan = rep.plan;
    let c = &plan.coordination;
    let seconds = |v: f64| format!("{v:.2} s");
    let (verdict, class, label) = verdict(rep);
    // With `--route-bound`, the bound stated may come from whole programs.
    let bound_label = match &plan.route_bound {
        Some(r) if r.bound_s > r.legs_s => format!(
            "lower bound from whole programs (legs alone: {:.2} s; cycle ×{:.2})",
            r.legs_s, plan.ratio_to_lower_bound
        ),
        _ => format!("lower bound (cycle ×{:.2})", plan.ratio_to_lower_bound),
    };
    html! {
        div class="figures" {
            (figure(seconds(plan.cycle_time_s), "cycle time", ""))
            (figure(seconds(plan.delta_t_s), "Δt (longest − shortest)", ""))
            (figure(seconds(plan.lower_bound_s), bound_label, ""))
            (figure(seconds(c.uncoordinated_cycle_time_s), "cycle before coordination", ""))
            (figure(
                format_args!("{} / {}", c.conflicts_before.len(), plan.stats.conflicts_resolved),
                "conflicts found / resolved",
                "",
            ))
            (figure(format_args!("{} / {}", c.waits, c.poses_changed), "waits / poses changed", ""))
            (figure(verdict, label, class))
            (figure(format_args!("{:.1} s", plan.compute_s.total), "compute", ""))
        }
    }
}

/// Per robot: its colour, MPs, times, and MPs in order.
fn robot_table(plan: &Plan) -> Markup {
    html! {
        table id="robots" {
            tr {
                th { "robot" } th { "MPs" } th { "moving s" } th { "measuring s" }
                th { "waiting s" } th { "total s" } th class="text" { "MPs in order" }
            }
            @for (r, rp) in plan.robots.iter().enumerate() {
                @let c = robot_colour(r).map(|x| (x * 255.0).round() as u8);
                @let order = rp.tasks.iter().map(|v| v.task.as_str()).collect::<Vec<_>>();
                tr {
                    td {
                        span class="swatch" style={ "background:rgb(" (c[0]) "," (c[1]) "," (c[2]) ")" } {}
                        (rp.name)
                    }
                    td { (rp.tasks.len()) }
                    td { (format_args!("{:.2}", rp.motion_s)) }
                    td { (format_args!("{:.2}", rp.measuring_s)) }
                    td { (format_args!("{:.2}", rp.waiting_s)) }
                    td { (format_args!("{:.2}", rp.total_s)) }
                    td class="text" { (order.join(" → ")) }
                }
            }
        }
    }
}

fn violation_table(v: &verify::Report) -> Markup {
    html! {
        h3 class="bad" { "Violations" }
        table {
            tr {
                th { "what" } th { "robots" } th { "time s" } th { "MP" }
                th class="text" { "detail" }
            }
            @for x in &v.violations {
                @let robots = [x.robot.as_deref(), x.other.as_deref()].into_iter().flatten().collect::<Vec<_>>();
                tr {
                    td { (format_args!("{:?}", x.kind)) }
                    td { (robots.join(" & ")) }
                    td { @if let Some(t) = x.time_s { (format_args!("{t:.2}")) } }
                    td { (x.task.as_deref().unwrap_or("")) }
                    td class="text" { (x.detail) }
                }
            }
        }
    }
}

/// The coordination: strategy, priority, the conflicts and the waits.
fn coordination_section(plan: &Plan) -> Markup {
    let c = &plan.coordination;
    html! {
        section id="coordination" {
            h2 { "Coordination" }
            p {
                "Strategy " b { (c.strategy) }
                @if !c.priority.is_empty() { ", priority " (c.priority.join(" > ")) }
                "; " (c.conflicts_before.len()) " conflict(s) in the programs before coordination, "
                (plan.stats.conflicts_resolved) " resolution(s), " (format_args!("{:.1}", plan.compute_s.coordination))
                " s of compute."
            }
            @let conflicts = shown_conflicts(plan);
            @if !conflicts.is_empty() { (conflict_table(conflicts)) }
            (wait_table(plan))
        }
    }
}

fn conflict_table(list: &[ConflictOut]) -> Markup {
    html! {
        table id="conflicts" {
            tr {
                th { "#" } th { "robots" } th { "from s" } th { "to s" } th { "scenario" }
                th class="text" { "what they were doing" }
            }
            @for (k, x) in list.iter().enumerate() {
                tr {
                    td { "C" (k + 1) }
                    td { (x.robots[0]) " & " (x.robots[1]) }
                    td { (format_args!("{:.2}", x.start_s)) }
                    td { (format_args!("{:.2}", x.end_s)) }
                    td { @if x.scenario == 1 { "1: both measuring" } @else { "2: moving" } }
                    td class="text" {
                        (x.robots[0]) ": " (x.activity[0].text("measuring")) "; " (x.robots[1]) ": " (x.activity[1].text("measuring"))
                    }
                }
            }
        }
    }
}

fn wait_table(plan: &Plan) -> Markup {
    let waits: Vec<_> = plan
        .robots
        .iter()
        .flat_map(|r| r.waits.iter().map(move |w| (r, w)))
        .collect();
    html! {
        @if !waits.is_empty() {
            table id="waits" {
                tr {
                    th { "robot" } th class="text" { "where" } th { "from s" } th { "for s" }
                    th { "reason" } th { "lets pass" }
                }
                @for (r, w) in waits {
                    tr {
                        td { (r.name) }
                        td class="text" { (r.wait_place(w)) }
                        td { (format_args!("{:.2}", w.start_s)) }
                        td { (format_args!("{:.2}", w.duration_s)) }
                        td { (w.reason) }
                        td { (w.for_robot.as_deref().unwrap_or("")) }
                    }
                }
            }
        }
    }
}

/// The MPs no robot measures, with the furthest check any probe pose passed; the robots that
/// can measure none.
fn unmeasured_section(plan: &Plan) -> Markup {
    html! {
        @if !plan.unmeasured.is_empty() {
            section id="unmeasured" {
                h2 class="bad" { "Unmeasured MPs" }
                table {
                    tr { th { "MP" } th class="text" { "furthest check any probe pose passed" } }
                    @for u in &plan.unmeasured {
                        tr { td { (u.task) } td class="text" { (u.reason) } }
                    }
                }
            }
        }
        @if !plan.idle_robots.is_empty() {
            section id="idle" {
                h2 { "Idle robots" }
                p { "These robots can do none of the MPs: they stay at home, and Δt leaves them out." }
                table {
                    tr { th { "robot" } th class="text" { "why" } }
                    @for i in &plan.idle_robots {
                        tr { td { (i.robot) } td class="text" { (i.reason) } }
                    }
                }
            }
        }
    }
}

/// The plan's settings as a table of their wire names and values.
fn settings_section(plan: &Plan) -> Markup {
    let rows: Vec<(String, String)> = match serde_json::to_value(&plan.settings) {
        Ok(Value::Object(map)) => map
            .into_iter()
            .map(|(k, v)| {
                let v = match v {
                    Value::String(s) => s,
                    Value::Null => "—".into(),
                    other => other.to_string(),
                };
                (k, v)
            })
            .collect(),
        _ => Vec::new(),
    };
    html! {
        section id="settings" {
            h2 { "Settings" }
            table {
                @for (k, v) in &rows {
                    tr { td { (k) } td class="text" { (v) } }
                }
            }
        }
    }
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
    let first = |k: usize| (k == 0).then_some("text");
    html! {
        (DOCTYPE)
        html lang="en" {
            (head(title))
            body {
                main {
                    h1 { (title) }
                    p class="sub" { (intro) }
                    section id="bars-section" {
                        h2 { "Time per robot and cycle time (paper 000 Fig. 10)" }
                        (charts::strategy_bars(bars, bound))
                    }
                    section id="table-section" {
                        h2 { "Strategies (paper 000 Table 3)" }
                        table id="strategies" {
                            tr { @for (k, h) in header.iter().enumerate() { th class=[first(k)] { (h) } } }
                            @for row in rows {
                                tr {
                                    @for (k, c) in row.cells.iter().enumerate() {
                                        td class=[first(k)] { @if row.ours { b { (c) } } @else { (c) } }
                                    }
                                }
                            }
                        }
                    }
                    footer { "Written by cellplan " (env!("CARGO_PKG_VERSION")) "." }
                }
            }
        }
    }
    .into_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Text from outside (cell, robot and strategy names, labels) is escaped wherever the page
    /// puts it.
    #[test]
    fn the_compare_page_escapes_what_it_is_given() {
        let page = compare_html(
            "cell <a>",
            "MPs & \"robots\"",
            &["<th>".into(), "x".into()],
            &[CompareRow {
                cells: vec!["</td>".into(), "1".into()],
                ours: true,
            }],
            &[StrategyBar {
                label: "<b>".into(),
                robots: vec![("R&1".into(), 1.0)],
                cycle_time_s: 1.0,
                spread_s: None,
            }],
            None,
        );
        assert!(page.starts_with("<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">"));
        assert!(page.contains("<title>cell &lt;a&gt;</title>"));
        assert!(page.contains("<h1>cell &lt;a&gt;</h1><p class=\"sub\">MPs &amp; &quot;robots&quot;</p>"));
        assert!(page.contains("<tr><th class=\"text\">&lt;th&gt;</th><th>x</th></tr>"));
        assert!(page.contains("<tr><td class=\"text\"><b>&lt;/td&gt;</b></td><td><b>1</b></td></tr>"));
        assert!(page.contains("<title>&lt;b&gt;: R&amp;1 1.00 s</title>"));
        assert!(page.ends_with("</footer></main></body></html>"));
    }

    /// The data for the viewer cannot end its script element or open a comment, and reads back
    /// the same.
    #[test]
    fn script_json_keeps_markup_out_and_reads_back() {
        let data = serde_json::json!({"name": "</script><!-- & -->"});
        let text = script_json(&data);
        assert!(!text.contains(['<', '>', '&']), "{text}");
        assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), data);
    }
}
