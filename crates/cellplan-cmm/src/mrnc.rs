//! Paper 003 §3.2: RRT with multi-root-node competition (RRT-MRNC, Algorithms 1–4) for one
//! orientation group. Within a group the head keeps its orientation, so the search is over the
//! head centre (x, y, z) with the angles fixed.
//!
//! - **RootSampling** (Alg. 2): a candidate root per MP, resampled all together until every
//!   root–root and root–start segment is collision-free;
//! - **SearchingforRoots** (Alg. 3): from the MP's approach position, steps along a direction
//!   of the vector library (the MPs' normals, the bisectors of the group's normals, the probe's
//!   own axis backwards) with probability ε0, else a random one, each step `rand · Range` plus a
//!   perturbation of size ζ, until the point lies in the safe space (clearance at least
//!   `safety`); a walk that leaves the machine's travel starts again from the MP with a new
//!   direction;
//! - **RootRewire** (Alg. 4): `Root_max` rounds, each trying a new root per MP and keeping it
//!   when eq. 4's cost `‖Q − root‖ + ‖start − root‖` falls — and, as Alg. 2 requires of every
//!   root, its segments to the start and the other roots stay collision-free;
//! - then RRT* from each root to its MP's approach position (Alg. 1, lines 9–18).
//!
//! The result links the start to every root, every root to every other, and each root to its
//! MP: any subset of the group's MPs is then a path through the roots with no new planning.
use crate::classify::Probe;
use crate::part::Mp;
use cellplan_geom::DVec3;
use cellplan_kin::cmm::CmmHead;
use cellplan_motion::plan::{
    JointSpace, PlannerParams, Problem, StateValidity, Termination, check_segment, planner,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// RRT-MRNC's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MrncSettings {
    /// ε0: probability of stepping along a library direction (the paper: slightly above 0.5).
    pub eps0: f64,
    /// ζ: the perturbation added to each step (m).
    pub zeta: f64,
    /// Range: the largest step (m).
    pub range: f64,
    /// Clearance a root must have: the safe space (m).
    pub safety: f64,
    /// Root_max: rewiring rounds.
    pub root_max: usize,
    /// Most RootSampling rounds before the group is given up.
    pub max_rounds: usize,
    /// Most steps of one SearchingforRoots.
    pub max_steps: usize,
    /// Samples of each RRT* from a root to its MP.
    pub rrt_samples: usize,
    /// The RRT* samples within the box of the root and the MP's approach, widened by this (m).
    pub local_margin: f64,
    /// Distance of the approach position from the surface, along the normal (m).
    pub pretouch: f64,
    /// Clearance below which a segment counts as contact (m).
    pub min_clearance: f64,
    /// Seed.
    pub seed: u64,
}

impl Default for MrncSettings {
    fn default() -> Self {
        MrncSettings {
            eps0: 0.6,
            zeta: 0.01,
            range: 0.08,
            safety: 0.02,
            root_max: 30,
            max_rounds: 500,
            max_steps: 40,
            rrt_samples: 8000,
            local_margin: 0.08,
            pretouch: 0.005,
            min_clearance: 1e-4,
            seed: 0,
        }
    }
}

/// One group's stored paths (configurations `[x, y, z, a, b]`).
#[derive(Clone, Debug, PartialEq)]
pub struct GroupPaths {
    /// Head angles of the group.
    pub angles: (f64, f64),
    /// The group's start (a safe configuration above the part).
    pub start: Vec<f64>,
    /// Per MP: its root.
    pub roots: Vec<Vec<f64>>,
    /// Per MP: its approach configuration (pretouch off the surface along the normal).
    pub approaches: Vec<Vec<f64>>,
    /// Per MP: the path from its root to its approach (inclusive).
    pub local: Vec<Vec<Vec<f64>>>,
    /// RootSampling rounds used.
    pub rounds: usize,
    /// Roots replaced by rewiring.
    pub rewired: usize,
}

/// Why a group could not be planned.
#[derive(Clone, Debug, PartialEq)]
pub enum MrncError {
    /// An MP's approach configuration is not reachable or not clear at the group's angles.
    Approach(usize),
    /// No set of mutually visible roots within the rounds.
    Roots,
    /// RRT* found no path from a root to its MP.
    Local(usize),
}

