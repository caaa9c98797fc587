//! The coordination diagram of two robots (O'Donnell & Lozano-Pérez): the pairs of positions
//! along their two paths at which they would come closer than the clearance, whatever the
//! clock, covered by axis-aligned boxes.
//!
//! A robot's *position* is the time of its program without waits: waits change when it is
//! where, never where it goes. Between two waypoints a program moves along the straight joint
//! segment (rest to rest), so over an interval of positions inside one segment every
//! configuration lies on the segment between the configurations at the interval's ends, and no
//! point of the robot moves farther from where it is at the interval's middle than
//! `max over both ends of Σ_j r_j·|q_j(end) − q_j(middle)|` (the per-joint radii). A rectangle
//! of positions is therefore free when the distance of the two robots at its centre exceeds the
//! clearance plus both reaches: no contact is missed between samples (the distance is bounded
//! below by the robots' sphere covers, and measured exactly on the smallest rectangles only).
//! Rectangles that cannot be proven free are halved (along the robot that moves more) down to
//! [`MIN_CELL`]; those left are in conflict. A body pair proven apart over a rectangle is apart
//! over every rectangle inside it, so the halves ask only the body pairs their rectangle could
//! not prove apart, and a pair of pieces only those whose swept spheres may meet. Each pair of
//! pieces (one of each path) keeps the bounding box of its
//! conflicts: a box per pair of pieces follows the shape of a long conflict as a staircase,
//! where one bounding box of the whole would serialise the robots. A pair of pieces is worked
//! out in the pieces' own positions, from each piece's own motion, so its answer depends on
//! what the two pieces are and not on where they lie on their paths ([`DiagramCache::with_pieces`]
//! keeps it by that).
use super::Ctx;
use super::program::{Activity, Program, Timed};
use crate::plan::PlanError;
use cellplan_geom::DVec3;
use cellplan_model::robot::Scratch;
use cellplan_motion::timing::Trajectory;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::rc::Rc;

mod cache;
mod spheres;
pub use cache::DiagramCache;
use cache::PieceKey;
pub(crate) use cache::diagrams_reusing;
use spheres::{Covers, Placed, SpherePair, body_spheres, close_pairs};

/// A hasher for the diagram's keys by position (a robot flag and the bits of an `f64`): one
/// multiply and rotate per word, as rustc's Fx hash; the keys are few and not adversarial.
#[derive(Default)]
struct PositionHasher(u64);

impl Hasher for PositionHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// Maps keyed by a robot flag and a position's bits.
type ByPosition<V> = HashMap<(bool, u64), V, BuildHasherDefault<PositionHasher>>;

/// Smallest rectangle side (s of position) that is still halved.
pub(crate) const MIN_CELL: f64 = 0.02;
/// Distances are measured up to this (m) beyond what a rectangle needs (a larger cap only
/// costs work: the answer is whether the distance exceeds the need).
const DISTANCE_SLACK: f64 = 1e-3;

/// Where a robot can stand still: a waypoint it reaches at rest (every waypoint, since legs are
/// timed rest to rest, except the last of each leg: that is the MP, whose measurement follows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rest {
    /// Position (s).
    pub at: f64,
    /// The program's leg and waypoint (as [`super::Wait`] names them).
    pub leg: usize,
    /// Waypoint of the leg.
    pub waypoint: usize,
}

/// One piece of a robot's path: moving along a straight joint segment, or standing.
#[derive(Clone, Debug)]
struct Piece {
    from: f64,
    to: f64,
    moving: bool,
    /// Its motion from its own start: the diagram of two pieces is worked out in the pieces'
    /// own positions, `[0, len]`, so that it depends on what the pieces are, never on where
    /// they lie on their paths (see [`PieceCache`]).
    motion: Motion,
    /// Its length in its own positions.
    len: f64,
    /// Its entry in the context's [`PieceCache`] (`None`: not kept there).
    id: Option<u32>,
}

/// A piece's motion from its own start.
#[derive(Clone, Debug)]
enum Motion {
    /// Along one segment from rest to rest (the segment timed on its own).
    Segment(Trajectory),
    /// Standing at a configuration.
    Stand(Vec<f64>),
    /// A segment of a blended leg: the leg's trajectory from this time on.
    Blended(std::sync::Arc<Trajectory>, f64),
}

