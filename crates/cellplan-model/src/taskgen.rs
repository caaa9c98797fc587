//! Generating measurement points on a part's surface for building cells: area-weighted samples,
//! normals turned to the side that can be seen from outside, spread apart by farthest-point
//! selection. Deterministic for a seed.
use crate::tasks::{Feature, Task, TaskId};
use cellplan_geom::{CollisionWorld, DVec3, Mesh, Pose, ShapeSpec};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;

/// What to generate.
#[derive(Clone, Debug)]
pub struct GenOptions {
    /// How many points.
    pub count: usize,
    /// RNG seed.
    pub seed: u64,
    /// Per axis (x, y, z): keep points with `lo ≤ coordinate ≤ hi` (mesh units).
    pub region: [(f64, f64); 3],
    /// Keep points whose outward normal is within `angle` (rad) of this unit direction.
    pub facing: Option<(DVec3, f64)>,
}

impl GenOptions {
    /// `count` points anywhere, facing anywhere.
    pub fn new(count: usize, seed: u64) -> Self {
        GenOptions {
            count,
            seed,
            region: [(f64::NEG_INFINITY, f64::INFINITY); 3],
            facing: None,
        }
    }
}

/// Why [`sample_tasks`] found too few points.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TaskGenError {
    /// The mesh has no vertices.
    #[error("the mesh is empty")]
    Empty,
    /// The mesh's triangles have no area.
    #[error("the mesh has no area")]
    NoArea,
    /// Fewer points qualify than asked for.
    #[error(
        "only {found} surface points in the region face outwards as asked, fewer than the {wanted} wanted"
    )]
    TooFew {
        /// Points that qualify.
        found: usize,
        /// Points asked for.
        wanted: usize,
    },
}

/// Points and outward normals on `mesh` (mesh units and frame), named `M1`, `M2`, ... in order
/// along the mesh's longest axis. Errors say why too few points qualify.
pub fn sample_tasks(mesh: &Mesh, opts: &GenOptions) -> Result<Vec<Task>, TaskGenError> {
    let (lo, hi) = mesh.aabb().ok_or(TaskGenError::Empty)?;
    let diagonal = (hi - lo).length();
    let centre = (lo + hi) / 2.0;
    let mut world = CollisionWorld::new();
    world.add_static("part", &ShapeSpec::Mesh(Arc::new(mesh.clone())), Pose::IDENTITY);

    let areas: Vec<f64> = (0..mesh.triangles.len()).map(|i| mesh.triangle_area(i)).collect();
    let mut cumulative = Vec::with_capacity(areas.len());
    let mut total = 0.0;
    for a in &areas {
        total += a;
        cumulative.push(total);
    }
    if total <= 0.0 {
        return Err(TaskGenError::NoArea);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let pool_size = (opts.count * 60).max(3000);
    let eps = diagonal * 1e-5;
    let escapes = |p: DVec3, d: DVec3| world.cast_ray_static(p + d * eps, d, diagonal * 10.0).is_none();
    let mut pool: Vec<(DVec3, DVec3)> = Vec::new();
    for _ in 0..pool_size * 4 {
        if pool.len() >= pool_size {
            break;
        }
        let r = rng.random_range(0.0..total);
        let tri = cumulative.partition_point(|&c| c < r).min(areas.len() - 1);
        let (mut u, mut v): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let [a, b, c] = mesh.triangles[tri].map(|i| mesh.vertices[i as usize]);
        let p = a + (b - a) * u + (c - a) * v;
        if (0..3).any(|k| p[k] < opts.region[k].0 || p[k] > opts.region[k].1) {
            continue;
        }
        let n = mesh.triangle_normal(tri);
        if n == DVec3::ZERO {
            continue;
        }
        let outward = match (escapes(p, n), escapes(p, -n)) {
            (true, false) => n,
            (false, true) => -n,
            (true, true) => {
                if (p - centre).dot(n) >= 0.0 {
                    n
                } else {
                    -n
                }
            }
            (false, false) => continue,
        };
        if let Some((dir, angle)) = opts.facing
            && outward.dot(dir) < angle.cos()
        {
            continue;
        }
        pool.push((p, outward));
    }
    if pool.len() < opts.count {
        return Err(TaskGenError::TooFew {
            found: pool.len(),
            wanted: opts.count,
        });
    }
    // Farthest-point selection from a seeded first point.
    let mut chosen = vec![rng.random_range(0..pool.len())];
    let mut nearest: Vec<f64> = pool
        .iter()
        .map(|(p, _)| (*p - pool[chosen[0]].0).length())
        .collect();
    while chosen.len() < opts.count {
        let (next, _) =
            nearest.iter().enumerate().fold(
                (0, f64::NEG_INFINITY),
                |best, (i, &d)| if d > best.1 { (i, d) } else { best },
            );
        chosen.push(next);
        for (i, (p, _)) in pool.iter().enumerate() {
            nearest[i] = nearest[i].min((*p - pool[next].0).length());
        }
    }
    let axis = (hi - lo).max_position();
    chosen.sort_by(|&a, &b| pool[a].0[axis].total_cmp(&pool[b].0[axis]));
    Ok(chosen
        .iter()
        .enumerate()
        .map(|(k, &i)| Task {
            id: TaskId(k),
            name: format!("M{}", k + 1),
            position: pool[i].0,
            normal: pool[i].1,
            values: Vec::new(),
            feature: Feature::Surface,
            line: k + 2,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed unit cube as a mesh.
    fn cube() -> Mesh {
        ShapeSpec::Box {
            half_extents: DVec3::splat(0.5),
        }
        .to_mesh()
    }

    #[test]
    fn points_lie_on_the_surface_with_outward_normals() {
        let tasks = sample_tasks(&cube(), &GenOptions::new(20, 7)).unwrap();
        assert_eq!(tasks.len(), 20);
        for t in &tasks {
            // On a face of the cube: one coordinate at ±0.5, the normal along it, pointing out.
            let k = t.position.abs().max_position();
            assert!((t.position[k].abs() - 0.5).abs() < 1e-9);
            assert!((t.normal[k] - t.position[k].signum()).abs() < 1e-9, "{t:?}");
        }
    }

    #[test]
    fn same_seed_same_points_and_spread_apart() {
        let a = sample_tasks(&cube(), &GenOptions::new(12, 3)).unwrap();
        let b = sample_tasks(&cube(), &GenOptions::new(12, 3)).unwrap();
        assert!(a.iter().zip(&b).all(|(x, y)| x.position == y.position));
        let min = a
            .iter()
            .flat_map(|x| {
                a.iter()
                    .filter(move |y| y.name != x.name)
                    .map(move |y| (x.position - y.position).length())
            })
            .fold(f64::INFINITY, f64::min);
        assert!(min > 0.2, "closest pair {min}");
    }

    #[test]
    fn region_and_facing_filter() {
        let mut o = GenOptions::new(5, 1);
        o.facing = Some((DVec3::X, 0.1));
        let t = sample_tasks(&cube(), &o).unwrap();
        assert!(t.iter().all(|t| t.normal.dot(DVec3::X) > 0.99));
        let mut o = GenOptions::new(5, 1);
        o.region[2] = (0.4, f64::INFINITY);
        let t = sample_tasks(&cube(), &o).unwrap();
        assert!(t.iter().all(|t| t.position.z >= 0.4));
        let mut o = GenOptions::new(5, 1);
        o.region[0] = (5.0, 6.0);
        assert!(sample_tasks(&cube(), &o).is_err());
    }
}
