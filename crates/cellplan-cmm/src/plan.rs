//! Planning a CMM cell end to end: classify the MPs (§3.1), plan every group's paths (§3.2),
//! order groups and MPs (§3.3); and the three ways of inspecting a subset later (Table 4):
//! through the stored roots, along the initial path, or planned from scratch.
use crate::cell::CmmCell;
use crate::classify::{Classification, Method, classify_with};
use crate::document::{CmmPlan, Parts, Strategy, settings};
use crate::job::{Job, JobError, Reused, plan_job};
use crate::motion::{CmmValidity, space};
use cellplan_motion::plan::{JointSpace, StateValidity};
use cellplan_solve::GtspMethod;
use std::time::Instant;

/// What to plan.
#[derive(Clone, Debug)]
pub struct Request {
    /// How the groups and MPs are ordered.
    pub order: GtspMethod,
    /// How the groups are found (`None`: the cell's choice).
    pub classification: Option<Method>,
    /// Seed.
    pub seed: u64,
    /// Only these MPs (indices into the cell's); `None`: all.
    pub subset: Option<Vec<usize>>,
}

/// A planned cell.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The job.
    pub job: Job,
    /// The classification method used.
    pub classification: Method,
    /// Candidate orientations tried.
    pub orientations: usize,
}

/// Why a cell could not be planned at all.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanError {
    /// The job could not be laid out.
    Job(JobError),
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Job(JobError::TurnHeight(h)) => write!(
                f,
                "the head must turn {:.0} mm high (above the part by the probe's reach) but the Z travel ends lower",
                h * 1e3
            ),
            PlanError::Job(JobError::Home) => {
                write!(f, "the way up from home to the turn height is not clear")
            }
        }
    }
}

/// Plans the cell (or a subset of its MPs).
pub fn run(cell: &CmmCell, req: &Request) -> Result<Outcome, PlanError> {
    let started = Instant::now();
    let probe = cell.probe();
    let method = req.classification.unwrap_or(cell.classification);
    let all: Vec<usize> = (0..cell.mps.len()).collect();
    let chosen = req.subset.clone().unwrap_or(all);
    let sub: Vec<_> = chosen.iter().map(|&i| cell.mps[i].clone()).collect();
    let space = space(&probe, &cell.travel);
    let validity = CmmValidity {
        probe: &probe,
        margin: cell.clearance,
    };
    let c = classification(cell, &probe, &space, &validity, &sub, method);
    let groups: Vec<_> = c
        .groups
        .into_iter()
        .map(|mut g| {
            g.members = g.members.iter().map(|&k| chosen[k]).collect();
            g
        })
        .collect();
    let s = settings(cell, req.order, req.seed);
    let mut job =
        plan_job(&probe, &validity, &space, &cell.mps, &groups, &cell.home, &s).map_err(PlanError::Job)?;
    for &k in &c.unmeasurable {
        job.unmeasured.push((
            chosen[k],
            format!(
                "no head orientation within its cone ({}°) touches it with the probe clear of the part",
                cell.mps[chosen[k]].theta_deg
            ),
        ));
    }
    job.unmeasured.sort_by_key(|u| u.0);
    job.compute_s = started.elapsed().as_secs_f64();
    Ok(Outcome {
        job,
        classification: method,
        orientations: c.orientations,
    })
}

/// §3.1 on `mps` (a cell's MPs or a subset): the cell's candidate orientations, faces'
/// adjacency and touch clearance, an orientation counting for an MP only where RRT-MRNC can
/// also reach its approach ([`approach_usable`]).
pub fn classification(
    cell: &CmmCell,
    probe: &crate::classify::Probe,
    space: &JointSpace,
    validity: &CmmValidity,
    mps: &[crate::part::Mp],
    method: Method,
) -> Classification {
    let adjacent = |f: usize, g: usize| cell.adjacent(f, g);
    let usable = approach_usable(cell, space, validity, mps);
    classify_with(
        mps,
        &adjacent,
        probe,
        &cell.orientations(),
        cell.touch_clearance,
        method,
        &usable,
    )
}

/// RRT-MRNC's own test of an MP's approach configuration at head angles: within the travel and
/// clear by the cell's clearance (with the planner's `min_clearance`), so that classification
/// never forms a group the planner then cannot enter.
pub fn approach_usable<'a>(
    cell: &'a CmmCell,
    space: &'a JointSpace,
    validity: &'a CmmValidity<'a>,
    mps: &'a [crate::part::Mp],
) -> impl Fn(usize, (f64, f64)) -> bool + Sync + 'a {
    let min = crate::mrnc::MrncSettings::default().min_clearance;
    move |i: usize, angles: (f64, f64)| {
        let q = crate::mrnc::approach(&cell.head, &mps[i], angles, cell.pretouch);
        space.contains(&q) && validity.clearance(&q) > min
    }
}

/// The plan document of an outcome.
pub fn document(cell: &CmmCell, out: &Outcome, req: &Request, strategy: Strategy) -> CmmPlan {
    CmmPlan::new(&Parts {
        cell,
        job: &out.job,
        path: None,
        strategy,
        classification: out.classification,
        order: req.order,
        seed: req.seed,
    })
}

