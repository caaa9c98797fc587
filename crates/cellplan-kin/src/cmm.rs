//! A five-axis coordinate measuring machine (paper 003): three linear axes carry the ram, whose
//! end holds a two-axis probe head — B turns about the ram's (vertical) axis, A tilts the probe
//! away from straight down — and the probe: an extension of length L1 and a stylus of length L2
//! ending in a ball of diameter D0 (paper 003, Table 1: 50, 150 and 3 mm).
//!
//! Machine coordinates `q = [x, y, z, a, b]`: `x, y, z` the centre of the head's A axis (m), `a`,
//! `b` the head angles (rad). With `a = 0` the probe points straight down (−Z); `a > 0` tilts it
//! toward +X when `b = 0`. The probe direction is
//! `d(a, b) = (sin a cos b, sin a sin b, −cos a)`, and the ball centre sits `L1 + L2` along it.
//!
//! [`CmmHead::inverse`] is the closed form from a ball-centre position and a probe direction;
//! [`CmmSpeeds::move_time`] is paper 003's motion model (assumption 1: the machine either moves or
//! rotates, never both; movement at one speed, rotation at another), with a trapezoidal option.
use glam::DVec3;

/// Two angles closer than this are one (rad).
const ANGLE_TOL: f64 = 1e-9;

/// The head and probe of a five-axis CMM.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CmmHead {
    /// Probe extension length L1 (m).
    pub l1: f64,
    /// Stylus length L2 (m).
    pub l2: f64,
    /// Stylus ball diameter D0 (m).
    pub ball_diameter: f64,
    /// Range of the tilt A (rad), within [−π, π].
    pub a_range: [f64; 2],
    /// Range of the rotation B (rad), within [−2π, 2π].
    pub b_range: [f64; 2],
    /// Indexing step of both head axes (rad), for heads that stop only at multiples of it
    /// (e.g. 7.5° for a PH10); `None` for a continuous head.
    pub index_step: Option<f64>,
}

/// How fast the machine moves and turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CmmSpeeds {
    /// Speed of the linear axes along the straight path of the head (m/s); paper 003: 85 mm/s.
    pub movement: f64,
    /// Speed of each head axis (rad/s).
    pub rotation: f64,
    /// Acceleration of the linear motion (m/s²) and of the head axes (rad/s²), for the
    /// trapezoidal profile; `None`: full speed at once, as the paper assumes.
    pub acceleration: Option<(f64, f64)>,
}

/// A configuration `[x, y, z, a, b]`.
pub type CmmQ = [f64; 5];

impl CmmHead {
    /// Paper 003, Table 1: L1 = 50 mm, L2 = 150 mm, D0 = 3 mm; a continuous head with A in
    /// [0°, 105°] and B in [−180°, 180°] (a PH10-like range).
    pub fn paper() -> Self {
        CmmHead {
            l1: 0.050,
            l2: 0.150,
            ball_diameter: 0.003,
            a_range: [0.0, 105f64.to_radians()],
            b_range: [-std::f64::consts::PI, std::f64::consts::PI],
            index_step: None,
        }
    }

    /// Distance from the A-axis centre to the ball centre (m).
    pub fn reach(&self) -> f64 {
        self.l1 + self.l2
    }

    /// The probe direction at head angles `a`, `b` (unit, from the head toward the ball).
    pub fn direction(a: f64, b: f64) -> DVec3 {
        DVec3::new(a.sin() * b.cos(), a.sin() * b.sin(), -a.cos())
    }

    /// Ball centre and probe direction of a configuration.
    pub fn forward(&self, q: &CmmQ) -> (DVec3, DVec3) {
        let d = Self::direction(q[3], q[4]);
        (DVec3::new(q[0], q[1], q[2]) + self.reach() * d, d)
    }

    /// Whether the head angles are within range (and on the index grid, for an indexing head).
    pub fn angles_allowed(&self, a: f64, b: f64) -> bool {
        let inside = |v: f64, r: [f64; 2]| v >= r[0] - ANGLE_TOL && v <= r[1] + ANGLE_TOL;
        let on_grid = |v: f64| {
            self.index_step.is_none_or(|s| {
                let k = (v / s).round();
                (v - k * s).abs() <= 1e-7
            })
        };
        inside(a, self.a_range) && inside(b, self.b_range) && on_grid(a) && on_grid(b)
    }

