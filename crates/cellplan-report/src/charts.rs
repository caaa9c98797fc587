//! The report's charts as SVG: the Gantt chart of every robot's activities, the time–position
//! chart of paper 000 Fig. 7/8, and the strategy bar chart of Fig. 10.
//!
//! Charts that share the plan's clock carry `data-t0`, `data-t1`, `data-x0`, `data-x1` (the
//! time range and the horizontal pixel range it maps to) and a `line.cursor`, so the page's
//! script can move a time cursor over them and turn a click into a time.
//!
//! They are [`maud`] templates for the HTML page (every name spliced in is escaped); empty SVG
//! elements are written with an end tag (`<line …></line>`), which HTML reads like `<line …/>`.
use super::playback::{Doing, intervals};
use super::svg::ROBOT_COLOURS;
use cellplan_core::document::{ConflictOut, Plan, RobotPlan};
use maud::{Markup, html};
use std::fmt::Write;

/// Width of every chart (SVG user units, drawn at 100 % of the page column).
pub const WIDTH: f64 = 960.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 16.0;
const WAIT_COLOUR: &str = "#d62728";

fn colour(r: usize) -> &'static str {
    ROBOT_COLOURS[r % ROBOT_COLOURS.len()]
}

/// A coordinate with one decimal.
fn f1(v: f64) -> String {
    format!("{v:.1}")
}

/// A coordinate or a time with two decimals.
fn f2(v: f64) -> String {
    format!("{v:.2}")
}

/// A step of 1, 2 or 5 × 10^k that cuts `span` into about `target` pieces.
pub fn nice_step(span: f64, target: usize) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / target.max(1) as f64;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// Ticks from `first` to `last` by `step` (their count less one): at most 200, none when the
/// range is not finite.
fn ticks(first: f64, last: f64, step: f64) -> usize {
    let n = ((last - first) / step + 1e-9).floor();
    if n.is_finite() && n >= 0.0 {
        (n as usize).min(200)
    } else {
        0
    }
}

/// A linear map from data to pixels.
#[derive(Clone, Copy)]
struct Axis {
    d0: f64,
    d1: f64,
    p0: f64,
    p1: f64,
}

impl Axis {
    fn at(&self, d: f64) -> f64 {
        let span = self.d1 - self.d0;
        if span.abs() < 1e-12 {
            return self.p0;
        }
        self.p0 + (d - self.d0) / span * (self.p1 - self.p0)
    }
}

/// Ticks and labels of a time axis at the bottom (`y`) and vertical grid lines up to `top`.
fn time_axis(x: Axis, top: f64, y: f64) -> Markup {
    let step = nice_step(x.d1 - x.d0, 12);
    html! {
        @for k in 0..=ticks(0.0, x.d1, step) {
            @let t = k as f64 * step;
            @let px = f1(x.at(t));
            line x1=(px) y1=(f1(top)) x2=(px) y2=(f1(y)) class="grid" {}
            text x=(px) y=(f1(y + 14.0)) class="tick" text-anchor="middle" { (trim(t)) }
        }
        text x=(f1((x.p0 + x.p1) / 2.0)) y=(f1(y + 30.0)) class="label" text-anchor="middle" { "time (s)" }
    }
}

