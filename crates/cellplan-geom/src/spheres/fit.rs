//! Sphere covers fitted to convex polytopes (see the parent module for what a cover must hold).
//!
//! # The proof of containment
//!
//! The polytope `P` is given by its points, **every** edge of a triangulation of its surface,
//! and planes `n·x ≤ d` each of which holds all its points (any normal will do: the offset is
//! the largest `n·p` over the points). It is cut by a grid of planes along three orthogonal
//! axes into cells `C`. Each vertex of the convex polytope `P ∩ C` lies on three of the planes
//! bounding `P` or `C`, which makes four kinds:
//!
//! 1. on three of `P`'s: a point of `P` inside `C`;
//! 2. on two of `P`'s and one of `C`'s: where an edge of `P` crosses a plane of `C`;
//! 3. on one of `P`'s and two of `C`'s: where an edge of `C` (a grid line between two cut
//!    planes) leaves `P`;
//! 4. on three of `C`'s: a corner of `C` inside `P`.
//!
//! Kinds 1 and 2 are collected from the points and edges (with a tolerance that only adds
//! points). Kinds 3 and 4 are the ends of each grid line's piece inside the planes' polytope
//! `Q ⊇ P`, cut at the cells' bounds: the line's piece inside `P` lies within the piece inside
//! `Q`, so its ends lie on the segment between the collected ones. Every vertex of `P ∩ C` is
//! thus in the convex hull of the points collected for `C`, and so is `P ∩ C` itself; a sphere
//! holding those points (its radius the largest distance to them) holds `P ∩ C`, a sphere
//! being convex. The cells tile `P`, so the spheres together hold it. Where the centre lies
//! does not matter to the proof: it is placed to make the spheres stick out of `P` as little
//! as possible (below).
//!
//! # How the cover is chosen
//!
//! Candidate grids (cells about as long as wide, along the body's axes or its principal axes,
//! up to [`MAX_SPHERES`] cells) are each given one sphere per non-empty cell, and scored by the
//! cover's **excess**: over a fixed set of directions `u`, the mean of how far the cover's
//! support `max (c·u + r)` reaches beyond the polytope's `max p·u` — how much a distance bound
//! from the cover falls short of the true distance, on average over where the other object
//! lies. Each sphere costs [`SPHERE_COST`] of excess (a pair of bodies tests every pair of
//! their spheres). The best few grids have their centres moved (a pattern search, each sphere
//! in turn) to lower the excess further, and the best is kept.
use super::{RADIUS_SLACK, Sphere};
use crate::DVec3;

/// Most spheres in a fitted cover.
pub const MAX_SPHERES: usize = 12;

/// What each sphere of a cover costs, in metres of mean excess.
pub const SPHERE_COST: f64 = 1e-3;

/// Directions over which the excess is measured.
const DIRECTIONS: usize = 200;

/// Grids whose centres are optimised (the best by excess with their first centres).
const REFINED: usize = 3;

/// A convex polytope to cover (see the module documentation).
pub(super) struct Polytope {
    points: Vec<DVec3>,
    edges: Vec<[usize; 2]>,
    /// Outward normals `n` (unit) and offsets `d`: `n·p ≤ d` for every point `p`.
    planes: Vec<(DVec3, f64)>,
}

impl Polytope {
    /// The polytope of `points` with the edges of a triangulation of its surface and the
    /// normals of planes to bound it; `None` when a point is not finite or there is none.
    pub(super) fn new(
        points: &[DVec3],
        edges: impl IntoIterator<Item = [usize; 2]>,
        normals: impl IntoIterator<Item = DVec3>,
    ) -> Option<Polytope> {
        if points.is_empty() || points.iter().any(|p| !p.is_finite()) {
            return None;
        }
        let n = points.len();
        let edges = edges.into_iter().filter(|e| e[0] < n && e[1] < n).collect();
        let planes = normals
            .into_iter()
            .filter_map(|n| n.try_normalize())
            .map(|n| {
                (
                    n,
                    points.iter().map(|p| n.dot(*p)).fold(f64::NEG_INFINITY, f64::max),
                )
            })
            .collect();
        Some(Polytope {
            points: points.to_vec(),
            edges,
            planes,
        })
    }
}

/// An orthonormal frame: the grid's three axes.
type Frame = [DVec3; 3];

