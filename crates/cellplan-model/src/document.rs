//! What every process's plan document shares: reading one (bounded, with the line of a JSON
//! error), checking its format and version, and its JSON Schema as text kept in `docs/`.
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::path::Path;

/// Reads a JSON document of at most `limit` bytes; `what` names it in errors ("a PCB plan
/// document").
pub fn read_json<T: DeserializeOwned>(path: &Path, limit: u64, what: &str) -> Result<T, String> {
    let text = crate::io::read_bounded(path, limit).map_err(|e| format!("cannot read the plan: {e}"))?;
    serde_json::from_str(&text).map_err(|e| format!("line {}: not {what}: {e}", e.line()))
}

/// `Ok` when a document's `(format, version)` is the one this build reads.
pub fn check_version(found: (&str, u32), wanted: (&str, u32)) -> Result<(), String> {
    if found == wanted {
        return Ok(());
    }
    Err(format!(
        "a `{}` version {} document; this cellplan reads `{}` version {}",
        found.0, found.1, wanted.0, wanted.1
    ))
}

/// A JSON Schema (as `schemars::schema_for!` makes it) as the text `docs/*.schema.json` holds.
pub fn schema_text(schema: &impl Serialize) -> String {
    let mut text = serde_json::to_string_pretty(schema).unwrap_or_default();
    text.push('\n');
    text
}

/// For the tests that keep `docs/*.schema.json` true: the file at `path` is `generated`
/// (rewritten first when `CELLPLAN_UPDATE_SCHEMA` is set); its parsed schema, or why not.
pub fn schema_file_matches(path: &Path, generated: &str) -> Result<serde_json::Value, String> {
    if std::env::var_os("CELLPLAN_UPDATE_SCHEMA").is_some() {
        std::fs::write(path, generated).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    let on_disk =
        std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if on_disk != generated {
        return Err(format!(
            "{} is not the schema of the document's types",
            path.display()
        ));
    }
    serde_json::from_str(&on_disk).map_err(|e| e.to_string())
}
