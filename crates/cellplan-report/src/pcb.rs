//! The report and the placement program of a PCB-assembly plan (paper 004), from the plan
//! document and the cell only: the board with the placement order and the bins, the robots' X
//! over time (paper Fig. 8/9) with the safety delays marked, a Gantt chart per device, and the
//! summary.
use crate::escape;
use cellplan_pcb::PcbCell;
use cellplan_pcb::document::{DeviceKind, DeviceOut, PcbPlan};
use cellplan_verify::pcb::PcbReport;
use maud::{DOCTYPE, Markup, PreEscaped, html};
use std::fmt::Write;

const COLORS: [&str; 2] = ["#1f77b4", "#d62728"];

/// The placement program: one row per placement, per robot in order, with the rendezvous and
/// the times (mm, degrees, s) — what a machine's job importer can start from.
pub fn program_csv(plan: &PcbPlan) -> String {
    let mut s = String::from(
        "robot,step,component,footprint,value,feeder,bin,carriage_y_mm,pick_x_mm,pick_y_mm,pick_start_s,pick_end_s,\
         table_x_mm,table_y_mm,place_x_mm,place_y_mm,rotation_deg,safety_delay_s,place_start_s,place_end_s\n",
    );
    for robot in &plan.robots {
        for (step, p) in plan
            .placements
            .iter()
            .filter(|p| p.robot == robot.name)
            .enumerate()
        {
            let bin = plan.bins.iter().find(|b| b.feeder == p.feeder && b.bin == p.bin);
            let (fp, val) = bin.map_or(("", ""), |b| (b.footprint.as_str(), b.value.as_str()));
            let q = |s: &str| {
                if s.contains([',', '"', '\n']) {
                    format!("\"{}\"", s.replace('"', "\"\""))
                } else {
                    s.to_string()
                }
            };
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{:.3},{:.3},{:.3},{:.4},{:.4},{:.3},{:.3},{:.3},{:.3},{:.3},{:.4},{:.4},{:.4}",
                q(&p.robot),
                step + 1,
                q(&p.component),
                q(fp),
                q(val),
                q(&p.feeder),
                p.bin,
                p.pick.device[1] * 1e3,
                p.pick.point[0] * 1e3,
                p.pick.point[1] * 1e3,
                p.pick.t[0],
                p.pick.t[1],
                p.place.device[0] * 1e3,
                p.place.device[1] * 1e3,
                p.place.point[0] * 1e3,
                p.place.point[1] * 1e3,
                p.rotation_rad.to_degrees(),
                p.safety_delay_s,
                p.place.t[0],
                p.place.t[1]
            );
        }
    }
    s
}

fn robot_index(plan: &PcbPlan, name: &str) -> usize {
    plan.robots.iter().position(|r| r.name == name).unwrap_or(0)
}

