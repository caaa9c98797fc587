//! Self pairs bounded by a table over one joint: the bodies turned about the joints at the
//! ends of the chain between them.
//!
//! A few self pairs stay within a centimetre or two of each other in most configurations: on
//! the MBM UR5, the base and the upper arm (16 mm apart over most of the range), the forearm's
//! pieces and the wrist. Their sphere covers overlap in every configuration, so every segment
//! step asked them an exact (GJK) distance and was cut short by them.
//!
//! One joint is enough after turning. The proximal body of a pair does not move under the
//! first joint between the two, whose axis stands still in its frame; turned a whole turn
//! about that axis ([`Revolved`]), it becomes a set that the joint leaves in place, and the
//! distance from that set to the distal body bounds the pair's distance whatever that joint's
//! value. Likewise the distal body turned about the last joint between them. With two joints
//! between the bodies, turning one end leaves the other joint; with three, turning both ends
//! leaves the middle one. [`PairTable`] samples that distance over the joint's range (once per
//! turn) so finely that between samples — a sample's distance less how far the joint can move
//! the two sets towards each other since it (`L·|Δq|`, `L` the smaller reach of the two from
//! the joint's axis) — at most [`LOSS`] is lost.
//!
//! A segment step then asks the table for the least bound over the values the joint takes
//! within the step ([`PairTable::least_within`]): where that is positive, the pair cannot touch
//! anywhere in the step, and it neither shortens the step nor costs a distance query. Every
//! value is a certified lower bound, so the segment check's guarantee is unchanged.
//! [`PairTables::build`] makes the tables of an arm's close pairs once, when the arm is set up:
//! the pairs whose covers come within [`CLOSE`] of each other in at least a quarter of
//! [`PROBES`] configurations spread over the limits (a fixed sequence: the tables, and so the
//! work of every check, depend on the arm alone).
use super::{Arm, DISTANCE_SLACK, moved_by};
use cellplan_geom::convex_overlap;
use cellplan_geom::revolved::{Cylinder, Revolved, inner_cylinders};
use cellplan_geom::{BroadPhase, PlacedCovers};
use cellplan_geom::{DVec3, Pose, convex_distance};
use parry3d_f64::shape::SupportMap;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A pair is close when its covers come within this (m) of each other…
pub const CLOSE: f64 = 0.02;

/// …in at least a quarter of this many configurations.
pub const PROBES: usize = 64;

/// The largest loss (m) of the bound between two samples of a table: samples are spaced so
/// that `L·h/2` stays within it (unless [`MAX_SAMPLES`] binds).
const LOSS: f64 = 1e-3;

/// Samples of a table at most (and at least [`MIN_SAMPLES`]).
const MAX_SAMPLES: usize = 4096;
const MIN_SAMPLES: usize = 16;

/// Distances are asked up to this (m); beyond, the sample says this much.
const TABLE_CAP: f64 = 0.1;

/// What a proof of contact shrinks a cylinder by beyond the motion it covers (m): far more than
/// GJK's tolerance for an overlap ([`convex_overlap`]).
const CONTACT_SLACK: f64 = 1e-4;

/// A turned end's cylinders for proofs of contact are the largest and the widest at least twice
/// this long (m; see [`inner_cylinders`]): a robot's base is a disc whose widest part is thin.
const CYLINDER_HALF_HEIGHT: f64 = 0.003;

/// A lower bound on one self pair's distance as a function of one joint's value.
#[derive(Clone, Debug, PartialEq)]
pub struct PairTable {
    /// The joint.
    joint: usize,
    /// Its value at the first sample.
    pub(super) lo: f64,
    /// The spacing of the samples.
    pub(super) step: f64,
    /// A whole turn when the joint's range spans one: values are taken modulo it.
    period: Option<f64>,
    /// How fast the distance can fall per unit of the joint (m/rad).
    lipschitz: f64,
    /// The distance at each sample, certified from below, less the slack.
    values: Vec<f64>,
    /// At each sample, whether the pair is proven in contact for every value of the joint
    /// within half a spacing of it, whatever the other joints (see [`PairTable::touches`]);
    /// empty when the ends have no cylinder to prove it with.
    contact: Vec<bool>,
}

impl PairTable {
    /// The joint the table runs over.
    pub fn joint(&self) -> usize {
        self.joint
    }

