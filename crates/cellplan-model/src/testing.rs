//! A stand-in process for the model's own tests: the example cells' `[process]` table is
//! accepted as it is, the tool points along the task normal at the task, nothing is refused.
use crate::process::{Figure, Process, ProcessEntry, ProcessInput, ProcessReason, Words, Work};
use crate::{Cell, InputError, LoadOptions, Registry, Robot, Task, TaskId};
use cellplan_geom::{CollisionWorld, Pose};
use std::path::Path;
use std::sync::Arc;

#[derive(Debug)]
struct Plain;

static WORDS: Words = Words {
    task: "task",
    tasks: "tasks",
    working: "working",
    tool: "tool",
};

impl Process for Plain {
    fn kind(&self) -> &'static str {
        "optical-inspection"
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn words(&self) -> &'static Words {
        &WORDS
    }
    fn parameters(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    fn tool_reach(&self) -> f64 {
        0.0
    }
    fn tool_poses(&self, task: &Task) -> Vec<Pose> {
        vec![Pose::from_translation(task.position)]
    }
    fn pose_check(&self, _: &Task, _: &Pose) -> Result<(), ProcessReason> {
        Ok(())
    }
    fn reached_check(&self, _: &CollisionWorld, _: &Task, _: &Pose) -> Result<(), ProcessReason> {
        Ok(())
    }
    fn arm_check(
        &self,
        _: &CollisionWorld,
        _: &Robot,
        _: &[Pose],
        _: &Task,
        _: &Pose,
    ) -> Result<(), ProcessReason> {
        Ok(())
    }
    fn work(&self, _: &Task) -> Work {
        Work::Dwell(0.0)
    }
    fn visit_figures(&self, _: &Task, _: &Pose) -> Vec<Figure> {
        Vec::new()
    }
    fn local_sets(&self, _: &[Task], _: &[TaskId], _: f64) -> Option<Vec<Vec<TaskId>>> {
        None
    }
    fn nearby_poses(&self, _: &Task, _: &Pose, _: f64) -> Vec<Pose> {
        Vec::new()
    }
}

fn build(input: &ProcessInput) -> Result<Arc<dyn Process>, InputError> {
    let _: toml::Table = input.parse()?;
    Ok(Arc::new(Plain))
}

/// The registry of the model's tests.
pub fn registry() -> Registry {
    Registry::new().with(ProcessEntry {
        kind: "optical-inspection",
        summary: "stand-in",
        task_columns: &[],
        build,
    })
}

/// An example cell (`examples/<name>`) under the stand-in process.
pub fn example(name: &str, self_pair_samples: usize) -> Cell {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../examples/{name}/cell.toml"));
    crate::load(
        &path,
        &registry(),
        &LoadOptions {
            self_pair_samples,
            ..LoadOptions::default()
        },
    )
    .unwrap()
}
