//! A whole inspection job (paper 003 §3): the groups (§3.1), each group's stored paths
//! (§3.2, RRT-MRNC), the order of the groups and of the MPs inside each (§3.3), and the
//! times of Table 3 — movement, rotation, inspection, motion.
//!
//! Within a group every path runs start → root → approach, root → root, approach → root →
//! start, so a group's order is a travelling-salesperson tour from its start over the MPs, the
//! cost of a step the movement time through the two roots. Between groups the head goes up
//! to a safe height above the next group's start, turns there (paper 003 assumption 1: it
//! moves or it turns, never both), and comes down. The group order is a tour from the home
//! position over the group starts. Both are solved by `cellplan-solve`: the paper's enhanced
//! GA ([`GtspMethod::Ga`]) or ours (iterated local search, [`GtspMethod::Ils`]).
use crate::classify::Group;
use crate::classify::Probe;
use crate::mrnc::{GroupPaths, MrncError, MrncSettings, group_start, plan_group};
use crate::part::Mp;
use cellplan_kin::cmm::{CmmQ, CmmSpeeds};
use cellplan_motion::plan::{JointSpace, StateValidity, check_segment};
use cellplan_solve::{CostMatrix, Gtsp, GtspMethod, GtspParams, solve_gtsp};
use std::time::{Duration, Instant};

/// The job's settings.
#[derive(Clone, Copy, Debug)]
pub struct JobSettings {
    /// RRT-MRNC.
    pub mrnc: MrncSettings,
    /// Speeds and the time per MP.
    pub speeds: CmmSpeeds,
    /// Time to inspect one MP (s); paper 003: 1 s.
    pub inspection_s: f64,
    /// The orderings' method.
    pub order: GtspMethod,
    /// Iterations of the ordering heuristics (so that the result depends on the seed only).
    pub order_iterations: usize,
    /// Height the head goes up to before it turns (m).
    pub turn_height: f64,
    /// Lowest height of a group's start (m).
    pub start_height: f64,
}

impl Default for JobSettings {
    fn default() -> Self {
        JobSettings {
            mrnc: MrncSettings::default(),
            speeds: CmmSpeeds::paper(),
            inspection_s: 1.0,
            order: GtspMethod::Ils,
            order_iterations: 2000,
            turn_height: 0.75,
            start_height: 0.55,
        }
    }
}

/// A planned job.
#[derive(Clone, Debug)]
pub struct Job {
    /// Per group (in the classification's order): its paths and its MPs' visiting order
    /// (indices into the group's members).
    pub groups: Vec<(GroupPaths, Vec<usize>, Vec<usize>)>,
    /// The order of the groups.
    pub group_order: Vec<usize>,
    /// The whole path, configuration by configuration, from home back to home.
    pub path: Vec<Vec<f64>>,
    /// Movement time (s).
    pub movement_s: f64,
    /// Rotation time (s).
    pub rotation_s: f64,
    /// Inspection time (s).
    pub inspection_s: f64,
    /// Computation time (s).
    pub compute_s: f64,
    /// The height the head turns at: high enough that every configuration there keeps the
    /// whole probe above every static object, so moves and turns at it need no check.
    pub turn_height: f64,
    /// Where the job starts and ends.
    pub home: Vec<f64>,
}

impl Job {
    /// Movement + rotation + inspection (s), Table 3's motion time.
    pub fn motion_s(&self) -> f64 {
        self.movement_s + self.rotation_s + self.inspection_s
    }

    /// Paper 003's path reuse: the path for the MPs `subset` (indices into the job's MP list)
    /// from the stored paths alone — the job's group order and each group's MP order, groups
    /// without a wanted MP skipped, each wanted MP reached through its root — with no sampling
    /// and no collision query. Every segment is one planning checked: a group's stored paths,
    /// the vertical move between a group's start and the turn height (the same whichever
    /// group comes before or after), the way from and to home, and moves and turns at the turn
    /// height, which are clear by construction ([`Job::turn_height`]). MPs the job does not hold are returned as the error.
    pub fn reuse(&self, subset: &[usize], s: &JobSettings) -> Result<Reused, Vec<usize>> {
        let home = &self.home;
        let started = Instant::now();
        let s = &JobSettings {
            turn_height: self.turn_height,
            ..*s
        };
        let unknown: Vec<usize> = subset
            .iter()
            .copied()
            .filter(|i| !self.groups.iter().any(|(_, _, members)| members.contains(i)))
            .collect();
        if !unknown.is_empty() {
            return Err(unknown);
        }
        let mut path: Vec<Vec<f64>> = vec![home.to_vec()];
        let mut at = home.to_vec();
        let mut count = 0;
        for &g in &self.group_order {
            let (paths, order, members) = &self.groups[g];
            let wanted: Vec<usize> = order
                .iter()
                .copied()
                .filter(|&k| subset.contains(&members[k]))
                .collect();
            if wanted.is_empty() {
                continue;
            }
            path.extend(transition(s, &at, &paths.start).into_iter().skip(1));
            path.extend(paths.reuse(&wanted).into_iter().skip(1));
            count += wanted.len();
            at = paths.start.clone();
        }
        path.extend(transition(s, &at, home).into_iter().skip(1));
        path.dedup();
        let compute_s = started.elapsed().as_secs_f64();
        Ok(Reused::new(path, count, s, compute_s))
    }