    /// Whether the pair is in contact, proven, wherever the joint stands at `v` (the other
    /// joints anywhere); `false` where the table cannot tell.
    ///
    /// A turned end is rotation-invariant about its joint's axis, and so is a cylinder about
    /// that axis inside it ([`inner_cylinders`]): that cylinder stays inside the body whatever
    /// the turned joint's value. At a sample, the cylinder shrunk by `δ` is found overlapping
    /// the other end (its own body, or its cylinder). Over half a spacing `h/2` from the
    /// sample, a point common to both moves relative to the other end by at most `L·h/2` (`L`
    /// the table's Lipschitz constant, the smaller reach of the two ends from the joint's axis,
    /// which the common point lies within); `δ` exceeds it, so the point stays inside the
    /// unshrunk cylinder, and the bodies overlap.
    #[inline]
    pub fn touches(&self, v: f64) -> bool {
        let n = self.contact.len();
        if n == 0 || !v.is_finite() {
            return false;
        }
        let mut x = v - self.lo;
        if let Some(p) = self.period {
            x = x.rem_euclid(p);
        }
        let g = (x / self.step).round();
        // Outside the sampled range nothing is known.
        if !(0.0..n as f64).contains(&g) {
            return false;
        }
        self.contact[g as usize]
    }

    /// The least bound (m, 0 where the table says nothing) over the joint's values within
    /// `radius` of `v`.
    pub fn least_within(&self, v: f64, radius: f64) -> f64 {
        let n = self.values.len();
        let span = self.step * (n - 1) as f64;
        let radius = radius.abs();
        if !(v.is_finite() && radius.is_finite()) {
            return 0.0;
        }
        let mut x = v - self.lo;
        if let Some(p) = self.period {
            // A whole turn or more covers every value.
            if 2.0 * radius >= p {
                return self.least_cells(0, n - 1);
            }
            x = x.rem_euclid(p);
            let (a, b) = (x - radius, x + radius);
            // The interval, wrapped into [0, p): one piece or two.
            return if a < 0.0 {
                self.least_on(0.0, b).min(self.least_on(a + p, span))
            } else if b > span {
                self.least_on(a, span).min(self.least_on(0.0, b - p))
            } else {
                self.least_on(a, b)
            };
        }
        let (a, b) = (x - radius, x + radius);
        // Outside the sampled range nothing is known.
        if a < 0.0 || b > span * (1.0 + 1e-12) {
            return 0.0;
        }
        self.least_on(a, b)
    }

    /// The least bound over `[a, b]` (offsets from `lo`, within the sampled span).
    fn least_on(&self, a: f64, b: f64) -> f64 {
        let n = self.values.len();
        let cell = |x: f64| ((x / self.step).floor().max(0.0) as usize).min(n - 2);
        let (ga, gb) = (cell(a.max(0.0)), cell(b.max(0.0)));
        if ga == gb {
            // Within one cell: the bound at its ends less the motion from each.
            let s = ga as f64 * self.step;
            let (ta, tb) = ((a - s).clamp(0.0, self.step), (b - s).clamp(0.0, self.step));
            let left = self.values[ga] - self.lipschitz * tb;
            let right = self.values[ga + 1] - self.lipschitz * (self.step - ta);
            return left.max(right).max(0.0);
        }
        self.least_cells(ga, gb + 1)
    }

    /// The least bound over the cells between samples `ga` and `gb` (`ga < gb`): each cell's
    /// lower end value less half its width's motion.
    fn least_cells(&self, ga: usize, gb: usize) -> f64 {
        let least = self.values[ga..=gb].iter().copied().fold(f64::INFINITY, f64::min);
        (least - 0.5 * self.lipschitz * self.step).max(0.0)
    }
}

/// One end of a pair as the table sees it: the body's own shape, or the body turned about an
/// axis (body frame).
enum End {
    Own,
    /// Turned, with cylinders about the axis inside the body (none when none fits).
    Turned(Revolved, Vec<Cylinder>),
}