impl Piece {
    /// The configuration at position `s` of the piece's own (clamped to `[0, len]`).
    fn at(&self, s: f64) -> Vec<f64> {
        let s = s.clamp(0.0, self.len);
        match &self.motion {
            Motion::Segment(t) => t.position(s),
            Motion::Stand(q) => q.clone(),
            Motion::Blended(t, start) => t.position(start + s),
        }
    }

    /// A position of the piece's own on its path: its ends exactly at the piece's ends.
    fn on_path(&self, s: f64) -> f64 {
        if s <= 0.0 {
            self.from
        } else if s >= self.len {
            self.to
        } else {
            (self.from + s).min(self.to)
        }
    }
}

/// A robot's path as positions: its program without waits on the clock.
#[derive(Clone)]
pub(crate) struct RobotPath {
    /// The robot (cell index).
    pub robot: usize,
    /// Length (s): the program's duration without waits.
    pub len: f64,
    /// Where it may wait, by position (the first is home at 0).
    pub rests: Vec<Rest>,
    /// Positions of each measurement (arrive, depart).
    pub visits: Vec<(f64, f64)>,
    pieces: Vec<Piece>,
    /// The program on the clock, without its waits.
    pub timed: Timed,
    /// The path exactly (robot, every waypoint, segment time, measuring pose and dwell, as
    /// bits): equal signatures, equal paths, equal diagrams (see [`DiagramCache`]).
    signature: Vec<u64>,
}

impl RobotPath {
    /// The path of `program` (its waits are ignored).
    pub fn new(ctx: &Ctx, program: &Program) -> Result<RobotPath, PlanError> {
        let bare = program.without_waits();
        let timed = ctx.timed(&bare)?;
        let mut rests = Vec::new();
        for (k, at) in timed.arrivals.iter().enumerate() {
            for (w, &a) in at.iter().enumerate() {
                if w + 1 < bare.legs[k].waypoints.len() {
                    rests.push(Rest {
                        at: a,
                        leg: k,
                        waypoint: w,
                    });
                }
            }
        }
        if rests.first().is_none_or(|r| r.at > 0.0) {
            // A program without legs stands at home.
            rests.insert(
                0,
                Rest {
                    at: 0.0,
                    leg: 0,
                    waypoint: 0,
                },
            );
        }
        let limits = &ctx.limits[program.robot];
        let kept = ctx.diagrams.and_then(|d| d.pieces.as_ref());
        // A piece's key (only where pieces are kept): its robot and bits.
        let key = |tag: u64, head: &[u64], values: &[&[f64]]| {
            kept.map(|_| {
                let mut key = vec![tag, program.robot as u64];
                key.extend_from_slice(head);
                key.extend(values.iter().flat_map(|v| v.iter()).map(|x| x.to_bits()));
                key
            })
        };
        // Each blended leg's trajectory, shared by its segments.
        let mut blended: Vec<Option<std::sync::Arc<Trajectory>>> = vec![None; bare.legs.len()];
        let mut keys = Vec::with_capacity(timed.spans.len());
        let mut pieces = Vec::with_capacity(timed.spans.len());
        for s in &timed.spans {
            let (motion, len, key) = match s.what {
                Activity::Move { leg: k, segment } => {
                    let leg = &bare.legs[k];
                    match &leg.blend {
                        Some(b) => {
                            let times = &b.waypoint_times;
                            let t =
                                blended[k].get_or_insert_with(|| std::sync::Arc::new(b.trajectory.clone()));
                            let len = times[segment + 1] - times[segment];
                            (
                                Motion::Blended(std::sync::Arc::clone(t), times[segment]),
                                len,
                                None,
                            )
                        }
                        None => {
                            let (a, b) = (&leg.waypoints[segment], &leg.waypoints[segment + 1]);
                            let t = super::program::segment_trajectory(a, b, limits)?;
                            let len = t.duration();
                            (Motion::Segment(t), len, key(0, &[], &[a, b]))
                        }
                    }
                }
                Activity::Measure { visit } => {
                    let v = &bare.visits[visit];
                    let key = key(1, &[v.dwell.to_bits()], &[&v.q]);
                    (Motion::Stand(v.q.clone()), v.dwell, key)
                }
                // Without waits, only a program without legs has one: at home, for no time.
                Activity::Wait { .. } => (Motion::Stand(bare.home.clone()), s.end - s.start, None),
            };
            keys.push(key);
            pieces.push(Piece {
                from: s.start,
                to: s.end,
                moving: matches!(s.what, Activity::Move { .. }),
                motion,
                len,
                id: None,
            });
        }
        if let Some(cache) = kept {
            for (piece, id) in pieces.iter_mut().zip(cache.ids(keys)) {
                piece.id = id;
            }
        }
        let mut signature = vec![program.robot as u64];
        signature.extend(bare.home.iter().map(|x| x.to_bits()));
        for leg in &bare.legs {
            signature.push(leg.waypoints.len() as u64);
            signature.extend(
                leg.waypoints
                    .iter()
                    .flatten()
                    .chain(&leg.segments)
                    .map(|x| x.to_bits()),
            );
        }
        for v in &bare.visits {
            signature.extend(v.q.iter().chain([&v.dwell]).map(|x| x.to_bits()));
        }
        Ok(RobotPath {
            robot: program.robot,
            len: timed.end(),
            rests,
            visits: timed.visits.clone(),
            pieces,
            timed,
            signature,
        })
    }

