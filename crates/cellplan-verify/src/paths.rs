//! The legs: chained home → tasks → home, naming their ends, proven clear of the static scene
//! and of the robot itself between the configurations measured (conservative advancement on
//! each body's and self pair's motion bound, see [`check_leg`]); and the trajectory walked
//! forward along them, so that the motion checked is the motion timed.
use super::{VerifySettings, Violation, ViolationKind};
use cellplan_core::document::{LegOut, RobotPlan};
use cellplan_core::plan::Stop;
use cellplan_geom::BodyContact;
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use rayon::prelude::*;

/// The leg checks; returns the configurations checked.
pub(super) fn check(
    cell: &Cell,
    robots: &[(&Robot, &RobotPlan)],
    settings: &VerifySettings,
    out: &mut Vec<Violation>,
) -> usize {
    // Robot by robot, side by side; the violations are reported in robot order.
    let per_robot: Vec<(Vec<Violation>, usize)> = robots
        .par_iter()
        .map(|&(robot, rp)| {
            let mut found = Vec::new();
            let checked = check_robot(cell, robot, rp, settings, &mut found);
            (found, checked)
        })
        .collect();
    let mut checked = 0;
    for (found, n) in per_robot {
        out.extend(found);
        checked += n;
    }
    checked
}

/// [`check`] for one robot: the number of samples checked.
fn check_robot(
    cell: &Cell,
    robot: &Robot,
    rp: &RobotPlan,
    settings: &VerifySettings,
    out: &mut Vec<Violation>,
) -> usize {
    if rp.legs.len() != rp.tasks.len() + 1 {
        out.push(Violation::robot(
            ViolationKind::Continuity,
            &rp.name,
            None,
            None,
            format!(
                "{} legs for {} tasks (want one more)",
                rp.legs.len(),
                rp.tasks.len()
            ),
        ));
        return 0;
    }
    let mut checked = 0;
    let mut scratch = Scratch::default();
    let gaps = gaps(cell, robot);
    let mut at: &[f64] = &rp.home;
    for (i, leg) in rp.legs.iter().enumerate() {
        let to: &[f64] = rp.tasks.get(i).map_or(&rp.home, |v| &v.q);
        check_ends(rp, i, leg, at, to, out);
        checked += check_leg(cell, robot, rp, leg, (settings, &gaps), &mut scratch, out);
        at = to;
    }
    if let Some((t, detail)) = follow_legs(robot, rp, settings.limit_tolerance) {
        out.push(Violation::robot(
            ViolationKind::OffPath,
            &rp.name,
            Some(t),
            None,
            detail,
        ));
    }
    checked
}

/// A leg starts where the one before ended, ends at its task (or home), names those stops,
/// and is one segment when it says it is straight.
fn check_ends(rp: &RobotPlan, i: usize, leg: &LegOut, at: &[f64], to: &[f64], out: &mut Vec<Violation>) {
    let stop = |k: usize| {
        if k == 0 || k > rp.tasks.len() {
            Stop::Home
        } else {
            Stop::Task(rp.tasks[k - 1].task.clone())
        }
    };
    let mut push = |detail: String| {
        out.push(Violation::robot(
            ViolationKind::Continuity,
            &rp.name,
            Some(leg.start_s),
            None,
            detail,
        ));
    };
    let (first, last) = (&leg.waypoints[0], &leg.waypoints[leg.waypoints.len() - 1]);
    if dist(first, at) > 1e-9 || dist(last, to) > 1e-9 {
        push(format!("leg {} does not join its neighbours", name(leg)));
    }
    if leg.from != stop(i) || leg.to != stop(i + 1) {
        push(format!(
            "leg {i} says {}, but the visits make it {} → {}",
            name(leg),
            stop(i).label(),
            stop(i + 1).label()
        ));
    }
    for b in &leg.blends {
        let w = &leg.waypoints;
        let fits = b.waypoint > 0
            && b.waypoint + 1 < w.len()
            && 2.0 * b.radius <= dist(&w[b.waypoint - 1], &w[b.waypoint]) + 1e-9
            && 2.0 * b.radius <= dist(&w[b.waypoint], &w[b.waypoint + 1]) + 1e-9;
        if !fits {
            push(format!(
                "leg {}: the blend at waypoint {} reaches past the middle of a segment",
                name(leg),
                b.waypoint
            ));
        }
    }
    if let Some(wait) = rp
        .waits
        .iter()
        .find(|x| x.leg == i && leg.blends.iter().any(|b| b.waypoint == x.waypoint))
    {
        push(format!(
            "leg {} is blended at waypoint {}, where the robot waits",
            name(leg),
            wait.waypoint
        ));
    }
    if leg.straight && leg.waypoints.len() != 2 {
        push(format!(
            "leg {} says it is straight but has {} waypoints",
            name(leg),
            leg.waypoints.len()
        ));
    }
}