    /// The paper's "reuse of the initial path": the whole stored path walked again, touching
    /// only the MPs of `subset`.
    pub fn reuse_initial_path(&self, subset: &[usize], s: &JobSettings) -> Reused {
        Reused::new(self.path.clone(), subset.len(), s, 0.0)
    }
}

/// A path for a subset of MPs, with its times.
#[derive(Clone, Debug)]
pub struct Reused {
    /// The path.
    pub path: Vec<Vec<f64>>,
    /// Movement time (s).
    pub movement_s: f64,
    /// Rotation time (s).
    pub rotation_s: f64,
    /// Inspection time (s).
    pub inspection_s: f64,
    /// Time to make it (s).
    pub compute_s: f64,
}

impl Reused {
    fn new(path: Vec<Vec<f64>>, inspections: usize, s: &JobSettings, compute_s: f64) -> Self {
        let movement_s: f64 = path
            .windows(2)
            .map(|w| s.speeds.movement_time(&q5(&w[0]), &q5(&w[1])))
            .sum();
        let rotation_s: f64 = path
            .windows(2)
            .map(|w| s.speeds.rotation_time(&q5(&w[0]), &q5(&w[1])))
            .sum();
        Reused {
            path,
            movement_s,
            rotation_s,
            inspection_s: inspections as f64 * s.inspection_s,
            compute_s,
        }
    }

    /// Movement + rotation + inspection (s).
    pub fn motion_s(&self) -> f64 {
        self.movement_s + self.rotation_s + self.inspection_s
    }
}

/// A tour from node 0 of `costs` over all the others, by the settings' method, as the indices
/// (0-based) of the other nodes in visiting order. (Single-node clusters and a depot outside
/// them always make a valid GTSP, so the fallback to the given order is never taken.)
fn tour_from_depot(costs: CostMatrix, s: &JobSettings) -> Vec<usize> {
    let n = costs.n() - 1;
    let given: Vec<usize> = (0..n).collect();
    if n <= 1 {
        return given;
    }
    let Ok(tsp) =
        Gtsp::new(costs, (1..=n).map(|k| vec![k]).collect()).and_then(|p| p.with_depots(Some(0), None))
    else {
        return given;
    };
    let params = GtspParams {
        method: s.order,
        seed: s.mrnc.seed,
        max_iterations: Some(s.order_iterations),
        time_limit: Duration::from_secs(3600),
    };
    solve_gtsp(&tsp, &params)
        .tour
        .nodes
        .iter()
        .map(|&v| v - 1)
        .collect()
}

/// From one group's start to another's (or home): up to the turn height, turn, down.
fn transition(s: &JobSettings, from: &[f64], to: &[f64]) -> Vec<Vec<f64>> {
    let lift = |q: &[f64]| vec![q[0], q[1], s.turn_height.max(q[2]), q[3], q[4]];
    let up = lift(from);
    let mut above = lift(to);
    above[3] = from[3];
    above[4] = from[4];
    let turned = lift(to);
    let mut p = vec![from.to_vec(), up, above, turned, to.to_vec()];
    p.dedup();
    p
}

/// Why a job could not be planned.
#[derive(Clone, Debug, PartialEq)]
pub enum JobError {
    /// A group has no clear start.
    Start(usize),
    /// RRT-MRNC failed in a group.
    Group(usize, MrncError),
    /// A move between groups (or to or from home) is not clear: the group (or `None` for the
    /// way home).
    Turn(Option<usize>),
    /// The turn height (above every static object by the probe's reach) is beyond the Z travel.
    TurnHeight(f64),
}

fn q5(q: &[f64]) -> CmmQ {
    [q[0], q[1], q[2], q[3], q[4]]
}