fn xyz(q: &[f64]) -> DVec3 {
    DVec3::new(q[0], q[1], q[2])
}

fn random_unit(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 1e-3 && l <= 1.0 {
            return v / l;
        }
    }
}

/// The approach configuration of `mp` at head angles `angles`.
pub fn approach(head: &CmmHead, mp: &Mp, angles: (f64, f64), pretouch: f64) -> Vec<f64> {
    let d = CmmHead::direction(angles.0, angles.1);
    let ball = mp.position + mp.normal * (head.ball_diameter / 2.0 + pretouch);
    let c = ball - d * head.reach();
    vec![c.x, c.y, c.z, angles.0, angles.1]
}

/// RRT-MRNC for the MPs `members` (indices into `mps`) at head angles `angles`, from `start`.
#[allow(clippy::too_many_arguments)]
pub fn plan_group(
    probe: &Probe,
    validity: &dyn StateValidity,
    space: &JointSpace,
    mps: &[Mp],
    members: &[usize],
    angles: (f64, f64),
    start: &[f64],
    s: &MrncSettings,
) -> Result<GroupPaths, MrncError> {
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    // The group's space: the angles fixed.
    let mut space = space.clone();
    space.lower[3] = angles.0;
    space.upper[3] = angles.0;
    space.lower[4] = angles.1;
    space.upper[4] = angles.1;
    let head = probe.head();
    let approaches: Vec<Vec<f64>> = members
        .iter()
        .map(|&i| approach(head, &mps[i], angles, s.pretouch))
        .collect();
    for (k, q) in approaches.iter().enumerate() {
        if !(space.contains(q) && validity.clearance(q) > s.min_clearance) {
            return Err(MrncError::Approach(members[k]));
        }
    }
    // The vector library: the normals, their pairwise bisectors, the probe axis backwards.
    let d = CmmHead::direction(angles.0, angles.1);
    let mut library: Vec<DVec3> = members.iter().map(|&i| mps[i].normal).collect();
    for (x, &i) in members.iter().enumerate() {
        for &j in &members[x + 1..] {
            let b = mps[i].normal + mps[j].normal;
            if b.length() > 1e-6 && (mps[i].normal - mps[j].normal).length() > 1e-6 {
                library.push(b.normalize());
            }
        }
    }
    library.push(-d);
    let mut unique: Vec<DVec3> = Vec::with_capacity(library.len());
    for v in library {
        if !unique.iter().any(|u| (*u - v).length() < 1e-9) {
            unique.push(v);
        }
    }
    let library = unique;
    let config = |p: DVec3| vec![p.x, p.y, p.z, angles.0, angles.1];
    // (The clearance is capped at `motion::CAP`; a safety at or above it could never be met.)
    let safety = s.safety.min(0.9 * crate::motion::CAP);
    let safe = |q: &[f64]| space.contains(q) && validity.clearance(q) >= safety;
    let clear = |a: &[f64], b: &[f64]| check_segment(&space, validity, a, b, s.min_clearance).valid;
    // Algorithm 3.
    let direction = |rng: &mut ChaCha8Rng| {
        if rng.random::<f64>() < s.eps0 {
            library[rng.random_range(0..library.len())]
        } else {
            random_unit(rng)
        }
    };
    let search = |rng: &mut ChaCha8Rng, k: usize| -> Option<Vec<f64>> {
        let mut v = direction(rng);
        let mut p = xyz(&approaches[k]);
        for _ in 0..s.max_steps {
            p += v * (rng.random::<f64>() * s.range) + random_unit(rng) * s.zeta;
            let q = config(p);
            if !space.contains(&q) {
                // Out of the machine's travel: this direction is spent; again from the MP.
                p = xyz(&approaches[k]);
                v = direction(rng);
                continue;
            }
            if safe(&q) {
                return Some(q);
            }
        }
        None
    };
    // Algorithm 2: roots for all, mutually visible and visible from the start.
    let n = members.len();
    let mut roots: Option<Vec<Vec<f64>>> = None;
    let mut rounds = 0;
    while rounds < s.max_rounds {
        rounds += 1;
        let Some(candidates) = (0..n).map(|k| search(&mut rng, k)).collect::<Option<Vec<_>>>() else {
            continue;
        };
        let visible = candidates.iter().all(|r| clear(start, r))
            && (0..n).all(|a| (a + 1..n).all(|b| clear(&candidates[a], &candidates[b])));
        if visible {
            roots = Some(candidates);
            break;
        }
    }
    let Some(mut roots) = roots else {
        return Err(MrncError::Roots);
    };
    // Algorithm 4: rewiring by eq. 4.
    let cost = |k: usize, r: &[f64]| (xyz(&approaches[k]) - xyz(r)).length() + (xyz(start) - xyz(r)).length();
    let mut rewired = 0;
    for _ in 0..s.root_max {
        for k in 0..n {
            let Some(new) = search(&mut rng, k) else { continue };
            if cost(k, &new) < cost(k, &roots[k]) - 1e-12
                && clear(start, &new)
                && (0..n).filter(|&j| j != k).all(|j| clear(&new, &roots[j]))
            {
                roots[k] = new;
                rewired += 1;
            }
        }
    }
    // RRT* from each root to its MP.
    let mut local = Vec::with_capacity(n);
    for k in 0..n {
        let seed = s.seed.wrapping_add(k as u64);
        let path = local_path(&space, validity, &roots[k], &approaches[k], s, seed)
            .ok_or(MrncError::Local(members[k]))?;
        local.push(path.waypoints);
    }
    Ok(GroupPaths {
        angles,
        start: start.to_vec(),
        roots,
        approaches,
        local,
        rounds,
        rewired,
    })
}

