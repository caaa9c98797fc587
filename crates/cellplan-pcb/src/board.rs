//! Boards: the components to place, read from a KiCad 6–9 board (`.kicad_pcb`) or a KiCad
//! position file (CSV).
//!
//! The board frame: x to the right, y up (KiCad's own y points down, so it is negated), origin at
//! the lower left corner of the board outline (the `Edge.Cuts` drawings; without them, of the
//! footprints), SI units. Rotations are KiCad's, counter-clockwise seen from the front.
use crate::sexpr::{self, Node};
use cellplan_model::InputError;
use cellplan_model::io::read_bounded;
use std::path::{Path, PathBuf};

/// Largest board file read (KiCad boards of large designs are tens of MB).
pub const MAX_BOARD_BYTES: u64 = 128 << 20;
/// Most footprints on a board.
pub const MAX_COMPONENTS: usize = 20_000;

/// The side of the board a component sits on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The front (KiCad `F.Cu`, `top`).
    Front,
    /// The back (KiCad `B.Cu`, `bottom`).
    Back,
}

/// How a footprint is mounted (KiCad's `attr`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Mount {
    /// Surface mounted.
    Smd,
    /// Through-hole.
    ThroughHole,
    /// Neither stated.
    Unspecified,
}

/// One footprint of the board.
#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    /// Reference designator (`R12`).
    pub reference: String,
    /// Value (`10k`).
    pub value: String,
    /// Footprint (`Resistor_SMD:R_0402_1005Metric`).
    pub footprint: String,
    /// Position in the board frame (m).
    pub position: [f64; 2],
    /// Rotation (rad, counter-clockwise seen from the front).
    pub rotation: f64,
    /// Side.
    pub side: Side,
    /// Mounting.
    pub mount: Mount,
    /// Marked "do not populate".
    pub dnp: bool,
    /// Marked "exclude from position files" (or "board only").
    pub excluded: bool,
    /// Line of the footprint in its file.
    pub line: usize,
}

/// A board as read.
#[derive(Clone, Debug)]
pub struct Board {
    /// The file.
    pub path: PathBuf,
    /// Title (from the title block, else the file name).
    pub title: String,
    /// Every footprint, in file order.
    pub components: Vec<Component>,
    /// Width and height of the outline (m).
    pub size: [f64; 2],
}

/// Reads a board: `.kicad_pcb` or a KiCad position file (`.csv`), by content.
pub fn read(path: &Path) -> Result<Board, InputError> {
    let text = read_bounded(path, MAX_BOARD_BYTES).map_err(|e| {
        InputError::new(path, format!("cannot read the board: {e}"))
            .hint("give a KiCad 6–9 .kicad_pcb file or a KiCad position file (.csv)")
    })?;
    let first = text.trim_start();
    if first.starts_with('(') {
        read_kicad(path, &text)
    } else if first.to_ascii_lowercase().starts_with("ref,") || first.starts_with("\"Ref\"") {
        read_positions(path, &text)
    } else {
        Err(InputError::at_line(path, Some(1), "not a KiCad board: neither a .kicad_pcb S-expression nor a position CSV (header `Ref,Val,Package,PosX,PosY,Rot,Side`)")
            .hint("give a KiCad 6–9 .kicad_pcb file, or export positions with `kicad-cli pcb export pos --format csv --units mm`"))
    }
}

fn number(path: &Path, node: &Node, s: Option<&str>, what: &str) -> Result<f64, InputError> {
    let v = s
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|v| v.is_finite() && v.abs() < 1e6);
    v.ok_or_else(|| {
        InputError::at_line(
            path,
            Some(node.line()),
            format!(
                "{what}: expected a number (mm, below 1e6), found {}",
                s.map_or("nothing".into(), |s| format!("`{s}`"))
            ),
        )
        .hint("the board file is damaged; open and save it in KiCad")
    })
}