/// The board, the components numbered in placement order and coloured by robot, each robot's
/// order as a line.
fn board_svg(plan: &PcbPlan, cell: &PcbCell) -> String {
    let (w, h) = (cell.board.size[0].max(1e-3), cell.board.size[1].max(1e-3));
    let scale = 700.0 / w.max(h * 1.6);
    let (pw, ph) = (w * scale + 40.0, h * scale + 40.0);
    let px = |x: f64| 20.0 + x * scale;
    let py = |y: f64| 20.0 + (h - y) * scale;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"board\" viewBox=\"0 0 {pw:.0} {ph:.0}\" width=\"{pw:.0}\" height=\"{ph:.0}\">\
         <rect x=\"20\" y=\"20\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#e8f3e8\" stroke=\"#2f6f2f\"/>",
        w * scale,
        h * scale
    );
    for (r, robot) in plan.robots.iter().enumerate() {
        let pts: Vec<String> = plan
            .placements
            .iter()
            .filter(|p| p.robot == robot.name)
            .filter_map(|p| cell.components.iter().find(|c| c.reference == p.component))
            .map(|c| format!("{:.1},{:.1}", px(c.position[0]), py(c.position[1])))
            .collect();
        let _ = write!(
            s,
            "<polyline class=\"order\" points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-opacity=\"0.5\" stroke-width=\"1.2\"/>",
            pts.join(" "),
            COLORS[r % 2]
        );
    }
    for (k, p) in plan.placements.iter().enumerate() {
        let Some(c) = cell.components.iter().find(|c| c.reference == p.component) else {
            continue;
        };
        let color = COLORS[robot_index(plan, &p.robot) % 2];
        let _ = write!(
            s,
            "<g class=\"component\"><title>{} ({}) — #{} by {}, bin {} of {}</title><circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"{color}\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"9\">{}</text></g>",
            escape(&p.component),
            escape(&c.value),
            k + 1,
            escape(&p.robot),
            p.bin,
            escape(&p.feeder),
            px(c.position[0]),
            py(c.position[1]),
            px(c.position[0]) + 5.0,
            py(c.position[1]) - 3.0,
            k + 1
        );
    }
    s += "</svg>";
    s
}

/// Device position at `t` (straight moves; the X chart samples them).
fn position(
    dev: &DeviceOut,
    drive: &cellplan_pcb::cell::Drive,
    model: cellplan_pcb::MotionModel,
    t: f64,
) -> [f64; 2] {
    let mut pos = dev.start;
    for m in &dev.moves {
        if t >= m.t[1] {
            pos = m.to;
        } else if t > m.t[0] {
            let len = ((m.to[0] - m.from[0]).powi(2) + (m.to[1] - m.from[1]).powi(2)).sqrt();
            let f = if len > 0.0 {
                drive.progress(model, len, t - m.t[0]) / len
            } else {
                1.0
            };
            return [
                m.from[0] + f * (m.to[0] - m.from[0]),
                m.from[1] + f * (m.to[1] - m.from[1]),
            ];
        } else {
            break;
        }
    }
    pos
}

/// The robots' X over time (paper Fig. 8/9): crossing lines would be collisions; safety delays
/// drawn as thick strokes at the pick.
fn x_time_svg(plan: &PcbPlan, cell: &PcbCell) -> String {
    let t_end = plan
        .devices
        .iter()
        .flat_map(|d| d.moves.iter().map(|m| m.t[1]))
        .fold(plan.cycle_time_s, f64::max)
        .max(1e-3);
    let robots: Vec<(&DeviceOut, &cellplan_pcb::cell::Robot)> = plan
        .devices
        .iter()
        .filter(|d| d.kind == DeviceKind::Robot)
        .filter_map(|d| cell.robots.iter().find(|r| r.name == d.name).map(|r| (d, r)))
        .collect();
    let (xmin, xmax) = robots
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (_, r)| {
            (a.min(r.x_given[0]), b.max(r.x_given[1]))
        });
    let (w, h, l, top) = (900.0, 330.0, 60.0, 30.0);
    let tx = |t: f64| l + t / t_end * (w - l - 20.0);
    let xy = |x: f64| top + (1.0 - (x - xmin) / (xmax - xmin).max(1e-9)) * (h - top - 40.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"x-time\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\">\
         <line x1=\"{l}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#888\"/>\
         <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\">time (s), assembly ends at {:.3} s</text>\
         <text x=\"4\" y=\"12\" font-size=\"11\">X (mm)</text>",
        h - 40.0,
        w - 20.0,
        h - 40.0,
        l,
        h - 22.0,
        plan.cycle_time_s
    );
    for k in 0..=4 {
        let x = xmin + (xmax - xmin) * k as f64 / 4.0;
        let _ = write!(
            s,
            "<text x=\"4\" y=\"{:.1}\" font-size=\"10\">{:.0}</text>",
            xy(x) + 3.0,
            x * 1e3
        );
    }
    let _ = write!(
        s,
        "<line x1=\"{0:.1}\" y1=\"{top}\" x2=\"{0:.1}\" y2=\"{1:.1}\" stroke=\"#999\" stroke-dasharray=\"4 3\"/>",
        tx(plan.cycle_time_s),
        h - 40.0
    );
    for (r, (dev, robot)) in robots.iter().enumerate() {
        let steps = 1500;
        let pts: Vec<String> = (0..=steps)
            .map(|k| {
                let t = t_end * k as f64 / steps as f64;
                format!(
                    "{:.1},{:.1}",
                    tx(t),
                    xy(position(dev, &robot.drive, cell.motion, t)[0])
                )
            })
            .collect();
        let _ = write!(
            s,
            "<polyline class=\"robot-x\" data-robot=\"{}\" points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\"/>",
            escape(&dev.name),
            pts.join(" "),
            COLORS[r % 2]
        );
        for p in plan
            .placements
            .iter()
            .filter(|p| p.robot == dev.name && p.safety_delay_s > 1e-9)
        {
            let _ = write!(
                s,
                "<line class=\"safety-delay\" x1=\"{0:.1}\" y1=\"{2:.1}\" x2=\"{1:.1}\" y2=\"{2:.1}\" stroke=\"#ff9900\" stroke-width=\"6\"><title>safety delay {3:.3} s before placing {4}</title></line>",
                tx(p.pick.t[1]),
                tx(p.pick.t[1] + p.safety_delay_s),
                xy(p.pick.point[0]),
                p.safety_delay_s,
                escape(&p.component)
            );
        }
    }
    s += "</svg>";
    s
}