/// The space RRT* searches between `a` and `b`: their box widened by `margin`, within `space`.
pub fn local_space(space: &JointSpace, a: &[f64], b: &[f64], margin: f64) -> JointSpace {
    let mut local = space.clone();
    for j in 0..3 {
        local.lower[j] = space.lower[j].max(a[j].min(b[j]) - margin);
        local.upper[j] = space.upper[j].min(a[j].max(b[j]) + margin);
    }
    local
}

/// A path from a root to its MP's approach (Alg. 1, lines 9–18).
#[derive(Clone, Debug, PartialEq)]
pub struct LocalPath {
    /// Root to approach, inclusive.
    pub waypoints: Vec<Vec<f64>>,
    /// The straight segment was clear: no sampling.
    pub straight: bool,
}

/// The path from `root` to `approach` in `space` (the group's, angles fixed): the straight
/// segment when it is clear, else RRT* with `s.rrt_samples` samples in the box of the two ends
/// widened by `s.local_margin`.
pub fn local_path(
    space: &JointSpace,
    validity: &dyn StateValidity,
    root: &[f64],
    approach: &[f64],
    s: &MrncSettings,
    seed: u64,
) -> Option<LocalPath> {
    if check_segment(space, validity, root, approach, s.min_clearance).valid {
        return Some(LocalPath {
            waypoints: vec![root.to_vec(), approach.to_vec()],
            straight: true,
        });
    }
    let local_space = local_space(space, root, approach, s.local_margin);
    let goals = [approach.to_vec()];
    let problem = Problem {
        min_clearance: s.min_clearance,
        ..Problem::new(&local_space, validity, root, &goals)
    };
    let params = PlannerParams {
        seed,
        ..PlannerParams::default()
    };
    let mut rrt = (planner("rrt-star").ok()?.build)(&params);
    let result = rrt.solve(&problem, &Termination::samples(s.rrt_samples));
    result.status.is_solved().then_some(LocalPath {
        waypoints: result.waypoints,
        straight: false,
    })
}