    /// The path as the scheduler sees it.
    pub fn track(&self) -> super::schedule::Track {
        super::schedule::Track {
            robot: self.robot,
            len: self.len,
            rests: self.rests.iter().map(|r| r.at).collect(),
        }
    }
}

/// Positions `[a.0, a.1]` of robot `robots.0` and `[b.0, b.1]` of robot `robots.1` at which
/// the two may come closer than the clearance.
#[derive(Clone, Debug, PartialEq)]
pub struct ConflictBox {
    /// The robots (cell indices, first < second).
    pub robots: (usize, usize),
    /// Positions of the first robot.
    pub a: (f64, f64),
    /// Positions of the second robot.
    pub b: (f64, f64),
    /// Whether a robot standing still at an end of its interval — `[a start, a end, b start,
    /// b end]` — is certified clear of the other robot anywhere in the other's interval (so a
    /// robot may wait at a rest there). Only ends at rests are certified; the others are false.
    pub open: [bool; 4],
}

/// Per robot, per visit: how much of the other robots' paths (s of position, summed over the
/// boxes) conflicts with the robot standing at that measurement — the room its pose there
/// takes from the others.
pub(crate) fn blocking(paths: &[RobotPath], boxes: &[ConflictBox]) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = paths.iter().map(|p| vec![0.0; p.visits.len()]).collect();
    let index = |r: usize| paths.iter().position(|p| p.robot == r);
    for b in boxes {
        for (me, mine, theirs) in [(b.robots.0, b.a, b.b), (b.robots.1, b.b, b.a)] {
            let Some(i) = index(me) else { continue };
            for (v, &(from, to)) in paths[i].visits.iter().enumerate() {
                if mine.0 < to && from < mine.1 {
                    out[i][v] += theirs.1 - theirs.0;
                }
            }
        }
    }
    out
}

/// What building the diagrams cost.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct DiagramWork {
    /// Rectangles looked at.
    pub cells: usize,
    /// Exact distance queries.
    pub distances: usize,
}

/// An interval of one piece's positions, and whether the piece moves.
type Span = (f64, f64, bool);

/// The two halves of rectangle `a × b`, halved along `a` (or along `b`), the lower first.
fn halves(a: Span, b: Span, along_a: bool) -> [(Span, Span); 2] {
    if along_a {
        let m = 0.5 * (a.0 + a.1);
        [((a.0, m, a.2), b), ((m, a.1, a.2), b)]
    } else {
        let m = 0.5 * (b.0 + b.1);
        [(a, (b.0, m, b.2)), (a, (m, b.1, b.2))]
    }
}

/// What a rectangle of two pieces' positions is (see [`PairDiagram::judge`]).
enum Rect {
    Free,
    Conflict,
    HalveA,
    HalveB,
}

