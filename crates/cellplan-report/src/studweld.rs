//! The report of a stud-weld plan (paper 002), from the plan document and the cell only: the
//! cost breakdown shaped like the paper's Table 2 (travel, welding, total) with the cycle time;
//! the whole cycle's joint torques over time with the welds shaded; per move, its torque and
//! velocity plots (as fractions of the limits), its J and how it was found; per weld, the
//! alternative held and where its cost lies in the stud's range (Table 1's shape).
use cellplan_studweld::cell::WeldCell;
use cellplan_studweld::document::WeldPlan;
use cellplan_studweld::leg::Motion;
use cellplan_studweld::profile::{Profile, holding, profile};
use cellplan_studweld::sequence::Sequencer;
use cellplan_verify::studweld::WeldReport;
use maud::{DOCTYPE, Markup, PreEscaped, html};
use std::fmt::Write;

/// One colour per joint.
const JOINT_COLOURS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
];
const LEFT: f64 = 46.0;
const RIGHT: f64 = 10.0;
const TOP: f64 = 18.0;
const BOTTOM: f64 = 22.0;

/// A chart of joint series over time: `(t, series)`, `series[k]` is the values of every joint at `t[k]`; `y`
/// is the vertical range; dashed lines at ±1 (the limits) when inside it; `shade` are time
/// intervals drawn behind (the welds).
fn chart(
    id: &str,
    title: &str,
    (t, series): (&[f64], &[Vec<f64>]),
    t_end: f64,
    y: f64,
    shade: &[[f64; 2]],
    size: (f64, f64),
) -> String {
    let (w, h) = size;
    let x_of = |v: f64| LEFT + (w - LEFT - RIGHT) * if t_end > 0.0 { v / t_end } else { 0.0 };
    let y_of = |v: f64| TOP + (h - TOP - BOTTOM) * (1.0 - (v + y) / (2.0 * y));
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg id=\"{id}\" class=\"sw-chart\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\" xmlns=\"http://www.w3.org/2000/svg\" font-family=\"sans-serif\"><text x=\"{LEFT}\" y=\"12\" font-size=\"11\">{}</text>",
        crate::escape(title)
    );
    for [a, b] in shade {
        let _ = write!(
            s,
            "<rect x=\"{:.1}\" y=\"{TOP}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#eeeeee\"></rect>",
            x_of(*a),
            (x_of(*b) - x_of(*a)).max(0.5),
            h - TOP - BOTTOM
        );
    }
    for v in [-1.0f64, 0.0, 1.0] {
        if v.abs() > y {
            continue;
        }
        let dash = if v == 0.0 { "" } else { " stroke-dasharray=\"4 3\"" };
        let _ = write!(
            s,
            "<line x1=\"{LEFT}\" x2=\"{:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"#999\"{dash}></line><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"end\">{}</text>",
            w - RIGHT,
            y_of(v),
            y_of(v),
            LEFT - 4.0,
            y_of(v) + 3.0,
            if v == 0.0 {
                "0".to_string()
            } else {
                format!("{v:+.0}")
            }
        );
    }
    let joints = series.first().map_or(0, Vec::len);
    for j in 0..joints {
        let mut d = String::new();
        for (k, (tk, v)) in t.iter().zip(series).enumerate() {
            let _ = write!(
                d,
                "{}{:.1},{:.1}",
                if k == 0 { "M" } else { " L" },
                x_of(*tk),
                y_of(v[j].clamp(-y, y))
            );
        }
        let _ = write!(
            s,
            "<path d=\"{d}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.3\"><title>joint {}</title></path>",
            JOINT_COLOURS[j % JOINT_COLOURS.len()],
            j + 1
        );
    }
    let _ = write!(
        s,
        "<text x=\"{LEFT}\" y=\"{:.1}\" font-size=\"10\">0 s</text><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"end\">{t_end:.2} s</text></svg>",
        h - 6.0,
        w - RIGHT,
        h - 6.0
    );
    s
}

/// The vertical range of a chart: the limits (±1) and the data, a little beyond.
fn range(series: &[Vec<f64>]) -> f64 {
    let peak = series.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    (peak.max(1.0) * 1.05).min(10.0)
}