/// The table of bodies `i` and `j` of `arm` (see the module documentation), or `None` when it
/// does not apply: other than two or three joints between them, a sliding joint among those,
/// or a body that is not a convex polyhedron or a box. Of the ends that can be turned, the
/// choice whose samples clear the most (each counted up to 2 cm) is kept.
pub fn pair_table(arm: &Arm, i: usize, j: usize) -> Option<PairTable> {
    let (a, b) = (moved_by(arm, i), moved_by(arm, j));
    let (near, far, first, end) = if b >= a { (i, j, a, b) } else { (j, i, b, a) };
    let chain = arm.chain;
    let m = end.checked_sub(first)?;
    if !(2..=3).contains(&m) || !(first..end).all(|k| chain.joints.get(k).is_some_and(|j| j.is_rotational()))
    {
        return None;
    }
    let q = chain.mid_configuration();
    let (mut links, mut poses) = (Vec::new(), Vec::new());
    arm.body_poses(&q, &mut links, &mut poses);
    // Joint k's axis in the world at `q`: a point and the unit direction.
    let axis = |k: usize| -> Option<(DVec3, DVec3)> {
        let l = chain.joint_link(k)?;
        let frame = arm.base * *links.get(l)?;
        Some((
            frame.translation,
            (frame.rotation * chain.joints[k].axis).try_normalize()?,
        ))
    };
    let points = |body: usize| arm.world.body_points(arm.group, body);
    // Body `body` turned about joint k's axis, in the body's frame.
    let turned = |body: usize, k: usize| -> Option<End> {
        let (o, d) = axis(k)?;
        let to_body = poses.get(body)?.inverse();
        let (pts, o, d) = (points(body)?, to_body.transform_point(o), to_body.rotation * d);
        Some(End::Turned(
            Revolved::new(&pts, o, d)?,
            inner_cylinders(&pts, o, d, CYLINDER_HALF_HEIGHT),
        ))
    };
    let (pn, pf) = (points(near)?, points(far)?);
    let options = if m == 2 {
        vec![
            (turned(near, first)?, End::Own, first + 1),
            (End::Own, turned(far, end - 1)?, first),
        ]
    } else {
        vec![(turned(near, first)?, turned(far, end - 1)?, first + 1)]
    };
    let mut best: Option<(f64, PairTable)> = None;
    for (en, ef, free) in options {
        let Some(table) = sample(arm, (near, &en, &pn), (far, &ef, &pf), free, axis(free)?, &q) else {
            continue;
        };
        let score = table.values.iter().map(|v| v.clamp(0.0, 0.02)).sum::<f64>() / table.values.len() as f64;
        if best.as_ref().is_none_or(|(s, _)| score > *s) {
            best = Some((score, table));
        }
    }
    best.map(|(_, t)| t)
}

/// The table of one choice of ends over joint `free` (its axis in the world at the reference
/// configuration `q`: `(o, d)`).
fn sample(
    arm: &Arm,
    (near, en, pn): (usize, &End, &[DVec3]),
    (far, ef, pf): (usize, &End, &[DVec3]),
    free: usize,
    (o, d): (DVec3, DVec3),
    q: &[f64],
) -> Option<PairTable> {
    let joint = arm.chain.joints.get(free)?;
    let (mut links, mut poses) = (Vec::new(), Vec::new());
    arm.body_poses(q, &mut links, &mut poses);
    // How far each end's points lie from the free joint's axis: the relative motion the joint
    // causes is a turn about it, as fast as the nearer of the two ends allows. (At `q`: a
    // turned end's reach does not depend on the joint it was turned about, an own end's on no
    // joint between the two.)
    let reach = |body: usize, e: &End, own: &[DVec3]| -> Option<f64> {
        let pose = poses.get(body)?;
        Some(match e {
            End::Own => own
                .iter()
                .map(|p| (pose.transform_point(*p) - o).cross(d).length())
                .fold(0.0, f64::max),
            End::Turned(r, _) => {
                let to_body = pose.inverse();
                r.reach_from(to_body.transform_point(o), to_body.rotation * d)
            }
        })
    };
    let lipschitz = reach(near, en, pn)?.min(reach(far, ef, pf)?);
    let tau = std::f64::consts::TAU;
    let (lo, hi) = (joint.lower, joint.upper);
    if !(lo.is_finite() && hi.is_finite() && hi > lo && lipschitz.is_finite()) {
        return None;
    }
    let (span, period) = if hi - lo >= tau {
        (tau, Some(tau))
    } else {
        (hi - lo, None)
    };
    let n = ((span * lipschitz / (2.0 * LOSS)).ceil() as usize + 1).clamp(MIN_SAMPLES, MAX_SAMPLES);
    let step = span / (n - 1) as f64;
    // The proof of contact: one end's cylinder shrunk by how far half a spacing moves the
    // ends (see [`PairTable::touches`]), against the other end as it stays whatever its
    // turned joint's value: its own body, or its cylinder.
    let shrink = 0.5 * lipschitz * step + CONTACT_SLACK;
    let shrunk = |cs: &[Cylinder]| -> Vec<Cylinder> { cs.iter().filter_map(|c| c.eroded(shrink)).collect() };
    let proof = match (en, ef) {
        (End::Turned(_, c), End::Turned(_, other)) if !other.is_empty() => {
            Some(Proof::NearOnFarCylinders(shrunk(c), other))
        }
        (End::Turned(_, c), End::Own) => Some(Proof::NearOnFar(shrunk(c))),
        (End::Own, End::Turned(_, c)) => Some(Proof::FarOnNear(shrunk(c))),
        _ => None,
    }
    .filter(|p| !p.cylinders().is_empty());
    let mut cq = q.to_vec();
    let mut values = Vec::with_capacity(n);
    let mut contact = Vec::with_capacity(if proof.is_some() { n } else { 0 });
    for g in 0..n {
        cq[free] = lo + step * g as f64;
        arm.body_poses(&cq, &mut links, &mut poses);
        let ((pa, sa), (pb, sb)) = (
            placed(arm, near, *poses.get(near)?, en)?,
            placed(arm, far, *poses.get(far)?, ef)?,
        );
        values.push(convex_distance(&pa, sa, &pb, sb, TABLE_CAP) - DISTANCE_SLACK);
        if let Some(proof) = &proof {
            let (pn, pf) = (*poses.get(near)?, *poses.get(far)?);
            let touching = proof.cylinders().iter().any(|c| match proof {
                Proof::NearOnFarCylinders(_, other) => other.iter().any(|o| convex_overlap(&pn, c, &pf, o)),
                Proof::NearOnFar(_) => convex_overlap(&pn, c, &pb, sb),
                Proof::FarOnNear(_) => convex_overlap(&pa, sa, &pf, c),
            });
            contact.push(touching);
        }
    }
    // A table that proves nothing keeps no flags.
    if !contact.contains(&true) {
        contact.clear();
    }
    Some(PairTable {
        joint: free,
        lo,
        step,
        period,
        lipschitz,
        values,
        contact,
    })
}

