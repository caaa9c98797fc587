//! A convex hull with a fast support function (hill climbing on its edge graph).
//!
//! parry's `ConvexPolyhedron` finds a support point by scanning every vertex. A robot link's
//! hull has a few hundred, and GJK asks for a support point several times per triangle, so
//! that scan dominates the hot path. Here the search starts at a precomputed vertex (the
//! support of the centre of the direction's cell in a cube map of 6 × 8 × 8 cells) and climbs
//! along hull edges while a neighbour projects further. On a convex polytope a vertex that no
//! neighbour improves on is a maximum, so the answer is exact; it takes a step or two.
//!
//! (Plateaus: a point inside a face, with every neighbour equal, is only a maximum when the
//! face is the top one for the direction. The start is the top for a direction within 90° of
//! the query, and the climb only goes up, so it never starts on or reaches a bottom face.)
use crate::DVec3;
use parry3d_f64::shape::{ConvexPolyhedron, SupportMap};

/// Hulls with fewer points are scanned directly.
const MIN_POINTS: usize = 24;

/// A convex polyhedron's vertices and edge graph, for fast support queries.
#[derive(Clone, Debug)]
pub(crate) struct FastHull {
    points: Vec<DVec3>,
    /// Neighbours of vertex `v`: `adj[offsets[v]..offsets[v + 1]]`.
    offsets: Vec<u32>,
    adj: Vec<u32>,
    /// Start vertex per cube-map cell (see [`cell`]).
    start: Vec<u32>,
}

/// Cells per cube-map face side.
const GRID: usize = 8;

/// The cube-map cell of a direction: the face of its largest component, then its two other
/// components (divided by the largest) on a `GRID × GRID` grid. Zero or NaN directions give 0.
#[inline]
fn cell(dir: DVec3) -> usize {
    let a = dir.abs();
    let (face, u, v, m) = if a.x >= a.y && a.x >= a.z {
        (usize::from(dir.x < 0.0), dir.y, dir.z, a.x)
    } else if a.y >= a.z {
        (2 + usize::from(dir.y < 0.0), dir.z, dir.x, a.y)
    } else {
        (4 + usize::from(dir.z < 0.0), dir.x, dir.y, a.z)
    };
    if m.is_nan() || m <= 0.0 {
        return 0;
    }
    let grid = |w: f64| (((w / m + 1.0) * 0.5 * GRID as f64) as usize).min(GRID - 1);
    (face * GRID + grid(u)) * GRID + grid(v)
}

/// The direction at the centre of a cube-map cell (inverse of [`cell`]).
fn cell_centre(k: usize) -> DVec3 {
    let (face, rest) = (k / (GRID * GRID), k % (GRID * GRID));
    let w = |i: usize| (i as f64 + 0.5) / GRID as f64 * 2.0 - 1.0;
    let (u, v) = (w(rest / GRID), w(rest % GRID));
    let s = if face % 2 == 0 { 1.0 } else { -1.0 };
    match face / 2 {
        0 => DVec3::new(s, u, v),
        1 => DVec3::new(v, s, u),
        _ => DVec3::new(u, v, s),
    }
}

