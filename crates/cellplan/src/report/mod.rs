//! Reports for people and machines.
pub mod charts;
pub mod check;
pub mod html;
pub mod playback;
pub mod scene;
pub mod svg;