/// Reads a `.kicad_pcb` text.
pub fn read_kicad(path: &Path, text: &str) -> Result<Board, InputError> {
    let root = sexpr::parse(text).map_err(|e| {
        InputError::at_line(path, Some(e.line), format!("not a KiCad board: {}", e.message))
            .hint("give a KiCad 6–9 .kicad_pcb file as KiCad writes it")
    })?;
    if root.head() != Some("kicad_pcb") {
        return Err(InputError::at_line(
            path,
            Some(root.line()),
            format!(
                "not a KiCad board: the file is a `{}` S-expression, not `kicad_pcb`",
                root.head().unwrap_or("?")
            ),
        )
        .hint("give a KiCad 6–9 .kicad_pcb file (a footprint library or schematic is not a board)"));
    }
    if root.child("footprint").is_none() && root.child("module").is_some() {
        let version = root.child("version").and_then(|v| v.arg(0)).unwrap_or("?");
        return Err(InputError::at_line(
            path,
            Some(root.line()),
            format!("a KiCad 5 board (format version {version}, footprints as `module`)"),
        )
        .hint("open the board in KiCad 6 or newer and save it; cellplan reads KiCad 6–9 boards"));
    }
    let title = root
        .child("title_block")
        .and_then(|t| t.child("title"))
        .and_then(|t| t.arg(0))
        .map(str::to_string)
        .unwrap_or_else(|| file_stem(path));
    let mut raw = Vec::new();
    for fp in root.children("footprint") {
        if raw.len() >= MAX_COMPONENTS {
            return Err(InputError::at_line(
                path,
                Some(fp.line()),
                format!("more than {MAX_COMPONENTS} footprints"),
            )
            .hint("split the board, or give a position file with the components to place"));
        }
        raw.push(footprint(path, fp)?);
    }
    // The outline: every point of the Edge.Cuts drawings.
    let mut outline = Bounds::default();
    for item in root.items() {
        let Some(head) = item.head() else { continue };
        if !head.starts_with("gr_") || item.child("layer").and_then(|l| l.arg(0)) != Some("Edge.Cuts") {
            continue;
        }
        for key in ["start", "end", "mid", "center"] {
            if let Some(p) = item.child(key) {
                outline.add(number(path, p, p.arg(0), key)?, number(path, p, p.arg(1), key)?);
            }
        }
        if let Some(pts) = item.child("pts") {
            for xy in pts.children("xy") {
                outline.add(
                    number(path, xy, xy.arg(0), "xy")?,
                    number(path, xy, xy.arg(1), "xy")?,
                );
            }
        }
    }
    Ok(finish(path, title, raw, outline, 1.0))
}

/// A footprint in KiCad's frame (mm, y down) before the board frame is known.
fn footprint(path: &Path, fp: &Node) -> Result<Component, InputError> {
    let line = fp.line();
    let footprint = fp.arg(0).unwrap_or("").to_string();
    let at = fp.child("at").ok_or_else(|| {
        InputError::at_line(
            path,
            Some(line),
            format!("footprint `{footprint}` has no position (`at`)"),
        )
        .hint("the board file is damaged; open and save it in KiCad")
    })?;
    let x = number(path, at, at.arg(0), "footprint position x")?;
    let y = number(path, at, at.arg(1), "footprint position y")?;
    let rot = match at.arg(2) {
        Some(s) => number(path, at, Some(s), "footprint rotation")?,
        None => 0.0,
    };
    let side = match fp.child("layer").and_then(|l| l.arg(0)) {
        Some("B.Cu") => Side::Back,
        _ => Side::Front,
    };
    // KiCad 8+: (property "Reference" "R1"); KiCad 6–7: (fp_text reference "R1").
    let text_of = |name: &str| -> Option<String> {
        fp.children("property")
            .find(|p| p.arg(0) == Some(name))
            .and_then(|p| p.arg(1))
            .or_else(|| {
                fp.children("fp_text")
                    .find(|p| p.arg(0).is_some_and(|k| k.eq_ignore_ascii_case(name)))
                    .and_then(|p| p.arg(1))
            })
            .map(str::to_string)
    };
    let reference = text_of("Reference").unwrap_or_default();
    let value = text_of("Value").unwrap_or_default();
    let attrs: Vec<&str> = fp.child("attr").map(|a| a.args().collect()).unwrap_or_default();
    let mount = if attrs.contains(&"smd") {
        Mount::Smd
    } else if attrs.contains(&"through_hole") {
        Mount::ThroughHole
    } else {
        Mount::Unspecified
    };
    let flag = |name: &str| {
        fp.child(name)
            .is_some_and(|n| n.arg(0).is_none_or(|v| v == "yes"))
    };
    Ok(Component {
        reference,
        value,
        footprint,
        position: [x, y],
        rotation: rot.to_radians(),
        side,
        mount,
        dnp: attrs.contains(&"dnp") || flag("dnp"),
        excluded: attrs.contains(&"exclude_from_pos_files") || attrs.contains(&"board_only"),
        line,
    })
}

