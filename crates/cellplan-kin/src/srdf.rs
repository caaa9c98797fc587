//! Reading the collision rules of an SRDF (MoveIt's semantic robot description): the link pairs
//! that are never checked against each other.
use crate::KinError;
use crate::urdf::xml;
use cellplan_geom::read::{LimitedReadError, read_limited, show_bytes, utf8_text};
use std::path::Path;

/// Largest SRDF file read, in bytes (16 MiB; real ones are a few kilobytes).
pub const MAX_SRDF_BYTES: u64 = 16 << 20;

/// A `<disable_collisions link1 link2 reason>` rule.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DisabledPair {
    /// First link name.
    pub link1: String,
    /// Second link name.
    pub link2: String,
    /// Why (`Adjacent`, `Never`, `Default`, …), as written.
    pub reason: String,
}

/// The `disable_collisions` rules of the SRDF at `path`, in file order. Other elements are
/// ignored. Refuses a file that is not XML with a `<robot>` root, and a rule without both links.
pub fn read_disabled_pairs(path: &Path) -> Result<Vec<DisabledPair>, KinError> {
    let refuse = |line: Option<usize>, message: String, hint: &str| KinError::Urdf {
        path: path.to_path_buf(),
        line,
        message,
        hint: hint.to_string(),
    };
    let bytes = read_limited(path, MAX_SRDF_BYTES).map_err(|e| match e {
        LimitedReadError::Io(source) => KinError::Io {
            path: path.to_path_buf(),
            source,
        },
        LimitedReadError::TooLarge { size } => refuse(
            None,
            format!(
                "the file is {size}, larger than the {} an SRDF may have",
                show_bytes(MAX_SRDF_BYTES)
            ),
            "check that the path names an SRDF",
        ),
    })?;
    let text = utf8_text(bytes).map_err(|e| {
        refuse(
            Some(e.line),
            format!(
                "byte {} (0x{:02x}) is not UTF-8 text: this is not an SRDF file",
                e.offset, e.byte
            ),
            "check that the path names an SRDF, and save it as UTF-8",
        )
    })?;
    parse_disabled_pairs(&text).map_err(|(line, message)| {
        refuse(
            Some(line),
            message,
            "an SRDF is an XML file with a <robot> root; each <disable_collisions> names link1 and link2",
        )
    })
}

/// [`read_disabled_pairs`] on text; errors as (line, message).
pub(crate) fn parse_disabled_pairs(text: &str) -> Result<Vec<DisabledPair>, (usize, String)> {
    let doc = xml::parse(text).map_err(|(line, msg)| (line, format!("not well-formed XML: {msg}")))?;
    let root = doc.root();
    if root.name != "robot" {
        return Err((
            root.line,
            format!("the root element is <{}>, not <robot>", root.name),
        ));
    }
    doc.children(root)
        .filter(|e| e.name == "disable_collisions")
        .map(|e| match (e.attr("link1"), e.attr("link2")) {
            (Some(a), Some(b)) => Ok(DisabledPair {
                link1: a.to_string(),
                link2: b.to_string(),
                reason: e.attr("reason").unwrap_or_default().to_string(),
            }),
            _ => Err((e.line, "<disable_collisions> without link1 and link2".to_string())),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rules_and_refuses_broken_ones() {
        let text = r#"<?xml version="1.0"?>
<robot name="r">
  <group name="arm"><chain base_link="a" tip_link="c"/></group>
  <disable_collisions link1="a" link2="b" reason="Adjacent" />
  <disable_collisions link1="b" link2="c" reason="Never"/>
</robot>"#;
        let pairs = parse_disabled_pairs(text).unwrap();
        assert_eq!(pairs.len(), 2);
        assert_eq!((pairs[1].link1.as_str(), pairs[1].link2.as_str()), ("b", "c"));
        assert_eq!(pairs[0].reason, "Adjacent");
        let missing = "<robot name=\"r\">\n<disable_collisions link1=\"a\"/>\n</robot>";
        assert_eq!(parse_disabled_pairs(missing).unwrap_err().0, 2);
        assert!(
            parse_disabled_pairs("<srdf/>")
                .unwrap_err()
                .1
                .contains("not <robot>")
        );
        assert!(parse_disabled_pairs("<robot><x></robot>").is_err());
    }
}