/// The fitted cover of `poly` (see the module documentation).
pub(super) fn fitted_cover(poly: &Polytope) -> Vec<Sphere> {
    let scorer = Scorer::new(&poly.points);
    let mut frames = vec![[DVec3::X, DVec3::Y, DVec3::Z]];
    frames.extend(principal_axes(&poly.points));
    // Each grid's cost, spheres, cells' points and first step of the pattern search.
    type Tried = (f64, Vec<(DVec3, f64)>, Vec<Vec<DVec3>>, f64);
    let mut tried: Vec<Tried> = Vec::new();
    for frame in &frames {
        let grid = Grid::new(poly, frame);
        for n in grid.candidates() {
            let cells = grid.cell_points(poly, n);
            let spheres: Vec<(DVec3, f64)> = cells.iter().map(|c| start_sphere(c)).collect();
            let cost = scorer.cost(&spheres);
            let step = grid.extent.max_element() / n.iter().copied().max().unwrap_or(1) as f64 / 4.0;
            tried.push((cost, spheres, cells, step));
        }
    }
    tried.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Option<(f64, Vec<(DVec3, f64)>)> = None;
    for (_, mut spheres, cells, step) in tried.into_iter().take(REFINED) {
        scorer.refine(&mut spheres, &cells, step);
        let cost = scorer.cost(&spheres);
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, spheres));
        }
    }
    best.map(|(_, s)| s)
        .unwrap_or_default()
        .into_iter()
        .map(|(centre, radius)| Sphere {
            centre,
            radius: radius * (1.0 + RADIUS_SLACK.0) + RADIUS_SLACK.1,
        })
        .collect()
}

/// The sphere about the centre of the bounding box of `points` holding them.
fn start_sphere(points: &[DVec3]) -> (DVec3, f64) {
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let c = (lo + hi) * 0.5;
    (c, reach(c, points))
}

/// The largest distance from `c` to `points`.
fn reach(c: DVec3, points: &[DVec3]) -> f64 {
    points
        .iter()
        .map(|p| (*p - c).length_squared())
        .fold(0.0, f64::max)
        .sqrt()
}

/// The cuts of a polytope along a frame's axes.
struct Grid {
    frame: Frame,
    /// Each point's coordinates along the axes.
    coords: Vec<DVec3>,
    lo: DVec3,
    hi: DVec3,
    extent: DVec3,
    /// Slack (m) in the tests of which cell a point lies in (only adds points).
    tol: f64,
}

