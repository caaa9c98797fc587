//! One segment step of [`ArmValidity`] ([`crate::plan::StateValidity::segment_step`]): each
//! part's motion bounds over the segment, made once per segment, and the step at one sample —
//! the parts asked only as far as the step needs, their bounds taken where the arm stands where
//! that is tighter ([`ArmValidity::posed_bound`]).
use super::clusters::Settled;
use super::radii::PosedAxes;
use super::{ArmValidity, ENOUGH_SHARE, STEP_SHARE, measured_for, trusted};
use crate::plan::{SegmentMotion, narrow_step};
use cellplan_geom::{PlacedCovers, Pose, Precision};
use std::ops::Range;

impl ArmValidity<'_> {
    /// How far a part's distance can fall over a segment: by its own radii (a moving body's,
    /// or a pair's) when [`Self::own_radii`] is on, else by the space's.
    fn part_bound(&self, motion: &SegmentMotion, joints: &Range<usize>, own: &[f64]) -> f64 {
        if self.own_radii {
            motion.bound_with(joints, own)
        } else {
            motion.bound(joints)
        }
    }

    /// Every part's [`Self::part_bound`] over `motion`: the moving bodies', then the pairs',
    /// then the largest of each cluster's moving bodies' and of each group's pairs' (see
    /// [`Clusters`]).
    pub(super) fn part_bounds(&self, motion: &SegmentMotion) -> Vec<f64> {
        // Every part with its joints and radii: the moving bodies, then the pairs.
        let parts = || {
            let scene = self
                .moving
                .iter()
                .map(|(i, joints)| (joints, self.body_radii.get(*i).map_or(&[][..], |r| r)));
            let pairs = self
                .pairs
                .iter()
                .map(|(_, _, joints, radii)| (joints, &radii[..]));
            scene.chain(pairs)
        };
        let mut scene: Vec<f64> = parts()
            .map(|(joints, radii)| self.part_bound(motion, joints, radii))
            .collect();
        let pairs = scene.split_off(self.moving.len());
        let largest = |n: usize, of: &[Option<usize>], bounds: &[f64]| {
            let mut out = vec![0.0f64; n];
            for (c, b) in of.iter().zip(bounds) {
                if let Some(c) = c {
                    out[*c] = out[*c].max(*b);
                }
            }
            out
        };
        let clusters = largest(self.clusters.spheres.len(), &self.clusters.scene, &scene);
        let mut groups = vec![0.0f64; self.clusters.groups.len()];
        for (gs, b) in self.clusters.pair.iter().zip(&pairs) {
            for g in gs.iter().flatten() {
                groups[*g] = groups[*g].max(*b);
            }
        }
        // Each part's drift (see [`Self::posed_bound`]), by the radii its bound uses.
        let drifts: Vec<f64> = parts()
            .map(|(joints, radii)| motion.drift_with(joints, if self.own_radii { radii } else { &[] }))
            .collect();
        [scene, pairs, clusters, groups, drifts].concat()
    }

    /// The clearance a part with motion bound `bound` is asked for, in a step of `step`: the
    /// step times the bound, at most [`Self::cap`] and at least the floor (the floor alone for
    /// a part that does not move).
    #[inline]
    fn wanted(&self, bound: f64, step: f64, floor: f64) -> f64 {
        if bound > 0.0 {
            (step * bound).min(self.cap).max(floor)
        } else {
            floor
        }
    }

    /// The step after one part, asked only as far as it matters: `wanted` is the clearance
    /// that would not shorten the step (the step so far times the part's bound, or the floor
    /// when the part cannot move), at most [`Self::cap`]; `query((cap, enough, precision))` is
    /// the part's distance capped at `cap` (the broad phase inside it skips every exact query
    /// whose bound reaches the cap), or a bound of it that reaches `enough` ([`ENOUGH_SHARE`] of
    /// `wanted`, at least the floor, so that a part is never failed on a bound), its exact
    /// queries to [`STEP_SHARE`] of the excess over the floor. A part at its cap gives
    /// [`Self::step_at_cap`]; one below it `narrow_step` by its clearance (`None`: below the
    /// floor).
    #[inline]
    fn capped_step(
        &self,
        query: impl FnOnce((f64, f64, Precision)) -> f64,
        offset: f64,
        bound: f64,
        step: f64,
        floor: f64,
    ) -> Option<f64> {
        let wanted = self.wanted(bound, step, floor);
        let cap = measured_for(wanted + offset);
        let enough = measured_for((ENOUGH_SHARE * wanted).max(floor) + offset).min(cap);
        // Exact about the floor (every answer as the exact distance's), within
        // [`STEP_SHARE`] above it.
        let above = measured_for(floor + offset);
        let d = query((
            cap,
            enough,
            Precision {
                share: STEP_SHARE,
                above,
            },
        ));
        if d >= cap {
            Some(self.step_at_cap(bound, step, floor))
        } else {
            narrow_step(step, trusted(d) - offset, bound, floor)
        }
    }

    /// The step after a part with motion bound `bound` whose clearance reaches what it is asked
    /// ([`Self::wanted`]): shortened only where [`Self::cap`] binds, to the cap over the bound
    /// (the floor's, if that is larger). The same as `narrow_step` by `wanted`, without its
    /// rounding where nothing binds: a part settled by its cluster and the same part settled by
    /// its own query give the same step, bit for bit.
    #[inline]
    fn step_at_cap(&self, bound: f64, step: f64, floor: f64) -> f64 {
        if bound > 0.0 && step * bound > self.cap {
            step.min(self.cap.max(floor) / bound)
        } else {
            step
        }
    }

    /// [`StateValidity::segment_step`] at body poses `bodies` (covers placed in `placed`, the
    /// joint axes in `axes`), each part's bounds over the segment in `bounds`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_posed(
        &self,
        q: &[f64],
        motion: &SegmentMotion,
        floor: f64,
        limit: f64,
        bounds: &[f64],
        bodies: &[Pose],
        placed: &PlacedCovers,
        axes: &PosedAxes,
    ) -> Option<f64> {
        let margin = self.margin.max(0.0);
        let (m, p) = (self.moving.len(), self.pairs.len());
        let c = self.clusters.spheres.len();
        let part = |range: Range<usize>| bounds.get(range).unwrap_or(&[]);
        let (scene_bounds, pair_bounds) = (part(0..m), part(m..m + p));
        let g = self.clusters.groups.len();
        let (cluster_bounds, group_bounds) = (part(m + p..m + p + c), part(m + p + c..m + p + c + g));
        let drifts = part(m + p + c + g..bounds.len());
        let (scene_drifts, pair_drifts) = (drifts.get(..m).unwrap_or(&[]), drifts.get(m..).unwrap_or(&[]));
        let mut step = limit;
        let mut settled = Settled::default();
        for (k, ((i, joints), &b)) in self.moving.iter().zip(scene_bounds).enumerate().rev() {
            let drift = scene_drifts.get(k).copied().unwrap_or(f64::INFINITY);
            // A cluster clear of the scene by what its farthest-moving body is asked
            // settles each of its bodies as that body's own query would (its cap).
            if let Some(c) = self.scene_cluster(k)
                && settled.clear(c, || {
                    let asked = self.wanted(
                        cluster_bounds.get(c).copied().unwrap_or(f64::INFINITY),
                        step,
                        floor,
                    );
                    self.broad
                        .sphere_clears_scene(self.clusters.placed(c, bodies), measured_for(asked + margin))
                })
            {
                // Its step is shortened only where the cap binds: there by its bound at the
                // sample, as its own query would be.
                if step * b > self.cap {
                    let b = self.posed_bound(b, drift, *i, joints, bodies, axes, motion, step);
                    step = self.step_at_cap(b, step, floor);
                }
                continue;
            }
            let b = self.posed_bound(b, drift, *i, joints, bodies, axes, motion, step);
            step = self.capped_step(
                |ask| self.scene_part(*i, bodies, placed, ask),
                margin,
                b,
                step,
                floor,
            )?;
        }
        let mut settled = Settled::default();
        for (k, ((i, j, joints, _), &b)) in self.pairs.iter().zip(pair_bounds).enumerate() {
            // A pair whose table shows it apart over every value its joint takes within the
            // step neither shortens the step nor costs a query.
            if let Some(t) = self.arm.pair_tables.and_then(|t| t.get(*i, *j))
                && let Some(&v) = q.get(t.joint())
                && t.least_within(v, step * motion.delta(t.joint())) >= floor
            {
                continue;
            }
            let far = self.pair_far.get(k).copied().unwrap_or(*j);
            let drift = pair_drifts.get(k).copied().unwrap_or(f64::INFINITY);
            // Two links' clusters (or a body and a cluster) apart by what their pairs are
            // asked settle those pairs.
            if self.pair_groups(k).any(|&g| {
                settled.clear(g, || {
                    let asked =
                        self.wanted(group_bounds.get(g).copied().unwrap_or(f64::INFINITY), step, floor);
                    self.clusters.group_apart(g, bodies, measured_for(asked))
                })
            }) {
                if step * b > self.cap {
                    let b = self.posed_bound(b, drift, far, joints, bodies, axes, motion, step);
                    step = self.step_at_cap(b, step, floor);
                }
                continue;
            }
            let b = self.posed_bound(b, drift, far, joints, bodies, axes, motion, step);
            step = self.capped_step(
                |ask| self.pair_part(*i, *j, q, bodies, placed, ask),
                0.0,
                b,
                step,
                floor,
            )?;
        }
        Some(step)
    }
}