#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: [f64; 2],
    max: [f64; 2],
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds {
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        }
    }
}

impl Bounds {
    fn add(&mut self, x: f64, y: f64) {
        self.min = [self.min[0].min(x), self.min[1].min(y)];
        self.max = [self.max[0].max(x), self.max[1].max(y)];
    }

    fn is_empty(&self) -> bool {
        self.min[0] > self.max[0]
    }
}

/// Moves the components from the file's frame (mm; `y_sign` −1 where the file's y points up, 1
/// where it points down as in `.kicad_pcb`) to the board frame.
fn finish(path: &Path, title: String, mut raw: Vec<Component>, mut outline: Bounds, y_sign: f64) -> Board {
    if outline.is_empty() {
        for c in &raw {
            outline.add(c.position[0], c.position[1]);
        }
    }
    if outline.is_empty() {
        outline.add(0.0, 0.0);
    }
    // Board frame: x from the outline's left edge, y up from its lower edge.
    let (x0, y_low) = if y_sign > 0.0 {
        (outline.min[0], outline.max[1])
    } else {
        (outline.min[0], outline.min[1])
    };
    for c in &mut raw {
        let x = c.position[0] - x0;
        let y = if y_sign > 0.0 {
            y_low - c.position[1]
        } else {
            c.position[1] - y_low
        };
        c.position = [x * 1e-3, y * 1e-3];
    }
    Board {
        path: path.to_path_buf(),
        title,
        components: raw,
        size: [
            (outline.max[0] - outline.min[0]) * 1e-3,
            (outline.max[1] - outline.min[1]) * 1e-3,
        ],
    }
}

fn file_stem(path: &Path) -> String {
    path.file_stem()
        .map_or("board".into(), |s| s.to_string_lossy().into_owned())
}

/// Reads a KiCad position file (CSV: `Ref,Val,Package,PosX,PosY,Rot,Side`, mm, y up).
pub fn read_positions(path: &Path, text: &str) -> Result<Board, InputError> {
    let mut reader = csv::ReaderBuilder::new()
        .flexible(false)
        .from_reader(text.as_bytes());
    let headers = reader.headers().map_err(|e| csv_error(path, &e))?.clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h.trim().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                cellplan_model::other_separator(path, text).unwrap_or_else(|| {
                    InputError::at_line(path, Some(1), format!("the position file has no `{name}` column"))
                        .hint("KiCad writes `Ref,Val,Package,PosX,PosY,Rot,Side`; export with `kicad-cli pcb export pos --format csv --units mm`")
                })
            })
    };
    let (c_ref, c_val, c_pkg, c_x, c_y, c_rot, c_side) = (
        col("Ref")?,
        col("Val")?,
        col("Package")?,
        col("PosX")?,
        col("PosY")?,
        col("Rot")?,
        col("Side")?,
    );
    let mut raw = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| csv_error(path, &e))?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        if raw.len() >= MAX_COMPONENTS {
            return Err(InputError::at_line(
                path,
                Some(line),
                format!("more than {MAX_COMPONENTS} components"),
            )
            .hint("split the position file"));
        }
        let field = |i: usize| record.get(i).unwrap_or("").trim();
        let num = |i: usize, what: &str| -> Result<f64, InputError> {
            field(i)
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.abs() < 1e6)
                .ok_or_else(|| {
                    InputError::at_line(
                        path,
                        Some(line),
                        format!("{what}: expected a number (mm, below 1e6), found `{}`", field(i)),
                    )
                    .hint("positions are in mm and rotations in degrees, as KiCad writes them")
                })
        };
        let side = match field(c_side).to_ascii_lowercase().as_str() {
            "top" | "front" => Side::Front,
            "bottom" | "back" => Side::Back,
            other => {
                return Err(InputError::at_line(
                    path,
                    Some(line),
                    format!("side `{other}`: expected `top` or `bottom`"),
                )
                .hint("the Side column says `top` or `bottom`"));
            }
        };
        raw.push(Component {
            reference: field(c_ref).to_string(),
            value: field(c_val).to_string(),
            footprint: field(c_pkg).to_string(),
            position: [num(c_x, "PosX")?, num(c_y, "PosY")?],
            rotation: num(c_rot, "Rot")?.to_radians(),
            side,
            mount: Mount::Smd,
            dnp: false,
            excluded: false,
            line,
        });
    }
    Ok(finish(path, file_stem(path), raw, Bounds::default(), -1.0))
}

