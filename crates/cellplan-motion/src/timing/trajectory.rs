//! Trajectories made of pieces of constant joint acceleration.

use super::TimingError;

/// One piece of a [`Trajectory`]: for `0 ≤ τ ≤ duration`, joint `j` is at
/// `position[j] + velocity[j]·τ + ½·acceleration[j]·τ²`.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Duration in s (≥ 0).
    pub duration: f64,
    /// Joint positions at the start of the piece.
    pub position: Vec<f64>,
    /// Joint velocities at the start of the piece.
    pub velocity: Vec<f64>,
    /// Constant joint accelerations over the piece.
    pub acceleration: Vec<f64>,
}

impl Piece {
    /// Positions `τ` s into the piece (not clamped).
    pub fn position_at(&self, tau: f64) -> Vec<f64> {
        (0..self.position.len())
            .map(|j| self.position[j] + tau * (self.velocity[j] + 0.5 * tau * self.acceleration[j]))
            .collect()
    }

    /// Velocities `τ` s into the piece (not clamped).
    pub fn velocity_at(&self, tau: f64) -> Vec<f64> {
        self.velocity
            .iter()
            .zip(&self.acceleration)
            .map(|(v, a)| v + a * tau)
            .collect()
    }

    /// Positions at the end of the piece.
    pub fn end_position(&self) -> Vec<f64> {
        self.position_at(self.duration)
    }

    /// Velocities at the end of the piece.
    pub fn end_velocity(&self) -> Vec<f64> {
        self.velocity_at(self.duration)
    }
}

/// A joint trajectory starting at t = 0: a sequence of [`Piece`]s played one after the other,
/// each with constant joint acceleration, so position, velocity and acceleration are exact.
/// Always has at least one piece. Queries clamp `t` to `[0, duration]`; at a boundary between
/// pieces the later piece answers (acceleration is right-continuous).
///
/// Continuity between pieces is not enforced by [`Trajectory::new`] or
/// [`Trajectory::append`]; [`check_limits`](super::check_limits) reports jumps. Trajectories
/// built by this module are continuous in position and velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    pieces: Vec<Piece>,
    starts: Vec<f64>,
    duration: f64,
}

