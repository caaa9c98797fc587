//! Validity as a clearance, and the conservative segment check built on it (see the
//! [module documentation](super) for the proof).
use super::JointSpace;
use std::ops::Range;

/// Steps are shortened by this factor so that a step never reaches the clearance exactly.
const STEP_SAFETY: f64 = 0.999;

/// A segment whose points move at most this far (m, the bound of the joint radii) gets one
/// probe per this much, at most [`MAX_PROBES`].
const PROBE_SPACING: f64 = 0.02;

/// Most probes of one segment before it is covered: the bisection order's first seven (the
/// halves, quarters and eighths) and then the sixteenths nearest the start, 1/16 and 3/16. A
/// segment's contact lies near its start more often than elsewhere (RRT extends the tree's
/// nodes nearest the obstacles most), so those two pay; the other six sixteenths cost every
/// valid segment more than they save the invalid ones. MBM UR5 planning instructions, the
/// same paths: 15 → 9 probes, −7.2 % / −5.3 % on two sets of problems; 7, 8, 10, 11 and 12
/// gave +2.1 / −4.7 / −6.0 / −4.4 / −2.7 % on the first.
pub(crate) const MAX_PROBES: usize = 9;

/// Most probes of a query's direct segment, start to goal ([`super::Straight`], the first try of
/// [`super::Leg`]): long, and in a cluttered scene blocked by thin obstacles that nine probes
/// step over, to be met then by covering up to them. The bisection order goes on to the
/// 32nds. MBM UR5 planning instructions, the same paths: −5.6 % / −2.1 % on two sets of
/// problems against nine (31: −5.4 % / −1.8 %; 127: as 63; 63 for every segment whose points
/// move more than 4 m: −5.5 % / −1.4 %).
pub(crate) const DIRECT_PROBES: usize = 63;

/// A covering sample goes this share of the smaller neighbouring radius past the gap's left
/// end: a sample whose radius comes out a little below its neighbours' then still reaches back
/// to the gap's end, instead of leaving a sliver that costs a sample of its own (the samples'
/// covers overlap by 41 % on the MBM UR5's valid segments; 0.8 against 1: 12.4 → 11.9 samples
/// per valid segment, planning instructions −1.3 % / −0.6 % on two sets of problems, the same
/// paths; 0.5–0.7 and 1.2 make more samples).
const PLACE: f64 = 0.8;

/// One clearance with the joints whose motion can reduce it (see
/// [`StateValidity::clearances`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Clearance {
    /// How far (m) the points involved may move relative to each other; `<= 0`: invalid.
    pub distance: f64,
    /// The joints (indices, clipped to the space) whose motion can reduce it: along a segment
    /// the points involved move relative to each other by at most
    /// `Σ_{j in joints} radii[j]·|Δq_j|`.
    pub joints: Range<usize>,
}

/// Whether a configuration is valid, as a clearance.
pub trait StateValidity: Sync {
    /// A lower bound on how far (m) every point of every moving body may move from its place
    /// at `q` before the state can become invalid: the distance to every obstacle (static
    /// scene and checked self pairs) minus the required margin. `<= 0` (or NaN) means invalid.
    /// Implementations may cap the value (return `min(d, cap)`) for speed: a smaller value is
    /// always safe.
    fn clearance(&self, q: &[f64]) -> f64;

    /// The same, finer: several clearances into `out` (cleared first), each with the range of
    /// joints that can reduce it — on a serial chain, a body on link `k` is moved only by
    /// joints up to `k`, and two bodies of the chain move relative to each other only by the
    /// joints between them. The segment check steps by the smallest `distance / bound over
    /// joints`, which allows long steps when the only tight clearance is one that few joints
    /// change (a tool near the wrist it hangs on). The smallest distance must not exceed
    /// [`StateValidity::clearance`]. Default: that one clearance, over every joint.
    fn clearances(&self, q: &[f64], out: &mut Vec<Clearance>) {
        out.clear();
        out.push(Clearance {
            distance: self.clearance(q),
            joints: 0..usize::MAX,
        });
    }

    /// Whether `q` is valid (its clearance is positive): a yes-or-no test, which an
    /// implementation may answer faster than [`StateValidity::clearance`] measures. The segment
    /// check probes a few points with it first, to reject a segment with a contact before
    /// covering it. Default: `clearance(q) > 0`.
    fn is_valid(&self, q: &[f64]) -> bool {
        self.clearance(q) > 0.0
    }

    /// Whether `q`'s clearance is at least `floor` (`clearance(q) >= floor`, NaN failing): a
    /// yes-or-no test, which an implementation may answer faster than
    /// [`StateValidity::clearance`] measures, asking each part only as far as the floor. The
    /// planners check the ends of a query and their roadmap nodes with it. Default: the
    /// comparison.
    fn clear_of(&self, q: &[f64], floor: f64) -> bool {
        let c = self.clearance(q);
        !c.is_nan() && c >= floor
    }

