//! Checks of a URDF's structure and numbers that urdf-rs would reject without a line, or accept
//! silently: every number finite, lengths within [`MAX_LENGTH_M`], joints and inertials whole.
use super::{Loader, MAX_LENGTH_M, line_of, xml};
use crate::KinError;
use std::collections::HashMap;

/// Which bound the numbers of an attribute must meet.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Bound {
    /// Finite.
    Finite,
    /// Finite and at most [`MAX_LENGTH_M`] in magnitude.
    Length,
}

impl Loader<'_> {
    /// Checks the structure urdf-rs would reject (or silently accept) with a line number.
    pub(super) fn validate(&self, doc: &xml::Document) -> Result<(), KinError> {
        let root = doc.root();
        if root.name != "robot" {
            let hint = if root.name.contains("xacro") || self.text.contains("xmlns:xacro") {
                "this looks like xacro: run `xacro file.urdf.xacro > file.urdf` first"
            } else {
                "a URDF file has a <robot> root element"
            };
            return Err(self.err(
                Some(root.line),
                format!(
                    "the root element is <{}>, not <robot>: this is not a URDF",
                    root.name
                ),
                hint,
            ));
        }
        let xacro_hint = "this looks like xacro: run `xacro file.urdf.xacro > file.urdf` first";
        let mut link_names: HashMap<&str, usize> = HashMap::new();
        let mut joint_names: HashMap<&str, usize> = HashMap::new();
        for e in doc.children(root) {
            if e.name.starts_with("xacro:") {
                return Err(self.err(
                    Some(e.line),
                    format!("<{}> is a xacro macro, not URDF", e.name),
                    xacro_hint,
                ));
            }
            let (names, what) = match e.name.as_str() {
                "link" => (&mut link_names, "link"),
                "joint" => (&mut joint_names, "joint"),
                _ => continue,
            };
            let Some(name) = e.attr("name") else {
                return Err(self.err(
                    Some(e.line),
                    format!("<{what}> without a name"),
                    format!("give the {what} a name=\"...\" attribute"),
                ));
            };
            if let Some(first) = names.insert(name, e.line) {
                return Err(self.err(
                    Some(e.line),
                    format!("{what} '{name}' is defined twice (first on line {first})"),
                    format!("{what} names must be unique"),
                ));
            }
            if what == "link" {
                let owner = format!("link '{name}'");
                for c in doc.children(e) {
                    match c.name.as_str() {
                        "collision" | "visual" => {
                            self.validate_origin(doc, c, &owner)?;
                            self.validate_geometry(doc, c, &owner)?;
                        }
                        "inertial" => self.validate_inertial(doc, c, &owner)?,
                        _ => {}
                    }
                }
            } else {
                self.validate_joint(doc, e, name)?;
            }
        }
        Ok(())
    }

    fn validate_joint(&self, doc: &xml::Document, e: &xml::Element, name: &str) -> Result<(), KinError> {
        const TYPES: [&str; 7] = [
            "revolute",
            "continuous",
            "prismatic",
            "fixed",
            "floating",
            "planar",
            "spherical",
        ];
        let Some(ty) = e.attr("type") else {
            return Err(self.err(
                Some(e.line),
                format!("joint '{name}' has no type"),
                "add type=\"revolute\" (or continuous, prismatic, fixed)",
            ));
        };
        if !TYPES.contains(&ty) {
            return Err(self.err(
                Some(e.line),
                format!("joint '{name}' has unknown type '{ty}'"),
                "use revolute, continuous, prismatic, fixed, floating or planar",
            ));
        }
        for role in ["parent", "child"] {
            match doc.child(e, role) {
                Some(p) if p.attr("link").is_some() => {}
                Some(p) => {
                    return Err(self.err(
                        Some(p.line),
                        format!("<{role}> of joint '{name}' has no link attribute"),
                        format!("write <{role} link=\"...\"/>"),
                    ));
                }
                None => {
                    return Err(self.err(
                        Some(e.line),
                        format!("joint '{name}' has no <{role}>"),
                        format!("add <{role} link=\"...\"/>"),
                    ));
                }
            }
        }
        let owner = format!("joint '{name}'");
        self.validate_origin(doc, e, &owner)?;
        if let Some(axis) = doc.child(e, "axis") {
            self.numbers(&owner, axis, "xyz", 3, true, Bound::Finite)?;
        }
        match doc.child(e, "limit") {
            Some(limit) => {
                // A prismatic joint's limits are lengths; a revolute joint's are angles.
                let position = if ty == "prismatic" {
                    Bound::Length
                } else {
                    Bound::Finite
                };
                for attr in ["lower", "upper"] {
                    self.numbers(&owner, limit, attr, 1, false, position)?;
                }
                self.numbers(&owner, limit, "effort", 1, false, Bound::Finite)?;
                self.numbers(&owner, limit, "velocity", 1, true, Bound::Finite)?;
            }
            None if ty == "revolute" || ty == "prismatic" => {
                return Err(self.err(
                    Some(e.line),
                    format!("{ty} joint '{name}' has no <limit>"),
                    "add <limit lower=\"..\" upper=\"..\" effort=\"..\" velocity=\"..\"/> (or make it continuous)",
                ));
            }
            None => {}
        }
        Ok(())
    }

    fn validate_inertial(&self, doc: &xml::Document, e: &xml::Element, owner: &str) -> Result<(), KinError> {
        self.validate_origin(doc, e, owner)?;
        match doc.child(e, "mass") {
            Some(m) => self.numbers(owner, m, "value", 1, true, Bound::Finite)?,
            None => {
                return Err(self.err(
                    Some(e.line),
                    "<inertial> without <mass>",
                    "add <mass value=\"...\"/> or remove the <inertial>",
                ));
            }
        }
        match doc.child(e, "inertia") {
            Some(i) => {
                for attr in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"] {
                    self.numbers(owner, i, attr, 1, true, Bound::Finite)?;
                }
                Ok(())
            }
            None => Err(self.err(
                Some(e.line),
                "<inertial> without <inertia>",
                "add <inertia ixx=.. ixy=.. ixz=.. iyy=.. iyz=.. izz=../>",
            )),
        }
    }

    fn validate_origin(&self, doc: &xml::Document, e: &xml::Element, owner: &str) -> Result<(), KinError> {
        if let Some(o) = doc.child(e, "origin") {
            self.numbers(owner, o, "xyz", 3, false, Bound::Length)?;
            self.numbers(owner, o, "rpy", 3, false, Bound::Finite)?;
        }
        Ok(())
    }

    fn validate_geometry(
        &self,
        doc: &xml::Document,
        collision: &xml::Element,
        owner: &str,
    ) -> Result<(), KinError> {
        let Some(g) = doc.child(collision, "geometry") else {
            return Err(self.err(
                Some(collision.line),
                format!("<{}> without <geometry>", collision.name),
                "add <geometry> with a box, cylinder, sphere or mesh",
            ));
        };
        let Some(shape) = doc.children(g).next() else {
            return Err(self.err(
                Some(g.line),
                "empty <geometry>",
                "add a box, cylinder, sphere or mesh",
            ));
        };
        match shape.name.as_str() {
            "box" => self.numbers(owner, shape, "size", 3, true, Bound::Length),
            "cylinder" | "capsule" => {
                self.numbers(owner, shape, "radius", 1, true, Bound::Length)?;
                self.numbers(owner, shape, "length", 1, true, Bound::Length)
            }
            "sphere" => self.numbers(owner, shape, "radius", 1, true, Bound::Length),
            "mesh" => {
                if shape.attr("filename").is_none() {
                    return Err(self.err(
                        Some(shape.line),
                        "<mesh> without filename",
                        "add filename=\"package://...\"",
                    ));
                }
                // A factor: the scaled mesh is checked when it is loaded.
                self.numbers(owner, shape, "scale", 3, false, Bound::Finite)
            }
            other => Err(self.err(
                Some(shape.line),
                format!("unknown geometry <{other}>"),
                "use box, cylinder, sphere or mesh",
            )),
        }
    }

    /// Attribute `attr` of `e` (an element of `owner`, e.g. `joint 'j1'`) holds `n` numbers,
    /// finite and within `bound`.
    fn numbers(
        &self,
        owner: &str,
        e: &xml::Element,
        attr: &str,
        n: usize,
        required: bool,
        bound: Bound,
    ) -> Result<(), KinError> {
        let Some(v) = e.attr(attr) else {
            if required {
                return Err(self.err(
                    Some(e.line),
                    format!("<{}> needs attribute {attr}", e.name),
                    format!("add {attr}=\"...\" with {n} number(s)"),
                ));
            }
            return Ok(());
        };
        let parsed: Vec<Option<f64>> = v
            .split_whitespace()
            .map(|s| s.parse::<f64>().ok().filter(|x| !x.is_nan()))
            .collect();
        if parsed.len() != n || parsed.iter().any(Option::is_none) {
            return Err(self.err(
                Some(e.line),
                format!("attribute {attr}=\"{v}\" of <{}> must be {n} number(s)", e.name),
                format!("write {n} number(s) separated by spaces"),
            ));
        }
        let values = parsed.into_iter().flatten();
        if let Some(x) = values.clone().find(|x| !x.is_finite()) {
            return Err(self.err(
                Some(e.line),
                format!(
                    "attribute {attr}=\"{v}\" of <{}> in {owner} is {x}, not a finite number",
                    e.name
                ),
                "write finite numbers (to leave a joint limit open, leave the attribute out)",
            ));
        }
        if bound == Bound::Length
            && let Some(x) = values.clone().find(|x| x.abs() > MAX_LENGTH_M)
        {
            return Err(self.err(
                Some(e.line),
                format!(
                    "attribute {attr}=\"{v}\" of <{}> in {owner}: {x:e} m exceeds {MAX_LENGTH_M:e} m \
                     in magnitude — is the unit right?",
                    e.name
                ),
                "URDF lengths are in metres: convert millimetres (divide by 1000)",
            ));
        }
        Ok(())
    }

    /// A line for an urdf-rs error message: the one it states, else where a quoted value of
    /// the message first occurs in the file.
    pub(super) fn guess_line(&self, msg: &str) -> Option<usize> {
        if let Some(rest) = msg.split("Line: ").nth(1) {
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            if let Ok(l) = digits.parse() {
                return Some(l);
            }
        }
        for (open, close) in [('`', '`'), ('[', ']')] {
            if let Some(start) = msg.find(open) {
                let rest = &msg[start + 1..];
                if let Some(end) = rest.find(close) {
                    let needle = &rest[..end];
                    let found = (!needle.is_empty())
                        .then(|| line_of(self.text, &format!("\"{needle}\"")))
                        .flatten();
                    if found.is_some() {
                        return found;
                    }
                }
            }
        }
        None
    }
}