struct PairDiagram<'a> {
    ctx: &'a Ctx<'a>,
    pa: &'a RobotPath,
    pb: &'a RobotPath,
    sa: Vec<Option<(DVec3, f64)>>,
    sb: Vec<Option<(DVec3, f64)>>,
    /// Per body of each robot, its sphere cover (body frame).
    ca: Covers,
    cb: Covers,
    scratch: Scratch,
    /// The work of the current pair of pieces.
    work: DiagramWork,
    /// The pieces worked on (one of each path); rectangles are in their own positions.
    x: &'a Piece,
    y: &'a Piece,
    /// The bounding box of the conflicts found so far in the current pair of pieces.
    found: Option<LocalBox>,
    /// Placements in the current pair of pieces, by robot (first or not) and position.
    placed: ByPosition<Rc<Placed>>,
    /// The body pairs still to be proven apart, one list per rectangle on the way down (see
    /// [`Self::cell`]); at the bottom, those of the current pair of pieces' swept spheres.
    pairs: Vec<SpherePair>,
    /// Room for the second cover's spheres near the first body (see [`close_pairs`]).
    near: Vec<(DVec3, f64)>,
    /// Configurations at positions in the current pair of pieces, as `placed` keys them.
    positions: ByPosition<Vec<f64>>,
    /// Placements no longer in `placed`, their buffers reused by the next ones (all but the
    /// configuration's, which the trajectory hands over new).
    pool: Vec<Placed>,
}

/// The conflicts of one pair of pieces in the pieces' own positions: `a` of the first piece,
/// `b` of the second, and which ends are open (as [`ConflictBox::open`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct LocalBox {
    a: (f64, f64),
    b: (f64, f64),
    open: [bool; 4],
}

