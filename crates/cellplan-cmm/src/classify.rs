//! Paper 003 §3.1: group the measuring points by probe orientation — the fewest orientations
//! that measure every MP, each MP's probe direction within its cone (θ of its normal) and its
//! touch pose collision-free, each group's MPs on at most two faces, and those adjacent
//! (eq. 3).
//!
//! As a set cover: a column is an orientation together with a face or a pair of adjacent faces;
//! it covers the MPs on those faces that the orientation measures. The paper solves it with
//! the greedy rule (its ref. \[29\]); [`Method::Exact`] is `cellplan-solve`'s branch and bound.
use cellplan_geom::{CollisionWorld, DQuat, DVec3, GroupBody, GroupId, Pose, ShapeSpec};
use cellplan_kin::cmm::{CmmHead, CmmQ};
use cellplan_solve::SetCover;
use cellplan_solve::setcover::{self, ExactLimits};

use crate::part::Mp;

/// The probe's bodies beyond [`CmmHead`]'s lengths (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeBodies {
    /// Stylus stem diameter (thinner than the ball, so that the ball touches first).
    pub stem_diameter: f64,
    /// Extension (L1) diameter; paper 003 Table 1: 11 mm.
    pub extension_diameter: f64,
    /// The head: a cylinder on the A axis' centre, going up (diameter, height).
    pub head: (f64, f64),
    /// The ram above the head: a square column (side, height).
    pub ram: (f64, f64),
    /// How far above the ball's centre the stem is checked (the ball's neighbourhood touches
    /// the part by design).
    pub stem_start: f64,
}

impl ProbeBodies {
    /// Bodies for paper 003's probe (Table 1) on a PH10-like head.
    pub fn paper() -> Self {
        ProbeBodies {
            stem_diameter: 0.002,
            extension_diameter: 0.011,
            head: (0.05, 0.10),
            ram: (0.08, 0.6),
            stem_start: 0.004,
        }
    }
}

/// How to solve the cover.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The paper's: the column covering most uncovered MPs, repeatedly.
    Greedy,
    /// Fewest groups, by branch and bound.
    Exact,
}

/// One group: an orientation and its MPs.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// Head angles (a, b) (rad).
    pub angles: (f64, f64),
    /// The faces it spans (one or two adjacent).
    pub faces: Vec<usize>,
    /// Indices into the MP list.
    pub members: Vec<usize>,
}

/// The result.
#[derive(Clone, Debug, PartialEq)]
pub struct Classification {
    /// The groups.
    pub groups: Vec<Group>,
    /// MPs no orientation measures (with none of the candidates).
    pub unmeasurable: Vec<usize>,
    /// Candidate orientations tried.
    pub orientations: usize,
}

/// The probe as collision bodies in the world (group), and where each body sits for a probe
/// whose A-axis centre is at `head` pointing along `d`.
pub struct Probe {
    world: CollisionWorld,
    group: GroupId,
    moving: GroupId,
    head: CmmHead,
    bodies: ProbeBodies,
}

impl Probe {
    /// The part (and fixture) `statics` as static objects, the probe as two groups of bodies:
    /// for touching (the ball and the stem's last `stem_start` left out — they touch by design)
    /// and for moving (the whole probe).
    pub fn new(statics: Vec<(String, ShapeSpec, Pose)>, head: CmmHead, bodies: ProbeBodies) -> Self {
        let mut world = CollisionWorld::new();
        for (name, shape, pose) in statics {
            world.add_static(&name, &shape, pose);
        }
        let group = world.add_group("probe", probe_bodies(&head, &bodies, false));
        let moving = world.add_group("probe-moving", probe_bodies(&head, &bodies, true));
        Probe {
            world,
            group,
            moving,
            head,
            bodies,
        }
    }

