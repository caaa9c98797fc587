//! The CMM plan document (`plan.json`, `docs/plan-format.md` § CMM inspection): the machine's
//! path as configurations `[x, y, z, a, b]` (m, rad) — straight moves of the head centre, head
//! turns — with the MPs touched at some of them, each group's stored paths (start, roots,
//! root-to-MP paths) from which any subset is re-inspected, and the times of paper 003's
//! Table 3. `cellplan verify` re-derives every number from this document and the cell alone.
use crate::cell::CmmCell;
use crate::classify::{Group, Method};
use crate::job::{Job, JobGroup, JobSettings, Reused};
use crate::mrnc::GroupPaths;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `format` of a CMM plan.
pub const FORMAT: &str = "cellplan-cmm-plan";
/// Version of the layout.
pub const VERSION: u32 = 1;
/// Largest plan file read (bytes).
pub const MAX_PLAN_BYTES: u64 = 256 << 20;

/// How the path of a plan was made.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// Planned whole: groups, RRT-MRNC, orders.
    Plan,
    /// A subset through the stored roots (paper 003's path reuse).
    ReuseRoots,
    /// The initial path walked again, touching only the subset.
    ReuseInitialPath,
    /// The subset planned from scratch.
    Replan,
}

impl Strategy {
    /// The name as written.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Plan => "plan",
            Strategy::ReuseRoots => "reuse-roots",
            Strategy::ReuseInitialPath => "reuse-initial-path",
            Strategy::Replan => "replan",
        }
    }
}

/// The plan.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CmmPlan {
    /// Always `cellplan-cmm-plan`.
    pub format: String,
    /// Layout version ([`VERSION`]).
    pub version: u32,
    /// `cmm-inspection`.
    pub process: String,
    /// The cell's name.
    pub cell: String,
    /// The cell file, absolute where it could be resolved (`cellplan reuse` reads it).
    pub cell_file: String,
    /// How this path was made.
    pub strategy: Strategy,
    /// `exact` or `greedy` (paper 003's).
    pub classification: String,
    /// `ga` (paper 003's enhanced GA) or `ils` (ours).
    pub order: String,
    /// Seed of the run.
    pub seed: u64,
    /// Height the head turns at (m): every move and turn there is above the part by the
    /// probe's whole reach.
    pub turn_height_m: f64,
    /// Where the path starts and ends.
    pub home: [f64; 5],
    /// The groups and their stored paths.
    pub groups: Vec<GroupOut>,
    /// The order the groups are visited in (indices into `groups`).
    pub group_order: Vec<usize>,
    /// The path.
    pub path: Vec<Waypoint>,
    /// The MPs measured, in the order they are touched.
    pub tasks: Vec<String>,
    /// MPs of the cell the plan does not measure, with the reason.
    pub unmeasured: Vec<Unmeasured>,
    /// Time of the head's straight moves (s).
    pub movement_s: f64,
    /// Time of the head's turns (s).
    pub rotation_s: f64,
    /// Time of the touches: the cell's time per MP × MPs (s).
    pub inspection_s: f64,
    /// Movement + rotation + inspection (s), paper 003's motion time.
    pub motion_time_s: f64,
    /// Wall-clock time of the planning or reuse (s; the only number not re-derived).
    pub compute_s: f64,
}

/// One orientation group with its stored paths.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GroupOut {
    /// Head angles A, B (deg).
    pub angles_deg: [f64; 2],
    /// The faces (one, or two adjacent).
    pub faces: Vec<String>,
    /// Its MPs, in the order they are visited.
    pub mps: Vec<String>,
    /// The group's start.
    pub start: [f64; 5],
    /// Per MP (as in `mps`): its root.
    pub roots: Vec<[f64; 5]>,
    /// Per MP: the path from its root to its approach configuration (inclusive).
    pub local: Vec<Vec<[f64; 5]>>,
}

/// One configuration of the path.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Waypoint {
    /// `[x, y, z, a, b]`: the head's A-axis centre (m) and the head angles (rad).
    pub q: [f64; 5],
    /// The MP touched here: the probe moves along its normal from the pretouch distance to
    /// the surface and back.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub touch: Option<String>,
}

/// An MP left out.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Unmeasured {
    /// The MP.
    pub id: String,
    /// Why.
    pub reason: String,
}

fn q5(q: &[f64]) -> [f64; 5] {
    [q[0], q[1], q[2], q[3], q[4]]
}