/// Plans a job from the groups of a classification.
#[allow(clippy::too_many_arguments)]
pub fn plan_job(
    probe: &Probe,
    validity: &dyn StateValidity,
    space: &JointSpace,
    mps: &[Mp],
    groups: &[Group],
    home: &[f64],
    s: &JobSettings,
) -> Result<Job, JobError> {
    let started = Instant::now();
    // The turn height: above every static object by the probe's whole reach and a margin, so
    // that at it any position and any orientation is clear.
    let head = probe.head();
    let top = probe.statics_top();
    let turn_height = s.turn_height.max(top + head.reach() + head.ball_diameter + 0.05);
    if turn_height > space.upper[2] {
        return Err(JobError::TurnHeight(turn_height));
    }
    let s = &JobSettings { turn_height, ..*s };
    let move_time = |a: &[f64], b: &[f64]| s.speeds.move_time(&q5(a), &q5(b));
    let path_time = |p: &[Vec<f64>]| p.windows(2).map(|w| move_time(&w[0], &w[1])).sum::<f64>();
    // Each group's paths.
    let mut planned: Vec<(GroupPaths, Vec<usize>)> = Vec::with_capacity(groups.len());
    for (g, group) in groups.iter().enumerate() {
        let start = group_start(
            probe,
            validity,
            space,
            mps,
            &group.members,
            group.angles,
            s.start_height,
        )
        .ok_or(JobError::Start(g))?;
        let settings = MrncSettings {
            seed: s.mrnc.seed.wrapping_add(g as u64),
            ..s.mrnc
        };
        let paths = plan_group(
            probe,
            validity,
            space,
            mps,
            &group.members,
            group.angles,
            &start,
            &settings,
        )
        .map_err(|e| JobError::Group(g, e))?;
        // The group's tour: node 0 its start, node k + 1 its k-th MP.
        let n = group.members.len();
        let leg = |a: usize, b: usize| -> f64 {
            // From node a to node b through the roots (a local path runs root → approach).
            let out = if a == 0 {
                0.0
            } else {
                path_time(&paths.local[a - 1])
            };
            let into = if b == 0 {
                0.0
            } else {
                path_time(&paths.local[b - 1])
            };
            let from = if a == 0 { &paths.start } else { &paths.roots[a - 1] };
            let to = if b == 0 { &paths.start } else { &paths.roots[b - 1] };
            out + move_time(from, to) + into
        };
        let costs = CostMatrix::from_fn(n + 1, |a, b| if a == b { 0.0 } else { leg(a, b) });
        let order = tour_from_depot(costs, s);
        planned.push((paths, order));
    }
    // The turns between groups: up above the next start, turn, down.
    let transition = |from: &[f64], to: &[f64]| transition(s, from, to);
    let m = groups.len();
    // The group order: node 0 home, node g + 1 group g's start.
    let starts: Vec<&Vec<f64>> = planned.iter().map(|(p, _)| &p.start).collect();
    let node = |k: usize| -> &[f64] { if k == 0 { home } else { starts[k - 1] } };
    let gcosts = CostMatrix::from_fn(m + 1, |a, b| {
        if a == b {
            0.0
        } else {
            path_time(&transition(node(a), node(b)))
        }
    });
    let group_order = tour_from_depot(gcosts, s);
    // The whole path and its times.
    let mut path: Vec<Vec<f64>> = vec![home.to_vec()];
    let mut at: Vec<f64> = home.to_vec();
    let mut inspections = 0usize;
    for &g in &group_order {
        let (paths, order) = &planned[g];
        let t = transition(&at, &paths.start);
        for w in t.windows(2) {
            if !check_segment(space, validity, &w[0], &w[1], s.mrnc.min_clearance).valid {
                return Err(JobError::Turn(Some(g)));
            }
        }
        path.extend(t.into_iter().skip(1));
        path.extend(paths.reuse(order).into_iter().skip(1));
        inspections += order.len();
        at = paths.start.clone();
    }
    let back = transition(&at, home);
    for w in back.windows(2) {
        if !check_segment(space, validity, &w[0], &w[1], s.mrnc.min_clearance).valid {
            return Err(JobError::Turn(None));
        }
    }
    path.extend(back.into_iter().skip(1));
    path.dedup();
    let movement_s: f64 = path
        .windows(2)
        .map(|w| s.speeds.movement_time(&q5(&w[0]), &q5(&w[1])))
        .sum();
    let rotation_s: f64 = path
        .windows(2)
        .map(|w| s.speeds.rotation_time(&q5(&w[0]), &q5(&w[1])))
        .sum();
    Ok(Job {
        groups: planned
            .into_iter()
            .zip(groups)
            .map(|((p, o), g)| (p, o, g.members.clone()))
            .collect(),
        group_order,
        path,
        movement_s,
        rotation_s,
        inspection_s: inspections as f64 * s.inspection_s,
        compute_s: started.elapsed().as_secs_f64(),
        turn_height,
        home: home.to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classify::{Method, classify};
    use crate::motion::{CmmValidity, space};
    use crate::part::block_adjacent;

    #[test]
    fn the_block_is_planned_whole_every_segment_clear_every_mp_once() {
        let started = Instant::now();
        let (mps, probe) = crate::scene::block();
        let orientations = crate::scene::grid();
        let groups = classify(&mps, &block_adjacent, &probe, &orientations, 0.001, Method::Exact).groups;
        let travel = crate::scene::TRAVEL;
        let space = space(&probe, &travel);
        let validity = CmmValidity {
            probe: &probe,
            margin: 0.002,
        };
        let home = vec![0.2, 0.12, 0.9, 0.0, 0.0];
        let mut results = Vec::new();
        for order in [GtspMethod::Ga, GtspMethod::Ils] {
            let job = plan_job(
                &probe,
                &validity,
                &space,
                &mps,
                &groups,
                &home,
                &JobSettings {
                    order,
                    ..JobSettings::default()
                },
            )
            .unwrap_or_else(|e| panic!("{order:?}: {e:?}"));
            // Every segment of the whole path is clear; every MP's approach is visited.
            for w in job.path.windows(2) {
                assert!(check_segment(&space, &validity, &w[0], &w[1], 1e-4).valid);
            }
            let mut visited = 0;
            for (paths, order, members) in &job.groups {
                assert_eq!(order.len(), members.len());
                for &k in order {
                    assert!(job.path.contains(&paths.approaches[k]));
                    visited += 1;
                }
            }
            assert_eq!(visited, 39);
            assert_eq!(job.path.first(), Some(&home));
            assert_eq!(job.path.last(), Some(&home));
            assert!((job.inspection_s - 39.0).abs() < 1e-9);
            eprintln!(
                "{order:?}: {} groups, movement {:.1} s, rotation {:.1} s, inspection {:.1} s, motion {:.1} s, computed in {:.2} s",
                job.groups.len(),
                job.movement_s,
                job.rotation_s,
                job.inspection_s,
                job.motion_s(),
                job.compute_s
            );
            results.push(job.motion_s());
        }
        assert!(
            results[1] <= results[0] * 1.05,
            "ours {} against the GA {}",
            results[1],
            results[0]
        );
        // Reuse on 20 random subsets of 3–20 MPs, against walking the initial path and against
        // planning the subset from scratch.
        use rand::{RngExt, SeedableRng};
        let settings = JobSettings::default();
        let job = plan_job(&probe, &validity, &space, &mps, &groups, &home, &settings).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (mut t_reuse, mut r_replan, mut r_initial, mut worst_replan) = (0.0, 0.0, 0.0, 0.0f64);
        for _ in 0..20 {
            let size = rng.random_range(3..=20);
            let mut subset: Vec<usize> = (0..mps.len()).collect();
            for i in (1..subset.len()).rev() {
                let j = rng.random_range(0..=i);
                subset.swap(i, j);
            }
            subset.truncate(size);
            let reused = job.reuse(&subset, &settings).unwrap();
            for w in reused.path.windows(2) {
                assert!(
                    check_segment(&space, &validity, &w[0], &w[1], 1e-4).valid,
                    "a reused segment collides"
                );
            }
            for &i in &subset {
                let (paths, _, members) = job.groups.iter().find(|(_, _, m)| m.contains(&i)).unwrap();
                let k = members.iter().position(|&x| x == i).unwrap();
                assert!(reused.path.contains(&paths.approaches[k]));
            }
            let initial = job.reuse_initial_path(&subset, &settings);
            assert!(reused.motion_s() <= initial.motion_s() + 1e-9);
            let sub_mps: Vec<Mp> = subset.iter().map(|&i| mps[i].clone()).collect();
            let sub_groups = classify(
                &sub_mps,
                &block_adjacent,
                &probe,
                &orientations,
                0.001,
                Method::Exact,
            )
            .groups;
            let replan =
                plan_job(&probe, &validity, &space, &sub_mps, &sub_groups, &home, &settings).unwrap();
            t_reuse += reused.compute_s;
            r_replan += reused.motion_s() / replan.motion_s();
            worst_replan = worst_replan.max(reused.motion_s() / replan.motion_s());
            r_initial += reused.motion_s() / initial.motion_s();
        }
        eprintln!(
            "reuse over 20 subsets: {:.1} µs per query; motion {:.3}× re-planning (worst {:.3}×), {:.3}× the initial path",
            t_reuse / 20.0 * 1e6,
            r_replan / 20.0,
            worst_replan,
            r_initial / 20.0
        );
        assert!(r_initial / 20.0 < 1.0);
        eprintln!("whole test {:.2} s", started.elapsed().as_secs_f64());
    }
}