impl Grid {
    fn new(poly: &Polytope, frame: &Frame) -> Grid {
        let coords: Vec<DVec3> = poly
            .points
            .iter()
            .map(|p| DVec3::new(frame[0].dot(*p), frame[1].dot(*p), frame[2].dot(*p)))
            .collect();
        let (lo, hi) = coords.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &u| (lo.min(u), hi.max(u)),
        );
        let extent = hi - lo;
        let scale = extent
            .max_element()
            .max(lo.abs().max_element())
            .max(hi.abs().max_element());
        Grid {
            frame: *frame,
            coords,
            lo,
            hi,
            extent,
            tol: 1e-9 * scale + 1e-12,
        }
    }

    /// Cell counts along the three axes to try: cells about as long as wide for a range of
    /// sizes, and slabs across the longest axis; at most [`MAX_SPHERES`] cells.
    fn candidates(&self) -> Vec<[usize; 3]> {
        let e = self.extent;
        let longest = e.max_element();
        if longest.is_nan() || longest <= 0.0 {
            return vec![[1, 1, 1]];
        }
        let mut out = Vec::new();
        for k in [1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 8.0] {
            let s = longest / k;
            let n = [0, 1, 2].map(|i| ((e[i] / s).round() as usize).max(1));
            out.push(n);
        }
        let k = e.max_position();
        for m in 2..=8 {
            let mut n = [1, 1, 1];
            n[k] = m;
            out.push(n);
        }
        out.retain(|n| n.iter().product::<usize>() <= MAX_SPHERES);
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The position of cut `k` of `n` along axis `i`.
    fn cut(&self, i: usize, k: usize, n: usize) -> f64 {
        if k >= n {
            self.hi[i]
        } else {
            self.lo[i] + self.extent[i] * k as f64 / n as f64
        }
    }

    /// The cells (indices along axis `i`) that coordinate `x` lies in, with the tolerance.
    fn span(&self, i: usize, x: f64, n: usize) -> std::ops::Range<usize> {
        let first = (0..n)
            .find(|&k| x <= self.cut(i, k + 1, n) + self.tol)
            .unwrap_or(n);
        let last = (first..n)
            .take_while(|&k| x >= self.cut(i, k, n) - self.tol)
            .last()
            .map_or(first, |k| k + 1);
        first..last
    }

    /// For each non-empty cell of the grid `n`, points whose hull holds the polytope's part in
    /// it (see the module documentation).
    fn cell_points(&self, poly: &Polytope, n: [usize; 3]) -> Vec<Vec<DVec3>> {
        let index = |c: [usize; 3]| (c[0] * n[1] + c[1]) * n[2] + c[2];
        let mut cells = vec![Vec::new(); n[0] * n[1] * n[2]];
        let mut add = |u: DVec3, fixed: Option<(usize, std::ops::Range<usize>)>, p: DVec3| {
            let spans = [0, 1, 2].map(|i| match &fixed {
                Some((a, r)) if *a == i => r.clone(),
                _ => self.span(i, u[i], n[i]),
            });
            for a in spans[0].clone() {
                for b in spans[1].clone() {
                    for c in spans[2].clone() {
                        cells[index([a, b, c])].push(p);
                    }
                }
            }
        };
        // 1: the points.
        for (p, u) in poly.points.iter().zip(&self.coords) {
            add(*u, None, *p);
        }
        // 2: the edges across the inner cut planes.
        for i in 0..3 {
            for k in 1..n[i] {
                let t = self.cut(i, k, n[i]);
                for &[a, b] in &poly.edges {
                    let (ua, ub) = (self.coords[a], self.coords[b]);
                    let (da, db) = (ua[i] - t, ub[i] - t);
                    if (da < 0.0) == (db < 0.0) || da == db {
                        continue;
                    }
                    let s = da / (da - db);
                    let (pa, pb) = (poly.points[a], poly.points[b]);
                    let mut u = ua + (ub - ua) * s;
                    u[i] = t;
                    add(u, Some((i, k - 1..k + 1)), pa + (pb - pa) * s);
                }
            }
        }
        // 3 and 4: the grid lines inside the planes' polytope, cut at the cells' bounds.
        for i in 0..3 {
            let (j, l) = ((i + 1) % 3, (i + 2) % 3);
            if n[j] == 1 && n[l] == 1 {
                // Only the four edges of the grid's box: vertices of kind 3 or 4 there lie on
                // two outer bounds, on an edge of the polytope (kind 2) or a point (kind 1).
                continue;
            }
            for kj in 0..=n[j] {
                for kl in 0..=n[l] {
                    let (tj, tl) = (self.cut(j, kj, n[j]), self.cut(l, kl, n[l]));
                    let base = self.frame[j] * tj + self.frame[l] * tl;
                    let Some((s0, s1)) = self.clip_line(poly, base, i) else {
                        continue;
                    };
                    for m in 0..n[i] {
                        let (a, b) = (s0.max(self.cut(i, m, n[i])), s1.min(self.cut(i, m + 1, n[i])));
                        if a > b {
                            continue;
                        }
                        let jr = kj.saturating_sub(1)..(kj + 1).min(n[j]);
                        let lr = kl.saturating_sub(1)..(kl + 1).min(n[l]);
                        for t in [a, b] {
                            let p = base + self.frame[i] * t;
                            for cj in jr.clone() {
                                for cl in lr.clone() {
                                    let mut c = [0; 3];
                                    (c[i], c[j], c[l]) = (m, cj, cl);
                                    cells[index(c)].push(p);
                                }
                            }
                        }
                    }
                }
            }
        }
        cells.retain(|c| !c.is_empty());
        cells
    }

    /// The piece `[s0, s1]` (coordinates along `dir`, within the grid's bounds on that axis,
    /// widened by the tolerance) of the line `base + s·dir` inside the planes' polytope.
    fn clip_line(&self, poly: &Polytope, base: DVec3, i: usize) -> Option<(f64, f64)> {
        let dir = self.frame[i];
        let (mut s0, mut s1) = (self.lo[i] - self.tol, self.hi[i] + self.tol);
        for (nrm, d) in &poly.planes {
            let (a, b) = (nrm.dot(dir), d + self.tol - nrm.dot(base));
            if a.abs() <= 1e-15 {
                if b < 0.0 {
                    return None;
                }
            } else if a > 0.0 {
                s1 = s1.min(b / a);
            } else {
                s0 = s0.max(b / a);
            }
            if s0 > s1 {
                return None;
            }
        }
        Some((s0, s1))
    }
}