/// The job's settings for `cell`: its speeds, inspection time, clearance and pretouch.
pub fn settings(cell: &CmmCell, order: cellplan_solve::GtspMethod, seed: u64) -> JobSettings {
    let d = JobSettings::default();
    JobSettings {
        mrnc: crate::mrnc::MrncSettings {
            pretouch: cell.pretouch,
            seed,
            ..d.mrnc
        },
        speeds: cell.speeds,
        inspection_s: cell.inspection_s,
        order,
        ..d
    }
}

/// What a document is made of.
pub struct Parts<'a> {
    /// The cell.
    pub cell: &'a CmmCell,
    /// The planned job (its stored paths).
    pub job: &'a Job,
    /// The path to write: the job's own, or a reuse of it.
    pub path: Option<&'a Reused>,
    /// How it was made.
    pub strategy: Strategy,
    /// Classification method.
    pub classification: Method,
    /// Order method.
    pub order: cellplan_solve::GtspMethod,
    /// Seed.
    pub seed: u64,
}

impl CmmPlan {
    /// The document of a job or of a path made from it.
    pub fn new(p: &Parts) -> Self {
        let cell = p.cell;
        let job = p.job;
        let name = |i: usize| cell.mps[i].name.clone();
        let groups = job
            .groups
            .iter()
            .map(|g| GroupOut {
                angles_deg: [g.paths.angles.0.to_degrees(), g.paths.angles.1.to_degrees()],
                faces: g.faces.iter().map(|&f| cell.faces[f].clone()).collect(),
                mps: g.order.iter().map(|&k| name(g.members[k])).collect(),
                start: q5(&g.paths.start),
                roots: g.order.iter().map(|&k| q5(&g.paths.roots[k])).collect(),
                local: g
                    .order
                    .iter()
                    .map(|&k| g.paths.local[k].iter().map(|q| q5(q)).collect())
                    .collect(),
            })
            .collect();
        let (path, touches, movement_s, rotation_s, inspection_s, compute_s) = match p.path {
            Some(r) => (
                &r.path,
                &r.touches,
                r.movement_s,
                r.rotation_s,
                r.inspection_s,
                r.compute_s,
            ),
            None => (
                &job.path,
                &job.touches,
                job.movement_s,
                job.rotation_s,
                job.inspection_s,
                job.compute_s,
            ),
        };
        let mut waypoints: Vec<Waypoint> = path
            .iter()
            .map(|q| Waypoint {
                q: q5(q),
                touch: None,
            })
            .collect();
        for &(at, mp) in touches {
            waypoints[at].touch = Some(name(mp));
        }
        let cell_file = std::fs::canonicalize(&cell.path)
            .unwrap_or_else(|_| cell.path.clone())
            .display()
            .to_string();
        let unmeasured = if p.strategy == Strategy::Plan || p.strategy == Strategy::Replan {
            job.unmeasured
                .iter()
                .map(|(i, r)| Unmeasured {
                    id: name(*i),
                    reason: r.clone(),
                })
                .collect()
        } else {
            Vec::new()
        };
        CmmPlan {
            format: FORMAT.into(),
            version: VERSION,
            process: crate::cell::KIND.into(),
            cell: cell.name.clone(),
            cell_file,
            strategy: p.strategy,
            classification: match p.classification {
                Method::Exact => "exact",
                Method::Greedy => "greedy",
            }
            .into(),
            order: order_name(p.order).into(),
            seed: p.seed,
            turn_height_m: job.turn_height,
            home: q5(&job.home),
            groups,
            group_order: job.group_order.clone(),
            path: waypoints,
            tasks: touches.iter().map(|&(_, mp)| name(mp)).collect(),
            unmeasured,
            movement_s,
            rotation_s,
            inspection_s,
            motion_time_s: movement_s + rotation_s + inspection_s,
            compute_s,
        }
    }

