//! Bodies grouped by link for the broad phase of [`super::ArmValidity`]: one sphere per link,
//! tested before the parts it holds.
use super::Arm;
use cellplan_geom::spheres::Sphere;
use cellplan_geom::{BroadPhase, Pose};
use std::ops::Range;

/// The bodies of one link share its frame, so one sphere holds their outer spheres; where that
/// sphere is clear of the scene (or of another link's) by what each of its parts is asked,
/// those parts answer their caps without a query of their own (the test they would make, on a
/// larger sphere: the same answers). A pair is in up to two groups: the two links' clusters,
/// and, when its first body's link has several bodies, that body alone against the other
/// link's cluster (the UR5's forearm pieces against its gripper's twelve). At most 64 clusters
/// moving against the scene and 64 groups (bits of a mask).
#[derive(Clone, Debug, Default)]
pub(super) struct Clusters {
    /// Per sphere: one of its bodies (whose pose places it) and the sphere in that frame. The
    /// links' clusters first, then single bodies of the groups.
    pub(super) spheres: Vec<(usize, Sphere)>,
    /// Per moving part (index into `moving`): its cluster, when that has two moving parts or
    /// more.
    pub(super) scene: Vec<Option<usize>>,
    /// Per pair (index into `pairs`): its groups, coarse then fine, each when it holds two
    /// pairs or more.
    pub(super) pair: Vec<[Option<usize>; 2]>,
    /// The groups: two spheres.
    pub(super) groups: Vec<(usize, usize)>,
}

/// How many groups a `u64` mask tracks.
const MASK_BITS: usize = 64;

impl Clusters {
    pub(super) fn new(
        arm: &Arm,
        broad: &BroadPhase,
        moving: &[(usize, Range<usize>)],
        pairs: &[(usize, usize)],
    ) -> Clusters {
        let n = arm.body_links.len();
        // One cluster per link with bodies, in body order.
        let mut of_body = vec![usize::MAX; n];
        let mut members: Vec<Vec<usize>> = Vec::new();
        for i in 0..n {
            let found = (0..i)
                .find(|&k| arm.body_links[k] == arm.body_links[i])
                .map(|k| of_body[k]);
            let c = found.unwrap_or_else(|| {
                members.push(Vec::new());
                members.len() - 1
            });
            of_body[i] = c;
            members[c].push(i);
        }
        let mut spheres: Vec<Option<(usize, Sphere)>> = members
            .iter()
            .map(|m| broad.outer_of(m).map(|s| (m[0], s)))
            .collect();
        // Body `i` alone, for the fine groups (its link has other bodies).
        let mut alone = vec![None; n];
        for i in 0..n {
            if members[of_body[i]].len() >= 2 {
                alone[i] = Some(spheres.len());
                spheres.push(broad.outer_of(&[i]).map(|s| (i, s)));
            }
        }
        let usable = |c: usize| spheres.get(c).is_some_and(Option::is_some);
        let mut moving_in = vec![0usize; members.len()];
        for (i, _) in moving {
            moving_in[of_body[*i]] += 1;
        }
        let scene = moving
            .iter()
            .map(|(i, _)| {
                let c = of_body[*i];
                (usable(c) && moving_in[c] >= 2 && c < MASK_BITS).then_some(c)
            })
            .collect();
        // Each pair's candidate groups (coarse, fine), counted.
        let keys: Vec<[Option<(usize, usize)>; 2]> = pairs
            .iter()
            .map(|&(i, j)| {
                let (ci, cj) = (of_body[i], of_body[j]);
                let fine = alone[i].filter(|_| members[cj].len() >= 2).map(|a| (a, cj));
                [Some((ci, cj)), fine]
            })
            .collect();
        let mut counts: Vec<((usize, usize), usize)> = Vec::new();
        for key in keys.iter().flatten().flatten() {
            match counts.iter_mut().find(|(k, _)| k == key) {
                Some((_, c)) => *c += 1,
                None => counts.push((*key, 1)),
            }
        }
        let mut groups: Vec<(usize, usize)> = Vec::new();
        let pair = keys
            .iter()
            .map(|ks| {
                ks.map(|key| {
                    let key = key?;
                    let size = counts.iter().find(|(k, _)| *k == key).map_or(0, |(_, c)| *c);
                    if !(usable(key.0) && usable(key.1) && key.0 != key.1 && size >= 2) {
                        return None;
                    }
                    let g = groups.iter().position(|&k| k == key).unwrap_or_else(|| {
                        groups.push(key);
                        groups.len() - 1
                    });
                    (g < MASK_BITS).then_some(g)
                })
            })
            .collect();
        let nowhere = Sphere {
            centre: cellplan_geom::DVec3::ZERO,
            radius: f64::INFINITY,
        };
        Clusters {
            spheres: spheres.into_iter().map(|s| s.unwrap_or((0, nowhere))).collect(),
            scene,
            pair,
            groups,
        }
    }

    /// Cluster `c`'s sphere placed at the body poses `bodies`.
    #[inline]
    pub(super) fn placed(&self, c: usize, bodies: &[Pose]) -> Sphere {
        let (body, s) = self.spheres[c];
        let pose = bodies.get(body).copied().unwrap_or(Pose::IDENTITY);
        Sphere {
            centre: pose.rotation * s.centre + pose.translation,
            radius: s.radius,
        }
    }

    /// Whether group `g`'s two clusters, placed at `bodies`, are at least `best` apart.
    #[inline]
    pub(super) fn group_apart(&self, g: usize, bodies: &[Pose], best: f64) -> bool {
        let (a, b) = self.groups[g];
        let (sa, sb) = (self.placed(a, bodies), self.placed(b, bodies));
        sa.apart_by(&sb, best.max(0.0))
    }
}

/// Groups tested and found clear within one check (bits of [`Clusters`]' indices).
#[derive(Clone, Copy, Default)]
pub(super) struct Settled {
    tested: u64,
    clear: u64,
}

impl Settled {
    /// The clusters against the scene and the groups of pairs, none tested yet.
    pub(super) fn untested() -> [std::cell::Cell<Settled>; 2] {
        Default::default()
    }

    /// Whether group `k` is clear: `test()` asked the first time only.
    #[inline]
    pub(super) fn clear(&mut self, k: usize, test: impl FnOnce() -> bool) -> bool {
        let bit = 1u64 << k;
        if self.tested & bit == 0 {
            self.tested |= bit;
            if test() {
                self.clear |= bit;
            }
        }
        self.clear & bit != 0
    }
}
