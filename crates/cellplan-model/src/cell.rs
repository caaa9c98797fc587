//! The cell: robots, tools, static objects, tasks and the process, loaded from a cell file and
//! checked, in SI units, with the collision world built.
use crate::InputError;
use crate::process::Process;
use crate::robot::{Robot, RobotId};
use crate::self_pairs;
use crate::spec::UnitsSpec;
use crate::tasks::Task;
use cellplan_geom::{CollisionWorld, Pose, ShapeSpec, StaticId};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;

/// The `[planning]` table: limits every process shares (SI).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Planning {
    /// Smallest distance between a robot (with its tool) and static objects, and between robots
    /// (m).
    pub clearance: f64,
    /// φ: most tasks one robot may be given.
    pub task_cap: usize,
    /// γ: largest difference between robots' times (s), if bounded.
    pub balance_limit: Option<f64>,
}

impl Default for Planning {
    fn default() -> Self {
        Planning {
            clearance: 0.010,
            task_cap: 14,
            balance_limit: None,
        }
    }
}

/// A static object of the scene.
#[derive(Clone, Debug)]
pub struct Object {
    /// Unique name.
    pub name: String,
    /// Shape in its own frame (m).
    pub shape: ShapeSpec,
    /// Pose in the world.
    pub pose: Pose,
    /// Its id in the collision world.
    pub id: StaticId,
}

/// Where things were written in the cell file, for messages about them.
#[derive(Clone, Debug, Default)]
pub struct Source {
    /// The cell file's text.
    pub text: String,
    /// Span of each robot's `base` (by robot index).
    pub robot_base: Vec<Range<usize>>,
}

/// A loaded, checked cell.
pub struct Cell {
    /// Name for reports.
    pub name: String,
    /// The cell file.
    pub path: PathBuf,
    /// Units the file was written in (outputs for people use them too).
    pub units: UnitsSpec,
    /// The process.
    pub process: Arc<dyn Process>,
    /// The shared planning limits.
    pub planning: Planning,
    /// Robots, in file order.
    pub robots: Vec<Robot>,
    /// Static objects, in file order.
    pub objects: Vec<Object>,
    /// Tasks, in file order.
    pub tasks: Vec<Task>,
    /// Static scene and robot bodies.
    pub world: CollisionWorld,
    /// The task file.
    pub tasks_path: PathBuf,
    /// Spans in the cell file.
    pub source: Source,
    /// Cache entries computed while loading, written by [`Cell::save_cache`] once the run has
    /// succeeded.
    pub pending_cache: Vec<self_pairs::PendingCache>,
}

impl Cell {
    /// An error pointing at robot `r`'s `base` in the cell file.
    pub fn error_at_robot_base(&self, r: RobotId, message: impl Into<String>) -> InputError {
        let span = self.source.robot_base.get(r.0).cloned().unwrap_or(0..0);
        InputError::at_span(&self.path, &self.source.text, span, message)
    }

    /// Writes the cache entries computed while loading (call once the run has succeeded; a
    /// cache that cannot be written is skipped, it only saves time).
    pub fn save_cache(&self) {
        for entry in &self.pending_cache {
            let _ = crate::io::write_atomic(&entry.file, entry.text.as_bytes());
        }
    }

    /// Robot by name.
    pub fn robot(&self, name: &str) -> Option<&Robot> {
        self.robots.iter().find(|r| r.name == name)
    }
}