/// The reuse of a plan for `subset` (MP indices of the cell) by `strategy`
/// ([`Strategy::ReuseRoots`] or [`Strategy::ReuseInitialPath`]): the document, or the MPs of the
/// subset the plan cannot touch. The compute time is the reuse alone.
pub fn reuse(
    cell: &CmmCell,
    plan: &CmmPlan,
    subset: &[usize],
    strategy: Strategy,
) -> Result<CmmPlan, ReuseError> {
    let job = plan.to_job(cell).map_err(ReuseError::Plan)?;
    let order = if plan.order == "ga" {
        GtspMethod::Ga
    } else {
        GtspMethod::Ils
    };
    let s = settings(cell, order, plan.seed);
    let reused: Reused = match strategy {
        Strategy::ReuseInitialPath => {
            let touched: Vec<usize> = job.touches.iter().map(|t| t.1).collect();
            let missing: Vec<usize> = subset.iter().copied().filter(|i| !touched.contains(i)).collect();
            if !missing.is_empty() {
                return Err(ReuseError::Unknown(missing));
            }
            job.reuse_initial_path(subset, &s)
        }
        _ => job.reuse(subset, &s).map_err(ReuseError::Unknown)?,
    };
    let classification = if plan.classification == "greedy" {
        Method::Greedy
    } else {
        Method::Exact
    };
    Ok(CmmPlan::new(&Parts {
        cell,
        job: &job,
        path: Some(&reused),
        strategy,
        classification,
        order,
        seed: plan.seed,
    }))
}

/// Why a reuse failed.
#[derive(Clone, Debug, PartialEq)]
pub enum ReuseError {
    /// The plan does not fit the cell.
    Plan(String),
    /// MPs of the subset the plan never measured.
    Unknown(Vec<usize>),
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn example() -> CmmCell {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cmm-block/cell.toml");
        crate::cell::load(&path).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_example_cell_reads_with_the_blocks_faces_and_adjacency() {
        let cell = example();
        assert_eq!(cell.mps.len(), 39);
        // The adjacency the cell lists is the generator's.
        for (f, a) in cell.faces.iter().enumerate() {
            for (g, b) in cell.faces.iter().enumerate() {
                let i = crate::part::BLOCK_FACES.iter().position(|x| x == a).unwrap();
                let j = crate::part::BLOCK_FACES.iter().position(|x| x == b).unwrap();
                assert_eq!(cell.adjacent(f, g), crate::part::block_adjacent(i, j), "{a} {b}");
            }
        }
        // The part is turned 90° about Z: the deck still faces up, the end x = 0 faces −Y.
        let d1 = &cell.mps[cell.mp("D1").unwrap()];
        assert!((d1.normal - cellplan_geom::DVec3::Z).length() < 1e-12);
        let e1 = &cell.mps[cell.mp("E1").unwrap()];
        assert!(
            (e1.normal + cellplan_geom::DVec3::Y).length() < 1e-12,
            "{}",
            e1.normal
        );
    }

    #[test]
    fn the_example_is_planned_whole_and_reused() {
        let cell = example();
        let req = Request {
            order: GtspMethod::Ils,
            classification: None,
            seed: 0,
            subset: None,
        };
        let out = run(&cell, &req).unwrap();
        let j = &out.job;
        eprintln!(
            "{} groups, unmeasured {:?}, movement {:.1} s rotation {:.1} s inspection {:.1} s motion {:.1} s compute {:.2} s",
            j.groups.len(),
            j.unmeasured,
            j.movement_s,
            j.rotation_s,
            j.inspection_s,
            j.motion_s(),
            j.compute_s
        );
        for g in &j.groups {
            eprintln!(
                "  group {:?} faces {:?} {} MPs",
                (g.paths.angles.0.to_degrees(), g.paths.angles.1.to_degrees()),
                g.faces,
                g.members.len()
            );
        }
        assert!(j.unmeasured.is_empty(), "{:?}", j.unmeasured);
        assert_eq!(j.touches.len(), 39);
        let doc = document(&cell, &out, &req, Strategy::Plan);
        assert_eq!(doc.tasks.len(), 39);
        let text = serde_json::to_string(&doc).unwrap();
        let back: CmmPlan = serde_json::from_str(&text).unwrap();
        assert_eq!(back, doc);
        let subset: Vec<usize> = vec![3, 17, 30, 8];
        let r = reuse(&cell, &doc, &subset, Strategy::ReuseRoots).unwrap();
        assert_eq!(r.tasks.len(), 4);
        let i = reuse(&cell, &doc, &subset, Strategy::ReuseInitialPath).unwrap();
        assert_eq!(i.tasks.len(), 4);
        assert!(r.motion_time_s < i.motion_time_s);
        assert!(matches!(
            reuse(&cell, &doc, &[3, 1000], Strategy::ReuseRoots),
            Err(ReuseError::Unknown(v)) if v == vec![1000]
        ));
    }
}
