//! A drawing of the cell from above (x–y) and from the side (y–z): static objects and robots at
//! home as filled silhouettes, measurement points coloured by reachability class.
use crate::escape;
use cellplan_core::CandidateTable;
use cellplan_geom::{DVec3, Mesh, Pose};
use cellplan_model::robot::Scratch;
use cellplan_model::{Cell, TaskId};
use std::fmt::Write;

/// Robot colours, in robot order (repeats after eight).
pub const ROBOT_COLOURS: [&str; 8] = [
    "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#17becf", "#bcbd22", "#e377c2",
];
const SHARED: &str = "#d6278c";
const UNMEASURABLE: &str = "#d62728";

/// A 2D occupancy grid that triangles are rasterised into.
struct Raster {
    min: [f64; 2],
    cell: f64,
    w: usize,
    h: usize,
    bits: Vec<bool>,
}

impl Raster {
    fn new(min: [f64; 2], max: [f64; 2], cell: f64) -> Self {
        let w = (((max[0] - min[0]) / cell).ceil() as usize).max(1);
        let h = (((max[1] - min[1]) / cell).ceil() as usize).max(1);
        Raster {
            min,
            cell,
            w,
            h,
            bits: vec![false; w * h],
        }
    }

    fn fill_triangle(&mut self, p: [[f64; 2]; 3]) {
        let area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        let lo = |k: usize| p.iter().map(|v| v[k]).fold(f64::INFINITY, f64::min);
        let hi = |k: usize| p.iter().map(|v| v[k]).fold(f64::NEG_INFINITY, f64::max);
        let to_cell = |v: f64, k: usize, n: usize| {
            (((v - self.min[k]) / self.cell).floor().max(0.0) as usize).min(n - 1)
        };
        let (x0, x1) = (to_cell(lo(0), 0, self.w), to_cell(hi(0), 0, self.w));
        let (y0, y1) = (to_cell(lo(1), 1, self.h), to_cell(hi(1), 1, self.h));
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let c = [
                    self.min[0] + (cx as f64 + 0.5) * self.cell,
                    self.min[1] + (cy as f64 + 0.5) * self.cell,
                ];
                let inside = if area.abs() < 1e-18 {
                    false
                } else {
                    let s = area.signum();
                    (0..3).all(|i| {
                        let (a, b) = (p[i], p[(i + 1) % 3]);
                        s * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) >= 0.0
                    })
                };
                // Thin triangles (seen edge-on) still mark the cell under their vertices.
                if inside {
                    self.bits[cy * self.w + cx] = true;
                }
            }
        }
        for v in p {
            let (cx, cy) = (to_cell(v[0], 0, self.w), to_cell(v[1], 1, self.h));
            self.bits[cy * self.w + cx] = true;
        }
    }

    /// Runs of filled cells as an SVG path (cell units mapped by `map`).
    fn path(&self, map: &dyn Fn([f64; 2]) -> [f64; 2]) -> String {
        let mut d = String::new();
        for cy in 0..self.h {
            let mut cx = 0;
            while cx < self.w {
                if !self.bits[cy * self.w + cx] {
                    cx += 1;
                    continue;
                }
                let start = cx;
                while cx < self.w && self.bits[cy * self.w + cx] {
                    cx += 1;
                }
                let a = map([
                    self.min[0] + start as f64 * self.cell,
                    self.min[1] + cy as f64 * self.cell,
                ]);
                let b = map([
                    self.min[0] + cx as f64 * self.cell,
                    self.min[1] + (cy + 1) as f64 * self.cell,
                ]);
                let _ = write!(
                    d,
                    "M{:.1} {:.1}H{:.1}V{:.1}H{:.1}Z",
                    a[0].min(b[0]),
                    a[1].min(b[1]),
                    a[0].max(b[0]),
                    a[1].max(b[1]),
                    a[0].min(b[0])
                );
            }
        }
        d
    }
}

struct View {
    name: &'static str,
    /// World → plane coordinates (right, up).
    project: fn(DVec3) -> [f64; 2],
}

const VIEWS: [View; 2] = [
    View {
        name: "from above (x right, y up)",
        project: |p| [p.x, p.y],
    },
    View {
        name: "from the side (y right, z up)",
        project: |p| [p.y, p.z],
    },
];

/// One thing drawn.
struct Item {
    label: String,
    colour: &'static str,
    meshes: Vec<Mesh>,
    /// Ground (floor slabs): drawn in the side view only and left out of the bounds.
    ground: bool,
}

/// Everything drawn, in drawing order.
fn scene(cell: &Cell) -> Vec<Item> {
    let lowest_base = cell
        .robots
        .iter()
        .map(|r| r.base.translation.z)
        .fold(f64::INFINITY, f64::min);
    let mut items = Vec::new();
    for (k, o) in cell.objects.iter().enumerate() {
        let mesh = o.shape.to_mesh().transformed(&o.pose);
        let ground = mesh.aabb().is_some_and(|(_, hi)| hi.z <= lowest_base + 1e-6);
        let colour = if ground {
            "#9aa0a8"
        } else if k == 0 {
            "#c4c8d0"
        } else {
            "#6f7580"
        };
        items.push(Item {
            label: o.name.clone(),
            colour,
            meshes: vec![mesh],
            ground,
        });
    }
    for r in &cell.robots {
        let mut scratch = Scratch::default();
        r.body_poses(&r.home, &mut scratch);
        let mut meshes = Vec::new();
        for ((s, local), pose) in r.body_shapes.iter().zip(&scratch.bodies) {
            let world: Pose = *pose * *local;
            meshes.push(s.to_mesh().transformed(&world));
        }
        items.push(Item {
            label: r.name.clone(),
            colour: ROBOT_COLOURS[r.id.0 % 8],
            meshes,
            ground: false,
        });
    }
    items
}