/// A leg for people: "M3 → M7".
pub(super) fn name(leg: &LegOut) -> String {
    format!("{} → {}", leg.from.label(), leg.to.label())
}

/// Most configurations measured on one piece of a leg, per joint step of its largest joint
/// travel (and [`MIN_PIECE_BUDGET`] more): a piece that grazes the clearance for long would
/// otherwise be walked in ever shorter steps. Past it the rest of the piece is reported
/// unproven.
const PIECE_BUDGET_PER_STEP: usize = 2;
const MIN_PIECE_BUDGET: usize = 2_000;

/// Longest stretch (m of a part's travel) one distance measurement is asked to clear: the
/// queries are capped at it, which keeps them cheap far from the scene.
const MAX_ROOM: f64 = 0.25;

/// One gap the leg check keeps: a body's from the scene (at least the clearance), or a checked
/// self pair's (apart), with how far the joints can move the one relative to the other.
#[derive(Clone, Debug)]
pub(crate) struct Gap {
    what: GapOf,
    /// Per joint, a bound on the distance from its axis of the points whose motion changes the
    /// gap: a body's ([`cellplan_kin::Chain::body_radii`]), or for a self pair the later
    /// body's over the joints between the two (the joints before move both alike).
    radii: Vec<f64>,
}

#[derive(Clone, Copy, Debug)]
enum GapOf {
    Scene(usize),
    Pair(usize, usize),
}

/// The gaps of `robot`'s legs: each body not exempt from the scene, and each checked self pair.
/// Each body's reach from its link's origin is its shape's offset plus the shape's own reach
/// (the shapes as the cell gives them, as in [`super::body_radii`]: this crate's own bound,
/// not the planner's sphere covers).
pub(crate) fn gaps(cell: &Cell, robot: &Robot) -> Vec<Gap> {
    let chain = &robot.model.chain;
    let reach = |i: usize| super::body_reach(robot, i);
    let link = |i: usize| robot.body_links.get(i).copied().unwrap_or(chain.links.len() - 1);
    let moved_by = chain.joints_to();
    let mut out: Vec<Gap> = (0..robot.body_links.len())
        .filter(|&i| !cell.world.is_static_exempt(robot.group, i))
        .map(|i| Gap {
            what: GapOf::Scene(i),
            radii: chain.body_radii(link(i), reach(i)),
        })
        .collect();
    for &(i, j) in cell.world.self_pairs(robot.group) {
        // The body moved by more joints is the later one.
        let (early, late) = if moved_by[link(i)] <= moved_by[link(j)] {
            (i, j)
        } else {
            (j, i)
        };
        let shared = moved_by[link(early)];
        let mut radii = chain.body_radii(link(late), reach(late));
        radii.iter_mut().take(shared).for_each(|r| *r = 0.0);
        out.push(Gap {
            what: GapOf::Pair(i, j),
            radii,
        });
    }
    out
}