    /// The radius, in segment parameter, of the piece of a segment around `q` proven valid:
    /// `min_k distance_k / motion.bound(joints_k)` over [`StateValidity::clearances`], at
    /// most `limit`; `None` when some distance is below `floor` (or NaN). `motion` says how far
    /// each joint moves over the whole segment ([`SegmentMotion`]). The segment check calls
    /// this; an implementation may override it to skip work the answer does not need — a
    /// distance query capped at `step · bound` (the step found so far) answers as well as an
    /// exact one — or to bound a part's motion more tightly than the space's radii do
    /// ([`SegmentMotion::bound_with`]: the radii of the bodies involved in that part).
    fn segment_step(&self, q: &[f64], motion: &SegmentMotion, floor: f64, limit: f64) -> Option<f64> {
        // One buffer per thread, taken out while in use (so a nested call gets its own).
        thread_local! {
            static BUF: std::cell::Cell<Vec<Clearance>> = const { std::cell::Cell::new(Vec::new()) };
        }
        let mut buf = BUF.take();
        self.clearances(q, &mut buf);
        let step = buf.iter().try_fold(limit, |step, c| {
            narrow_step(step, c.distance, motion.bound(&c.joints), floor)
        });
        BUF.set(buf);
        step
    }
}

/// How far a straight joint-space segment moves each joint, and the Cartesian bounds that
/// follow (the `bound` of [`StateValidity::segment_step`]).
#[derive(Clone, Debug, Default)]
pub struct SegmentMotion {
    /// `|b_j − a_j|` per joint.
    delta: Vec<f64>,
    /// The space's radius per joint.
    radii: Vec<f64>,
    /// Prefix sums of `radii[j]·delta[j]`.
    prefix: Vec<f64>,
    /// Per-part bounds a checker keeps for this segment ([`SegmentMotion::memo`]): they depend
    /// on the segment alone, while the segment check asks them at every sample.
    memo: std::cell::OnceCell<(usize, Vec<f64>)>,
}

impl PartialEq for SegmentMotion {
    /// The same motion (the memo is a cache, not part of the value).
    fn eq(&self, other: &Self) -> bool {
        self.delta == other.delta && self.radii == other.radii && self.prefix == other.prefix
    }
}

impl SegmentMotion {
    /// The motion of a segment moving joint `j` by `delta[j]` (absolute values are taken) in a
    /// space with Cartesian radii `radii` (see [`JointSpace::radii`]; missing radii are
    /// infinite).
    pub fn new(radii: &[f64], delta: &[f64]) -> SegmentMotion {
        let n = delta.len();
        let delta: Vec<f64> = delta.iter().map(|d| d.abs()).collect();
        let radii: Vec<f64> = (0..n)
            .map(|j| radii.get(j).copied().unwrap_or(f64::INFINITY))
            .collect();
        let mut prefix = Vec::with_capacity(n + 1);
        prefix.push(0.0);
        for j in 0..n {
            let term = if delta[j] == 0.0 { 0.0 } else { radii[j] * delta[j] };
            prefix.push(prefix[j] + term);
        }
        SegmentMotion {
            delta,
            radii,
            prefix,
            memo: std::cell::OnceCell::new(),
        }
    }