/// The excess of covers over one polytope (see the module documentation).
struct Scorer {
    dirs: Vec<DVec3>,
    /// The polytope's support along each direction.
    support: Vec<f64>,
}

impl Scorer {
    fn new(points: &[DVec3]) -> Scorer {
        let dirs: Vec<DVec3> = (0..DIRECTIONS)
            .map(|k| {
                // A Fibonacci lattice: directions spread evenly over the sphere.
                let z = 1.0 - 2.0 * (k as f64 + 0.5) / DIRECTIONS as f64;
                let a = k as f64 * 2.399_963_229_728_653;
                let r = (1.0 - z * z).sqrt();
                DVec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect();
        let support = dirs
            .iter()
            .map(|d| points.iter().map(|p| d.dot(*p)).fold(f64::NEG_INFINITY, f64::max))
            .collect();
        Scorer { dirs, support }
    }

    /// Mean excess of `spheres` plus their cost.
    fn cost(&self, spheres: &[(DVec3, f64)]) -> f64 {
        let total: f64 = self
            .dirs
            .iter()
            .zip(&self.support)
            .map(|(d, h)| {
                spheres
                    .iter()
                    .map(|(c, r)| d.dot(*c) + r)
                    .fold(f64::NEG_INFINITY, f64::max)
                    - h
            })
            .sum();
        total / self.dirs.len() as f64 + SPHERE_COST * spheres.len() as f64
    }

    /// Moves each sphere's centre (its radius following: the reach to its cell's points) to
    /// lower the excess, by a pattern search along the axes from `step` down to 0.1 mm.
    fn refine(&self, spheres: &mut [(DVec3, f64)], cells: &[Vec<DVec3>], step: f64) {
        let moves = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ];
        let mut others = vec![0.0; self.dirs.len()];
        for _round in 0..2 {
            for s in 0..spheres.len() {
                for (k, d) in self.dirs.iter().enumerate() {
                    others[k] = spheres
                        .iter()
                        .enumerate()
                        .filter(|(t, _)| *t != s)
                        .map(|(_, (c, r))| d.dot(*c) + r)
                        .fold(f64::NEG_INFINITY, f64::max);
                }
                let score = |c: DVec3| {
                    let r = reach(c, &cells[s]);
                    let sum: f64 = self
                        .dirs
                        .iter()
                        .zip(&others)
                        .zip(&self.support)
                        .map(|((d, o), h)| o.max(d.dot(c) + r) - h)
                        .sum();
                    (sum, r)
                };
                let (mut c, _) = spheres[s];
                let (mut best, mut r) = score(c);
                let mut h = step;
                let mut evals = 0;
                while h > 1e-4 && evals < 400 {
                    let mut moved = false;
                    for m in moves {
                        evals += 1;
                        let (v, rr) = score(c + m * h);
                        if v < best - 1e-12 {
                            (best, r, c) = (v, rr, c + m * h);
                            moved = true;
                        }
                    }
                    if !moved {
                        h *= 0.5;
                    }
                }
                spheres[s] = (c, r);
            }
        }
    }
}

/// The principal axes of `points` (eigenvectors of their covariance, by Jacobi rotations),
/// largest spread first;
/// `None` when they are not all finite.
fn principal_axes(points: &[DVec3]) -> Option<Frame> {
    let n = points.len() as f64;
    let mean = points.iter().copied().sum::<DVec3>() / n;
    let mut a = [[0.0f64; 3]; 3];
    for p in points {
        let d = *p - mean;
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += d[i] * d[j] / n;
            }
        }
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off <= 1e-30 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() <= 1e-300 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J, with J the rotation in the (p, q) plane.
            for row in &mut a {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = [0, 1, 2].map(|k| c * rp[k] - s * rq[k]);
            a[q] = [0, 1, 2].map(|k| s * rp[k] + c * rq[k]);
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // Largest spread first.
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    let col = |k: usize| DVec3::new(v[0][order[k]], v[1][order[k]], v[2][order[k]]);
    let x = col(0).try_normalize()?;
    let y = (col(1) - x * x.dot(col(1))).try_normalize()?;
    let z = x.cross(y);
    z.is_finite().then_some([x, y, z])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DQuat;
    use parry3d_f64::shape::ConvexPolyhedron;
    use proptest::prelude::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Points of the solid hull: its vertices, points on the edges and inside the faces of its
    /// triangles, and weighted means of its vertices (most near the surface: the weights are
    /// steep).
    fn hull_samples(hull: &ConvexPolyhedron, rng: &mut ChaCha8Rng) -> Vec<DVec3> {
        let (v, t) = hull.to_trimesh();
        let mut out = v.clone();
        for tri in &t {
            let [a, b, c] = tri.map(|i| v[i as usize]);
            for _ in 0..3 {
                let s: f64 = rng.random_range(0.0..=1.0);
                out.extend([a + (b - a) * s, b + (c - b) * s, c + (a - c) * s]);
                let (x, y): (f64, f64) = (rng.random_range(0.0..=1.0), rng.random_range(0.0..=1.0));
                let (x, y) = if x + y > 1.0 { (1.0 - x, 1.0 - y) } else { (x, y) };
                out.push(a + (b - a) * x + (c - a) * y);
            }
        }
        for _ in 0..500 {
            let w: Vec<f64> = (0..v.len())
                .map(|_| rng.random_range(0.0..1.0f64).powi(8))
                .collect();
            let sum: f64 = w.iter().sum();
            if sum > 0.0 {
                out.push(v.iter().zip(&w).map(|(p, w)| *p * *w).sum::<DVec3>() / sum);
            }
        }
        out
    }

    /// The first of `points` outside every sphere, if any.
    fn outside(spheres: &[(DVec3, f64)], points: &[DVec3]) -> Option<DVec3> {
        points
            .iter()
            .copied()
            .find(|p| !spheres.iter().any(|(c, r)| (*p - *c).length() <= *r))
    }

    fn random_hull(seed: u64, n: usize, scale: DVec3, turn: DVec3) -> Option<ConvexPolyhedron> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let rot = DQuat::from_euler(glam::EulerRot::XYZ, turn.x, turn.y, turn.z);
        let pts: Vec<DVec3> = (0..n)
            .map(|_| {
                let u = DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                rot * (u * scale) + DVec3::new(0.3, -0.1, 0.2)
            })
            .collect();
        ConvexPolyhedron::from_convex_hull(&pts)
    }

