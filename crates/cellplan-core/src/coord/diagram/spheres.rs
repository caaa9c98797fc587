//! The diagram's sphere tests: each robot's body spheres and covers, placed, and the body
//! pairs whose covers come within a distance ([`close_pairs`]).
use crate::coord::Ctx;
use cellplan_geom::{DVec3, Pose};
use cellplan_model::robot::Robot;

/// One robot placed at a position: its configuration and body bounding spheres.
#[derive(Default)]
pub(super) struct Placed {
    pub(super) q: Vec<f64>,
    pub(super) poses: Vec<Pose>,
    /// World bounding sphere of each body with shapes, and which body it is.
    pub(super) spheres: Vec<(DVec3, f64)>,
    pub(super) bodies: Vec<usize>,
    /// Every body's sphere cover in the world, body `i`'s at the robot's [`Covers::ranges`]
    /// `[i]` (empty for a body without shapes).
    pub(super) covers: Vec<(DVec3, f64)>,
}

/// Per robot, per body: one sphere (body frame) holding the body's sphere cover.
pub(super) fn body_spheres(ctx: &Ctx, robot: &Robot) -> Vec<Option<(DVec3, f64)>> {
    let world = &ctx.cell.world;
    (0..world.body_count(robot.group))
        .map(|i| {
            let cover = world.body_cover(robot.group, i);
            if cover.is_empty() {
                return None;
            }
            let centre = cover.iter().map(|s| s.centre).sum::<DVec3>() / cover.len() as f64;
            let radius = cover
                .iter()
                .map(|s| (s.centre - centre).length() + s.radius)
                .fold(0.0, f64::max);
            Some((centre, radius))
        })
        .collect()
}

/// A robot's sphere covers in their body frames, one list for all bodies.
pub(super) struct Covers {
    pub(super) spheres: Vec<(DVec3, f64)>,
    /// Body `i`'s spheres are `spheres[ranges[i]]`.
    pub(super) ranges: Vec<std::ops::Range<usize>>,
}

impl Covers {
    pub(super) fn of(ctx: &Ctx, robot: &Robot) -> Covers {
        let world = &ctx.cell.world;
        let mut c = Covers {
            spheres: Vec::new(),
            ranges: Vec::new(),
        };
        for i in 0..world.body_count(robot.group) {
            let from = c.spheres.len();
            c.spheres.extend(
                world
                    .body_cover(robot.group, i)
                    .iter()
                    .map(|s| (s.centre, s.radius)),
            );
            c.ranges.push(from..c.spheres.len());
        }
        c
    }
}

/// Added to the reach with which a sphere of the second cover is kept as near the first body's
/// sphere: far more than the rounding of a containment or a squared distance (~1e-15 m), so
/// that no sphere [`close_pairs`] would pair is left out.
const NEAR_SLACK: f64 = 1e-9;

/// A pair of body spheres of two placed robots: the index into the first's
/// [`Placed::spheres`] and into the second's (the same bodies at every placement).
pub(super) type SpherePair = (u32, u32);