    /// Values that depend on this motion alone, computed by `make` on the first call and kept
    /// for the segment's later samples. `owner` names the caller (a checker's address): a
    /// memo made by another owner is not returned (`make` runs again, and its result is not
    /// kept).
    pub fn memo(&self, owner: usize, make: impl Fn() -> Vec<f64>) -> std::borrow::Cow<'_, [f64]> {
        let (by, values) = self.memo.get_or_init(|| (owner, make()));
        if *by == owner {
            std::borrow::Cow::Borrowed(values)
        } else {
            std::borrow::Cow::Owned(make())
        }
    }

    /// `|b_j − a_j|`: how far the segment moves joint `j` (0 beyond the segment's joints).
    pub fn delta(&self, j: usize) -> f64 {
        self.delta.get(j).copied().unwrap_or(0.0)
    }

    /// The motion of the segment `a → b` in `space`.
    pub fn of(space: &JointSpace, a: &[f64], b: &[f64]) -> SegmentMotion {
        let n = space.dim().min(a.len()).min(b.len());
        let delta: Vec<f64> = (0..n).map(|j| b[j] - a[j]).collect();
        SegmentMotion::new(&space.radii, &delta)
    }

    /// Bound (m) on how far the points move, along the whole segment, by the joints
    /// `joints` (clipped to the space): `Σ_{j in joints} radii[j]·|Δq_j|`.
    pub fn bound(&self, joints: &Range<usize>) -> f64 {
        let n = self.delta.len();
        let (lo, hi) = (joints.start.min(n), joints.end.min(n));
        if hi > lo {
            self.prefix[hi] - self.prefix[lo]
        } else {
            0.0
        }
    }

    /// The same bound with per-joint radii of the points concerned (`own[j]`, each used only
    /// where it is below the space's): `Σ_{j in joints} min(own[j], radii[j])·|Δq_j|`. For
    /// the points of one body, `own` may be that body's radii
    /// ([`cellplan_kin::Chain::body_radii`]), which are smaller than the whole arm's.
    pub fn bound_with(&self, joints: &Range<usize>, own: &[f64]) -> f64 {
        let n = self.delta.len();
        let (lo, hi) = (joints.start.min(n), joints.end.min(n));
        (lo..hi)
            .filter(|&j| self.delta[j] != 0.0)
            .map(|j| own.get(j).map_or(self.radii[j], |&r| r.min(self.radii[j])) * self.delta[j])
            .sum()
    }

    /// `E = Σ_{j in joints} |Δq_j|·Σ_{i>j in joints} R_i·|Δq_i|`, with `R_i`
    /// [`Self::bound_with`]'s radii: how much the points of one body can add, over the parameter
    /// length 1, to [`Self::bound_at`]'s first term as the joints move them farther from the axes
    /// of the joints before (see there). It depends on the segment alone.
    pub fn drift_with(&self, joints: &Range<usize>, own: &[f64]) -> f64 {
        let n = self.delta.len();
        let (lo, hi) = (joints.start.min(n), joints.end.min(n));
        let (mut later, mut sum) = (0.0, 0.0);
        for j in (lo..hi).rev() {
            let d = self.delta[j];
            if d == 0.0 {
                continue;
            }
            sum += later * d;
            later += own.get(j).map_or(self.radii[j], |&r| r.min(self.radii[j])) * d;
        }
        sum
    }

    /// A bound on how far the points of one body move, over any part of the segment of
    /// parameter length up to `t`, from where they stand at a sample: `Σ_{j in joints} ρ_j·|Δq_j|
    /// + t·drift`, where `ρ_j = reach(j)` is the body's largest distance from joint `j`'s axis at
    /// the sample (infinite for a sliding joint) and `drift` is [`Self::drift_with`]. Moving
    /// one joint at a time through the box the step spans, joint `j` moves the body's points no
    /// faster than their distance from its axis there, which exceeds `ρ_j` by at most how far
    /// the later joints carry them in the frame of `j`'s link (where its axis stands still):
    /// `t·Σ_{i>j} R_i·|Δq_i|`. The bound holds for every `t' ≤ t` as `t'·bound_at(t)`.
    pub fn bound_at(&self, joints: &Range<usize>, reach: impl Fn(usize) -> f64, drift: f64, t: f64) -> f64 {
        let n = self.delta.len();
        let (lo, hi) = (joints.start.min(n), joints.end.min(n));
        let mut sum = t * drift;
        for j in lo..hi {
            let d = self.delta[j];
            if d != 0.0 {
                sum += reach(j) * d;
            }
        }
        sum
    }

    /// The bound over every joint.
    pub fn total(&self) -> f64 {
        self.prefix.last().copied().unwrap_or(0.0)
    }
}

/// One part's say in [`StateValidity::segment_step`]: `None` when its clearance `distance` is
/// below `floor` (or NaN), else `step` shortened to `distance / bound` if that is shorter
/// (a part whose joints do not move, `bound` 0, only has to be valid).
pub fn narrow_step(step: f64, distance: f64, bound: f64, floor: f64) -> Option<f64> {
    // NaN fails the comparison and so counts as a contact.
    if distance.is_nan() || distance < floor {
        return None;
    }
    Some(if bound > 0.0 {
        step.min(distance / bound)
    } else {
        step
    })
}

/// A plain function or closure of `q` is a validity checker (its value is the clearance).
impl<F: Fn(&[f64]) -> f64 + Sync> StateValidity for F {
    fn clearance(&self, q: &[f64]) -> f64 {
        self(q)
    }
}

/// The outcome of [`check_segment`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SegmentCheck {
    /// Whether the whole straight segment is valid.
    pub valid: bool,
    /// Validity calls made: [`StateValidity::segment_step`] and the probes.
    pub calls: usize,
    /// Of those, the yes-or-no probes ([`StateValidity::is_valid`]).
    pub probes: usize,
}