    /// The job whose stored paths this document holds, for reuse: groups (MPs in their
    /// visiting order), group order, and the document's own path and touches. MPs the cell
    /// does not hold are the error.
    pub fn to_job(&self, cell: &CmmCell) -> Result<Job, String> {
        let find = |id: &str| {
            cell.mp(id)
                .ok_or_else(|| format!("the plan names MP `{id}`, which the cell does not hold"))
        };
        let mut groups = Vec::with_capacity(self.groups.len());
        for (gi, g) in self.groups.iter().enumerate() {
            let n = g.mps.len();
            if g.roots.len() != n || g.local.len() != n || g.local.iter().any(|l| l.is_empty()) {
                return Err(format!(
                    "group {gi}: `mps`, `roots` and `local` must be as long, every local path non-empty"
                ));
            }
            let members = g.mps.iter().map(|id| find(id)).collect::<Result<Vec<_>, _>>()?;
            let faces = g
                .faces
                .iter()
                .map(|f| {
                    cell.faces
                        .iter()
                        .position(|x| x == f)
                        .ok_or_else(|| format!("group {gi}: unknown face `{f}`"))
                })
                .collect::<Result<Vec<_>, _>>()?;
            let local: Vec<Vec<Vec<f64>>> = g
                .local
                .iter()
                .map(|l| l.iter().map(|q| q.to_vec()).collect())
                .collect();
            groups.push(JobGroup {
                paths: GroupPaths {
                    angles: (g.angles_deg[0].to_radians(), g.angles_deg[1].to_radians()),
                    start: g.start.to_vec(),
                    roots: g.roots.iter().map(|q| q.to_vec()).collect(),
                    approaches: local.iter().map(|l| l[l.len() - 1].clone()).collect(),
                    local,
                    rounds: 0,
                    rewired: 0,
                },
                order: (0..n).collect(),
                members,
                faces,
            });
        }
        let mut sorted = self.group_order.clone();
        sorted.sort_unstable();
        if sorted != (0..groups.len()).collect::<Vec<_>>() {
            return Err("`group_order` must list every group once".into());
        }
        let mut touches = Vec::new();
        for (at, w) in self.path.iter().enumerate() {
            if let Some(id) = &w.touch {
                touches.push((at, find(id)?));
            }
        }
        let path: Vec<Vec<f64>> = self.path.iter().map(|w| w.q.to_vec()).collect();
        Ok(Job {
            groups,
            group_order: self.group_order.clone(),
            path,
            touches,
            movement_s: self.movement_s,
            rotation_s: self.rotation_s,
            inspection_s: self.inspection_s,
            compute_s: self.compute_s,
            order_s: 0.0,
            turn_height: self.turn_height_m,
            home: self.home.to_vec(),
            unmeasured: Vec::new(),
        })
    }

    /// Per group in visiting order: its index and the head's turn into it from the group
    /// before (or home), the larger of the two angle changes (deg).
    pub fn group_turns(&self) -> Vec<(usize, f64)> {
        let mut at = [self.home[3].to_degrees(), self.home[4].to_degrees()];
        self.group_order
            .iter()
            .map(|&g| {
                let a = self.groups[g].angles_deg;
                let turn = (a[0] - at[0]).abs().max((a[1] - at[1]).abs());
                at = a;
                (g, turn)
            })
            .collect()
    }

    /// The groups as a classification would give them (for re-planning a subset).
    pub fn classification_groups(&self, cell: &CmmCell) -> Vec<Group> {
        self.groups
            .iter()
            .map(|g| Group {
                angles: (g.angles_deg[0].to_radians(), g.angles_deg[1].to_radians()),
                faces: g
                    .faces
                    .iter()
                    .filter_map(|f| cell.faces.iter().position(|x| x == f))
                    .collect(),
                members: g.mps.iter().filter_map(|id| cell.mp(id)).collect(),
            })
            .collect()
    }
}

/// `ga` or `ils`.
pub fn order_name(m: cellplan_solve::GtspMethod) -> &'static str {
    match m {
        cellplan_solve::GtspMethod::Ga => "ga",
        _ => "ils",
    }
}

/// Reads a plan document.
pub fn read(path: &std::path::Path) -> Result<CmmPlan, String> {
    let plan: CmmPlan = cellplan_model::document::read_json(path, MAX_PLAN_BYTES, "a CMM plan document")?;
    cellplan_model::document::check_version((&plan.format, plan.version), (FORMAT, VERSION))?;
    Ok(plan)
}

/// The JSON Schema of the document, as `docs/cmm-plan.schema.json` holds it.
pub fn schema() -> String {
    cellplan_model::document::schema_text(&schemars::schema_for!(CmmPlan))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// `docs/cmm-plan.schema.json` is the schema of these types (regenerate it with
    /// `CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-cmm schema`).
    #[test]
    fn the_schema_in_docs_is_generated_from_the_types() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/cmm-plan.schema.json");
        let schema =
            cellplan_model::document::schema_file_matches(&path, &super::schema()).unwrap_or_else(|e| {
                panic!("{e}; regenerate it with CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-cmm schema")
            });
        let required = schema["required"].as_array().unwrap();
        for key in [
            "path",
            "groups",
            "tasks",
            "motion_time_s",
            "movement_s",
            "rotation_s",
            "inspection_s",
        ] {
            assert!(
                required.iter().any(|k| k == key),
                "{key} not required: {required:?}"
            );
        }
    }
}
