//! Building a test part's triangle mesh face by face: planar rectangles in a [`Frame`], cut
//! into cells around circular openings ([`Circle`]) whose walls go into the part (holes,
//! bores) or out of it (bosses), as [`Opening`] says. Faces meet with T-junctions along shared
//! cell edges: exact for distances, not for inside/outside tests. Shared by the test parts of
//! [`crate::part`] and [`crate::housing`].
use cellplan_geom::Mesh;
use glam::DVec3;
use std::f64::consts::TAU;

/// A planar frame: a point and two unit axes; the face's outward normal is `u × v`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub(crate) origin: DVec3,
    pub(crate) u: DVec3,
    pub(crate) v: DVec3,
}

impl Frame {
    /// The point at (s, t).
    pub(crate) fn at(&self, s: f64, t: f64) -> DVec3 {
        self.origin + s * self.u + t * self.v
    }

    /// The face's outward unit normal.
    pub(crate) fn normal(&self) -> DVec3 {
        self.u.cross(self.v).normalize()
    }

    /// The same frame moved `d` along its normal.
    pub(crate) fn offset(&self, d: f64) -> Frame {
        Frame {
            origin: self.origin + d * self.normal(),
            ..*self
        }
    }
}

/// A circle cut into (or standing on) a face: centre in the face's (s, t), radius, and how far
/// it goes: negative into the part (a bore or hole), positive out of it (a boss).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Circle {
    pub(crate) s: f64,
    pub(crate) t: f64,
    pub(crate) r: f64,
    pub(crate) depth: f64,
}

impl Circle {
    /// The angle of the circle's ring vertex nearest `phi` (rad, from the frame's `u` toward
    /// `v`) with `segments` segments.
    pub(crate) fn vertex_angle(phi: f64, segments: usize) -> f64 {
        let n = segments as f64;
        TAU * (phi / TAU * n).round().rem_euclid(n) / n
    }

    /// A point of the wall of this circle cut into face `f`, `below` the face (into the part),
    /// on the ring vertex nearest the angle `phi` — on a vertical edge of the wall's mesh, so
    /// exactly on the mesh whatever `segments` — and the wall's normal there for a hole (facing
    /// the axis).
    pub(crate) fn wall_point(&self, f: &Frame, phi: f64, below: f64, segments: usize) -> (DVec3, DVec3) {
        let phi = Self::vertex_angle(phi, segments);
        let ring = f.at(self.s + self.r * phi.cos(), self.t + self.r * phi.sin());
        let n = f.normal();
        (ring - below * n, -(phi.cos() * f.u + phi.sin() * f.v).normalize())
    }
}

/// What is built at a circle cut into a face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Opening {
    /// The wall and its end: a blind hole's bottom (`depth < 0`) or a boss's face (`depth > 0`).
    Closed,
    /// A boss (`depth > 0`) whose face carries a blind bore of radius `r`, `depth` deep below
    /// the boss's face: the boss's wall, the ring between the two circles, the bore's wall and
    /// bottom.
    BoredBoss {
        /// The bore's radius.
        r: f64,
        /// The bore's depth below the boss's face.
        depth: f64,
    },
    /// A hole through the part: its wall only, open at the far end, where the face the hole
    /// comes out of is cut with [`Opening::Bare`].
    Through,
    /// The opening alone (the far end of a [`Opening::Through`] hole).
    Bare,
}

/// A mesh under construction.
#[derive(Default)]
pub(crate) struct Builder {
    pub(crate) mesh: Mesh,
}

impl Builder {
    /// A new vertex.
    pub(crate) fn vertex(&mut self, p: DVec3) -> u32 {
        self.mesh.vertices.push(p);
        (self.mesh.vertices.len() - 1) as u32
    }

    /// A triangle wound so that its normal points along `facing`.
    pub(crate) fn tri(&mut self, a: u32, b: u32, c: u32, facing: DVec3) {
        let v = &self.mesh.vertices;
        let n = (v[b as usize] - v[a as usize]).cross(v[c as usize] - v[a as usize]);
        if n.dot(facing) >= 0.0 {
            self.mesh.triangles.push([a, b, c]);
        } else {
            self.mesh.triangles.push([a, c, b]);
        }
    }