/// Conservative check of the straight joint-space segment `a → b`: valid only when every
/// configuration on it is proven valid (see the module documentation). A clearance below
/// `min_clearance` (clamped to at least 1e-9) counts as invalid.
pub fn check_segment(
    space: &JointSpace,
    validity: &dyn StateValidity,
    a: &[f64],
    b: &[f64],
    min_clearance: f64,
) -> SegmentCheck {
    let (mut calls, mut probes) = (0, 0);
    let valid = segment_valid_counted(
        space,
        validity,
        (a, b),
        (min_clearance, MAX_PROBES),
        &mut calls,
        &mut probes,
    );
    SegmentCheck {
        valid,
        calls: calls + probes,
        probes,
    }
}

/// The check of [`check_segment`]; counts the clearance calls into `calls`.
///
/// The segment is covered by parameter intervals proven valid, one around each sample (its
/// radius from [`StateValidity::segment_step`]). Gaps between covered pieces are kept on a
/// stack, the gap nearer the start on top; a gap wider than two of its ends' radii is entered
/// [`PLACE`] of the smaller radius past its left end (where, the radius being 1-Lipschitz in
/// the parameter, the new ball about touches the covered piece: each sample covers about twice
/// its radius, where a walk would cover one), a narrower gap is sampled in its middle. The
/// check ends at the first contact or when no gap is left. A gap is split by its own ends
/// alone, so the order the gaps are taken in changes neither the samples of a valid segment
/// nor any answer, only how soon a contact is met: nearest the start first, where contacts
/// lie most often (see [`MAX_PROBES`]; first-in first-out took 0.7 % / 0.1 % more MBM
/// planning instructions).
pub(crate) fn segment_valid(
    space: &JointSpace,
    validity: &dyn StateValidity,
    (a, b): (&[f64], &[f64]),
    min_clearance: f64,
    max_probes: usize,
    calls: &mut usize,
) -> bool {
    let mut probes = 0;
    let valid = segment_valid_counted(
        space,
        validity,
        (a, b),
        (min_clearance, max_probes),
        calls,
        &mut probes,
    );
    *calls += probes;
    valid
}

/// [`segment_valid`] counting the steps into `calls` and the probes into `probes`.
fn segment_valid_counted(
    space: &JointSpace,
    validity: &dyn StateValidity,
    (a, b): (&[f64], &[f64]),
    (min_clearance, max_probes): (f64, usize),
    calls: &mut usize,
    probes_made: &mut usize,
) -> bool {
    let floor = min_clearance.max(1e-9);
    let n = space.dim().min(a.len()).min(b.len());
    let motion = SegmentMotion::of(space, a, b);
    if !motion.total().is_finite() {
        return false;
    }
    // Probes: a contact inside the segment is found in a few yes-or-no tests, in bisection
    // order, rather than by covering the segment up to it (steps shrink geometrically towards
    // a contact). Only an invalid point rejects, so the answer is unchanged.
    let probes = ((motion.total() / PROBE_SPACING) as usize).min(max_probes);
    if probes > 0 {
        let mut q = Vec::with_capacity(n);
        let mut level = 2usize;
        let mut done = 0;
        'probe: while done < probes {
            for k in (1..level).step_by(2) {
                space.interpolate(a, b, k as f64 / level as f64, &mut q);
                *probes_made += 1;
                if !validity.is_valid(&q) {
                    return false;
                }
                done += 1;
                if done == probes {
                    break 'probe;
                }
            }
            level *= 2;
        }
    }
    let mut measure = |q: &[f64], limit: f64| -> Option<f64> {
        *calls += 1;
        validity
            .segment_step(q, &motion, floor, limit)
            .map(|r| r * STEP_SAFETY)
    };
    let Some(ra) = measure(a, 1.0) else {
        return false;
    };
    let Some(rb) = measure(b, 1.0) else {
        return false;
    };
    // Gaps (left end, its radius, right end, its radius).
    let mut gaps = vec![(0.0, ra, 1.0, rb)];
    let mut q = Vec::with_capacity(n);
    // The first sample goes to the middle, the point farthest from both (valid) ends, where
    // a contact is likeliest.
    let mut first = true;
    while let Some((s0, r0, s1, r1)) = gaps.pop() {
        let (lo, hi) = (s0 + r0, s1 - r1);
        if lo >= hi {
            continue;
        }
        let guess = PLACE * r0.min(r1);
        let s = if std::mem::take(&mut first) || hi - lo <= 2.0 * guess {
            0.5 * (lo + hi)
        } else {
            lo + guess
        };
        space.interpolate(a, b, s, &mut q);
        // A radius beyond the farther end of the gap is of no use.
        let Some(r) = measure(&q, (s - s0).max(s1 - s)) else {
            return false;
        };
        gaps.push((s, r, s1, r1));
        gaps.push((s0, r0, s, r));
    }
    true
}