/// A start for a group: above the middle of its MPs' approach positions, backed off along the
/// probe's axis (so that the probe points at the part from outside it), at least at height
/// `z_min`, stepping further back and up until the whole probe is 5 cm clear; kept within
/// the travel.
pub fn group_start(
    probe: &Probe,
    validity: &dyn StateValidity,
    space: &JointSpace,
    mps: &[Mp],
    members: &[usize],
    angles: (f64, f64),
    z_min: f64,
) -> Option<Vec<f64>> {
    if members.is_empty() {
        return None;
    }
    let head = probe.head();
    let d = CmmHead::direction(angles.0, angles.1);
    let centre = members
        .iter()
        .map(|&i| xyz(&approach(head, &mps[i], angles, 0.0)))
        .sum::<DVec3>()
        / members.len() as f64;
    for k in 0..20 {
        let back = 0.1 + 0.05 * k as f64;
        let mut p = centre - d * back;
        p.z = p.z.max(z_min) + 0.02 * k as f64;
        // Within the travel: a start the travel cuts off is taken at its edge (and higher).
        let q: Vec<f64> = [p.x, p.y, p.z, angles.0, angles.1]
            .iter()
            .enumerate()
            .map(|(j, &v)| v.clamp(space.lower[j], space.upper[j]))
            .collect();
        if space.contains(&q) && validity.clearance(&q) >= 0.05 {
            return Some(q);
        }
    }
    None
}

impl GroupPaths {
    /// The path through the group for the MPs at positions `subset` (indices into the group's
    /// members, in the order given): start → root → approach → root → next root … → start,
    /// made of stored segments only. Each approach appears once (the touch and retract happen
    /// there).
    pub fn reuse(&self, subset: &[usize]) -> Vec<Vec<f64>> {
        let mut path = vec![self.start.clone()];
        for &k in subset {
            path.extend(self.local[k].iter().cloned());
            path.extend(self.local[k].iter().rev().skip(1).cloned());
        }
        path.push(self.start.clone());
        path.dedup();
        path
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classify::{Method, classify};
    use crate::motion::{CmmValidity, space};
    use crate::part::block_adjacent;

    #[test]
    fn every_group_of_the_block_gets_roots_and_paths_and_any_subset_is_a_clear_path() {
        let (mps, probe) = crate::scene::block();
        let orientations = crate::scene::grid();
        let groups = classify(&mps, &block_adjacent, &probe, &orientations, 0.001, Method::Exact).groups;
        let travel = crate::scene::TRAVEL;
        let space = space(&probe, &travel);
        let validity = CmmValidity {
            probe: &probe,
            margin: 0.002,
        };
        for (g, group) in groups.iter().enumerate() {
            let start = group_start(
                &probe,
                &validity,
                &space,
                &mps,
                &group.members,
                group.angles,
                0.55,
            )
            .unwrap_or_else(|| panic!("group {g}: no clear start"));
            assert!(
                validity.clearance(&start) > 0.02,
                "group {g}: the start is not clear"
            );
            let settings = MrncSettings {
                seed: g as u64,
                ..MrncSettings::default()
            };
            let paths = plan_group(
                &probe,
                &validity,
                &space,
                &mps,
                &group.members,
                group.angles,
                &start,
                &settings,
            )
            .unwrap_or_else(|e| panic!("group {g}: {e:?}"));
            assert_eq!(paths.roots.len(), group.members.len());
            eprintln!(
                "group {g}: {} MPs, roots after {} sampling rounds, {} rewired, local paths of {} waypoints",
                group.members.len(),
                paths.rounds,
                paths.rewired,
                paths.local.iter().map(Vec::len).sum::<usize>()
            );
            // Every root sees the start and every other root; every local path is clear.
            let seg = |a: &[f64], b: &[f64]| check_segment(&space, &validity, a, b, 1e-4).valid;
            for (k, r) in paths.roots.iter().enumerate() {
                assert!(seg(&paths.start, r));
                for r2 in &paths.roots[k + 1..] {
                    assert!(seg(r, r2));
                }
                let l = &paths.local[k];
                assert_eq!(l.first(), Some(r));
                assert_eq!(l.last(), Some(&paths.approaches[k]));
                assert!(l.windows(2).all(|w| seg(&w[0], &w[1])));
            }
            // Reuse: every other member, in reverse order.
            let subset: Vec<usize> = (0..group.members.len()).rev().step_by(2).collect();
            let path = paths.reuse(&subset);
            assert!(
                path.windows(2).all(|w| seg(&w[0], &w[1])),
                "group {g}: a reused path collides"
            );
            for &k in &subset {
                assert!(path.contains(&paths.approaches[k]));
            }
        }
    }
}