/// A number without trailing zeros.
fn trim(v: f64) -> String {
    let s = format!("{v:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Ticks, labels and horizontal grid lines of a vertical value axis on the left, and its
/// label turned along it.
fn value_axis(y: Axis, label: &str) -> Markup {
    let step = nice_step(y.d1 - y.d0, 6);
    let first = (y.d0 / step).ceil() * step;
    html! {
        @for k in 0..=ticks(first, y.d1, step) {
            @let v = first + k as f64 * step;
            @let py = y.at(v);
            line x1=(LEFT) y1=(f1(py)) x2=(f1(WIDTH - RIGHT)) y2=(f1(py)) class="grid" {}
            text x=(f1(LEFT - 6.0)) y=(f1(py + 4.0)) class="tick" text-anchor="end" { (trim(v)) }
        }
        text transform={ "translate(16 " (f1((y.p0 + y.p1) / 2.0)) ") rotate(-90)" } class="label" text-anchor="middle" {
            (label)
        }
    }
}

/// The `viewBox` of a chart `height` units high.
fn view_box(height: f64) -> String {
    format!("0 0 {WIDTH} {height:.0}")
}

/// The time range every chart of a plan shares: 0 to the cycle time (or the longest
/// uncoordinated program, if longer).
pub fn time_range(plan: &Plan) -> f64 {
    let before = plan
        .coordination
        .uncoordinated_probe
        .iter()
        .map(|p| p.dt_s * p.xyz.len().saturating_sub(1) as f64)
        .fold(0.0, f64::max);
    plan.robots
        .iter()
        .map(|r| r.end_s)
        .fold(plan.cycle_time_s, f64::max)
        .max(before)
        .max(1e-3)
}

/// Gantt chart: a row per robot with its moving, measuring and waiting intervals (each with a
/// tooltip), the cycle time and the lower bound.
pub fn gantt(plan: &Plan) -> Markup {
    let row = 30.0;
    let top = 26.0;
    let height = top + row * plan.robots.len() as f64 + 44.0;
    let x = Axis {
        d0: 0.0,
        d1: time_range(plan),
        p0: LEFT,
        p1: WIDTH - RIGHT,
    };
    let bottom = top + row * plan.robots.len() as f64;
    let legend_items = [
        ("moving", "#888", 0.35),
        ("measuring", "#888", 1.0),
        ("waiting for another robot", WAIT_COLOUR, 0.9),
    ];
    html! {
        svg id="gantt" class="chart clock" viewBox=(view_box(height))
            data-t0=(x.d0) data-t1=(x.d1) data-x0=(x.p0) data-x1=(x.p1)
            xmlns="http://www.w3.org/2000/svg" role="img" aria-label="Gantt chart of every robot's activities" {
            (time_axis(x, top - 6.0, bottom))
            @for (r, rp) in plan.robots.iter().enumerate() {
                (gantt_row(x, r, rp, top + row * r as f64, row))
            }
            (gantt_marks(plan, x, top, bottom))
            (legend(LEFT, height - 6.0, &legend_items))
            line class="cursor" x1=(LEFT) y1=(f1(top - 6.0)) x2=(LEFT) y2=(f1(bottom)) {}
        }
    }
}

/// A robot's row of the Gantt chart: its name and a bar per interval, with a tooltip.
fn gantt_row(x: Axis, r: usize, rp: &RobotPlan, y: f64, row: f64) -> Markup {
    html! {
        text x=(f1(LEFT - 8.0)) y=(f1(y + row / 2.0 + 4.0)) class="name" text-anchor="end" { (rp.name) }
        @for iv in intervals(rp) {
            @let (fill, opacity, what) = interval_look(r, rp, iv.doing);
            rect class=(iv.doing.word()) x=(f2(x.at(iv.start))) y=(f1(y + 4.0))
                width=(f2((x.at(iv.end) - x.at(iv.start)).max(0.5))) height=(f1(row - 8.0))
                fill=(fill) fill-opacity=(opacity) {
                title { (rp.name) " " (what) ": " (f2(iv.start)) "–" (f2(iv.end)) " s" }
            }
        }
    }
}

/// The fill, opacity and tooltip words of an interval of robot `r`.
fn interval_look(r: usize, rp: &RobotPlan, doing: Doing) -> (&'static str, f64, String) {
    match doing {
        Doing::Moving => (colour(r), 0.35, "moving".to_string()),
        Doing::Measuring(k) => (colour(r), 1.0, format!("measuring {}", rp.tasks[k].task)),
        Doing::Waiting(k) => {
            let w = &rp.waits[k];
            let whom = w
                .for_robot
                .as_deref()
                .map(|f| format!(" for {f}"))
                .unwrap_or_default();
            (
                WAIT_COLOUR,
                0.9,
                format!("waiting ({}){whom} at {}", w.reason, rp.wait_place(w)),
            )
        }
    }
}

/// The cycle time and the lower bound as vertical lines over the Gantt rows.
fn gantt_marks(plan: &Plan, x: Axis, top: f64, bottom: f64) -> Markup {
    let marks = [
        (plan.cycle_time_s, "cycle", "cycle", "end"),
        (plan.lower_bound_s, "bound", "lower bound", "start"),
    ];
    html! {
        @for (t, class, label, anchor) in marks {
            @if t > 0.0 && t <= x.d1 + 1e-9 {
                @let px = f1(x.at(t));
                line x1=(px) y1=(f1(top - 8.0)) x2=(px) y2=(f1(bottom)) class=(class) {}
                text x=(px) y=(f1(top - 12.0)) class={ "tick " (class) } text-anchor=(anchor) {
                    (label) " " (f2(t)) " s"
                }
            }
        }
    }
}

/// Legend entries from `x0` along `y`: a swatch and a label each.
fn legend(x0: f64, y: f64, items: &[(&str, &str, f64)]) -> Markup {
    let xs = items.iter().scan(x0, |x, (label, _, _)| {
        let here = *x;
        *x += 30.0 + 6.5 * label.chars().count() as f64;
        Some(here)
    });
    html! {
        @for (x, (label, fill, opacity)) in xs.zip(items) {
            rect x=(f1(x)) y=(f1(y - 9.0)) width="14" height="10" fill=(fill) fill-opacity=(opacity) {}
            text x=(f1(x + 18.0)) y=(f1(y)) class="tick" { (label) }
        }
    }
}

/// One robot's probe positions along the chart's axis over time.
pub struct Track<'a> {
    /// Robot index (colour).
    pub robot: usize,
    /// Name.
    pub name: &'a str,
    /// `(t, position along the axis)`.
    pub points: Vec<(f64, f64)>,
}

/// What a time–position chart marks.
pub enum Marks<'a> {
    /// Conflicts (before coordination, or left by strategy `none`).
    Conflicts(&'a [ConflictOut]),
    /// The plan's waits and changed poses (after coordination).
    Resolution(&'a Plan),
}

/// Time–position chart (paper 000 Fig. 7/8): each robot's probe position along `axis_name`
/// against time, one line per robot, with conflicts or waits marked.
pub fn time_position(
    id: &str,
    title: &str,
    tracks: &[Track],
    axis_name: &str,
    axis: usize,
    marks: Marks,
    t_end: f64,
) -> Markup {
    let (top, plot_h) = (30.0, 300.0);
    let height = top + plot_h + 64.0;
    let (mut lo, mut hi) = tracks
        .iter()
        .flat_map(|t| t.points.iter().map(|p| p.1))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        (lo, hi) = (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.06).max(0.05);
    let y = Axis {
        d0: lo - pad,
        d1: hi + pad,
        p0: top + plot_h,
        p1: top,
    };
    let x = Axis {
        d0: 0.0,
        d1: t_end,
        p0: LEFT,
        p1: WIDTH - RIGHT,
    };
    let chart = TimePosition { x, y, pad, axis };
    html! {
        svg id=(id) class="chart clock timepos" viewBox=(view_box(height))
            data-t0=(x.d0) data-t1=(x.d1) data-x0=(x.p0) data-x1=(x.p1)
            xmlns="http://www.w3.org/2000/svg" role="img" aria-label=(title) {
            text x=(LEFT) y="16" class="title" { (title) }
            (time_axis(x, top, top + plot_h))
            (value_axis(y, &format!("probe {axis_name} (m)")))
            // Marks under the lines.
            @match marks {
                Marks::Conflicts(conflicts) => (chart.conflicts(conflicts)),
                Marks::Resolution(plan) => (chart.resolution(plan, tracks)),
            }
            @for tr in tracks {
                path class="track" d=(chart.track_path(tr)) stroke=(colour(tr.robot)) { title { (tr.name) } }
            }
            (track_legend(tracks, &marks, height))
            line class="cursor" x1=(LEFT) y1=(top) x2=(LEFT) y2=(f1(top + plot_h)) {}
        }
    }
}

/// The axes of a time–position chart, the padding of its value range, and the axis (0: x,
/// 1: y) of the probe position it draws.
struct TimePosition {
    x: Axis,
    y: Axis,
    pad: f64,
    axis: usize,
}

impl TimePosition {
    /// A box per conflict over its time and the two probes' positions, labelled `C1`, `C2`…
    fn conflicts(&self, conflicts: &[ConflictOut]) -> Markup {
        let (x, y, pad) = (self.x, self.y, self.pad);
        html! {
            @for (k, c) in conflicts.iter().enumerate() {
                @let (a, b) = (c.probe_xyz[0][self.axis], c.probe_xyz[1][self.axis]);
                @let (x0, x1) = (x.at(c.start_s), x.at(c.end_s.max(c.start_s)));
                @let (y0, y1) = (y.at(a.max(b) + pad * 0.5), y.at(a.min(b) - pad * 0.5));
                g class="conflict" {
                    rect x=(f1(x0 - 3.0)) y=(f1(y0)) width=(f1((x1 - x0) + 6.0)) height=(f1((y1 - y0).max(6.0))) rx="6" {}
                    text x=(f1(x0)) y=(f1(y0 - 4.0)) class="tick conflict-label" { "C" (k + 1) }
                    title {
                        "C" (k + 1) ": " (c.robots[0]) " & " (c.robots[1]) ", " (f2(c.start_s)) "–"
                        (f2(c.end_s)) " s, scenario " (c.scenario) " — " (c.activity[0].text("measuring")) " / "
                        (c.activity[1].text("measuring"))
                    }
                }
            }
        }
    }

    /// The plan's waits (on the waiting robot's track) and its perturbed poses.
    fn resolution(&self, plan: &Plan, tracks: &[Track]) -> Markup {
        let (x, y) = (self.x, self.y);
        html! {
            @for rp in &plan.robots {
                @if let Some(track) = tracks.iter().find(|t| t.name == rp.name) {
                    @for w in &rp.waits {
                        @let py = y.at(track_at(track, w.start_s));
                        g class="wait" {
                            rect x=(f1(x.at(w.start_s))) y=(f1(py - 6.0))
                                width=(f1((x.at(w.start_s + w.duration_s) - x.at(w.start_s)).max(2.0)))
                                height="12" rx="3" {}
                            title { (rp.name) " waits " (f2(w.duration_s)) " s at " (rp.wait_place(w)) " (" (w.reason) ")" }
                        }
                    }
                    @for v in rp.tasks.iter().filter(|v| v.perturbation_rad.is_some()) {
                        @let (px, py) = (x.at(v.arrive_s), y.at(v.tcp.xyz[self.axis]));
                        g class="perturbed" {
                            path d={ "M" (f1(px - 6.0)) " " (f1(py)) " l6 -6 l6 6 l-6 6 z" } {}
                            title { (rp.name) ": probe orientation at " (v.task) " perturbed" }
                        }
                    }
                }
            }
        }
    }

    /// The SVG path of a track.
    fn track_path(&self, tr: &Track) -> String {
        let mut d = String::new();
        for (k, &(t, p)) in tr.points.iter().enumerate() {
            let _ = write!(
                d,
                "{}{:.1} {:.1}",
                if k == 0 { "M" } else { " L" },
                self.x.at(t),
                self.y.at(p)
            );
        }
        d
    }
}

/// The track's position at time `t` (its last point at or before `t`).
fn track_at(track: &Track, t: f64) -> f64 {
    let k = track.points.partition_point(|p| p.0 <= t).saturating_sub(1);
    track.points.get(k).map_or(0.0, |p| p.1)
}

/// The legend of a time–position chart: a line per robot, then what the marks mean.
fn track_legend(tracks: &[Track], marks: &Marks, height: f64) -> Markup {
    let xs: Vec<f64> = tracks
        .iter()
        .scan(LEFT, |lx, tr| {
            let here = *lx;
            *lx += 40.0 + 7.0 * tr.name.chars().count() as f64;
            Some(here)
        })
        .collect();
    let end = tracks
        .last()
        .zip(xs.last())
        .map_or(LEFT, |(tr, lx)| lx + 40.0 + 7.0 * tr.name.chars().count() as f64);
    let extra: &[(&str, &str, f64)] = match marks {
        Marks::Conflicts(_) => &[("conflict (robots closer than the clearance)", WAIT_COLOUR, 0.35)],
        Marks::Resolution(_) => &[("wait", WAIT_COLOUR, 0.8), ("perturbed pose ◆", "#000", 0.0)],
    };
    html! {
        @for (tr, lx) in tracks.iter().zip(&xs) {
            line x1=(f1(*lx)) y1=(f1(height - 10.0)) x2=(f1(lx + 18.0)) y2=(f1(height - 10.0))
                stroke=(colour(tr.robot)) stroke-width="3" {}
            text x=(f1(lx + 22.0)) y=(f1(height - 6.0)) class="tick" { (tr.name) }
        }
        (legend(end + 10.0, height - 6.0, extra))
    }
}

/// One strategy's result for the bar chart.
pub struct StrategyBar {
    /// Label (allocation + coordination).
    pub label: String,
    /// Per robot time (s).
    pub robots: Vec<(String, f64)>,
    /// Cycle time (s).
    pub cycle_time_s: f64,
    /// Spread of the cycle time over cases (s), for studies over several MP sets.
    pub spread_s: Option<f64>,
}

/// Bar chart like paper 000 Fig. 10: per strategy a group of bars, one per robot, and the cycle
/// time marked above each group (with its spread when given); `bound` draws a dashed line.
pub fn strategy_bars(bars: &[StrategyBar], bound: Option<f64>) -> Markup {
    let (top, plot_h) = (20.0, 260.0);
    let height = top + plot_h + 120.0;
    let t_max = bars
        .iter()
        .map(|b| {
            b.robots
                .iter()
                .map(|r| r.1)
                .fold(b.cycle_time_s + b.spread_s.unwrap_or(0.0), f64::max)
        })
        .fold(bound.unwrap_or(0.0), f64::max)
        .max(1e-3)
        * 1.08;
    let y = Axis {
        d0: 0.0,
        d1: t_max,
        p0: top + plot_h,
        p1: top,
    };
    let group = (WIDTH - LEFT - RIGHT) / bars.len().max(1) as f64;
    html! {
        svg id="strategy-bars" class="chart" viewBox=(view_box(height))
            xmlns="http://www.w3.org/2000/svg" role="img" aria-label="time per robot and cycle time per strategy" {
            (value_axis(y, "time (s)"))
            @for (g, b) in bars.iter().enumerate() {
                (bar_group(b, y, LEFT + group * g as f64, group, top + plot_h))
            }
            @if let Some(lb) = bound {
                @let py = f1(y.at(lb));
                line class="bound" x1=(LEFT) y1=(py) x2=(f1(WIDTH - RIGHT)) y2=(py) {}
                text x=(f1(WIDTH - RIGHT)) y=(f1(y.at(lb) - 4.0)) class="tick bound" text-anchor="end" {
                    "lower bound " (f2(lb)) " s"
                }
            }
        }
    }
}

/// One strategy's group of bars from `x0`, `group` wide: a bar per robot, the cycle time (and
/// its spread) above them, and the label under the plot's `bottom`.
fn bar_group(b: &StrategyBar, y: Axis, x0: f64, group: f64, bottom: f64) -> Markup {
    let n = b.robots.len().max(1) as f64;
    let w = (group * 0.8) / n;
    let py = y.at(b.cycle_time_s);
    let cx = x0 + group / 2.0;
    html! {
        @for (r, (name, t)) in b.robots.iter().enumerate() {
            rect class="bar" x=(f1(x0 + group * 0.1 + w * r as f64)) y=(f1(y.at(*t)))
                width=(f1((w - 1.0).max(1.0))) height=(f1(y.at(0.0) - y.at(*t))) fill=(colour(r)) {
                title { (b.label) ": " (name) " " (f2(*t)) " s" }
            }
        }
        line class="cycle" x1=(f1(x0 + group * 0.05)) y1=(f1(py)) x2=(f1(x0 + group * 0.95)) y2=(f1(py)) {}
        text x=(f1(cx)) y=(f1(py - 5.0 - if b.spread_s.is_some() { 8.0 } else { 0.0 }))
            class="tick" text-anchor="middle" { (f2(b.cycle_time_s)) }
        @if let Some(sd) = b.spread_s {
            @let (a, c) = (f1(y.at(b.cycle_time_s - sd)), f1(y.at(b.cycle_time_s + sd)));
            path class="spread" d={
                "M" (f1(cx)) " " (a) " V" (c) " M" (f1(cx - 4.0)) " " (a) " h8 M" (f1(cx - 4.0)) " " (c) " h8"
            } {}
        }
        text transform={ "translate(" (f1(x0 + group * 0.2)) " " (f1(bottom + 14.0)) ") rotate(30)" } class="tick" {
            (b.label)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_are_one_two_five() {
        assert_eq!(nice_step(30.0, 12), 5.0);
        assert_eq!(nice_step(10.0, 12), 1.0);
        assert_eq!(nice_step(0.9, 6), 0.2);
        assert_eq!(nice_step(0.0, 6), 1.0);
    }

    #[test]
    fn charts_of_absurd_values_finish() {
        let tracks = [Track {
            robot: 0,
            name: "R1",
            points: vec![(0.0, 1e17), (1.0, -1e17), (2.0, f64::NAN)],
        }];
        let svg = time_position("t", "title", &tracks, "y", 1, Marks::Conflicts(&[]), 1e300).into_string();
        assert!(svg.ends_with("</svg>") && svg.matches("class=\"tick\"").count() < 500);
    }

    #[test]
    fn bars_have_one_rect_per_robot_and_strategy() {
        let bars = vec![
            StrategyBar {
                label: "a <b>".into(),
                robots: vec![("R1".into(), 3.0), ("R2".into(), 4.0)],
                cycle_time_s: 4.0,
                spread_s: None,
            },
            StrategyBar {
                label: "c".into(),
                robots: vec![("R1".into(), 5.0), ("R2".into(), 2.0)],
                cycle_time_s: 5.0,
                spread_s: Some(0.5),
            },
        ];
        let svg = strategy_bars(&bars, Some(2.5)).into_string();
        assert_eq!(svg.matches(r#"class="bar""#).count(), 4);
        assert!(svg.contains("a &lt;b&gt;"));
        assert!(svg.contains("lower bound 2.50 s"));
        assert_eq!(svg.matches(r#"class="spread""#).count(), 1);
    }
}