    /// Every head-angle pair `(a, b)` that points the probe along `dir` within the ranges (and
    /// the index grid), each with the A-axis centre that puts the ball centre at `ball`; sorted
    /// by `a` then `b`. Up to four: `(a, b)`, `(−a, b ± π)`, and `b ± 2π` where B's range allows.
    /// Straight down (`a = 0`), B is free: `b_hint` is used when allowed, else the B nearest to
    /// it within range.
    pub fn inverse(&self, ball: DVec3, dir: DVec3, b_hint: f64) -> Vec<CmmQ> {
        let len = dir.length();
        if !(len.is_finite() && len > 1e-12 && ball.is_finite()) {
            return Vec::new();
        }
        let d = dir / len;
        let head = ball - self.reach() * d;
        let a = (-d.z).clamp(-1.0, 1.0).acos();
        let mut candidates: Vec<(f64, f64)> = Vec::new();
        if a.sin().abs() < 1e-9 {
            // Along the B axis: any B. Prefer the hint, clamped into range (and onto the grid,
            // within range); straight up, the tilt may also be −π.
            let (lo, hi) = match self.index_step {
                Some(s) => (
                    (self.b_range[0] / s - 1e-9).ceil() * s,
                    (self.b_range[1] / s + 1e-9).floor() * s,
                ),
                None => (self.b_range[0], self.b_range[1]),
            };
            let mut b = b_hint.clamp(lo, hi);
            if let Some(s) = self.index_step {
                b = ((b / s).round() * s).clamp(lo, hi);
            }
            candidates.push((a, b));
            if a > 1.0 {
                candidates.push((-a, b));
            }
        } else {
            let b = d.y.atan2(d.x);
            for (aa, bb) in [(a, b), (-a, b + std::f64::consts::PI)] {
                for turn in [-1.0, 0.0, 1.0] {
                    candidates.push((aa, bb + turn * std::f64::consts::TAU));
                }
            }
        }
        let mut out: Vec<CmmQ> = candidates
            .into_iter()
            .filter(|&(a, b)| self.angles_allowed(a, b))
            .map(|(a, b)| [head.x, head.y, head.z, a, b])
            .collect();
        out.sort_by(|p, q| p[3].total_cmp(&q[3]).then(p[4].total_cmp(&q[4])));
        out.dedup_by(|p, q| (p[3] - q[3]).abs() < ANGLE_TOL && (p[4] - q[4]).abs() < ANGLE_TOL);
        out
    }

    /// Every head orientation on the index grid within range (none for a continuous head).
    pub fn indexed_orientations(&self) -> Vec<(f64, f64)> {
        let Some(s) = self.index_step else {
            return Vec::new();
        };
        let steps = |r: [f64; 2]| {
            let lo = (r[0] / s - 1e-7).ceil() as i64;
            let hi = (r[1] / s + 1e-7).floor() as i64;
            (lo..=hi).map(move |k| k as f64 * s)
        };
        steps(self.a_range)
            .flat_map(|a| steps(self.b_range).map(move |b| (a, b)))
            .collect()
    }
}

impl CmmSpeeds {
    /// Paper 003, Table 1: movement 85 mm/s; the head turns at 1 rad/s here (the paper's table
    /// gives "1" without a usable unit); full speed at once.
    pub fn paper() -> Self {
        CmmSpeeds {
            movement: 0.085,
            rotation: 1.0,
            acceleration: None,
        }
    }

    fn profile(distance: f64, speed: f64, acceleration: Option<f64>) -> f64 {
        let d = distance.abs();
        match acceleration {
            None => d / speed,
            Some(a) if d * a >= speed * speed => d / speed + speed / a,
            Some(a) => 2.0 * (d / a).sqrt(),
        }
    }

    /// Time of the straight linear move of the head centre (s).
    pub fn movement_time(&self, from: &CmmQ, to: &CmmQ) -> f64 {
        let d = DVec3::new(to[0] - from[0], to[1] - from[1], to[2] - from[2]).length();
        Self::profile(d, self.movement, self.acceleration.map(|a| a.0))
    }

    /// Time of the head rotation (both axes together, the longer one decides) (s).
    pub fn rotation_time(&self, from: &CmmQ, to: &CmmQ) -> f64 {
        let turn = (to[3] - from[3]).abs().max((to[4] - from[4]).abs());
        Self::profile(turn, self.rotation, self.acceleration.map(|a| a.1))
    }