    fn polytope(hull: &ConvexPolyhedron) -> Polytope {
        crate::spheres::convex_polytope(hull).unwrap()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// The proof of the module documentation, tested: for grids of every shape (cut in one,
        /// two and three directions, along the body's and the principal axes), a sphere about
        /// any centre reaching the points collected for its cell holds the hull's part in it —
        /// every sample of the hull, on its vertices, edges and faces and inside, lies in some
        /// sphere — and so does the fitted cover.
        #[test]
        fn every_grid_and_the_fitted_cover_hold_the_hull(
            seed in any::<u64>(),
            n in 4usize..60,
            scale in (0.002..0.5f64, 0.002..0.5f64, 0.002..0.5f64),
            turn in (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64),
        ) {
            let Some(hull) = random_hull(seed, n, DVec3::new(scale.0, scale.1, scale.2), DVec3::new(turn.0, turn.1, turn.2))
            else {
                return Ok(());
            };
            let poly = polytope(&hull);
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
            let samples = hull_samples(&hull, &mut rng);
            let fitted: Vec<(DVec3, f64)> = fitted_cover(&poly).iter().map(|s| (s.centre, s.radius)).collect();
            prop_assert!(!fitted.is_empty() && fitted.len() <= MAX_SPHERES);
            prop_assert_eq!(outside(&fitted, &samples), None);
            let mut frames = vec![[DVec3::X, DVec3::Y, DVec3::Z]];
            frames.extend(principal_axes(&poly.points));
            for frame in &frames {
                let grid = Grid::new(&poly, frame);
                for n in [[3, 3, 3], [2, 2, 1], [1, 3, 2], [4, 1, 1], [1, 1, 1]] {
                    let cells = grid.cell_points(&poly, n);
                    // Any centre: here one moved off the cell's points at random.
                    let spheres: Vec<(DVec3, f64)> = cells
                        .iter()
                        .map(|c| {
                            let (centre, _) = start_sphere(c);
                            let off = DVec3::new(
                                rng.random_range(-0.02..0.02),
                                rng.random_range(-0.02..0.02),
                                rng.random_range(-0.02..0.02),
                            );
                            let centre = centre + off;
                            (centre, reach(centre, c) * (1.0 + RADIUS_SLACK.0) + RADIUS_SLACK.1)
                        })
                        .collect();
                    prop_assert_eq!(outside(&spheres, &samples), None, "grid {:?}", n);
                }
            }
        }
    }