/// How a table proves contact: one end's shrunk cylinders (body frame) against the other end
/// as it stays whatever its turned joint's value.
enum Proof<'a> {
    /// The near end's, against the far end's own body.
    NearOnFar(Vec<Cylinder>),
    /// The near end's, against the far end's cylinders (both ends turned).
    NearOnFarCylinders(Vec<Cylinder>, &'a [Cylinder]),
    /// The far end's, against the near end's own body.
    FarOnNear(Vec<Cylinder>),
}

impl Proof<'_> {
    fn cylinders(&self) -> &[Cylinder] {
        match self {
            Proof::NearOnFar(c) | Proof::NearOnFarCylinders(c, _) | Proof::FarOnNear(c) => c,
        }
    }
}

/// End `e` of body `body` (at `pose`) as a support map and its pose in the world.
fn placed<'s>(arm: &Arm<'s>, body: usize, pose: Pose, e: &'s End) -> Option<(Pose, &'s dyn SupportMap)> {
    Some(match e {
        End::Own => {
            let (s, local) = arm.world.body_support(arm.group, body)?;
            (pose * local, s)
        }
        End::Turned(r, _) => (pose, r as &dyn SupportMap),
    })
}

/// A configuration drawn uniformly within the joint limits (a joint without finite limits at
/// its middle).
pub(super) fn random_configuration(arm: &Arm, rng: &mut ChaCha8Rng) -> Vec<f64> {
    arm.chain
        .joints
        .iter()
        .map(|j| {
            if j.lower.is_finite() && j.upper.is_finite() && j.upper > j.lower {
                rng.random_range(j.lower..=j.upper)
            } else {
                j.mid()
            }
        })
        .collect()
}

/// Configurations sampled for [`likely_contacts`].
const ORDER_PROBES: usize = 512;