    /// A rectangle [s0, s1] × [t0, t1] of a face, with blind circular openings (`depth < 0`;
    /// circles with `depth ≥ 0` are left out) cut into it: see [`Builder::face`].
    pub(crate) fn rect_face(
        &mut self,
        f: &Frame,
        s: [f64; 2],
        t: [f64; 2],
        holes: &[Circle],
        segments: usize,
    ) {
        let openings: Vec<(Circle, Opening)> = holes
            .iter()
            .filter(|h| h.depth < 0.0)
            .map(|&h| (h, Opening::Closed))
            .collect();
        self.face(f, s, t, &openings, segments);
    }

    /// A rectangle [s0, s1] × [t0, t1] of a face, with circular openings cut into it: cut into
    /// cells along s, one per opening (split halfway between neighbouring centres, so the
    /// openings must lie in distinct bands of s), each triangulated between the circle and the
    /// cell's border by angle, and each opening built as its [`Opening`] says.
    pub(crate) fn face(
        &mut self,
        f: &Frame,
        s: [f64; 2],
        t: [f64; 2],
        openings: &[(Circle, Opening)],
        segments: usize,
    ) {
        let n = f.normal();
        let mut openings = openings.to_vec();
        openings.sort_by(|a, b| a.0.s.total_cmp(&b.0.s));
        let mut edges = vec![s[0]];
        for w in openings.windows(2) {
            edges.push(0.5 * (w[0].0.s + w[1].0.s));
        }
        edges.push(s[1]);
        if openings.is_empty() {
            let q = [
                f.at(s[0], t[0]),
                f.at(s[1], t[0]),
                f.at(s[1], t[1]),
                f.at(s[0], t[1]),
            ]
            .map(|p| self.vertex(p));
            self.tri(q[0], q[1], q[2], n);
            self.tri(q[0], q[2], q[3], n);
            return;
        }
        for (k, (h, opening)) in openings.iter().enumerate() {
            let (a, b) = (edges[k], edges[k + 1]);
            self.cell_with_opening(f, [a, b], t, h, *opening, segments);
        }
    }

    /// One cell [a, b] × [t0, t1] around an opening, and what the opening is built into.
    fn cell_with_opening(
        &mut self,
        f: &Frame,
        sr: [f64; 2],
        tr: [f64; 2],
        h: &Circle,
        opening: Opening,
        segments: usize,
    ) {
        let n = f.normal();
        // The circle's points, counter-clockwise in (s, t).
        let ring: Vec<(f64, DVec3)> = (0..segments)
            .map(|j| {
                let phi = TAU * j as f64 / segments as f64;
                (phi, f.at(h.s + h.r * phi.cos(), h.t + h.r * phi.sin()))
            })
            .collect();
        // The border: the ray from the centre at each circle angle, and the four corners.
        let mut border: Vec<(f64, DVec3)> = ring
            .iter()
            .map(|&(phi, _)| {
                let (c, s) = (phi.cos(), phi.sin());
                let mut best = f64::INFINITY;
                for (lim, dir) in [(sr[0], c), (sr[1], c)] {
                    if dir.abs() > 1e-12 {
                        let l = (lim - h.s) / dir;
                        if l > 0.0 {
                            best = best.min(l);
                        }
                    }
                }
                for (lim, dir) in [(tr[0], s), (tr[1], s)] {
                    if dir.abs() > 1e-12 {
                        let l = (lim - h.t) / dir;
                        if l > 0.0 {
                            best = best.min(l);
                        }
                    }
                }
                (phi, f.at(h.s + best * c, h.t + best * s))
            })
            .collect();
        for (cs, ct) in [(sr[0], tr[0]), (sr[1], tr[0]), (sr[1], tr[1]), (sr[0], tr[1])] {
            let corner = f.at(cs, ct);
            // A ray that ends on the corner already put it in (as a second point there it
            // would leave a triangle without area).
            if border[..segments].iter().any(|(_, p)| p.distance(corner) < 1e-9) {
                continue;
            }
            let ang = (ct - h.t).atan2(cs - h.s).rem_euclid(TAU);
            border.push((ang, corner));
        }
        border.sort_by(|x, y| x.0.total_cmp(&y.0));
        let ring_ids: Vec<u32> = ring.iter().map(|&(_, p)| self.vertex(p)).collect();
        let border_ids: Vec<u32> = border.iter().map(|&(_, p)| self.vertex(p)).collect();
        // Zip the two loops by angle.
        let (ni, no) = (ring.len(), border.len());
        let (mut i, mut o) = (0usize, 0usize);
        while i < ni || o < no {
            let next_i = if i < ni {
                ring[(i + 1) % ni].0 + if i + 1 == ni { TAU } else { 0.0 }
            } else {
                f64::INFINITY
            };
            let next_o = if o < no {
                border[(o + 1) % no].0 + if o + 1 == no { TAU } else { 0.0 }
            } else {
                f64::INFINITY
            };
            if next_o <= next_i {
                self.tri(ring_ids[i % ni], border_ids[o % no], border_ids[(o + 1) % no], n);
                o += 1;
            } else {
                self.tri(ring_ids[i % ni], border_ids[o % no], ring_ids[(i + 1) % ni], n);
                i += 1;
            }
        }
        match opening {
            Opening::Closed => self.cylinder(f, h, &ring_ids, segments),
            Opening::Through => {
                self.wall(f, h, &ring_ids, segments);
            }
            Opening::Bare => {}
            Opening::BoredBoss { r, depth } => self.bored_boss(f, h, &ring_ids, r, depth, segments),
        }
    }

