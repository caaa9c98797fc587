//! The report's charts as SVG: the Gantt chart of every robot's activities, the time–position
//! chart of paper 000 Fig. 7/8, and the strategy bar chart of Fig. 10.
//!
//! Charts that share the plan's clock carry `data-t0`, `data-t1`, `data-x0`, `data-x1` (the
//! time range and the horizontal pixel range it maps to) and a `line.cursor`, so the page's
//! script can move a time cursor over them and turn a click into a time.
use super::playback::{Doing, intervals};
use super::svg::ROBOT_COLOURS;
use crate::escape;
use cellplan_core::document::{ConflictOut, Plan};
use std::fmt::Write;

/// Width of every chart (SVG user units, drawn at 100 % of the page column).
pub const WIDTH: f64 = 960.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 16.0;
const WAIT_COLOUR: &str = "#d62728";

fn colour(r: usize) -> &'static str {
    ROBOT_COLOURS[r % ROBOT_COLOURS.len()]
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
fn time_axis(s: &mut String, x: Axis, top: f64, y: f64) {
    let step = nice_step(x.d1 - x.d0, 12);
    for k in 0..=ticks(0.0, x.d1, step) {
        let t = k as f64 * step;
        let px = x.at(t);
        let _ = write!(
            s,
            r##"<line x1="{px:.1}" y1="{top:.1}" x2="{px:.1}" y2="{y:.1}" class="grid"/><text x="{px:.1}" y="{:.1}" class="tick" text-anchor="middle">{}</text>"##,
            y + 14.0,
            trim(t)
        );
    }
    let _ = write!(
        s,
        r##"<text x="{:.1}" y="{:.1}" class="label" text-anchor="middle">time (s)</text>"##,
        (x.p0 + x.p1) / 2.0,
        y + 30.0
    );
}