    /// The principal axes of a cloud stretched along a diagonal: the first is that diagonal.
    #[test]
    fn principal_axes_follow_the_spread() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let long = DVec3::new(1.0, 1.0, 0.0).normalize();
        let side = DVec3::new(1.0, -1.0, 2.0).normalize();
        let pts: Vec<DVec3> = (0..200)
            .map(|_| long * rng.random_range(-1.0..1.0) + side * rng.random_range(-0.1..0.1))
            .collect();
        let [x, y, z] = principal_axes(&pts).unwrap();
        assert!(x.dot(long).abs() > 0.999, "{x:?}");
        assert!(y.dot(side).abs() > 0.999, "{y:?}");
        assert!((x.dot(y)).abs() < 1e-12 && (z - x.cross(y)).length() < 1e-12);
    }

    /// A cube (its twelve edges, no diagonals) cut 3 × 3 × 1: its middle column meets no
    /// vertex and no edge of the cube, so the points that span it all come from the grid lines
    /// (kinds 3 and 4): its eight corners. Without them the middle of the cube would be left
    /// uncovered.
    #[test]
    fn the_middle_of_a_cut_cube_is_spanned_by_the_grid_lines() {
        let poly = super::super::box_polytope(DVec3::splat(0.5)).unwrap();
        assert_eq!(poly.edges.len(), 12);
        let grid = Grid::new(&poly, &[DVec3::X, DVec3::Y, DVec3::Z]);
        let cells = grid.cell_points(&poly, [3, 3, 1]);
        assert_eq!(cells.len(), 9);
        let sixth = |v: f64| (v.abs() - 1.0 / 6.0).abs() < 1e-12;
        let middle = cells
            .iter()
            .find(|c| c.iter().all(|p| p.x.abs() < 0.2 && p.y.abs() < 0.2))
            .expect("the middle cell has points");
        assert!(
            middle
                .iter()
                .all(|p| sixth(p.x) && sixth(p.y) && p.z.abs() == 0.5)
        );
        let mut corners: Vec<[i8; 3]> = middle
            .iter()
            .map(|p| p.signum().to_array().map(|v| v as i8))
            .collect();
        corners.sort_unstable();
        corners.dedup();
        assert_eq!(corners.len(), 8);
        let (c, r) = start_sphere(middle);
        assert!(c.length() < 1e-12);
        assert!((r - (2.0 / 36.0f64 + 0.25).sqrt()).abs() < 1e-12);
    }

    /// The fitted cover of a long box fits it: it sticks out by a few per cent of the box's
    /// size on average, where one bounding sphere sticks out by a third.
    #[test]
    fn a_long_box_is_covered_tightly() {
        let half = DVec3::new(0.25, 0.04, 0.03);
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { -1.0 } else { 1.0 };
                half * DVec3::new(s(1), s(2), s(4))
            })
            .collect();
        let hull = ConvexPolyhedron::from_convex_hull(&corners).unwrap();
        let poly = polytope(&hull);
        let scorer = Scorer::new(&poly.points);
        let fitted: Vec<(DVec3, f64)> = fitted_cover(&poly).iter().map(|s| (s.centre, s.radius)).collect();
        let excess = |s: &[(DVec3, f64)]| scorer.cost(s) - SPHERE_COST * s.len() as f64;
        let one = excess(&[(DVec3::ZERO, half.length())]);
        let fit = excess(&fitted);
        assert!(one > 0.08, "one sphere: {one}");
        assert!(fit < 0.01, "fitted: {fit} with {} spheres", fitted.len());
        assert!(fitted.len() >= 4, "cut along its length: {fitted:?}");
    }
}