    /// The wall of a circle from its ring on the face to `depth` along the face normal: into the
    /// part (`depth < 0`) facing the axis, out of it (a boss) facing away. Returns the ring at
    /// the far end.
    fn wall(&mut self, f: &Frame, h: &Circle, ring: &[u32], segments: usize) -> Vec<u32> {
        let n = f.normal();
        let end: Vec<u32> = (0..segments)
            .map(|j| {
                let p = self.mesh.vertices[ring[j] as usize];
                self.vertex(p + h.depth * n)
            })
            .collect();
        let sign = if h.depth < 0.0 { -1.0 } else { 1.0 };
        for j in 0..segments {
            let k = (j + 1) % segments;
            let mid = TAU * (j as f64 + 0.5) / segments as f64;
            let radial = (mid.cos() * f.u + mid.sin() * f.v).normalize();
            self.tri(ring[j], ring[k], end[k], sign * radial);
            self.tri(ring[j], end[k], end[j], sign * radial);
        }
        end
    }

    /// The wall of a circle (see [`Builder::wall`]) and its end cap, which faces out of the
    /// opening (a hole's bottom) or outward (a boss's face): along the face normal either way.
    fn cylinder(&mut self, f: &Frame, h: &Circle, ring: &[u32], segments: usize) {
        let n = f.normal();
        let end = self.wall(f, h, ring, segments);
        let c = self.vertex(f.at(h.s, h.t) + h.depth * n);
        for j in 0..segments {
            self.tri(c, end[j], end[(j + 1) % segments], n);
        }
    }

    /// A boss (`h.depth > 0`) on the ring `ring` with a blind bore of radius `r`, `depth` deep
    /// below the boss's face: the boss's wall, the ring between the circles on the boss's face,
    /// the bore's wall and bottom.
    fn bored_boss(&mut self, f: &Frame, h: &Circle, ring: &[u32], r: f64, depth: f64, segments: usize) {
        let n = f.normal();
        let end = self.wall(f, h, ring, segments);
        let top = f.offset(h.depth);
        let inner: Vec<u32> = (0..segments)
            .map(|j| {
                let phi = TAU * j as f64 / segments as f64;
                self.vertex(top.at(h.s + r * phi.cos(), h.t + r * phi.sin()))
            })
            .collect();
        for j in 0..segments {
            let k = (j + 1) % segments;
            self.tri(end[j], end[k], inner[k], n);
            self.tri(end[j], inner[k], inner[j], n);
        }
        let bore = Circle {
            s: h.s,
            t: h.t,
            r,
            depth: -depth,
        };
        self.cylinder(&top, &bore, &inner, segments);
    }

    /// A boss standing on a face (its base lies on the face, which is left whole).
    pub(crate) fn boss(&mut self, f: &Frame, h: &Circle, segments: usize) {
        let ring: Vec<u32> = (0..segments)
            .map(|j| {
                let phi = TAU * j as f64 / segments as f64;
                self.vertex(f.at(h.s + h.r * phi.cos(), h.t + h.r * phi.sin()))
            })
            .collect();
        self.cylinder(f, h, &ring, segments);
    }
}