/// A Gantt chart per device: moving, picking/placing, waiting.
fn gantt_svg(plan: &PcbPlan) -> String {
    let t_end = plan.cycle_time_s.max(1e-3);
    let rows = plan.devices.len();
    let (w, l, row_h) = (900.0, 90.0, 22.0);
    let h = rows as f64 * row_h + 40.0;
    let tx = |t: f64| l + t.min(t_end) / t_end * (w - l - 20.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"gantt\" viewBox=\"0 0 {w} {h:.0}\" width=\"{w}\" height=\"{h:.0}\">"
    );
    for (k, dev) in plan.devices.iter().enumerate() {
        let y = 10.0 + k as f64 * row_h;
        let _ = write!(
            s,
            "<text x=\"4\" y=\"{:.1}\" font-size=\"11\">{}</text><rect x=\"{l}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#f4f4f4\"/>",
            y + 14.0,
            escape(&dev.name),
            w - l - 20.0,
            row_h - 6.0
        );
        let mut bar = |a: f64, b: f64, color: &str, what: &str| {
            if b > a && a < t_end {
                let _ = write!(
                    s,
                    "<rect class=\"bar\" x=\"{:.2}\" y=\"{y:.1}\" width=\"{:.2}\" height=\"{:.1}\" fill=\"{color}\"><title>{what} {a:.3}–{b:.3} s</title></rect>",
                    tx(a),
                    (tx(b) - tx(a)).max(0.5),
                    row_h - 6.0
                );
            }
        };
        for m in &dev.moves {
            bar(m.t[0], m.t[1], "#9ecae1", "moving");
        }
        for p in &plan.placements {
            match dev.kind {
                DeviceKind::Robot if p.robot == dev.name => {
                    bar(p.pick.t[0], p.pick.t[1], "#31a354", "picking");
                    bar(p.place.t[0], p.place.t[1], "#756bb1", "placing");
                    bar(
                        p.pick.t[1],
                        p.pick.t[1] + p.safety_delay_s,
                        "#ff9900",
                        "safety delay",
                    );
                }
                DeviceKind::Feeder if p.feeder == dev.name => {
                    bar(p.pick.t[0], p.pick.t[1], "#31a354", "pick")
                }
                DeviceKind::Table => bar(p.place.t[0], p.place.t[1], "#756bb1", "placement"),
                _ => {}
            }
        }
    }
    let _ = write!(
        s,
        "<text x=\"{l}\" y=\"{:.1}\" font-size=\"11\">0 s</text><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\">{:.3} s</text></svg>",
        h - 8.0,
        w - 80.0,
        h - 8.0,
        t_end
    );
    s
}