impl FastHull {
    /// The fast form of `poly`; `None` when the hull is small enough to scan (or has no edges).
    pub(crate) fn new(poly: &ConvexPolyhedron) -> Option<FastHull> {
        let points = poly.points().to_vec();
        if points.len() < MIN_POINTS {
            return None;
        }
        let n = points.len();
        let mut degree = vec![0u32; n + 1];
        let edges: Vec<[u32; 2]> = poly
            .edges()
            .iter()
            .map(|e| e.vertices)
            .filter(|&[a, b]| a != b && (a as usize) < n && (b as usize) < n)
            .collect();
        for &[a, b] in &edges {
            degree[a as usize] += 1;
            degree[b as usize] += 1;
        }
        let mut offsets = vec![0u32; n + 1];
        for v in 0..n {
            offsets[v + 1] = offsets[v] + degree[v];
        }
        let mut fill = offsets.clone();
        let mut adj = vec![0u32; offsets[n] as usize];
        for &[a, b] in &edges {
            adj[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            adj[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        let connected: Vec<usize> = (0..n).filter(|&v| offsets[v + 1] > offsets[v]).collect();
        if connected.is_empty() {
            return None;
        }
        let start = (0..6 * GRID * GRID)
            .map(|k| {
                let a = cell_centre(k);
                connected
                    .iter()
                    .copied()
                    .max_by(|&u, &v| points[u].dot(a).total_cmp(&points[v].dot(a)))
                    .unwrap_or(0) as u32
            })
            .collect();
        Some(FastHull {
            points,
            offsets,
            adj,
            start,
        })
    }
}

impl SupportMap for FastHull {
    #[inline]
    fn local_support_point(&self, dir: DVec3) -> DVec3 {
        let mut v = self.start[cell(dir)] as usize;
        let mut best = self.points[v].dot(dir);
        loop {
            let mut next = v;
            let range = self.offsets[v] as usize..self.offsets[v + 1] as usize;
            for &u in &self.adj[range] {
                let d = self.points[u as usize].dot(dir);
                if d > best {
                    best = d;
                    next = u as usize;
                }
            }
            if next == v {
                return self.points[v];
            }
            v = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load_mesh;
    use std::path::Path;

    fn check_against_scan(poly: &ConvexPolyhedron) {
        let fast = FastHull::new(poly).expect("large hull");
        for k in 0..4000 {
            // Directions spread over the sphere, plus the axes and near-axis ones (ties).
            let t = k as f64 * 2.399_963_229_728_653;
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 4000.0;
            let r = (1.0 - z * z).sqrt();
            let dir = match k % 8 {
                0 => [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z][k / 8 % 6],
                _ => DVec3::new(r * t.cos(), r * t.sin(), z),
            };
            let got = fast.local_support_point(dir).dot(dir);
            let want = poly.local_support_point(dir).dot(dir);
            assert!(
                (got - want).abs() <= 1e-12 * (1.0 + want.abs()),
                "{dir}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn hill_climbing_matches_scanning_on_robot_links() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision");
        for link in [
            "base_link",
            "link_1",
            "link_2",
            "link_3",
            "link_4",
            "link_5",
            "link_6",
        ] {
            let m = load_mesh(&dir.join(format!("{link}.stl"))).unwrap();
            check_against_scan(&ConvexPolyhedron::from_convex_hull(&m.vertices).unwrap());
        }
    }

    #[test]
    fn hill_climbing_matches_scanning_with_coplanar_points() {
        // A 40-sided prism: two faces of 40 coplanar vertices (plateaus for ±z), and a
        // squashed sphere-like cloud.
        let pts: Vec<DVec3> = (0..80)
            .map(|k| {
                let t = std::f64::consts::TAU * (k / 2) as f64 / 40.0;
                DVec3::new(t.cos(), 0.5 * t.sin(), if k % 2 == 0 { -1.0 } else { 1.0 })
            })
            .collect();
        check_against_scan(&ConvexPolyhedron::from_convex_hull(&pts).unwrap());
        let ball: Vec<DVec3> = (0..300)
            .map(|k| {
                let t = k as f64 * 2.4;
                let z = 1.0 - 2.0 * (k as f64 + 0.5) / 300.0;
                let r = (1.0 - z * z).sqrt();
                DVec3::new(r * t.cos(), 2.0 * r * t.sin(), 0.5 * z)
            })
            .collect();
        check_against_scan(&ConvexPolyhedron::from_convex_hull(&ball).unwrap());
    }

    #[test]
    fn cube_map_cells_round_trip() {
        for k in 0..6 * GRID * GRID {
            assert_eq!(cell(cell_centre(k)), k);
            assert_eq!(cell(cell_centre(k) * 3.7), k);
        }
        assert_eq!(cell(DVec3::ZERO), 0);
        assert_eq!(cell(DVec3::splat(f64::NAN)), 0);
        assert_eq!(cell(DVec3::new(1.0, 1.0, 1.0)), cell(DVec3::new(1.0, 0.99, 0.99)));
    }

    #[test]
    fn small_hulls_are_scanned() {
        let cube: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        assert!(FastHull::new(&ConvexPolyhedron::from_convex_hull(&cube).unwrap()).is_none());
    }
}
