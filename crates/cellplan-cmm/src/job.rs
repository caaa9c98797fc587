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

/// One planned group: its stored paths, the visiting order of its MPs, its MPs and faces.
#[derive(Clone, Debug, PartialEq)]
pub struct JobGroup {
    /// RRT-MRNC's paths.
    pub paths: GroupPaths,
    /// Visiting order (indices into `members`).
    pub order: Vec<usize>,
    /// The MPs (indices into the job's MP list).
    pub members: Vec<usize>,
    /// The faces they lie on.
    pub faces: Vec<usize>,
}

/// A planned job.
#[derive(Clone, Debug)]
pub struct Job {
    /// The groups planned (a classification's groups, less what could not be planned; a group
    /// whose roots could not be found together is split in two).
    pub groups: Vec<JobGroup>,
    /// The order of the groups.
    pub group_order: Vec<usize>,
    /// The whole path, configuration by configuration, from home back to home.
    pub path: Vec<Vec<f64>>,
    /// Where MPs are touched: (index into `path`, MP). At that configuration the probe moves
    /// along the MP's normal to touch it and back.
    pub touches: Vec<(usize, usize)>,
    /// Movement time (s).
    pub movement_s: f64,
    /// Rotation time (s).
    pub rotation_s: f64,
    /// Inspection time (s).
    pub inspection_s: f64,
    /// Computation time (s).
    pub compute_s: f64,
    /// Of it, the time of the orderings (§3.3: the groups' TSPs and the GTSP over groups) (s).
    pub order_s: f64,
    /// The height the head turns at: high enough that every configuration there keeps the
    /// whole probe above every static object, so moves and turns at it need no check.
    pub turn_height: f64,
    /// Where the job starts and ends.
    pub home: Vec<f64>,
    /// MPs of the groups that could not be planned, with the reason.
    pub unmeasured: Vec<(usize, String)>,
}

/// A path being built: consecutive duplicates dropped, touches recorded.
#[derive(Default)]
struct PathBuilder {
    path: Vec<Vec<f64>>,
    touches: Vec<(usize, usize)>,
}

impl PathBuilder {
    fn push(&mut self, q: &[f64]) {
        if self.path.last().is_none_or(|l| l.as_slice() != q) {
            self.path.push(q.to_vec());
        }
    }

    fn extend(&mut self, qs: &[Vec<f64>]) {
        for q in qs {
            self.push(q);
        }
    }

    /// The group's stored paths for its members at `wanted` (positions in the group, in
    /// order): start → root → approach (touch) → root → … → start.
    fn group(&mut self, g: &JobGroup, wanted: &[usize]) {
        self.push(&g.paths.start);
        for &k in wanted {
            self.extend(&g.paths.local[k]);
            self.touches.push((self.path.len() - 1, g.members[k]));
            for q in g.paths.local[k].iter().rev().skip(1) {
                self.push(q);
            }
        }
        self.push(&g.paths.start);
    }
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
    /// height, which are clear by construction ([`Job::turn_height`]). MPs the job does not
    /// hold are returned as the error.
    pub fn reuse(&self, subset: &[usize], s: &JobSettings) -> Result<Reused, Vec<usize>> {
        let started = Instant::now();
        let s = &JobSettings {
            turn_height: self.turn_height,
            ..*s
        };
        let unknown: Vec<usize> = subset
            .iter()
            .copied()
            .filter(|i| !self.groups.iter().any(|g| g.members.contains(i)))
            .collect();
        if !unknown.is_empty() {
            return Err(unknown);
        }
        let mut b = PathBuilder::default();
        b.push(&self.home);
        let mut at = self.home.clone();
        for &g in &self.group_order {
            let group = &self.groups[g];
            let wanted: Vec<usize> = group
                .order
                .iter()
                .copied()
                .filter(|&k| subset.contains(&group.members[k]))
                .collect();
            if wanted.is_empty() {
                continue;
            }
            b.extend(&transition(s, &at, &group.paths.start));
            b.group(group, &wanted);
            at = group.paths.start.clone();
        }
        b.extend(&transition(s, &at, &self.home));
        let compute_s = started.elapsed().as_secs_f64();
        Ok(Reused::new(b.path, b.touches, s, compute_s))
    }

    /// The paper's "reuse of the initial path": the whole stored path walked again, touching
    /// only the MPs of `subset`.
    pub fn reuse_initial_path(&self, subset: &[usize], s: &JobSettings) -> Reused {
        let started = Instant::now();
        let touches = self
            .touches
            .iter()
            .copied()
            .filter(|(_, mp)| subset.contains(mp))
            .collect();
        Reused::new(self.path.clone(), touches, s, started.elapsed().as_secs_f64())
    }
}

