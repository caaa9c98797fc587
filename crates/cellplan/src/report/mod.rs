//! Reports for people and machines.
pub mod charts;
pub mod check;
pub mod html;
pub mod playback;
pub mod scene;
pub mod svg;

/// Text made safe for XML and HTML (element text and quoted attributes).
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
