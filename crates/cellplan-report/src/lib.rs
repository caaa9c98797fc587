//! cellplan's reports and exports: they read only the Plan document and the cell (for geometry
//! and kinematics), never the planner. [`svg`] draws a cell from above and from the side;
//! [`scene`] is the cell to draw (shared, decimated meshes; robots as their URDF chains);
//! [`playback`] reads a robot's intervals and joint values from a plan; [`charts`] draws the
//! Gantt, time–position and strategy charts; [`html`] assembles the self-contained report with
//! its WebGL viewer; [`gltf`] and [`csv`] export a plan for other tools; [`pcb`], [`cmm`] and
//! [`studweld`] are the pages of the PCB-assembly, CMM-inspection and stud-weld processes.
#![warn(missing_docs)]

pub mod charts;
pub mod cmm;
pub mod csv;
pub mod gltf;
pub mod html;
pub mod pcb;
pub mod playback;
pub mod scene;
pub mod studweld;
pub mod svg;

/// Text made safe for XML and HTML (element text and quoted attributes).
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