/// The self pairs of `arm` in the order a validity check should ask them, after the tables'
/// proofs of contact ([`PairTables::prove_contact`]), to find a contact soonest in a random
/// configuration: over [`ORDER_PROBES`] configurations spread over the limits (a fixed
/// sequence) that the tables do not prove invalid, the pair in contact in the most of them,
/// then the pair in contact in the most of the rest, and so on (the greedy order of a set
/// cover). Contacts are found with the covers first, the exact distance only where they
/// overlap.
fn likely_contacts(arm: &Arm, broad: &BroadPhase, tables: &PairTables) -> Vec<(usize, usize)> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x006f_7264_6572);
    let mut placed = PlacedCovers::default();
    let (mut links, mut poses) = (Vec::new(), Vec::new());
    // Per probe configuration, the pairs (indices into `self_pairs`) in contact there.
    let mut touching: Vec<Vec<usize>> = Vec::new();
    for _ in 0..ORDER_PROBES {
        let q = random_configuration(arm, &mut rng);
        if tables.prove_contact(&q) {
            continue;
        }
        arm.body_poses(&q, &mut links, &mut poses);
        broad.place(&poses, &mut placed);
        let pairs: Vec<usize> = (0..arm.self_pairs.len())
            .filter(|&k| {
                let (i, j) = arm.self_pairs[k];
                broad.pair_bound(i, j, &placed, 1e-6) <= 0.0
                    && arm.world.pair_distance(arm.group, i, j, &poses, 1e-6) <= 0.0
            })
            .collect();
        if !pairs.is_empty() {
            touching.push(pairs);
        }
    }
    let mut order = Vec::new();
    let mut count = vec![0usize; arm.self_pairs.len()];
    while !touching.is_empty() {
        count.iter_mut().for_each(|c| *c = 0);
        for k in touching.iter().flatten() {
            count[*k] += 1;
        }
        // The most often in contact; the first of those on a tie.
        let Some(best) = (0..count.len()).max_by_key(|&k| (count[k], std::cmp::Reverse(k))) else {
            break;
        };
        order.push(arm.self_pairs[best]);
        touching.retain(|pairs| !pairs.contains(&best));
    }
    order
}

/// The tables of an arm's close self pairs (see the module documentation), shared by every
/// checker of the arm.
#[derive(Clone, Debug, Default)]
pub struct PairTables {
    bodies: usize,
    /// Per pair `(i, j)`, `i < j`, at `i * bodies + j`: its index in `tables`, or `u32::MAX`.
    slots: Vec<u32>,
    tables: Vec<PairTable>,
    /// The self pairs in the order a check should ask them to find a contact soonest (see
    /// [`likely_contacts`]).
    likely: Vec<(usize, usize)>,
}

impl PairTables {
    /// The tables of `arm`'s close self pairs (of `arm.self_pairs`, those with a table).
    pub fn build(arm: &Arm) -> PairTables {
        let bodies = arm.body_links.len();
        let n = bodies.saturating_mul(bodies).min(1 << 16);
        let mut out = PairTables {
            bodies,
            slots: vec![u32::MAX; n],
            tables: Vec::new(),
            likely: Vec::new(),
        };
        let broad = BroadPhase::new(arm.world, arm.group, &[]);
        let mut placed = PlacedCovers::default();
        let mut rng = ChaCha8Rng::seed_from_u64(0x7461_626c_6573);
        let (mut links, mut poses) = (Vec::new(), Vec::new());
        let mut close = vec![0usize; arm.self_pairs.len()];
        for _ in 0..PROBES {
            let q = random_configuration(arm, &mut rng);
            arm.body_poses(&q, &mut links, &mut poses);
            broad.place(&poses, &mut placed);
            for (c, &(i, j)) in close.iter_mut().zip(arm.self_pairs) {
                *c += usize::from(broad.pair_bound(i, j, &placed, CLOSE) < CLOSE);
            }
        }
        for (&c, &(i, j)) in close.iter().zip(arm.self_pairs) {
            if 4 * c < PROBES {
                continue;
            }
            let (Some(k), Some(t)) = (out.index(i, j), pair_table(arm, i, j)) else {
                continue;
            };
            out.slots[k] = out.tables.len() as u32;
            out.tables.push(t);
        }
        out.likely = likely_contacts(arm, &broad, &out);
        out
    }

    fn index(&self, i: usize, j: usize) -> Option<usize> {
        let (i, j) = (i.min(j), i.max(j));
        let k = i.checked_mul(self.bodies)?.checked_add(j)?;
        (j < self.bodies && k < self.slots.len()).then_some(k)
    }

    /// The table of bodies `i` and `j`, if they have one.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> Option<&PairTable> {
        let s = *self.slots.get(self.index(i, j)?)?;
        self.tables.get(s as usize)
    }

    /// Whether some table proves its pair in contact at `q` ([`PairTable::touches`]): then
    /// `q` is invalid, whatever else holds.
    #[inline]
    pub fn prove_contact(&self, q: &[f64]) -> bool {
        self.tables
            .iter()
            .any(|t| q.get(t.joint).is_some_and(|&v| t.touches(v)))
    }

    /// The self pairs that make random configurations invalid, in the order that finds a
    /// contact soonest (a greedy set cover of the contacts at random configurations the tables
    /// do not prove invalid); pairs never seen in contact are not listed.
    pub fn likely_contacts(&self) -> &[(usize, usize)] {
        &self.likely
    }

    /// The number of tables.
    pub fn len(&self) -> usize {
        self.tables.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.tables.is_empty()
    }
}