impl<'a> PairDiagram<'a> {
    /// The piece worked on of the first robot or of the second.
    fn piece(&self, first: bool) -> &'a Piece {
        if first { self.x } else { self.y }
    }

    /// Robot `first` (or the second) placed at position `s` of its piece, remembered for the
    /// current pair of pieces (halving along one robot keeps the other where it was).
    fn place(&mut self, first: bool, s: f64) -> Rc<Placed> {
        let key = (first, s.to_bits());
        if let Some(p) = self.placed.get(&key) {
            return Rc::clone(p);
        }
        let p = Rc::new(self.place_new(first, s));
        self.placed.insert(key, Rc::clone(&p));
        p
    }

    fn place_new(&mut self, first: bool, s: f64) -> Placed {
        let path = if first { self.pa } else { self.pb };
        let robot = &self.ctx.cell.robots[path.robot];
        let mut out = self.pool.pop().unwrap_or_default();
        out.q = self.piece(first).at(s);
        robot.body_poses(&out.q, &mut self.scratch);
        let bodies_at = &self.scratch.bodies;
        let local = if first { &self.sa } else { &self.sb };
        out.spheres.clear();
        out.bodies.clear();
        for (i, (s, p)) in local.iter().zip(bodies_at).enumerate() {
            if let Some((c, r)) = s {
                out.spheres.push((p.transform_point(*c), *r));
                out.bodies.push(i);
            }
        }
        let own = if first { &self.ca } else { &self.cb };
        out.covers.clear();
        for (range, p) in own.ranges.iter().zip(bodies_at) {
            out.covers.extend(
                own.spheres[range.clone()]
                    .iter()
                    .map(|&(c, r)| (p.transform_point(c), r)),
            );
        }
        out.poses.clear();
        out.poses.extend_from_slice(bodies_at);
        out
    }

    /// Forgets the placements and positions of the current pair of pieces (their buffers are
    /// kept for the next).
    fn forget(&mut self) {
        self.pool
            .extend(self.placed.drain().filter_map(|(_, p)| Rc::try_unwrap(p).ok()));
        self.positions.clear();
    }

    /// The swept spheres of piece `piece` of the first path (or of the second) (see
    /// [`Swept`]).
    fn swept(&mut self, first: bool, piece: &'a Piece) -> Swept {
        if first {
            self.x = piece;
        } else {
            self.y = piece;
        }
        let placed = self.place(first, 0.5 * piece.len);
        let reach = self.reach(first, &placed.q, 0.0, piece.len, piece.moving);
        self.forget();
        let bodies: Vec<(DVec3, f64)> = placed.spheres.iter().map(|&(c, r)| (c, r + reach)).collect();
        let centre = if bodies.is_empty() {
            DVec3::ZERO
        } else {
            bodies.iter().map(|b| b.0).sum::<DVec3>() / bodies.len() as f64
        };
        let radius = bodies
            .iter()
            .map(|b| (b.0 - centre).length() + b.1)
            .fold(0.0, f64::max);
        Swept {
            bodies,
            all: (centre, radius),
        }
    }

    /// Whether the two placed robots are farther apart than `need`, exactly (up to the convex
    /// hulls), asking only the body pairs `self.pairs[close]` (the others are farther by their
    /// covers).
    fn apart(&mut self, xa: &Placed, xb: &Placed, close: std::ops::Range<usize>, need: f64) -> bool {
        self.work.distances += 1;
        let robots = &self.ctx.cell.robots;
        let (ga, gb) = (robots[self.pa.robot].group, robots[self.pb.robot].group);
        let world = &self.ctx.cell.world;
        self.pairs[close].iter().all(|&(i, j)| {
            let (i, j) = (xa.bodies[i as usize], xb.bodies[j as usize]);
            world.body_body_distance(ga, i, &xa.poses, gb, j, &xb.poses[j], need + DISTANCE_SLACK) > need
        })
    }

    /// How far any point of the robot can be from where it is at `mid` while at positions in
    /// `[from, to]` of its piece.
    fn reach(&mut self, first: bool, mid: &[f64], from: f64, to: f64, moving: bool) -> f64 {
        if !moving || to <= from {
            return 0.0;
        }
        let path = if first { self.pa } else { self.pb };
        let piece = self.piece(first);
        let radii = &self.ctx.radii[path.robot];
        [from, to]
            .iter()
            .map(|&s| {
                // Rectangles share their ends: each position is evaluated once per pair of pieces.
                let q = self
                    .positions
                    .entry((first, s.to_bits()))
                    .or_insert_with(|| piece.at(s));
                q.iter()
                    .zip(mid)
                    .zip(radii)
                    .map(|((a, b), r)| r * (a - b).abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// What rectangle `[a0, a1] × [b0, b1]` (of the two pieces' positions) is: free (the
    /// sphere covers, or the exact distance, exceed the clearance plus both robots' reach over
    /// it), to be halved (along the robot that moves more), or — once nothing is left to halve
    /// — in conflict. Only the body pairs `self.pairs[among]` are asked (every other is apart
    /// over a rectangle holding this one); those not proven apart here are pushed onto
    /// `self.pairs` for the halves to ask (the caller truncates it): a rectangle to be halved
    /// asks up to the first close pair ([`close_pairs`] with `first`), a smallest one all.
    fn judge(&mut self, a: Span, b: Span, among: std::ops::Range<usize>) -> Rect {
        self.work.cells += 1;
        let xa = self.place(true, 0.5 * (a.0 + a.1));
        let xb = self.place(false, 0.5 * (b.0 + b.1));
        let ra = self.reach(true, &xa.q, a.0, a.1, a.2);
        let rb = self.reach(false, &xb.q, b.0, b.1, b.2);
        let need = self.ctx.margin + ra + rb;
        let split_a = a.2 && a.1 - a.0 > MIN_CELL;
        let split_b = b.2 && b.1 - b.0 > MIN_CELL;
        // The sphere covers hold the meshes: their distance is a lower bound. The exact
        // distance only where nothing is left to halve (halving is cheaper than GJK, and
        // the covers decide most rectangles once small), and only for the body pairs whose
        // covers come close.
        let mark = self.pairs.len();
        close_pairs(
            (&self.ca.ranges, &self.cb.ranges),
            (&xa, &xb),
            need,
            (&mut self.pairs, among),
            split_a || split_b,
            &mut self.near,
        );
        let close = mark..self.pairs.len();
        if close.is_empty() {
            return Rect::Free;
        }
        if !(split_a || split_b) {
            return if self.apart(&xa, &xb, close, need) {
                Rect::Free
            } else {
                Rect::Conflict
            };
        }
        if split_a && (!split_b || ra >= rb) {
            Rect::HalveA
        } else {
            Rect::HalveB
        }
    }

    /// Rectangle `[a0, a1] × [b0, b1]` of the two pieces' positions: free, or halved, or
    /// recorded as in conflict, asking the body pairs `self.pairs[among]` only. A body pair
    /// the covers prove apart over a rectangle is apart over every rectangle inside it, so
    /// the halves ask only the pairs their rectangle could not prove apart.
    fn cell(&mut self, a: Span, b: Span, among: std::ops::Range<usize>) {
        // Inside what is already in conflict: nothing to learn.
        if self
            .found
            .as_ref()
            .is_some_and(|f| f.a.0 <= a.0 && a.1 <= f.a.1 && f.b.0 <= b.0 && b.1 <= f.b.1)
        {
            return;
        }
        let mark = self.pairs.len();
        match self.judge(a, b, among) {
            Rect::Free => {}
            Rect::Conflict => {
                let f = self.found.get_or_insert(LocalBox {
                    a: (a.0, a.1),
                    b: (b.0, b.1),
                    open: [false; 4],
                });
                f.a = (f.a.0.min(a.0), f.a.1.max(a.1));
                f.b = (f.b.0.min(b.0), f.b.1.max(b.1));
            }
            halve @ (Rect::HalveA | Rect::HalveB) => {
                let close = mark..self.pairs.len();
                for (a, b) in halves(a, b, matches!(halve, Rect::HalveA)) {
                    self.cell(a, b, close.clone());
                }
            }
        }
        self.pairs.truncate(mark);
    }

    /// Whether rectangle `[a0, a1] × [b0, b1]` is certified free (as [`Self::cell`] decides,
    /// halving until it is or a smallest rectangle is not), asking the body pairs
    /// `self.pairs[among]` only.
    fn certify(&mut self, a: Span, b: Span, among: std::ops::Range<usize>) -> bool {
        let mark = self.pairs.len();
        let free = match self.judge(a, b, among) {
            Rect::Free => true,
            Rect::Conflict => false,
            halve @ (Rect::HalveA | Rect::HalveB) => {
                let close = mark..self.pairs.len();
                halves(a, b, matches!(halve, Rect::HalveA))
                    .into_iter()
                    .all(|(a, b)| self.certify(a, b, close.clone()))
            }
        };
        self.pairs.truncate(mark);
        free
    }

    /// Marks the ends of `f` (found in the current pieces) at which a robot standing still is
    /// clear of the other's whole interval. Only ends at the ends of moving pieces are looked
    /// at: those are where rests are.
    ///
    /// Home is clear by construction: every leg and every measurement pose was planned with
    /// the other robots parked at home, keeping the cell's clearance (see
    /// [`crate::motion::robot_validity`]); the rectangles, by contrast, are conservative by
    /// the robots' reach over a smallest rectangle and by [`super::REPLAY_SLACK`], and would
    /// otherwise let a robot's home seem to block a path that was planned past it.
    fn open_ends(&mut self, f: &mut LocalBox, ends: PieceEnds, among: std::ops::Range<usize>) {
        let (x, y) = (self.x, self.y);
        let all = || among.clone();
        if x.moving {
            if f.a.0 <= 0.0 {
                f.open[0] = ends.0[0] || self.certify((0.0, 0.0, false), (f.b.0, f.b.1, y.moving), all());
            }
            if f.a.1 >= x.len {
                f.open[1] = ends.0[1] || self.certify((x.len, x.len, false), (f.b.0, f.b.1, y.moving), all());
            }
        }
        if y.moving {
            if f.b.0 <= 0.0 {
                f.open[2] = ends.1[0] || self.certify((f.a.0, f.a.1, x.moving), (0.0, 0.0, false), all());
            }
            if f.b.1 >= y.len {
                f.open[3] = ends.1[1] || self.certify((f.a.0, f.a.1, x.moving), (y.len, y.len, false), all());
            }
        }
    }

    /// The conflicts of pieces `x` and `y` in their own positions, and the work they took
    /// (`ends`: whether each piece starts and ends its path, where the robot is at home),
    /// asking only the body pairs whose swept spheres may meet (`self.pairs`, all of it).
    fn pieces(&mut self, x: &'a Piece, y: &'a Piece, ends: PieceEnds) -> (Option<LocalBox>, DiagramWork) {
        self.work = DiagramWork::default();
        (self.x, self.y) = (x, y);
        let swept = 0..self.pairs.len();
        self.cell((0.0, x.len, x.moving), (0.0, y.len, y.moving), swept.clone());
        let found = self.found.take().map(|mut f| {
            self.open_ends(&mut f, ends, swept);
            f
        });
        self.forget();
        (found, self.work)
    }
}

/// Whether a piece starts its path and whether it ends it (home, where a robot is clear of
/// the others by construction; see [`PairDiagram::open_ends`]), for the two pieces of a pair.
type PieceEnds = ([bool; 2], [bool; 2]);

/// The conflict boxes of robots `pa` and `pb`, and the work done.
fn pair_boxes(ctx: &Ctx, pa: &RobotPath, pb: &RobotPath) -> (Vec<ConflictBox>, DiagramWork) {
    let cell = ctx.cell;
    let (Some(x0), Some(y0)) = (pa.pieces.first(), pb.pieces.first()) else {
        return (Vec::new(), DiagramWork::default());
    };
    let mut d = PairDiagram {
        ctx,
        pa,
        pb,
        sa: body_spheres(ctx, &cell.robots[pa.robot]),
        sb: body_spheres(ctx, &cell.robots[pb.robot]),
        ca: Covers::of(ctx, &cell.robots[pa.robot]),
        cb: Covers::of(ctx, &cell.robots[pb.robot]),
        scratch: Scratch::default(),
        work: DiagramWork::default(),
        x: x0,
        y: y0,
        found: None,
        placed: ByPosition::default(),
        pairs: Vec::new(),
        near: Vec::new(),
        positions: ByPosition::default(),
        pool: Vec::new(),
    };
    // Each piece's swept body spheres (placed at its middle, grown by its reach) and one
    // sphere around them: most pairs of pieces are far apart, and a sphere test says so
    // without placing the robots again.
    let swept_a: Vec<Swept> = pa.pieces.iter().map(|x| d.swept(true, x)).collect();
    let swept_b: Vec<Swept> = pb.pieces.iter().map(|y| d.swept(false, y)).collect();
    const AT: f64 = 1e-9;
    let ends = |p: &Piece, path: &RobotPath| [p.from <= AT, p.to >= path.len - AT];
    let kept = ctx.diagrams.and_then(|c| c.pieces.as_ref());
    let margin = ctx.margin;
    let mut boxes = Vec::new();
    let mut work = DiagramWork::default();
    for (x, sx) in pa.pieces.iter().zip(&swept_a) {
        for (y, sy) in pb.pieces.iter().zip(&swept_b) {
            // The body pairs whose swept spheres come within the clearance: the others are
            // apart wherever the two pieces are.
            d.pairs.clear();
            sx.meeting(sy, margin, &mut d.pairs);
            if d.pairs.is_empty() {
                continue;
            }
            let pair_ends = (ends(x, pa), ends(y, pb));
            let (found, w) = match kept.zip(x.id.zip(y.id)) {
                Some((k, (i, j))) => k.answer(PieceKey::new(i, j, pair_ends), || d.pieces(x, y, pair_ends)),
                None => d.pieces(x, y, pair_ends),
            };
            work.cells += w.cells;
            work.distances += w.distances;
            if let Some(f) = found {
                boxes.push(ConflictBox {
                    robots: (pa.robot, pb.robot),
                    a: (x.on_path(f.a.0), x.on_path(f.a.1)),
                    b: (y.on_path(f.b.0), y.on_path(f.b.1)),
                    open: f.open,
                });
            }
        }
    }
    (boxes, work)
}

/// Where a robot can be while on one piece of its path: its body spheres at the piece's
/// middle grown by the piece's reach, and one sphere around them all.
struct Swept {
    bodies: Vec<(DVec3, f64)>,
    all: (DVec3, f64),
}

impl Swept {
    /// The body pairs (sphere indices) of the two that could come within `margin` (every pair
    /// left out cannot), pushed onto `out`.
    fn meeting(&self, other: &Swept, margin: f64, out: &mut Vec<SpherePair>) {
        let apart = |a: &(DVec3, f64), b: &(DVec3, f64)| (a.0 - b.0).length() - a.1 - b.1 > margin;
        if apart(&self.all, &other.all) {
            return;
        }
        for (i, a) in self.bodies.iter().enumerate() {
            for (j, b) in other.bodies.iter().enumerate() {
                if !apart(a, b) {
                    out.push((i as u32, j as u32));
                }
            }
        }
    }
}

/// The conflict boxes of every robot pair (pairs in order, in parallel; the result does not
/// depend on the thread count); [`PlanError::TimeLimit`] past the context's deadline.
pub(crate) fn diagrams(ctx: &Ctx, paths: &[RobotPath]) -> Result<(Vec<ConflictBox>, DiagramWork), PlanError> {
    let mut parts = Vec::new();
    diagrams_reusing(ctx, paths, &mut parts)
}