/// A number without trailing zeros.
fn trim(v: f64) -> String {
    let s = format!("{v:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Ticks, labels and horizontal grid lines of a vertical value axis on the left, and its
/// label turned along it.
fn value_axis(s: &mut String, y: Axis, label: &str) {
    let step = nice_step(y.d1 - y.d0, 6);
    let first = (y.d0 / step).ceil() * step;
    for k in 0..=ticks(first, y.d1, step) {
        let v = first + k as f64 * step;
        let py = y.at(v);
        let _ = write!(
            s,
            r#"<line x1="{LEFT}" y1="{py:.1}" x2="{:.1}" y2="{py:.1}" class="grid"/><text x="{:.1}" y="{:.1}" class="tick" text-anchor="end">{}</text>"#,
            WIDTH - RIGHT,
            LEFT - 6.0,
            py + 4.0,
            trim(v)
        );
    }
    let _ = write!(
        s,
        r#"<text transform="translate(16 {:.1}) rotate(-90)" class="label" text-anchor="middle">{}</text>"#,
        (y.p0 + y.p1) / 2.0,
        escape(label)
    );
}

/// The cursor line and the chart's time-mapping attributes.
fn clock_attrs(x: Axis) -> String {
    format!(
        r#"data-t0="{}" data-t1="{}" data-x0="{}" data-x1="{}""#,
        x.d0, x.d1, x.p0, x.p1
    )
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
pub fn gantt(plan: &Plan) -> String {
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
    let mut s = format!(
        r#"<svg id="gantt" class="chart clock" viewBox="0 0 {WIDTH} {height:.0}" {} xmlns="http://www.w3.org/2000/svg" role="img" aria-label="Gantt chart of every robot's activities">"#,
        clock_attrs(x)
    );
    time_axis(&mut s, x, top - 6.0, bottom);
    for (r, rp) in plan.robots.iter().enumerate() {
        let y = top + row * r as f64;
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" class="name" text-anchor="end">{}</text>"#,
            LEFT - 8.0,
            y + row / 2.0 + 4.0,
            escape(&rp.name)
        );
        for iv in intervals(rp) {
            let (fill, opacity, what) = match iv.doing {
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
            };
            let _ = write!(
                s,
                r#"<rect class="{}" x="{:.2}" y="{:.1}" width="{:.2}" height="{:.1}" fill="{fill}" fill-opacity="{opacity}"><title>{} {}: {:.2}–{:.2} s</title></rect>"#,
                iv.doing.word(),
                x.at(iv.start),
                y + 4.0,
                (x.at(iv.end) - x.at(iv.start)).max(0.5),
                row - 8.0,
                escape(&rp.name),
                escape(&what),
                iv.start,
                iv.end
            );
        }
    }
    for (t, class, label) in [
        (
            plan.cycle_time_s,
            "cycle",
            format!("cycle {:.2} s", plan.cycle_time_s),
        ),
        (
            plan.lower_bound_s,
            "bound",
            format!("lower bound {:.2} s", plan.lower_bound_s),
        ),
    ] {
        if t > 0.0 && t <= x.d1 + 1e-9 {
            let px = x.at(t);
            let _ = write!(
                s,
                r#"<line x1="{px:.1}" y1="{:.1}" x2="{px:.1}" y2="{bottom:.1}" class="{class}"/><text x="{px:.1}" y="{:.1}" class="tick {class}" text-anchor="{}">{label}</text>"#,
                top - 8.0,
                top - 12.0,
                if class == "cycle" { "end" } else { "start" }
            );
        }
    }
    legend(
        &mut s,
        LEFT,
        height - 6.0,
        &[
            ("moving", "#888", 0.35),
            ("measuring", "#888", 1.0),
            ("waiting for another robot", WAIT_COLOUR, 0.9),
        ],
    );
    let _ = write!(
        s,
        r#"<line class="cursor" x1="{LEFT}" y1="{:.1}" x2="{LEFT}" y2="{bottom:.1}"/></svg>"#,
        top - 6.0
    );
    s
}

fn legend(s: &mut String, x0: f64, y: f64, items: &[(&str, &str, f64)]) {
    let mut x = x0;
    for (label, fill, opacity) in items {
        let _ = write!(
            s,
            r#"<rect x="{x:.1}" y="{:.1}" width="14" height="10" fill="{fill}" fill-opacity="{opacity}"/><text x="{:.1}" y="{y:.1}" class="tick">{}</text>"#,
            y - 9.0,
            x + 18.0,
            escape(label)
        );
        x += 30.0 + 6.5 * label.chars().count() as f64;
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
) -> String {
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
    let mut s = format!(
        r#"<svg id="{id}" class="chart clock timepos" viewBox="0 0 {WIDTH} {height:.0}" {} xmlns="http://www.w3.org/2000/svg" role="img" aria-label="{}">"#,
        clock_attrs(x),
        escape(title)
    );
    let _ = write!(
        s,
        r#"<text x="{LEFT}" y="16" class="title">{}</text>"#,
        escape(title)
    );
    time_axis(&mut s, x, top, top + plot_h);
    value_axis(&mut s, y, &format!("probe {} (m)", axis_name));
    // Marks under the lines.
    match marks {
        Marks::Conflicts(conflicts) => {
            for (k, c) in conflicts.iter().enumerate() {
                let (a, b) = (c.probe_xyz[0][axis], c.probe_xyz[1][axis]);
                let (x0, x1) = (x.at(c.start_s), x.at(c.end_s.max(c.start_s)));
                let (y0, y1) = (y.at(a.max(b) + pad * 0.5), y.at(a.min(b) - pad * 0.5));
                let _ = write!(
                    s,
                    r#"<g class="conflict"><rect x="{:.1}" y="{y0:.1}" width="{:.1}" height="{:.1}" rx="6"/><text x="{:.1}" y="{:.1}" class="tick conflict-label">C{}</text><title>C{}: {} &amp; {}, {:.2}–{:.2} s, scenario {} — {} / {}</title></g>"#,
                    x0 - 3.0,
                    (x1 - x0) + 6.0,
                    (y1 - y0).max(6.0),
                    x0,
                    y0 - 4.0,
                    k + 1,
                    k + 1,
                    escape(&c.robots[0]),
                    escape(&c.robots[1]),
                    c.start_s,
                    c.end_s,
                    c.scenario,
                    escape(&c.activity[0].text("measuring")),
                    escape(&c.activity[1].text("measuring"))
                );
            }
        }
        Marks::Resolution(plan) => {
            for rp in &plan.robots {
                let Some(track) = tracks.iter().find(|t| t.name == rp.name) else {
                    continue;
                };
                let at = |t: f64| {
                    let k = track.points.partition_point(|p| p.0 <= t).saturating_sub(1);
                    track.points.get(k).map_or(0.0, |p| p.1)
                };
                for w in &rp.waits {
                    let py = y.at(at(w.start_s));
                    let _ = write!(
                        s,
                        r#"<g class="wait"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="12" rx="3"/><title>{} waits {:.2} s at {} ({})</title></g>"#,
                        x.at(w.start_s),
                        py - 6.0,
                        (x.at(w.start_s + w.duration_s) - x.at(w.start_s)).max(2.0),
                        escape(&rp.name),
                        w.duration_s,
                        escape(&rp.wait_place(w)),
                        w.reason
                    );
                }
                for v in rp.tasks.iter().filter(|v| v.perturbation_rad.is_some()) {
                    let (px, py) = (x.at(v.arrive_s), y.at(v.tcp.xyz[axis]));
                    let _ = write!(
                        s,
                        r#"<g class="perturbed"><path d="M{:.1} {py:.1} l6 -6 l6 6 l-6 6 z"/><title>{}: probe orientation at {} perturbed</title></g>"#,
                        px - 6.0,
                        escape(&rp.name),
                        escape(&v.task)
                    );
                }
            }
        }
    }
    for tr in tracks {
        let mut d = String::new();
        for (k, &(t, p)) in tr.points.iter().enumerate() {
            let _ = write!(
                d,
                "{}{:.1} {:.1}",
                if k == 0 { "M" } else { " L" },
                x.at(t),
                y.at(p)
            );
        }
        let _ = write!(
            s,
            r#"<path class="track" d="{d}" stroke="{}"><title>{}</title></path>"#,
            colour(tr.robot),
            escape(tr.name)
        );
    }
    let mut lx = LEFT;
    for tr in tracks {
        let _ = write!(
            s,
            r#"<line x1="{lx:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{}" stroke-width="3"/><text x="{:.1}" y="{:.1}" class="tick">{}</text>"#,
            height - 10.0,
            lx + 18.0,
            height - 10.0,
            colour(tr.robot),
            lx + 22.0,
            height - 6.0,
            escape(tr.name)
        );
        lx += 40.0 + 7.0 * tr.name.chars().count() as f64;
    }
    let extra: &[(&str, &str, f64)] = match marks {
        Marks::Conflicts(_) => &[("conflict (robots closer than the clearance)", WAIT_COLOUR, 0.35)],
        Marks::Resolution(_) => &[("wait", WAIT_COLOUR, 0.8), ("perturbed pose ◆", "#000", 0.0)],
    };
    legend(&mut s, lx + 10.0, height - 6.0, extra);
    let _ = write!(
        s,
        r#"<line class="cursor" x1="{LEFT}" y1="{top}" x2="{LEFT}" y2="{:.1}"/></svg>"#,
        top + plot_h
    );
    s
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
pub fn strategy_bars(bars: &[StrategyBar], bound: Option<f64>) -> String {
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
    let mut s = format!(
        r#"<svg id="strategy-bars" class="chart" viewBox="0 0 {WIDTH} {height:.0}" xmlns="http://www.w3.org/2000/svg" role="img" aria-label="time per robot and cycle time per strategy">"#
    );
    value_axis(&mut s, y, "time (s)");
    let group = (WIDTH - LEFT - RIGHT) / bars.len().max(1) as f64;
    for (g, b) in bars.iter().enumerate() {
        let x0 = LEFT + group * g as f64;
        let n = b.robots.len().max(1) as f64;
        let w = (group * 0.8) / n;
        for (r, (name, t)) in b.robots.iter().enumerate() {
            let px = x0 + group * 0.1 + w * r as f64;
            let _ = write!(
                s,
                r#"<rect class="bar" x="{px:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{}"><title>{}: {} {:.2} s</title></rect>"#,
                y.at(*t),
                (w - 1.0).max(1.0),
                y.at(0.0) - y.at(*t),
                colour(r),
                escape(&b.label),
                escape(name),
                t
            );
        }
        let py = y.at(b.cycle_time_s);
        let _ = write!(
            s,
            r#"<line class="cycle" x1="{:.1}" y1="{py:.1}" x2="{:.1}" y2="{py:.1}"/><text x="{:.1}" y="{:.1}" class="tick" text-anchor="middle">{:.2}</text>"#,
            x0 + group * 0.05,
            x0 + group * 0.95,
            x0 + group / 2.0,
            py - 5.0 - if b.spread_s.is_some() { 8.0 } else { 0.0 },
            b.cycle_time_s
        );
        if let Some(sd) = b.spread_s {
            let (a, c) = (y.at(b.cycle_time_s - sd), y.at(b.cycle_time_s + sd));
            let cx = x0 + group / 2.0;
            let _ = write!(
                s,
                r#"<path class="spread" d="M{cx:.1} {a:.1} V{c:.1} M{:.1} {a:.1} h8 M{:.1} {c:.1} h8"/>"#,
                cx - 4.0,
                cx - 4.0
            );
        }
        let _ = write!(
            s,
            r#"<text transform="translate({:.1} {:.1}) rotate(30)" class="tick">{}</text>"#,
            x0 + group * 0.2,
            top + plot_h + 14.0,
            escape(&b.label)
        );
    }
    if let Some(lb) = bound {
        let py = y.at(lb);
        let _ = write!(
            s,
            r#"<line class="bound" x1="{LEFT}" y1="{py:.1}" x2="{:.1}" y2="{py:.1}"/><text x="{:.1}" y="{:.1}" class="tick bound" text-anchor="end">lower bound {lb:.2} s</text>"#,
            WIDTH - RIGHT,
            WIDTH - RIGHT,
            py - 4.0
        );
    }
    s.push_str("</svg>");
    s
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
        let svg = time_position("t", "title", &tracks, "y", 1, Marks::Conflicts(&[]), 1e300);
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
        let svg = strategy_bars(&bars, Some(2.5));
        assert_eq!(svg.matches(r#"class="bar""#).count(), 4);
        assert!(svg.contains("a &lt;b&gt;"));
        assert!(svg.contains("lower bound 2.50 s"));
        assert_eq!(svg.matches(r#"class="spread""#).count(), 1);
    }
}