/// The whole cycle's torques: moves as profiled, each weld as its holding torques.
fn cycle_torques(w: &WeldCell, plan: &WeldPlan, profiles: &[Profile]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let (mut t, mut u) = (Vec::new(), Vec::new());
    for (k, (leg, p)) in plan.legs.iter().zip(profiles).enumerate() {
        for (tk, uk) in p.t.iter().zip(&p.torque) {
            t.push(leg.start_s + tk);
            u.push(uk.clone());
        }
        if let Some(v) = plan.visits.get(k) {
            let g = holding(w, &v.q);
            t.push(v.start_s);
            u.push(g.clone());
            t.push(v.end_s);
            u.push(g);
        }
    }
    (t, u)
}

fn legend(joints: usize) -> Markup {
    html! {
        p class="sw-legend" {
            @for j in 0..joints {
                span style=(format!("color:{}", JOINT_COLOURS[j % JOINT_COLOURS.len()])) { "━ " } "joint " (j + 1) " "
            }
            "— dashed lines are the limits; grey bands are the welds."
        }
    }
}

/// The whole page.
pub fn html(plan: &WeldPlan, w: &WeldCell, verdict: Option<&WeldReport>) -> String {
    let title = format!("cellplan — {}", plan.cell);
    let profiles: Vec<Profile> = plan.legs.iter().map(|l| profile(w, &l.motion)).collect();
    let t_end = plan.totals.cycle_time_s;
    let welds: Vec<[f64; 2]> = plan.visits.iter().map(|v| [v.start_s, v.end_s]).collect();
    let (ct, cu) = cycle_torques(w, plan, &profiles);
    let cycle_chart = chart(
        "cycle-torques",
        "joint torque / limit over the cycle",
        (&ct, &cu),
        t_end,
        range(&cu),
        &welds,
        (960.0, 260.0),
    );
    let joints = w.v_max.len();
    let fallbacks = plan.legs.iter().filter(|l| l.fallback.is_some()).count();
    let total = plan.totals.cost.max(1e-12);
    let verdict_text = match verdict {
        Some(v) if v.ok => format!(
            "verified: every move's discrete Euler–Lagrange equations re-evaluated (largest residual {:.1e}), limits, the clearance piece by piece ({} pieces), the welds held, every number re-derived",
            v.max_dynamics_residual, v.segments_checked
        ),
        Some(v) => format!("NOT VERIFIED ({} violations)", v.violations.len()),
        None => "not checked".to_string(),
    };
    let page: Markup = html! {
        (DOCTYPE)
        html lang="en" {
            (crate::html::head(&title))
            body {
                style { "svg.sw-chart{max-width:100%;height:auto}div.sw-legs{display:flex;flex-wrap:wrap;gap:8px}#table2{width:auto}#legs td:nth-child(6){text-align:left}figure.sw-leg{margin:0}.bar{display:flex;height:18px;max-width:960px}.bar span{display:block;height:18px}" }
                main {
                    h1 { (title) }
                    p class="sub" {
                        "Stud welding (paper 002): " b { (plan.visits.len()) } " welds, "
                        "sequenced on " b { (if plan.sequencer == Sequencer::OptimalControl { "optimal-control costs (the paper's new sequencer)" } else { "travel time, then each move optimised (the paper's old sequencer)" }) }
                        ", " (plan.sequencing.rounds) " lazy round(s)"
                        @if !plan.sequencing.converged { " (the OCP budget ended)" }
                        ", " (plan.sequencing.ocp_solves) " optimal-control problems solved"
                    }
                    section id="summary" {
                        h2 { "Cost (paper 002 Table 2)" }
                        table id="table2" {
                            tr { th { "" } th { "travel" } th { "welding" } th { "total J" } th { "cycle time" } }
                            tr {
                                th { "this plan" }
                                td id="travel-cost" { (format!("{:.1}", plan.totals.travel_cost)) }
                                td id="weld-cost" { (format!("{:.1}", plan.totals.weld_cost)) }
                                td id="cost" { (format!("{:.1}", plan.totals.cost)) }
                                td id="cycle-time" { (format!("{:.2} s", plan.totals.cycle_time_s)) }
                            }
                            tr { th { "paper, old sequence" } td { "2212.5" } td { "4590.4" } td { "6802.9" } td { "—" } }
                            tr { th { "paper, new sequence" } td { "1560.9" } td { "2323.1" } td { "3884.0" } td { "—" } }
                        }
                        div class="bar" title="travel (blue) and welding (orange) shares of J" {
                            span style=(format!("width:{:.1}%;background:#1f77b4", 100.0 * plan.totals.travel_cost / total)) {}
                            span style=(format!("width:{:.1}%;background:#ff7f0e", 100.0 * plan.totals.weld_cost / total)) {}
                        }
                        p { (format!("J = ∫ c_t + c_e uᵀu + c_v q̇ᵀq̇ dt; travel {:.0} %, welding {:.0} %. {} of {} moves are timed paths (the moves table says why).", 100.0 * plan.totals.travel_cost / total, 100.0 * plan.totals.weld_cost / total, fallbacks, plan.legs.len())) }
                        p id="verdict" { (verdict_text) }
                        @if let Some(v) = verdict && !v.violations.is_empty() {
                            ul class="violations" {
                                @for x in &v.violations { li { (format!("{:?}: {}", x.kind, x.detail)) } }
                            }
                        }
                        @if !plan.unweldable.is_empty() {
                            h3 { "Not welded" }
                            ul id="unweldable" {
                                @for u in &plan.unweldable { li { b { (u.stud) } " (" (u.reason) "): " (u.text) } }
                            }
                        }
                    }
                    section id="cycle-section" {
                        h2 { "Torques over the cycle" }
                        (legend(joints))
                        (PreEscaped(cycle_chart))
                    }
                    section id="welds-section" {
                        h2 { "Welds (paper 002 Table 1's shape)" }
                        table id="welds" {
                            tr { th { "#" } th { "stud" } th { "alternative" } th { "gun rotation °" } th { "weld cost" } th { "stud's range" } th { "largest holding torque / limit" } th { "start s" } }
                            @for (k, v) in plan.visits.iter().enumerate() {
                                @let spread = plan.alternatives.iter().find(|a| a.stud == v.stud).and_then(|a| a.weld_cost_range.map(|r| (a.count, r)));
                                @let g = holding(w, &v.q).iter().fold(0.0f64, |m, x| m.max(x.abs()));
                                tr {
                                    td { (k + 1) } td { (v.stud) } td { (v.alternative) }
                                    td { (format!("{:.0}", v.rotation_rad.to_degrees())) }
                                    td { (format!("{:.1}", v.weld_cost)) }
                                    td { @if let Some((n, [lo, hi])) = spread { (format!("{n} alternatives, {lo:.1}–{hi:.1}")) } }
                                    td { (format!("{g:.2}")) }
                                    td { (format!("{:.2}", v.start_s)) }
                                }
                            }
                        }
                    }
                    section id="legs-section" {
                        h2 { "Moves" }
                        table id="legs" {
                            tr { th { "#" } th { "from → to" } th { "start s" } th { "duration s" } th { "J" } th { "motion" } th { "peak speed / limit" } th { "peak torque / limit" } th { "solver iterations" } }
                            @for (k, (l, p)) in plan.legs.iter().zip(&profiles).enumerate() {
                                @let (pv, pu) = p.peaks();
                                tr {
                                    td { (k + 1) } td { (l.from) " → " (l.to) }
                                    td { (format!("{:.2}", l.start_s)) } td { (format!("{:.3}", l.duration_s)) }
                                    td { (format!("{:.1}", l.cost)) }
                                    td {
                                        @match &l.motion {
                                            Motion::Ocp(d) => { "DMOC, " (d.u.len()) " steps" @if l.trust_iterations > 0 { ", " (l.trust_iterations) " trust-region iteration(s)" } }
                                            Motion::TimedPath { waypoints, .. } => { "timed path, " (waypoints.len()) " waypoints" }
                                        }
                                        @if let Some(f) = &l.fallback { br; small { (f) } }
                                    }
                                    td { (format!("{pv:.2}")) } td { (format!("{pu:.2}")) }
                                    td { (l.iterations) }
                                }
                            }
                        }
                        h3 { "Torques and velocities per move" }
                        (legend(joints))
                        div class="sw-legs" {
                            @for (k, (l, p)) in plan.legs.iter().zip(&profiles).enumerate() {
                                @let end = p.t.last().copied().unwrap_or(0.0);
                                figure class="sw-leg" {
                                    (PreEscaped(chart(&format!("leg-{}-torque", k + 1), &format!("move {}: {} → {}, torque / limit", k + 1, l.from, l.to), (&p.t, &p.torque), end, range(&p.torque), &[], (470.0, 150.0))))
                                    (PreEscaped(chart(&format!("leg-{}-velocity", k + 1), &format!("move {}: velocity / limit", k + 1), (&p.t, &p.velocity), end, range(&p.velocity), &[], (470.0, 150.0))))
                                }
                            }
                        }
                    }
                }
            }
        }
    };
    page.into_string()
}