impl Trajectory {
    /// A trajectory from its pieces. Errors: no pieces, joint counts differing between or
    /// within pieces, negative or non-finite durations, non-finite values.
    pub fn new(pieces: Vec<Piece>) -> Result<Self, TimingError> {
        let first = pieces.first().ok_or(TimingError::Empty("trajectory"))?;
        let dof = first.position.len();
        for (i, p) in pieces.iter().enumerate() {
            for (what, v) in [
                ("position", &p.position),
                ("velocity", &p.velocity),
                ("acceleration", &p.acceleration),
            ] {
                if v.len() != dof {
                    return Err(TimingError::DimensionMismatch {
                        what: format!("piece {i} {what}"),
                        expected: dof,
                        found: v.len(),
                    });
                }
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(TimingError::NonFinite(format!("piece {i} {what}")));
                }
            }
            if !p.duration.is_finite() {
                return Err(TimingError::NonFinite(format!("piece {i} duration")));
            }
            if p.duration < 0.0 {
                return Err(TimingError::NegativeDuration {
                    index: i,
                    duration: p.duration,
                });
            }
        }
        Ok(Self::from_pieces_unchecked(pieces))
    }

    pub(crate) fn from_pieces_unchecked(pieces: Vec<Piece>) -> Self {
        let mut starts = Vec::with_capacity(pieces.len());
        let mut t = 0.0;
        for p in &pieces {
            starts.push(t);
            t += p.duration;
        }
        Self {
            pieces,
            starts,
            duration: t,
        }
    }

    /// Standing still at `q` for `duration` s (e.g. a measurement, or waiting for another
    /// robot). Panics if `duration` is negative or not finite.
    ///
    /// ```
    /// use cellplan_motion::timing::Trajectory;
    /// let mut t = Trajectory::dwell(&[0.0, 1.0], 1.5);
    /// t.append(&Trajectory::dwell(&[0.0, 1.0], 0.5));
    /// assert_eq!(t.duration(), 2.0);
    /// assert_eq!(t.velocity(1.0), vec![0.0, 0.0]);
    /// ```
    pub fn dwell(q: &[f64], duration: f64) -> Self {
        assert!(
            duration.is_finite() && duration >= 0.0,
            "dwell duration {duration}"
        );
        Self::from_pieces_unchecked(vec![Piece {
            duration,
            position: q.to_vec(),
            velocity: vec![0.0; q.len()],
            acceleration: vec![0.0; q.len()],
        }])
    }

    /// The pieces, in time order.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// Start time of each piece, in s.
    pub fn piece_starts(&self) -> &[f64] {
        &self.starts
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.pieces[0].position.len()
    }

    /// Total duration in s.
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// Positions at t = 0.
    pub fn start_position(&self) -> Vec<f64> {
        self.pieces[0].position.clone()
    }

    /// Positions at the end.
    pub fn end_position(&self) -> Vec<f64> {
        self.pieces[self.pieces.len() - 1].end_position()
    }

    /// The piece answering for time `t` and the time into it.
    fn locate(&self, t: f64) -> (&Piece, f64) {
        let t = if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, self.duration)
        };
        let i = self.starts.partition_point(|&s| s <= t).saturating_sub(1);
        let p = &self.pieces[i];
        (p, (t - self.starts[i]).clamp(0.0, p.duration))
    }

    /// Joint positions at time `t` (clamped to `[0, duration]`).
    pub fn position(&self, t: f64) -> Vec<f64> {
        let (p, tau) = self.locate(t);
        p.position_at(tau)
    }

    /// Joint velocities at time `t` (clamped).
    pub fn velocity(&self, t: f64) -> Vec<f64> {
        let (p, tau) = self.locate(t);
        p.velocity_at(tau)
    }

    /// Joint accelerations at time `t` (clamped; right-continuous at piece boundaries).
    pub fn acceleration(&self, t: f64) -> Vec<f64> {
        self.locate(t).0.acceleration.clone()
    }

    /// Positions at `t = 0, dt, 2·dt, …` and at `duration` (always the last sample; a grid time
    /// within `1e-9·dt` of the end is replaced by it). Times strictly increase, except for a
    /// zero-duration trajectory, which gives the single sample `(0, start)`. Panics unless
    /// `dt > 0` and finite.
    pub fn sample(&self, dt: f64) -> Vec<(f64, Vec<f64>)> {
        assert!(dt.is_finite() && dt > 0.0, "sample step {dt}");
        let n = (self.duration / dt).floor() as usize;
        let mut out = Vec::with_capacity(n + 2);
        for k in 0..=n {
            let t = k as f64 * dt;
            if t >= self.duration - 1e-9 * dt {
                break;
            }
            out.push((t, self.position(t)));
        }
        out.push((self.duration, self.end_position()));
        out
    }

    /// Appends `other`, shifted in time to start when `self` ends. Panics if the joint counts
    /// differ. Does not check that `other` starts where `self` ends.
    pub fn append(&mut self, other: &Trajectory) {
        assert_eq!(self.dof(), other.dof(), "append: joint counts differ");
        for (p, s) in other.pieces.iter().zip(&other.starts) {
            self.starts.push(self.duration + s);
            self.pieces.push(p.clone());
        }
        self.duration += other.duration;
    }

    /// The concatenation of `parts`, each shifted to start when the previous ends. Errors on
    /// an empty list or differing joint counts.
    pub fn concat(parts: &[Trajectory]) -> Result<Self, TimingError> {
        let (first, rest) = parts.split_first().ok_or(TimingError::Empty("trajectory list"))?;
        let mut out = first.clone();
        for (i, p) in rest.iter().enumerate() {
            if p.dof() != out.dof() {
                return Err(TimingError::DimensionMismatch {
                    what: format!("trajectory {}", i + 1),
                    expected: out.dof(),
                    found: p.dof(),
                });
            }
            out.append(p);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Trajectory {
        // joint 0 accelerates at 2 for 1 s, then cruises at 2 for 1 s.
        Trajectory::new(vec![
            Piece {
                duration: 1.0,
                position: vec![0.0],
                velocity: vec![0.0],
                acceleration: vec![2.0],
            },
            Piece {
                duration: 1.0,
                position: vec![1.0],
                velocity: vec![2.0],
                acceleration: vec![0.0],
            },
        ])
        .unwrap()
    }

    #[test]
    fn queries() {
        let t = ramp();
        assert_eq!(t.duration(), 2.0);
        assert_eq!(t.position(0.5), vec![0.25]);
        assert_eq!(t.velocity(0.5), vec![1.0]);
        assert_eq!(t.acceleration(0.5), vec![2.0]);
        assert_eq!(t.acceleration(1.0), vec![0.0]);
        assert_eq!(t.position(1.5), vec![2.0]);
        assert_eq!(t.position(-3.0), vec![0.0]);
        assert_eq!(t.position(9.0), vec![3.0]);
        assert_eq!(t.end_position(), vec![3.0]);
        assert_eq!(t.velocity(f64::NAN), vec![0.0]);
    }

    #[test]
    fn sample_ends_at_duration() {
        let t = ramp();
        let s = t.sample(0.3);
        assert_eq!(s.len(), 8); // 0, .3, ..., 1.8, 2.0
        assert_eq!(s.last().unwrap(), &(2.0, vec![3.0]));
        assert!(s.windows(2).all(|w| w[0].0 < w[1].0));
        // grid hits the end exactly: no duplicate end sample
        let s = t.sample(0.5);
        assert_eq!(
            s.iter().map(|x| x.0).collect::<Vec<_>>(),
            vec![0.0, 0.5, 1.0, 1.5, 2.0]
        );
        let z = Trajectory::dwell(&[1.0], 0.0).sample(0.1);
        assert_eq!(z, vec![(0.0, vec![1.0])]);
    }

    #[test]
    fn append_and_concat_shift_time() {
        let mut t = ramp();
        t.append(&Trajectory::dwell(&[3.0], 1.0));
        assert_eq!(t.duration(), 3.0);
        assert_eq!(t.piece_starts(), &[0.0, 1.0, 2.0]);
        assert_eq!(t.position(2.5), vec![3.0]);
        let c = Trajectory::concat(&[Trajectory::dwell(&[0.0], 1.0), ramp()]).unwrap();
        assert_eq!(c.position(1.5), vec![0.25]);
        assert!(Trajectory::concat(&[]).is_err());
        assert!(Trajectory::concat(&[ramp(), Trajectory::dwell(&[0.0, 0.0], 1.0)]).is_err());
    }

    #[test]
    fn new_validates() {
        assert!(Trajectory::new(vec![]).is_err());
        let bad = Piece {
            duration: -1.0,
            position: vec![0.0],
            velocity: vec![0.0],
            acceleration: vec![0.0],
        };
        assert!(matches!(
            Trajectory::new(vec![bad]),
            Err(TimingError::NegativeDuration { .. })
        ));
        let bad = Piece {
            duration: 1.0,
            position: vec![0.0],
            velocity: vec![0.0, 1.0],
            acceleration: vec![0.0],
        };
        assert!(matches!(
            Trajectory::new(vec![bad]),
            Err(TimingError::DimensionMismatch { .. })
        ));
    }
}