/// Checks a leg's pieces (its straight segments whole — the blends cut their ends, which
/// stay checked — then the blends' curves) with [`Prover::piece`]. Reports the leg's first bad
/// configuration and returns the configurations measured.
fn check_leg(
    cell: &Cell,
    robot: &Robot,
    rp: &RobotPlan,
    leg: &LegOut,
    (settings, gaps): (&VerifySettings, &[Gap]),
    scratch: &mut Scratch,
    out: &mut Vec<Violation>,
) -> usize {
    let curves: Vec<Piece> = pieces(leg)
        .into_iter()
        .filter(|p| matches!(p, Piece::Curve(..)))
        .collect();
    let lines = leg
        .waypoints
        .windows(2)
        .map(|w| Piece::Line(w[0].clone(), w[1].clone()));
    let mut prover = Prover::new(cell, robot, gaps, settings.joint_step);
    for piece in lines.chain(curves) {
        if let Err((kind, detail)) = prover.piece(&piece, scratch) {
            out.push(Violation::robot(
                kind,
                &rp.name,
                Some(leg.start_s),
                None,
                format!("on leg {}: {detail}", name(leg)),
            ));
            break;
        }
    }
    prover.measured
}

/// The proof that pieces of a robot's joint path keep the clearance from the scene and from
/// the robot itself, by conservative advancement: at a configuration every gap of the robot
/// ([`gaps`]) is measured, and the next configuration is the farthest along the piece at which
/// no gap's travel bound (`Σ_j R_j·|Δq_j|`, exact along a line and a curve) has reached what
/// that gap had to spare — beyond the clearance from the scene, beyond contact between the self
/// pairs — plus [`crate::robots::PROOF_TOLERANCE`]. Every configuration measured keeps the
/// clearance, and none between comes closer than the clearance less the tolerance. Joint
/// limits: a piece lies in the box of its ends (a curve within the triangle of its control
/// points), so the ends decide where the control points are measured too.
pub(crate) struct Prover<'a> {
    cell: &'a Cell,
    robot: &'a Robot,
    gaps: &'a [Gap],
    /// The scale of a piece's budget (see [`VerifySettings::joint_step`]).
    joint_step: f64,
    /// Configurations measured so far.
    measured: usize,
    /// Per gap: what it may travel before the next measurement.
    room: Vec<f64>,
    /// Per joint: its travel over the step being tried.
    moved: Vec<f64>,
}

impl<'a> Prover<'a> {
    pub(crate) fn new(cell: &'a Cell, robot: &'a Robot, gaps: &'a [Gap], joint_step: f64) -> Self {
        Prover {
            cell,
            robot,
            gaps,
            joint_step,
            measured: 0,
            room: vec![0.0; gaps.len()],
            moved: Vec::new(),
        }
    }

    /// The straight segment `a → b` (see [`Prover::piece`]).
    pub(crate) fn segment(
        &mut self,
        a: &[f64],
        b: &[f64],
        scratch: &mut Scratch,
    ) -> Result<(), (ViolationKind, String)> {
        self.piece(&Piece::Line(a.to_vec(), b.to_vec()), scratch)
    }