fn csv_error(path: &Path, e: &csv::Error) -> InputError {
    let line = e.position().map(|p| p.line() as usize);
    InputError::at_line(path, line, format!("not a KiCad position file: {e}"))
        .hint("KiCad writes `Ref,Val,Package,PosX,PosY,Rot,Side`, one row per component")
}

/// Which footprints a machine places.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    /// The side being populated.
    pub side: Side,
    /// The mountings placed (by default SMD only).
    pub mounts: Vec<Mount>,
    /// Only these references (empty: all); unknown ones are an error.
    pub only: Vec<String>,
}

/// Why a footprint is not placed.
pub fn skipped_because(c: &Component, sel: &Selection) -> Option<&'static str> {
    if c.dnp {
        Some("do not populate")
    } else if c.excluded {
        Some("excluded from position files")
    } else if c.reference.contains('*') {
        // KiCad's `REF**`: a footprint never annotated (mounting holes, logos, test pads).
        Some("not annotated (reference with `*`)")
    } else if c.side != sel.side {
        Some("other side")
    } else if !sel.mounts.contains(&c.mount) {
        Some("mounting not placed by this machine")
    } else if !sel.only.is_empty() && !sel.only.iter().any(|r| r == &c.reference) {
        Some("not in `components`")
    } else {
        None
    }
}