    /// The highest point of the static objects (m).
    pub fn statics_top(&self) -> f64 {
        (0..self.world.static_count())
            .filter_map(|i| self.world.static_aabb(cellplan_geom::StaticId(i as u32)))
            .map(|(_, hi)| hi.z)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The head and probe.
    pub fn head(&self) -> &CmmHead {
        &self.head
    }

    /// Poses of the bodies [`probe_bodies`] makes, for the A-axis centre at `centre` and probe
    /// direction `d`: the ball (`whole`), the stem, the extension, the head, the ram.
    fn body_poses(&self, centre: DVec3, d: DVec3, whole: bool) -> Vec<Pose> {
        let turn = DQuat::from_rotation_arc(DVec3::Z, d);
        let along = |from: f64, to: f64| Pose::from_parts(centre + d * (0.5 * (from + to)), turn);
        let reach = self.head.reach();
        let mut poses = Vec::with_capacity(5);
        if whole {
            poses.push(Pose::from_parts(centre + d * reach, DQuat::IDENTITY));
        }
        let stem_end = if whole {
            reach
        } else {
            reach - self.bodies.stem_start
        };
        poses.push(along(self.head.l1, stem_end));
        poses.push(along(0.0, self.head.l1));
        poses.push(Pose::from_parts(
            centre + DVec3::Z * (self.bodies.head.1 / 2.0),
            DQuat::IDENTITY,
        ));
        poses.push(Pose::from_parts(
            centre + DVec3::Z * (self.bodies.head.1 + self.bodies.ram.1 / 2.0),
            DQuat::IDENTITY,
        ));
        poses
    }

    /// The distance of the whole probe at `q` to the statics, capped at `cap` (m).
    pub fn distance(&self, q: &CmmQ, cap: f64) -> f64 {
        let poses = self.body_poses(DVec3::new(q[0], q[1], q[2]), CmmHead::direction(q[3], q[4]), true);
        self.world.group_static_distance(self.moving, &poses, cap)
    }

    /// Whether the probe touching `mp` (m, normal) along direction `d` stays `clearance` clear of
    /// the statics.
    pub fn touch_clear(&self, position: DVec3, normal: DVec3, d: DVec3, clearance: f64) -> bool {
        let ball = position + normal * (self.head.ball_diameter / 2.0);
        let centre = ball - d * self.head.reach();
        self.world
            .group_vs_static(self.group, &self.body_poses(centre, d, false), clearance)
            .is_none()
    }
}

/// The probe's bodies: the ball (`whole` only), the stem (all of L2 when `whole`, else from
/// the extension to `stem_start` above the ball's centre), the extension, the head, the ram.
fn probe_bodies(head: &CmmHead, b: &ProbeBodies, whole: bool) -> Vec<GroupBody> {
    let body = |name: &str, shape: ShapeSpec| GroupBody {
        name: name.into(),
        shapes: vec![(shape, Pose::IDENTITY)],
    };
    let cylinder = |diameter: f64, length: f64| ShapeSpec::Cylinder {
        radius: diameter / 2.0,
        half_height: length / 2.0,
    };
    let stem = if whole {
        head.l2
    } else {
        head.reach() - head.l1 - b.stem_start
    };
    let mut out = Vec::with_capacity(5);
    if whole {
        out.push(body(
            "ball",
            ShapeSpec::Sphere {
                radius: head.ball_diameter / 2.0,
            },
        ));
    }
    out.push(body("stem", cylinder(b.stem_diameter, stem)));
    out.push(body("extension", cylinder(b.extension_diameter, head.l1)));
    out.push(body("head", cylinder(b.head.0, b.head.1)));
    out.push(body(
        "ram",
        ShapeSpec::Box {
            half_extents: DVec3::new(b.ram.0 / 2.0, b.ram.0 / 2.0, b.ram.1 / 2.0),
        },
    ));
    out
}

/// Classifies `mps` (positions in m) over the candidate head `orientations`, with the faces'
/// adjacency (`adjacent(f, g)`), a probe and a clearance.
pub fn classify(
    mps: &[Mp],
    adjacent: &dyn Fn(usize, usize) -> bool,
    probe: &Probe,
    orientations: &[(f64, f64)],
    clearance: f64,
    method: Method,
) -> Classification {
    classify_with(mps, adjacent, probe, orientations, clearance, method, &|_, _| {
        true
    })
}

/// [`classify`], an orientation counting for an MP only where `usable(mp, angles)` also holds —
/// the planner's own test of the MP's approach configuration, so that no group is formed that
/// the planner cannot then reach (a candidate the planner cannot leave is not a candidate).
pub fn classify_with(
    mps: &[Mp],
    adjacent: &dyn Fn(usize, usize) -> bool,
    probe: &Probe,
    orientations: &[(f64, f64)],
    clearance: f64,
    method: Method,
    usable: &(dyn Fn(usize, (f64, f64)) -> bool + Sync),
) -> Classification {
    let n = mps.len();
    // feasible[o] = MPs orientation o measures.
    let feasible: Vec<Vec<usize>> = orientations
        .iter()
        .map(|&(a, b)| {
            let d = CmmHead::direction(a, b);
            (0..n)
                .filter(|&i| {
                    let m = &mps[i];
                    let angle = (-d).dot(m.normal).clamp(-1.0, 1.0).acos();
                    angle <= m.theta_deg.to_radians() + 1e-12
                        && probe.touch_clear(m.position, m.normal, d, clearance)
                        && usable(i, (a, b))
                })
                .collect()
        })
        .collect();
    let mut faces: Vec<usize> = mps.iter().map(|m| m.face).collect();
    faces.sort_unstable();
    faces.dedup();
    let mut face_sets: Vec<Vec<usize>> = faces.iter().map(|&f| vec![f]).collect();
    for (i, &f) in faces.iter().enumerate() {
        for &g in &faces[i + 1..] {
            if adjacent(f, g) {
                face_sets.push(vec![f, g]);
            }
        }
    }
    // Columns: (orientation, face set) with at least one MP.
    let mut columns: Vec<(usize, Vec<usize>, Vec<usize>)> = Vec::new();
    for (o, members) in feasible.iter().enumerate() {
        for fs in &face_sets {
            let rows: Vec<usize> = members
                .iter()
                .copied()
                .filter(|&i| fs.contains(&mps[i].face))
                .collect();
            if !rows.is_empty() {
                columns.push((o, fs.clone(), rows));
            }
        }
    }
    // Drop columns whose rows another column covers too (the cover is the same, smaller).
    columns.sort_by(|a, b| b.2.len().cmp(&a.2.len()).then(a.0.cmp(&b.0)).then(a.1.cmp(&b.1)));
    let mut kept: Vec<(usize, Vec<usize>, Vec<usize>)> = Vec::new();
    for c in columns {
        if !kept.iter().any(|k| c.2.iter().all(|r| k.2.contains(r))) {
            kept.push(c);
        }
    }
    let coverable: Vec<usize> = (0..n)
        .filter(|&i| kept.iter().any(|k| k.2.contains(&i)))
        .collect();
    let unmeasurable: Vec<usize> = (0..n).filter(|i| !coverable.contains(i)).collect();
    // The set cover over the coverable MPs.
    let row_of: std::collections::HashMap<usize, usize> =
        coverable.iter().enumerate().map(|(r, &i)| (i, r)).collect();
    let mut covers = vec![Vec::new(); coverable.len()];
    for (c, k) in kept.iter().enumerate() {
        for i in &k.2 {
            covers[row_of[i]].push(c);
        }
    }
    let sc = SetCover {
        rows: coverable.len(),
        columns: kept.len(),
        costs: vec![1.0; kept.len()],
        covers,
    };
    let cover = match method {
        Method::Greedy => setcover::greedy(&sc),
        Method::Exact => setcover::exact(
            &sc,
            &ExactLimits {
                time_limit: None,
                max_nodes: Some(2_000_000),
            },
        ),
    };
    // Each MP to the first chosen column that covers it.
    let mut chosen: Vec<usize> = cover.columns.clone();
    chosen.sort_unstable();
    let mut groups: Vec<Group> = chosen
        .iter()
        .map(|&c| Group {
            angles: orientations[kept[c].0],
            faces: kept[c].1.clone(),
            members: Vec::new(),
        })
        .collect();
    for &i in &coverable {
        if let Some(g) = chosen.iter().position(|&c| kept[c].2.contains(&i)) {
            groups[g].members.push(i);
        }
    }
    groups.retain(|g| !g.members.is_empty());
    Classification {
        groups,
        unmeasurable,
        orientations: orientations.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::part::block_adjacent;
    use crate::scene::{block as setup, grid};

    #[test]
    fn every_mp_of_the_block_is_grouped_within_its_cone_on_adjacent_faces() {
        let (mps, probe) = setup();
        let orientations = grid();
        let counts = crate::scene::classify_both(&mps, &probe, &block_adjacent).map(|c| c.groups.len());
        // The block is laid out like paper 003's case: five groups (Table 2).
        assert_eq!(counts[1], 5);
        eprintln!(
            "block: {} groups greedy, {} exact, over {} orientations",
            counts[0],
            counts[1],
            orientations.len()
        );
    }

    #[test]
    fn a_probe_pointing_into_the_part_collides() {
        let (mps, probe) = setup();
        let deck = &mps[0];
        // Straight down onto the deck: clear. Sideways into the block at the deck: not.
        assert!(probe.touch_clear(deck.position, deck.normal, -DVec3::Z, 0.001));
        assert!(!probe.touch_clear(deck.position, deck.normal, DVec3::X, 0.001));
    }
}