    /// Proves `piece` clear, or gives its first bad configuration's problem (or why the proof
    /// stopped: a piece that stays within the tolerance of its limits past a budget of
    /// measurements, two per joint step of its largest joint travel and 2,000 more).
    fn piece(&mut self, piece: &Piece, scratch: &mut Scratch) -> Result<(), (ViolationKind, String)> {
        let (cell, robot, gaps) = (self.cell, self.robot, self.gaps);
        let clearance = cell.planning.clearance;
        let tol = crate::robots::PROOF_TOLERANCE;
        let world = &cell.world;
        // Each joint's travel from parameter `f0` to `f1`, into `moved`.
        let travels = |f0: f64, f1: f64, moved: &mut Vec<f64>| {
            moved.clear();
            moved.extend((0..piece.dof()).map(|j| piece.travel(j, f0, f1)));
        };
        let bound = |g: &Gap, moved: &[f64]| -> f64 { g.radii.iter().zip(moved).map(|(r, m)| r * m).sum() };
        let steps = (piece.max_joint_travel() / self.joint_step).ceil() as usize;
        let budget = steps
            .saturating_mul(PIECE_BUDGET_PER_STEP)
            .saturating_add(MIN_PIECE_BUDGET);
        let mut f = 0.0;
        let mut measured = 0;
        loop {
            if measured == budget {
                return Err((
                    ViolationKind::StaticClearance,
                    format!(
                        "clearance not proven past {:.0} % of a segment: it stays within {:.1} mm of \
                         the scene or of touching itself, and the check stopped after {measured} \
                         configurations",
                        100.0 * f,
                        tol * 1e3
                    ),
                ));
            }
            measured += 1;
            self.measured += 1;
            let q = piece.at(f);
            travels(f, 1.0, &mut self.moved);
            let mut valid = robot.within_limits(&q);
            if valid {
                robot.body_poses(&q, scratch);
                for (g, spare) in gaps.iter().zip(self.room.iter_mut()) {
                    let rest = bound(g, &self.moved).min(MAX_ROOM);
                    let (d, need) = match g.what {
                        GapOf::Scene(i) => (
                            world.body_static_distance(
                                robot.group,
                                i,
                                &scratch.bodies,
                                clearance + tol + rest,
                            ),
                            clearance,
                        ),
                        GapOf::Pair(i, j) => (
                            world.pair_distance(robot.group, i, j, &scratch.bodies, tol + rest),
                            0.0,
                        ),
                    };
                    // A self pair touching (0) is a contact; the scene within the clearance too.
                    if d < need || (need == 0.0 && d <= 0.0) {
                        valid = false;
                        break;
                    }
                    *spare = d - need + tol;
                }
            }
            if !valid {
                // The configuration's first problem, named.
                return Err(config_violation(cell, robot, &q, clearance, scratch)
                    .unwrap_or((ViolationKind::StaticClearance, "closer than the clearance".into())));
            }
            if f >= 1.0 {
                return Ok(());
            }
            // The farthest parameter at which every gap's travel stays within its room.
            let (room, moved) = (&self.room, &mut self.moved);
            let next = super::farthest(f, 1.0, |to| {
                travels(f, to, moved);
                gaps.iter().zip(room).all(|(g, r)| bound(g, moved) <= *r)
            });
            f = next.max(f + 1e-12).min(1.0);
        }
    }
}

/// The first problem of one configuration: joint limits, the scene, the robot itself.
fn config_violation(
    cell: &Cell,
    robot: &Robot,
    q: &[f64],
    clearance: f64,
    scratch: &mut Scratch,
) -> Option<(ViolationKind, String)> {
    if !robot.within_limits(q) {
        return Some((ViolationKind::JointLimit, "outside the joint limits".into()));
    }
    robot.body_poses(q, scratch);
    match robot.contact_at(&cell.world, scratch, clearance) {
        None => None,
        Some(BodyContact::Static { body, object }) => Some((
            ViolationKind::StaticClearance,
            format!(
                "{} within {:.0} mm of {}",
                cell.world.body_name(robot.group, body),
                clearance * 1e3,
                cell.world.static_name(object)
            ),
        )),
        Some(BodyContact::SelfPair(i, j) | BodyContact::Pair(i, j)) => Some((
            ViolationKind::SelfCollision,
            format!(
                "{} touches {}",
                cell.world.body_name(robot.group, i),
                cell.world.body_name(robot.group, j)
            ),
        )),
    }
}

/// One piece of a leg's executed joint path: a straight segment, or the blend of a corner
/// (the quadratic Bézier curve with control points `a`, `p`, `c`).
#[derive(Clone, Debug)]
enum Piece {
    Line(Vec<f64>, Vec<f64>),
    Curve(Vec<f64>, Vec<f64>, Vec<f64>),
}

impl Piece {
    /// The point at parameter `f` in [0, 1].
    fn at(&self, f: f64) -> Vec<f64> {
        match self {
            Piece::Line(a, b) => a.iter().zip(b).map(|(x, y)| x + f * (y - x)).collect(),
            Piece::Curve(a, p, c) => (0..a.len())
                .map(|j| (1.0 - f) * (1.0 - f) * a[j] + 2.0 * f * (1.0 - f) * p[j] + f * f * c[j])
                .collect(),
        }
    }