    /// Paper 003 assumption 1: the machine moves or rotates, one after the other.
    pub fn move_time(&self, from: &CmmQ, to: &CmmQ) -> f64 {
        self.movement_time(from, to) + self.rotation_time(from, to)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn inverse_of_forward_reproduces_the_configuration(
            x in -0.5..0.5f64, y in -0.5..0.5f64, z in 0.0..0.7f64,
            a in 0.01..1.8f64, b in -3.1..3.1f64,
        ) {
            let head = CmmHead::paper();
            let q = [x, y, z, a, b];
            let (ball, d) = head.forward(&q);
            prop_assert!((d.length() - 1.0).abs() < 1e-12);
            prop_assert!(((ball - DVec3::new(x, y, z)).length() - head.reach()).abs() < 1e-12);
            let sols = head.inverse(ball, d, 0.0);
            prop_assert!(!sols.is_empty());
            prop_assert!(sols.iter().any(|s| s.iter().zip(&q).all(|(u, v)| (u - v).abs() < 1e-9)), "{sols:?} vs {q:?}");
            for s in &sols {
                let (ball2, d2) = head.forward(s);
                prop_assert!((ball2 - ball).length() < 1e-9 && (d2 - d).length() < 1e-9);
                prop_assert!(head.angles_allowed(s[3], s[4]));
            }
        }
    }

    #[test]
    fn straight_down_keeps_b_and_ranges_and_grid_filter() {
        let head = CmmHead::paper();
        let sols = head.inverse(DVec3::new(0.1, 0.2, 0.3), -DVec3::Z, 0.4);
        assert_eq!(sols.len(), 1);
        assert!(
            (sols[0][2] - (0.3 + 0.2)).abs() < 1e-12,
            "the head sits L1 + L2 above the ball"
        );
        assert!((sols[0][4] - 0.4).abs() < 1e-12);
        // Pointing up is beyond A's 105°.
        assert!(head.inverse(DVec3::ZERO, DVec3::Z, 0.0).is_empty());
        // A negative tilt is outside [0, 105°]: one solution for a sideways probe.
        assert_eq!(head.inverse(DVec3::ZERO, DVec3::X, 0.0).len(), 1);
        // A head that tilts both ways also reaches it tilted back with B turned half a turn —
        // at B = +180° and at −180°, both ends of B's range.
        let both = CmmHead {
            a_range: [-1.8, 1.8],
            ..head
        };
        assert_eq!(both.inverse(DVec3::ZERO, DVec3::X, 0.0).len(), 3);
        // An indexing head reaches only directions on its grid.
        let indexed = CmmHead {
            index_step: Some(7.5f64.to_radians()),
            ..head
        };
        let on = CmmHead::direction(15f64.to_radians(), 45f64.to_radians());
        assert_eq!(indexed.inverse(DVec3::ZERO, on, 0.0).len(), 1);
        let off = CmmHead::direction(16f64.to_radians(), 45f64.to_radians());
        assert!(indexed.inverse(DVec3::ZERO, off, 0.0).is_empty());
        assert_eq!(indexed.indexed_orientations().len(), 15 * 49);
        assert!(
            head.inverse(DVec3::NAN, on, 0.0).is_empty()
                && head.inverse(DVec3::ZERO, DVec3::ZERO, 0.0).is_empty()
        );
    }

    #[test]
    fn moving_and_turning_take_turns() {
        let s = CmmSpeeds::paper();
        let from = [0.0, 0.0, 0.0, 0.0, 0.0];
        let to = [0.085, 0.0, 0.0, 0.5, -1.0];
        assert!((s.movement_time(&from, &to) - 1.0).abs() < 1e-12);
        assert!((s.rotation_time(&from, &to) - 1.0).abs() < 1e-12);
        assert!((s.move_time(&from, &to) - 2.0).abs() < 1e-12);
        let t = CmmSpeeds {
            acceleration: Some((0.5, 2.0)),
            ..s
        };
        // 85 mm at 85 mm/s with 0.5 m/s²: cruise reached, 1 s + 0.17 s.
        assert!((t.movement_time(&from, &to) - (1.0 + 0.085 / 0.5)).abs() < 1e-12);
        assert!(t.move_time(&from, &to) > s.move_time(&from, &to));
    }
}