/// The whole page.
pub fn html(plan: &PcbPlan, cell: &PcbCell, verdict: Option<&PcbReport>) -> String {
    let title = format!("cellplan — {}", plan.cell);
    let gap = if plan.lower_bound_s > 0.0 {
        plan.cycle_time_s / plan.lower_bound_s - 1.0
    } else {
        0.0
    };
    let delays: f64 = plan.placements.iter().map(|p| p.safety_delay_s).sum();
    let page: Markup = html! {
        (DOCTYPE)
        html lang="en" {
            (crate::html::head(&title))
            body {
                main {
                    h1 { (title) }
                    p class="sub" {
                        "PCB assembly (paper 004): " b { (plan.placements.len()) } " components of "
                        (cell.board.title) ", " (plan.robots.len()) " robot(s), configuration "
                        b { (plan.configuration.name()) } ", optimiser " b { (plan.optimizer) } ", seed " (plan.seed)
                    }
                    section id="summary" {
                        h2 { "Summary" }
                        table {
                            tr { th { "assembly time" } td id="cycle-time" { (format!("{:.3} s", plan.cycle_time_s)) } }
                            tr { th { "lower bound" } td { (format!("{:.3} s (gap {:.1} %)", plan.lower_bound_s, 100.0 * gap)) } }
                            tr { th { "safety delays" } td { (format!("{delays:.3} s")) } }
                            tr { th { "verification" } td id="verdict" {
                                @match verdict {
                                    Some(v) if v.ok => "verified: every device replayed on one clock",
                                    Some(_) => "NOT VERIFIED",
                                    None => "not checked",
                                }
                            } }
                            tr { th { "compute" } td { (format!("{:.2} s, {} simulations", plan.compute_s, plan.evaluations)) } }
                        }
                        table {
                            tr { th { "robot" } th { "components" } th { "moving s" } th { "picking+placing s" } th { "waiting s" } th { "done at s" } }
                            @for r in &plan.robots {
                                tr { td { (r.name) } td { (r.components) } td { (format!("{:.3}", r.motion_s)) } td { (format!("{:.3}", r.working_s)) } td { (format!("{:.3}", r.waiting_s)) } td { (format!("{:.3}", r.total_s)) } }
                            }
                        }
                        @if let Some(v) = verdict && !v.violations.is_empty() {
                            ul class="violations" {
                                @for x in &v.violations { li { (format!("{:?}: {}", x.kind, x.detail)) } }
                            }
                        }
                    }
                    section id="board-section" {
                        h2 { "Board and placement order" }
                        (PreEscaped(board_svg(plan, cell)))
                        table id="bins" {
                            tr { th { "feeder" } th { "bin" } th { "footprint" } th { "value" } }
                            @for b in &plan.bins { tr { td { (b.feeder) } td { (b.bin) } td { (b.footprint) } td { (b.value) } } }
                        }
                    }
                    @if plan.robots.len() == 2 {
                        section id="x-time-section" {
                            h2 { "Robot X over time" }
                            p { "Crossing lines would be collisions (paper Fig. 8); orange strokes are safety delays (Fig. 9)." }
                            (PreEscaped(x_time_svg(plan, cell)))
                        }
                    } @else {
                        section id="x-time-section" {
                            h2 { "Robot X over time" }
                            (PreEscaped(x_time_svg(plan, cell)))
                        }
                    }
                    section id="gantt-section" {
                        h2 { "Gantt chart per device" }
                        (PreEscaped(gantt_svg(plan)))
                    }
                }
            }
        }
    };
    page.into_string()
}