    /// The largest total travel of one joint over the piece.
    fn max_joint_travel(&self) -> f64 {
        (0..self.dof())
            .map(|j| self.travel(j, 0.0, 1.0))
            .fold(0.0, f64::max)
    }

    fn dof(&self) -> usize {
        match self {
            Piece::Line(a, _) | Piece::Curve(a, _, _) => a.len(),
        }
    }

    /// How far joint `j` travels from parameter `f0` to `f1` (`f0 ≤ f1`): the integral of
    /// `|q_j'|`, exact (on a curve `q_j'` is linear in the parameter).
    fn travel(&self, j: usize, f0: f64, f1: f64) -> f64 {
        match self {
            Piece::Line(a, b) => (f1 - f0) * (b[j] - a[j]).abs(),
            Piece::Curve(a, p, c) => {
                // q_j'(f) = α + β·f
                let (alpha, beta) = (2.0 * (p[j] - a[j]), 2.0 * (a[j] - 2.0 * p[j] + c[j]));
                let prim = |f: f64| alpha * f + 0.5 * beta * f * f;
                let root = if beta != 0.0 { -alpha / beta } else { f64::NAN };
                if root > f0 && root < f1 {
                    (prim(root) - prim(f0)).abs() + (prim(f1) - prim(root)).abs()
                } else {
                    (prim(f1) - prim(f0)).abs()
                }
            }
        }
    }