/// The SVG drawing of the cell, with tasks coloured by reachability class when candidates are
/// given.
pub fn render(cell: &Cell, table: Option<&CandidateTable>) -> String {
    let items = scene(cell);
    let task_colour = |t: TaskId| -> &'static str {
        let Some(table) = table else { return "#000000" };
        match table.robots_for(t).as_slice() {
            [] => UNMEASURABLE,
            [one] => ROBOT_COLOURS[one.0 % 8],
            _ => SHARED,
        }
    };
    let width = 900.0;
    let margin = 30.0;
    let mut body = String::new();
    let mut y_offset = 60.0;
    for (v, view) in VIEWS.iter().enumerate() {
        // Bounds of everything in this view.
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut grow = |p: [f64; 2]| {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        };
        for item in items.iter().filter(|i| !i.ground) {
            for m in &item.meshes {
                m.vertices.iter().for_each(|v| grow((view.project)(*v)));
            }
        }
        cell.tasks.iter().for_each(|t| grow((view.project)(t.position)));
        if !lo[0].is_finite() {
            continue;
        }
        let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-3);
        let scale = (width - 2.0 * margin) / (hi[0] - lo[0]).max(1e-3);
        let height = (hi[1] - lo[1]) * scale + 2.0 * margin;
        let map = |p: [f64; 2]| {
            [
                margin + (p[0] - lo[0]) * scale,
                y_offset + height - margin - (p[1] - lo[1]) * scale,
            ]
        };
        let _ = writeln!(
            body,
            "<text x=\"{margin}\" y=\"{:.1}\" class=\"title\">{}</text>",
            y_offset - 8.0,
            view.name
        );
        let cell_size = span / 300.0;
        for item in &items {
            if item.ground && v == 0 {
                continue;
            }
            let (label, colour) = (&item.label, item.colour);
            let mut raster = Raster::new(lo, hi, cell_size);
            for m in &item.meshes {
                for t in &m.triangles {
                    let p = t.map(|i| (view.project)(m.vertices[i as usize]));
                    raster.fill_triangle(p);
                }
            }
            let _ = writeln!(
                body,
                "<path d=\"{}\" fill=\"{colour}\" fill-opacity=\"0.75\"><title>{}</title></path>",
                raster.path(&map),
                escape(label)
            );
        }
        // Robot names at their bases.
        for r in &cell.robots {
            let p = map((view.project)(r.base.translation));
            let _ = writeln!(
                body,
                "<text x=\"{:.1}\" y=\"{:.1}\" class=\"robot\" fill=\"{}\">{}</text>",
                p[0] + 6.0,
                p[1] + 14.0,
                ROBOT_COLOURS[r.id.0 % 8],
                escape(&r.name)
            );
        }
        let normal_len = span / 40.0;
        for t in &cell.tasks {
            let p = map((view.project)(t.position));
            let q = map((view.project)(t.position + t.normal * normal_len));
            let c = task_colour(t.id);
            let _ = writeln!(
                body,
                "<g><title>{}</title><line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{c}\" stroke-width=\"1.2\"/><circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3.2\" fill=\"{c}\" stroke=\"#000\" stroke-width=\"0.5\"/></g>",
                escape(&t.name),
                p[0],
                p[1],
                q[0],
                q[1],
                p[0],
                p[1]
            );
        }
        y_offset += height + 40.0;
    }
    // Legend.
    let mut legend = String::new();
    let mut x = margin;
    let mut entry = |colour: &str, label: &str| {
        let _ = write!(
            legend,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"5\" fill=\"{colour}\"/><text x=\"{:.1}\" y=\"{:.1}\" class=\"legend\">{}</text>",
            x,
            y_offset - 4.0,
            x + 9.0,
            y_offset,
            escape(label)
        );
        x += 20.0 + 7.0 * label.chars().count() as f64;
    };
    for r in &cell.robots {
        entry(
            ROBOT_COLOURS[r.id.0 % 8],
            &format!("δ {} (only {})", r.name, r.name),
        );
    }
    if table.is_some() {
        entry(SHARED, "shared (Q)");
        entry(UNMEASURABLE, "unmeasurable");
    }
    let total_h = y_offset + 20.0;
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{total_h:.0}\" viewBox=\"0 0 {width} {total_h:.0}\">\n<style>text{{font-family:sans-serif}} .title{{font-size:14px;font-weight:bold}} .robot{{font-size:13px;font-weight:bold}} .legend{{font-size:12px}}</style>\n<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n<text x=\"{margin}\" y=\"20\" class=\"title\">cell {} — {} robots, {} tasks</text>\n{body}{legend}\n</svg>\n",
        escape(&cell.name),
        cell.robots.len(),
        cell.tasks.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_makes_text_safe() {
        assert_eq!(escape("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }

    #[test]
    fn raster_fills_triangle_interior_only() {
        let mut r = Raster::new([0.0, 0.0], [10.0, 10.0], 1.0);
        r.fill_triangle([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]);
        assert!(r.bits[r.w + 1]); // (1.5, 1.5) inside
        assert!(!r.bits[8 * r.w + 8]); // (8.5, 8.5) outside
    }
}