/// A path for a subset of MPs, with its times.
#[derive(Clone, Debug)]
pub struct Reused {
    /// The path.
    pub path: Vec<Vec<f64>>,
    /// Where MPs are touched (index into `path`, MP).
    pub touches: Vec<(usize, usize)>,
    /// Movement time (s).
    pub movement_s: f64,
    /// Rotation time (s).
    pub rotation_s: f64,
    /// Inspection time (s).
    pub inspection_s: f64,
    /// Time to make it (s).
    pub compute_s: f64,
}

/// Movement and rotation time of a path (s).
pub fn path_times(path: &[Vec<f64>], speeds: &CmmSpeeds) -> (f64, f64) {
    let movement_s = path
        .windows(2)
        .map(|w| speeds.movement_time(&q5(&w[0]), &q5(&w[1])))
        .sum();
    let rotation_s = path
        .windows(2)
        .map(|w| speeds.rotation_time(&q5(&w[0]), &q5(&w[1])))
        .sum();
    (movement_s, rotation_s)
}

impl Reused {
    fn new(path: Vec<Vec<f64>>, touches: Vec<(usize, usize)>, s: &JobSettings, compute_s: f64) -> Self {
        let (movement_s, rotation_s) = path_times(&path, &s.speeds);
        Reused {
            inspection_s: touches.len() as f64 * s.inspection_s,
            path,
            touches,
            movement_s,
            rotation_s,
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
        max_stall: None,
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
pub fn transition(s: &JobSettings, from: &[f64], to: &[f64]) -> Vec<Vec<f64>> {
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

/// Why a job could not be planned at all.
#[derive(Clone, Debug, PartialEq)]
pub enum JobError {
    /// The turn height (above every static object by the probe's reach) is beyond the Z travel.
    TurnHeight(f64),
    /// The vertical move from home up to the turn height is not clear.
    Home,
}

fn q5(q: &[f64]) -> CmmQ {
    [q[0], q[1], q[2], q[3], q[4]]
}

/// The reason an MP is left unmeasured, in words.
fn mrnc_reason(e: &MrncError, angles: (f64, f64)) -> String {
    let at = format!(
        "at head angles A {:.1}°, B {:.1}°",
        angles.0.to_degrees(),
        angles.1.to_degrees()
    );
    match e {
        MrncError::Approach(_) => {
            format!("its approach configuration is outside the travel or not clear {at}")
        }
        MrncError::Roots => format!("no root that sees the group's start and the other roots {at}"),
        MrncError::Local(_) => format!("RRT* found no path from its root to its approach {at}"),
    }
}

/// Plans a job from the groups of a classification. What cannot be planned is left out with its
/// reason ([`Job::unmeasured`]): an MP whose approach or local path fails leaves its group, a
/// group whose roots cannot all see each other is split in two across its widest spread, a group with no clear start or
/// no clear way from the turn height is left out whole.
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
    let clear_path = |p: &[Vec<f64>]| {
        p.windows(2)
            .all(|w| check_segment(space, validity, &w[0], &w[1], s.mrnc.min_clearance).valid)
    };
    let lifted = |q: &[f64]| -> Vec<f64> {
        let mut l = q.to_vec();
        l[2] = l[2].max(turn_height);
        l
    };
    if !clear_path(&[home.to_vec(), lifted(home)]) {
        return Err(JobError::Home);
    }
    let mut unmeasured: Vec<(usize, String)> = Vec::new();
    let mut order_s = 0.0;
    // Each group's paths; failures shrink or split the group.
    let mut planned: Vec<JobGroup> = Vec::with_capacity(groups.len());
    let mut queue: std::collections::VecDeque<Group> = groups.iter().cloned().collect();
    let mut attempt = 0u64;
    while let Some(group) = queue.pop_front() {
        attempt += 1;
        if group.members.is_empty() {
            continue;
        }
        let Some(start) = group_start(
            probe,
            validity,
            space,
            mps,
            &group.members,
            group.angles,
            s.start_height,
        ) else {
            for &i in &group.members {
                unmeasured.push((
                    i,
                    format!(
                        "no clear start above its group (head angles A {:.1}°, B {:.1}°) within the travel",
                        group.angles.0.to_degrees(),
                        group.angles.1.to_degrees()
                    ),
                ));
            }
            continue;
        };
        // The way from the turn height down to the start must be clear.
        if !clear_path(&[start.clone(), lifted(&start)]) {
            for &i in &group.members {
                unmeasured.push((
                    i,
                    "the vertical move from the turn height to its group's start is not clear".into(),
                ));
            }
            continue;
        }
        let settings = MrncSettings {
            seed: s.mrnc.seed.wrapping_add(attempt - 1),
            ..s.mrnc
        };
        let paths = match plan_group(
            probe,
            validity,
            space,
            mps,
            &group.members,
            group.angles,
            &start,
            &settings,
        ) {
            Ok(p) => p,
            Err(e @ (MrncError::Approach(i) | MrncError::Local(i))) => {
                unmeasured.push((i, mrnc_reason(&e, group.angles)));
                queue.push_front(Group {
                    members: group.members.iter().copied().filter(|&m| m != i).collect(),
                    ..group
                });
                continue;
            }
            Err(e @ MrncError::Roots) => {
                if group.members.len() == 1 {
                    unmeasured.push((group.members[0], mrnc_reason(&e, group.angles)));
                } else {
                    // Split across the members' widest spread: roots that must see each other
                    // across the part end up in different halves.
                    let mut members = group.members.clone();
                    let pos = |i: usize| mps[i].position.to_array();
                    let spread = |j: usize| {
                        let v = members.iter().map(|&i| pos(i)[j]);
                        v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
                    };
                    let axis = (0..3)
                        .max_by(|&a, &b| spread(a).total_cmp(&spread(b)))
                        .unwrap_or(0);
                    members.sort_by(|&a, &b| pos(a)[axis].total_cmp(&pos(b)[axis]).then(a.cmp(&b)));
                    let half = members.len() / 2;
                    queue.push_front(Group {
                        members: members[half..].to_vec(),
                        ..group.clone()
                    });
                    queue.push_front(Group {
                        members: members[..half].to_vec(),
                        ..group
                    });
                }
                continue;
            }
        };
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
        let lap = Instant::now();
        let order = tour_from_depot(costs, s);
        order_s += lap.elapsed().as_secs_f64();
        planned.push(JobGroup {
            paths,
            order,
            members: group.members,
            faces: group.faces,
        });
    }
    // The group order: node 0 home, node g + 1 group g's start. Every move between them runs
    // at the turn height (clear by construction) or vertically above a start (checked above).
    let m = planned.len();
    let node = |k: usize| -> &[f64] { if k == 0 { home } else { &planned[k - 1].paths.start } };
    let gcosts = CostMatrix::from_fn(m + 1, |a, b| {
        if a == b {
            0.0
        } else {
            path_time(&transition(s, node(a), node(b)))
        }
    });
    let lap = Instant::now();
    let group_order = tour_from_depot(gcosts, s);
    order_s += lap.elapsed().as_secs_f64();
    // The whole path and its times.
    let mut b = PathBuilder::default();
    b.push(home);
    let mut at: Vec<f64> = home.to_vec();
    for &g in &group_order {
        let group = &planned[g];
        b.extend(&transition(s, &at, &group.paths.start));
        b.group(group, &group.order);
        at = group.paths.start.clone();
    }
    b.extend(&transition(s, &at, home));
    let (movement_s, rotation_s) = path_times(&b.path, &s.speeds);
    unmeasured.sort_by_key(|u| u.0);
    Ok(Job {
        groups: planned,
        group_order,
        inspection_s: b.touches.len() as f64 * s.inspection_s,
        path: b.path,
        touches: b.touches,
        movement_s,
        rotation_s,
        compute_s: started.elapsed().as_secs_f64(),
        order_s,
        turn_height,
        home: home.to_vec(),
        unmeasured,
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
            crate::scene::assert_job_whole(&job, &space, &validity, 39, &home);
            // Every MP's approach is visited.
            let mut visited = 0;
            for g in &job.groups {
                assert_eq!(g.order.len(), g.members.len());
                for &k in &g.order {
                    assert!(job.path.contains(&g.paths.approaches[k]));
                    visited += 1;
                }
            }
            assert_eq!(visited, 39);
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
                let g = job.groups.iter().find(|g| g.members.contains(&i)).unwrap();
                let k = g.members.iter().position(|&x| x == i).unwrap();
                assert!(reused.path.contains(&g.paths.approaches[k]));
                assert!(
                    reused
                        .touches
                        .iter()
                        .any(|&(at, mp)| mp == i && reused.path[at] == g.paths.approaches[k])
                );
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