    /// The parameter of the piece's point nearest `q` and its max-abs distance from `q`.
    fn place(&self, q: &[f64]) -> (f64, f64) {
        let off = |f: f64| {
            self.at(f)
                .iter()
                .zip(q)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let f = match self {
            Piece::Line(a, b) => {
                let (mut num, mut den) = (0.0, 0.0);
                for j in 0..a.len() {
                    num += (q[j] - a[j]) * (b[j] - a[j]);
                    den += (b[j] - a[j]).powi(2);
                }
                if den > 0.0 {
                    (num / den).clamp(0.0, 1.0)
                } else {
                    0.0
                }
            }
            Piece::Curve(..) => {
                // The squared distance along the curve: the best of a grid, then golden
                // section around it.
                let sq = |f: f64| {
                    self.at(f)
                        .iter()
                        .zip(q)
                        .map(|(x, y)| (x - y).powi(2))
                        .sum::<f64>()
                };
                const GRID: usize = 32;
                let best = (0..=GRID)
                    .map(|k| k as f64 / GRID as f64)
                    .min_by(|x, y| sq(*x).total_cmp(&sq(*y)))
                    .unwrap_or(0.0);
                let (mut lo, mut hi) = (
                    (best - 1.0 / GRID as f64).max(0.0),
                    (best + 1.0 / GRID as f64).min(1.0),
                );
                let g = 0.5 * (5f64.sqrt() - 1.0);
                for _ in 0..80 {
                    let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
                    if sq(x1) <= sq(x2) {
                        hi = x2;
                    } else {
                        lo = x1;
                    }
                }
                0.5 * (lo + hi)
            }
        };
        (f, off(f))
    }
}

/// A leg's executed joint path, piece by piece: its straight segments, cut short by the
/// blends at their ends, and each blend's curve at its corner.
fn pieces(leg: &LegOut) -> Vec<Piece> {
    let w = &leg.waypoints;
    let radius = |k: usize| {
        leg.blends
            .iter()
            .find(|b| b.waypoint == k)
            .map_or(0.0, |b| b.radius)
    };
    let mut out = Vec::new();
    for k in 0..w.len().saturating_sub(1) {
        let (a, b) = (&w[k], &w[k + 1]);
        let len = dist(a, b);
        let u: Vec<f64> = if len > 0.0 {
            a.iter().zip(b).map(|(x, y)| (y - x) / len).collect()
        } else {
            vec![0.0; a.len()]
        };
        let (r0, r1) = (radius(k).min(0.5 * len), radius(k + 1).min(0.5 * len));
        let start: Vec<f64> = a.iter().zip(&u).map(|(x, d)| x + r0 * d).collect();
        let end: Vec<f64> = b.iter().zip(&u).map(|(x, d)| x - r1 * d).collect();
        out.push(Piece::Line(start, end.clone()));
        if r1 > 0.0 && k + 2 < w.len() {
            let next = &w[k + 2];
            let ln = dist(b, next);
            let rn = r1.min(0.5 * ln);
            let join: Vec<f64> = b
                .iter()
                .zip(next)
                .map(|(x, y)| x + rn * (y - x) / ln.max(f64::MIN_POSITIVE))
                .collect();
            out.push(Piece::Curve(end, b.clone(), join));
        }
    }
    out
}

/// Walks the trajectory forward along the legs' joint paths (home → MPs → home, straight
/// joint segments between waypoints, blended corners along their curves): each sample must
/// lie on the path (within 1e-6 in every joint) at or after the previous sample's place, and
/// the path covered between two samples must not exceed, joint by joint, what the velocity
/// limit allows in their time. The first failure: its time and a sentence.
fn follow_legs(robot: &Robot, rp: &RobotPlan, vtol: f64) -> Option<(f64, String)> {
    const TOL: f64 = 1e-6;
    // (piece, leg) in order.
    let segments: Vec<(Piece, usize)> = rp
        .legs
        .iter()
        .enumerate()
        .flat_map(|(k, leg)| pieces(leg).into_iter().map(move |p| (p, k)))
        .collect();
    let leg_name = |s: usize| name(&rp.legs[segments[s].1]);
    // Every waypoint and sample has the robot's joint count: the document was validated and
    // the robot's joints matched.
    let dof = robot.dof();
    if segments.is_empty() {
        return None;
    }
    let place = |s: usize, q: &[f64]| segments[s].0.place(q);
    let (mut seg, mut frac) = (0usize, 0.0f64);
    let mut prev_t = rp.trajectory.first()?.t;
    for sample in &rp.trajectory {
        // The first piece at or after the current place that holds the sample.
        let found = (seg..segments.len()).find_map(|s| {
            let (f, off) = place(s, &sample.q);
            (off <= TOL && (s > seg || f >= frac - 1e-9)).then_some((s, f))
        });
        let Some((s, f)) = found else {
            let behind = (0..seg).any(|s| place(s, &sample.q).1 <= TOL);
            return Some((
                sample.t,
                if behind {
                    format!("the trajectory goes back along its path on leg {}", leg_name(seg))
                } else {
                    format!(
                        "the trajectory leaves the joint path of leg {} (the motion checked against the scene)",
                        leg_name(seg)
                    )
                },
            ));
        };
        // Path covered per joint from (seg, frac) to (s, f).
        let h = sample.t - prev_t;
        for j in 0..dof {
            let piece = |k: usize| &segments[k].0;
            let covered = if s == seg {
                piece(s).travel(j, frac.min(f), f)
            } else {
                piece(seg).travel(j, frac, 1.0)
                    + (seg + 1..s).map(|k| piece(k).travel(j, 0.0, 1.0)).sum::<f64>()
                    + piece(s).travel(j, 0.0, f)
            };
            if covered > robot.max_velocity[j] * h * (1.0 + vtol) + TOL {
                return Some((
                    prev_t,
                    format!(
                        "joint {} covers {:.4} along the path in {:.3} s, more than its velocity limit allows ({:.4})",
                        j + 1,
                        covered,
                        h,
                        robot.max_velocity[j] * h
                    ),
                ));
            }
        }
        (seg, frac, prev_t) = (s, f, sample.t);
    }
    None
}

/// Euclidean distance of two configurations (infinite when their lengths differ).
pub(super) fn dist(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

/// Largest joint difference.
pub(super) fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}
