//! A CMM-inspection cell (`[process] kind = "cmm-inspection"`, docs/cell-format.md): the
//! machine's travel, speeds and home, the head's angle ranges, the probe's bodies, the part (a
//! mesh, posed), its fixtures, and the measuring points (a task CSV in the part's frame) with
//! their faces and which faces are adjacent.
use crate::classify::{Method, Probe, ProbeBodies};
use crate::motion::Travel;
use crate::part::Mp;
use cellplan_geom::{Pose, ShapeSpec};
use cellplan_kin::cmm::{CmmHead, CmmSpeeds};
use std::path::PathBuf;

mod load;
pub use load::load;
#[cfg(test)]
pub(crate) use load::read_mps;

/// The `[process] kind` of a CMM-inspection cell.
pub const KIND: &str = "cmm-inspection";

/// Most MPs a cell may hold (RRT-MRNC checks every pair of roots of a group).
pub const MAX_MPS: usize = 2000;

/// A CMM-inspection cell, in metres and radians.
#[derive(Clone, Debug)]
pub struct CmmCell {
    /// Name (the default output folder).
    pub name: String,
    /// The cell file.
    pub path: PathBuf,
    /// The part and the fixtures: name, shape, pose in the machine frame.
    pub statics: Vec<(String, ShapeSpec, Pose)>,
    /// The part's mesh file and the metres per unit of its coordinates (for other tools).
    pub part_file: (PathBuf, f64),
    /// The measuring points, in the machine frame.
    pub mps: Vec<Mp>,
    /// The task file, and each MP's line in it.
    pub tasks_file: PathBuf,
    /// Line of each MP in the task file.
    pub mp_lines: Vec<usize>,
    /// Face names ([`Mp::face`] indexes them).
    pub faces: Vec<String>,
    /// Adjacent face pairs; `None`: every pair of faces counts as adjacent.
    pub adjacent: Option<Vec<(usize, usize)>>,
    /// The head and stylus.
    pub head: CmmHead,
    /// The probe's collision bodies.
    pub bodies: ProbeBodies,
    /// Travel of the head's A-axis centre.
    pub travel: Travel,
    /// Where every job starts and ends.
    pub home: [f64; 5],
    /// Movement and rotation speeds.
    pub speeds: CmmSpeeds,
    /// Time per MP: approach from the pretouch distance, touch, retract (s).
    pub inspection_s: f64,
    /// Smallest distance between the probe (head and ram included) and the part or a fixture
    /// while moving (m).
    pub clearance: f64,
    /// Smallest distance between the probe (less the ball and the stylus's last millimetres)
    /// and the part or a fixture while touching (m).
    pub touch_clearance: f64,
    /// Pretouch distance: the probe stops this far off the surface, along the normal, before it
    /// touches (m).
    pub pretouch: f64,
    /// The candidate orientations' grid step for a continuous head (rad).
    pub orientation_step: f64,
    /// How the groups are found.
    pub classification: Method,
}

impl CmmCell {
    /// The probe in this cell's scene.
    pub fn probe(&self) -> Probe {
        Probe::new(self.statics.clone(), self.head, self.bodies)
    }

    /// Whether faces `f` and `g` are adjacent (eq. 3).
    pub fn adjacent(&self, f: usize, g: usize) -> bool {
        f != g
            && self
                .adjacent
                .as_ref()
                .is_none_or(|pairs| pairs.iter().any(|&(a, b)| (a, b) == (f, g) || (b, a) == (f, g)))
    }

    /// The candidate head orientations: the index grid of an indexing head, else a grid of
    /// [`CmmCell::orientation_step`] within the ranges.
    pub fn orientations(&self) -> Vec<(f64, f64)> {
        if self.head.index_step.is_some() {
            return self.head.indexed_orientations();
        }
        CmmHead {
            index_step: Some(self.orientation_step),
            ..self.head
        }
        .indexed_orientations()
    }

    /// The MP named `id`.
    pub fn mp(&self, id: &str) -> Option<usize> {
        self.mps.iter().position(|m| m.name == id)
    }
}