/// The components to place, in the frame of the populated side (the back side is seen
/// mirrored: x ↦ width − x, rotation ↦ π − rotation).
pub fn select(board: &Board, sel: &Selection) -> Vec<Component> {
    board
        .components
        .iter()
        .filter(|c| skipped_because(c, sel).is_none())
        .map(|c| {
            let mut c = c.clone();
            if sel.side == Side::Back {
                c.position[0] = board.size[0] - c.position[0];
                c.rotation = std::f64::consts::PI - c.rotation;
            }
            c.rotation = c.rotation.rem_euclid(std::f64::consts::TAU);
            c
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const KICAD8: &str = r#"(kicad_pcb (version 20240108) (generator "pcbnew")
  (title_block (title "Test"))
  (gr_rect (start 100 50) (end 150 80) (layer "Edge.Cuts"))
  (footprint "Resistor_SMD:R_0402" (layer "F.Cu") (at 110 70 90)
    (property "Reference" "R1") (property "Value" "10k") (attr smd))
  (footprint "Capacitor_SMD:C_0402" (layer "B.Cu") (at 120 60)
    (property "Reference" "C1") (property "Value" "100n") (attr smd))
  (footprint "Conn:Pin" (layer "F.Cu") (at 130 60)
    (property "Reference" "J1") (property "Value" "HDR") (attr through_hole))
  (footprint "Logo" (layer "F.Cu") (at 140 60)
    (property "Reference" "G1") (property "Value" "LOGO") (attr board_only exclude_from_pos_files))
  (footprint "Resistor_SMD:R_0402" (layer "F.Cu") (at 145 60)
    (property "Reference" "R2") (property "Value" "1k") (attr smd dnp))
)"#;

    #[test]
    fn reads_a_kicad8_board_into_the_board_frame() {
        let b = read_kicad(Path::new("t.kicad_pcb"), KICAD8).unwrap();
        assert_eq!(b.title, "Test");
        assert_eq!(b.components.len(), 5);
        assert!((b.size[0] - 0.05).abs() < 1e-12 && (b.size[1] - 0.03).abs() < 1e-12);
        let r1 = &b.components[0];
        assert_eq!((r1.reference.as_str(), r1.value.as_str()), ("R1", "10k"));
        // x from the left edge (100), y up from the lower edge (80, KiCad y down).
        assert!((r1.position[0] - 0.010).abs() < 1e-12 && (r1.position[1] - 0.010).abs() < 1e-12);
        assert!((r1.rotation - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(r1.line, 4);
        assert!(b.components[4].dnp && b.components[3].excluded);
        let sel = Selection {
            side: Side::Front,
            mounts: vec![Mount::Smd],
            only: vec![],
        };
        let chosen: Vec<_> = select(&b, &sel).into_iter().map(|c| c.reference).collect();
        assert_eq!(chosen, ["R1"]);
        let back = Selection {
            side: Side::Back,
            ..sel
        };
        let c1 = &select(&b, &back)[0];
        assert_eq!(c1.reference, "C1");
        assert!((c1.position[0] - 0.03).abs() < 1e-12, "mirrored: 50 − 20 mm");
    }

    #[test]
    fn reads_kicad6_text_fields_and_position_files() {
        let k6 = r#"(kicad_pcb (version 20211014)
 (footprint "R" (layer "F.Cu") (at 1 2) (fp_text reference "R9" (at 0 0)) (fp_text value "47k" (at 0 0)) (attr smd)))"#;
        let b = read_kicad(Path::new("k6.kicad_pcb"), k6).unwrap();
        assert_eq!(b.components[0].reference, "R9");
        assert_eq!(b.components[0].value, "47k");
        let csv =
            "Ref,Val,Package,PosX,PosY,Rot,Side\nR1,10k,R_0402,10,5,90,top\nC1,1u,C_0603,20,15,0,bottom\n";
        let b = read_positions(Path::new("p.csv"), csv).unwrap();
        assert_eq!(b.components.len(), 2);
        assert_eq!(b.components[1].side, Side::Back);
        assert!(
            (b.components[1].position[1] - 0.010).abs() < 1e-12,
            "y up, from the lowest"
        );
        assert_eq!(b.components[1].line, 3);
    }

    #[test]
    fn refuses_what_is_not_a_board_with_the_line() {
        let e = read_kicad(Path::new("x"), "(kicad_sch (version 1))").unwrap_err();
        assert!(e.message.contains("not `kicad_pcb`"), "{}", e.message);
        let e = read_kicad(
            Path::new("x"),
            "(kicad_pcb (version 20171130) (module \"R\" (at 1 2)))",
        )
        .unwrap_err();
        assert!(e.message.contains("KiCad 5"), "{}", e.message);
        let e = read_kicad(
            Path::new("x"),
            "(kicad_pcb\n(footprint \"R\" (layer \"F.Cu\")\n (property \"Reference\" \"R1\")))",
        )
        .unwrap_err();
        assert!(e.message.contains("no position") && e.line == Some(2), "{e}");
        let e = read_kicad(Path::new("x"), "(kicad_pcb\n(footprint \"R\"\n (at 1 nan)))").unwrap_err();
        assert_eq!(e.line, Some(3));
        let e = read_positions(
            Path::new("p.csv"),
            "Ref,Val,Package,PosX,PosY,Rot,Side\nR1,1k,R,1,x,0,top\n",
        )
        .unwrap_err();
        assert_eq!(e.line, Some(2));
        let e = read_positions(Path::new("p.csv"), "Ref,Val,PosX\nR1,1k,1\n").unwrap_err();
        assert!(e.message.contains("Package"));
        // A spreadsheet's export with `;` between the columns is named as such.
        let e = read_positions(
            Path::new("p.csv"),
            "Ref;Val;Package;PosX;PosY;Rot;Side\nR1;1k;R;1,5;2;0;top\n",
        )
        .unwrap_err();
        assert!(e.message.contains("separated by `;`") && e.line == Some(1), "{e}");
    }
}
