//! Convex pieces of a concave mesh: the hull of a concave link (a forearm whose end bends
//! round the wrist) fills space the link does not, and a body made of that hull touches its
//! neighbours where the link does not. Cut into a few convex pieces, the bodies fit.
use crate::{DVec3, Mesh};
use parry3d_f64::shape::ConvexPolyhedron;
use parry3d_f64::transformation::vhacd::{VHACD, VHACDParameters};

/// Meshes with more triangles than this are left whole (the decomposition's time grows with
/// them; fine-tessellated meshes are usually of near-convex parts).
pub const MAX_TRIANGLES: usize = 5_000;

/// A mesh is cut only when its hull's volume exceeds its own by this factor.
pub const CONCAVITY_RATIO: f64 = 1.5;

/// Volume enclosed by a closed triangle mesh (divergence theorem; absolute value).
fn volume(vertices: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| vertices.get(i as usize).copied());
            Some(a?.dot(b?.cross(c?)) / 6.0)
        })
        .sum::<f64>()
        .abs()
}

/// The convex pieces of `mesh` when it is markedly concave (hull volume over
/// [`CONCAVITY_RATIO`] times its own, at most [`MAX_TRIANGLES`] triangles): V-HACD (parry)
/// cuts it, and each piece is the convex hull of the **original triangles** in its part, so the
/// pieces together contain every triangle of the mesh. `None` when the mesh is left whole.
/// Deterministic.
pub fn convex_pieces(mesh: &Mesh) -> Option<Vec<Vec<DVec3>>> {
    if mesh.triangles.len() > MAX_TRIANGLES || mesh.triangles.len() < 8 {
        return None;
    }
    let own = volume(&mesh.vertices, &mesh.triangles);
    let hull = ConvexPolyhedron::from_convex_hull(&mesh.vertices)?;
    let (hv, ht) = hull.to_trimesh();
    let hull_volume = volume(&hv, &ht);
    if own.is_nan() || own <= 0.0 || hull_volume < CONCAVITY_RATIO * own {
        return None;
    }
    let params = VHACDParameters {
        concavity: 0.005,
        max_convex_hulls: 4,
        ..VHACDParameters::default()
    };
    let parts = VHACD::decompose(&params, &mesh.vertices, &mesh.triangles, true)
        .compute_exact_convex_hulls(&mesh.vertices, &mesh.triangles);
    let pieces: Vec<Vec<DVec3>> = parts
        .into_iter()
        .map(|(v, _)| v)
        .filter(|v| v.len() >= 4)
        .collect();
    (pieces.len() > 1).then_some(pieces)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L of two boxes: concave, cut into pieces whose union holds every vertex and whose
    /// total volume is well below the hull's.
    #[test]
    fn an_l_is_cut_into_convex_pieces() {
        // The L as an outline extruded 0.2 in z.
        let outline = [
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 0.2),
            (0.2, 0.2),
            (0.2, 1.0),
            (0.0, 1.0),
        ];
        let n = outline.len() as u32;
        let mut vertices = Vec::new();
        for z in [0.0, 0.2] {
            vertices.extend(outline.iter().map(|&(x, y)| DVec3::new(x, y, z)));
        }
        let mut triangles = Vec::new();
        // Caps (fan from vertex 0 of the non-convex outline works for this L: it is star-shaped
        // from the corner (0, 0)).
        for k in 1..n - 1 {
            triangles.push([0, k + 1, k]);
            triangles.push([n, n + k, n + k + 1]);
        }
        for k in 0..n {
            let j = (k + 1) % n;
            triangles.push([k, j, n + j]);
            triangles.push([k, n + j, n + k]);
        }
        let mesh = Mesh { vertices, triangles };
        let pieces = convex_pieces(&mesh).expect("the L is concave");
        assert!(pieces.len() >= 2);
        let total: f64 = pieces
            .iter()
            .map(|p| {
                let h = ConvexPolyhedron::from_convex_hull(p).unwrap();
                let (v, t) = h.to_trimesh();
                volume(&v, &t)
            })
            .sum();
        // The L's own volume is 0.072, its hull's 0.104.
        assert!(total < 0.1, "{total}");
        // Every vertex and every triangle's centroid lies in some piece.
        use parry3d_f64::query::PointQuery;
        let hulls: Vec<ConvexPolyhedron> = pieces
            .iter()
            .map(|p| ConvexPolyhedron::from_convex_hull(p).unwrap())
            .collect();
        let inside = |q: DVec3| hulls.iter().any(|h| h.distance_to_local_point(q, true) < 1e-9);
        for v in &mesh.vertices {
            assert!(inside(*v), "{v:?} in no piece");
        }
        for t in &mesh.triangles {
            let c = t.iter().map(|&i| mesh.vertices[i as usize]).sum::<DVec3>() / 3.0;
            assert!(inside(c), "{c:?} in no piece");
        }
        // A box stays whole.
        let cube = crate::ShapeSpec::Box {
            half_extents: DVec3::splat(0.5),
        }
        .to_mesh();
        assert!(convex_pieces(&cube).is_none());
    }
}