/// Of the body pairs `pairs[among]` of the placed robots `xa` and `xb` (body `i`'s cover at
/// `ranges.0[i]` of `xa.covers`, and `ranges.1` of `xb`'s), those whose sphere covers come
/// within `need` of each other, pushed in order onto the end of `pairs`: a pair whose body
/// spheres come that close, and in which a sphere of the first cover comes that close to the
/// second body's sphere and to a sphere of the second cover. Every pair left out is farther
/// than `need` (the covers hold the meshes). With `first`, it stops at the first close pair
/// and pushes it with the pairs after it unasked (a rectangle that will be halved needs only
/// one; its halves ask the close one first and skip those proven apart before it).
///
/// Each body's sphere holds its cover, so a sphere of the second cover that comes within
/// `need` of a sphere of the first comes within `need` of the first body's sphere too: the
/// second cover is cut to those (`near`, reused room) once per pair of bodies, with
/// [`NEAR_SLACK`] against rounding, and the answer is that of every sphere against every one.
pub(super) fn close_pairs(
    ranges: (&[std::ops::Range<usize>], &[std::ops::Range<usize>]),
    (xa, xb): (&Placed, &Placed),
    need: f64,
    (pairs, among): (&mut Vec<SpherePair>, std::ops::Range<usize>),
    first: bool,
    near: &mut Vec<(DVec3, f64)>,
) {
    // Squared distances against squared reaches (all terms are non-negative): no square
    // root per sphere pair.
    let within = |c: DVec3, r: f64, d: DVec3, q: f64| {
        let reach = need + r + q;
        (c - d).length_squared() <= reach * reach
    };
    let end = among.end;
    for k in among {
        let (i, j) = pairs[k];
        let ((ca, ra), (cb, rb)) = (xa.spheres[i as usize], xb.spheres[j as usize]);
        if !within(ca, ra, cb, rb) {
            continue;
        }
        let (bi, bj) = (xa.bodies[i as usize], xb.bodies[j as usize]);
        near.clear();
        near.extend(
            xb.covers[ranges.1[bj].clone()]
                .iter()
                .filter(|&&(d, q)| within(ca, ra + NEAR_SLACK, d, q)),
        );
        if near.is_empty() {
            continue;
        }
        // A sphere of the first cover farther than `need` from the second body's sphere
        // is farther from every sphere it holds.
        let close = xa.covers[ranges.0[bi].clone()]
            .iter()
            .any(|&(c, r)| within(c, r, cb, rb) && near.iter().any(|&(d, q)| within(c, r, d, q)));
        if close {
            pairs.push((i, j));
            if first {
                pairs.extend_from_within(k + 1..end);
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_geom::DQuat;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every pair of the `na` body spheres of one robot and the `nb` of another, pushed onto `out`.
    fn every_sphere_pair(na: usize, nb: usize, out: &mut Vec<SpherePair>) {
        out.extend((0..na as u32).flat_map(|i| (0..nb as u32).map(move |j| (i, j))));
    }

    /// Every sphere of the first cover against every sphere of the second: what
    /// [`close_pairs`] must answer.
    fn every_pair(
        ranges: (&[std::ops::Range<usize>], &[std::ops::Range<usize>]),
        xa: &Placed,
        xb: &Placed,
        need: f64,
    ) -> Vec<(usize, usize)> {
        let within = |c: DVec3, r: f64, d: DVec3, q: f64| {
            let reach = need + r + q;
            (c - d).length_squared() <= reach * reach
        };
        let mut out = Vec::new();
        for (i, &(ca, ra)) in xa.spheres.iter().enumerate() {
            for (j, &(cb, rb)) in xb.spheres.iter().enumerate() {
                let (bi, bj) = (xa.bodies[i], xb.bodies[j]);
                let close = within(ca, ra, cb, rb)
                    && xa.covers[ranges.0[bi].clone()].iter().any(|&(c, r)| {
                        within(c, r, cb, rb)
                            && xb.covers[ranges.1[bj].clone()]
                                .iter()
                                .any(|&(d, q)| within(c, r, d, q))
                    });
                if close {
                    out.push((bi, bj));
                }
            }
        }
        out
    }

    /// A robot of `bodies` bodies with random covers (body frame), placed by random poses as
    /// the diagram places one: body spheres from the covers as [`body_spheres`] makes them.
    fn random_robot(rng: &mut ChaCha8Rng, bodies: usize) -> (Vec<std::ops::Range<usize>>, Placed) {
        let mut ranges = Vec::new();
        let mut p = Placed::default();
        for b in 0..bodies {
            let n = rng.random_range(0..6);
            let local: Vec<(DVec3, f64)> = (0..n)
                .map(|_| {
                    let c = DVec3::new(
                        rng.random_range(-0.4..0.4),
                        rng.random_range(-0.4..0.4),
                        rng.random_range(-0.4..0.4),
                    );
                    (c, rng.random_range(0.01..0.2))
                })
                .collect();
            let axis = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 0.3).normalize();
            let pose = Pose::from_parts(
                DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(0.0..2.0),
                ),
                DQuat::from_axis_angle(axis, rng.random_range(-3.0..3.0)),
            );
            let from = p.covers.len();
            p.covers
                .extend(local.iter().map(|&(c, r)| (pose.transform_point(c), r)));
            ranges.push(from..p.covers.len());
            if n > 0 {
                let centre = local.iter().map(|s| s.0).sum::<DVec3>() / n as f64;
                let radius = local
                    .iter()
                    .map(|s| (s.0 - centre).length() + s.1)
                    .fold(0.0, f64::max);
                p.spheres.push((pose.transform_point(centre), radius));
                p.bodies.push(b);
            }
        }
        (ranges, p)
    }

    #[test]
    fn close_pairs_are_those_of_every_sphere_against_every_sphere() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut some, mut none) = (0, 0);
        let mut near = Vec::new();
        for _ in 0..400 {
            let (na, nb) = (rng.random_range(1..8), rng.random_range(1..8));
            let (ra, xa) = random_robot(&mut rng, na);
            let (rb, xb) = random_robot(&mut rng, nb);
            // Needs at which a cover pair is just within or just beyond reach, and plain ones.
            let mut needs: Vec<f64> = vec![0.0, 0.05, 0.3];
            for &(c, r) in xa.covers.iter().take(3) {
                for &(d, q) in xb.covers.iter().take(3) {
                    let gap = (c - d).length() - r - q;
                    if gap >= 0.0 {
                        needs.extend([gap, gap * (1.0 - 1e-12), gap * (1.0 + 1e-12)]);
                    }
                }
            }
            for need in needs {
                let want = every_pair((&ra, &rb), &xa, &xb, need);
                let mut pairs = Vec::new();
                every_sphere_pair(xa.spheres.len(), xb.spheres.len(), &mut pairs);
                let all = pairs.len();
                close_pairs(
                    (&ra, &rb),
                    (&xa, &xb),
                    need,
                    (&mut pairs, 0..all),
                    false,
                    &mut near,
                );
                let bodies = |p: &[SpherePair]| -> Vec<(usize, usize)> {
                    p.iter()
                        .map(|&(i, j)| (xa.bodies[i as usize], xb.bodies[j as usize]))
                        .collect()
                };
                assert_eq!(bodies(&pairs[all..]), want, "need {need}");
                // Among every other pair only (in reverse order): those of them, in that order.
                let subset: Vec<SpherePair> = pairs[..all].iter().rev().step_by(2).copied().collect();
                // What the subset's asking pushes, asking all or stopping at the first.
                let mut ask = |first: bool| -> Vec<SpherePair> {
                    let mut among = subset.clone();
                    close_pairs(
                        (&ra, &rb),
                        (&xa, &xb),
                        need,
                        (&mut among, 0..subset.len()),
                        first,
                        &mut near,
                    );
                    among.split_off(subset.len())
                };
                let kept: Vec<(usize, usize)> =
                    bodies(&subset).into_iter().filter(|p| want.contains(p)).collect();
                assert_eq!(bodies(&ask(false)), kept, "need {need}, among some");
                // Stopping at the first: it, then every pair after it, unasked.
                let pushed = ask(true);
                match kept.first() {
                    None => assert!(pushed.is_empty()),
                    Some(&k) => {
                        let at = bodies(&subset)
                            .iter()
                            .position(|&p| p == k)
                            .expect("kept from the subset");
                        assert_eq!(&pushed[..], &subset[at..], "need {need}, the first");
                    }
                }
                if want.is_empty() {
                    none += 1;
                } else {
                    some += 1;
                }
            }
        }
        // Both answers were asked often.
        assert!(some > 500 && none > 500, "{some} close, {none} apart");
    }
}
