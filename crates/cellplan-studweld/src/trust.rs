//! Collision trust regions (paper 002 §2.4): starting from a collision-free trajectory, each
//! iteration solves the OCP with every grid point `q_i` kept in a box around the previous
//! iterate's, `n · max_j w_j |q_ij^{k+1} − q_ij^k| ≤ s · (φ(q_i^k) − d_c)`, then checks the new
//! trajectory densely; a trajectory that breaks the clearance is rejected and the boxes halved
//! (backtracking); the iteration stops when the cost falls by less than [`TrustSettings::
//! min_gain`] (relative) or after [`TrustSettings::iterations`].
//!
//! Here `φ` is the clearance of `q_i^k` in the leg planner's validity test (the distance of the
//! bodies to the scene less the cell's clearance, half the smallest self distance), and `w_j` is
//! the paper's `max_p ‖∂p/∂q_j‖₁` at `q_i^k` over the robot's points
//! ([`cellplan_motion::arm::point_speed_weights`], bounded from above over the bodies' sphere
//! covers). A point then moves by at most `Σ_j w_j |Δq_j| ≤ n max_j w_j |Δq_j|` to first order,
//! so at `s = 1` (the paper's box) the new grid points keep their clearance to first order, as
//! the paper says; it is the dense check of every new trajectory (grid points and the pieces
//! between them, by the motion core's conservative segment check) that proves it.
//!
//! Two things the paper leaves open, measured on `examples/studweld-kr210`:
//! - **The first iterate.** A path is not a trajectory: with its grid pinned in boxes of a few
//!   millimetres (planner paths graze the obstacles at the clearance) the DMOC rows have no
//!   solution — every boxed solve from the path's grid ended `LocallyInfeasible`, and 6 of 21
//!   moves fell back to timed paths. The iteration therefore starts from the dynamics'
//!   trajectory nearest the path (J plus a tracking term, [`TRACKING`]), kept when it is clear:
//!   it satisfies every constraint, so every boxed problem after it has a solution (the iterate
//!   itself). The path given should have room ([`crate::leg::roomy_path`]).
//! - **The boxes' scale `s`.** At the paper's `s = 1` each step moves the grid by millimetres
//!   and J falls by about 1 % per solve; `s` doubles after each accepted iterate (up to
//!   [`TrustSettings::max_scale`]) and halves after each rejected one — the dense check, not
//!   the box, decides what is kept.
use crate::cell::WeldCell;
use crate::leg::{Dmoc, unpack};
use cellplan_core::motion::{joint_radii, robot_validity};
use cellplan_motion::arm::point_speed_weights;
use cellplan_ocp::nlp::{self, Nlp, Status, Triplets};
use cellplan_ocp::problem::Move;

/// Tunables of the trust-region iteration.
#[derive(Clone, Copy, Debug)]
pub struct TrustSettings {
    /// Most accepted iterations.
    pub iterations: usize,
    /// Most halvings of the boxes after a rejected trajectory.
    pub backtracks: usize,
    /// Stop when the cost falls by less than this fraction.
    pub min_gain: f64,
    /// `d_c` (m): clearance kept beyond the cell's at grid points.
    pub extra_clearance: f64,
    /// Largest scale of the boxes over the paper's (which prove the grid points clear).
    pub max_scale: f64,
}

impl Default for TrustSettings {
    fn default() -> Self {
        TrustSettings {
            iterations: 20,
            backtracks: 3,
            min_gain: 1e-3,
            extra_clearance: 0.0,
            max_scale: 1024.0,
        }
    }
}

/// A [`Move`] with its variables boxed in `lo..hi` and, when `track` is given as
/// `(target, weight)`, `Σ_k weight_k (x_k − target_k)²` added to J.
struct Shaped<'a, 'b> {
    m: &'b Move<'a>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    track: Option<(Vec<f64>, Vec<f64>)>,
}

impl Nlp for Shaped<'_, '_> {
    fn num_vars(&self) -> usize {
        self.m.num_vars()
    }
    fn num_eq(&self) -> usize {
        self.m.num_eq()
    }
    fn num_ineq(&self) -> usize {
        self.m.num_ineq()
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (self.lo.clone(), self.hi.clone())
    }
    fn ineq_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        self.m.ineq_bounds()
    }
    fn initial_point(&self) -> Vec<f64> {
        self.m.initial_point()
    }
    fn objective(&self, x: &[f64]) -> f64 {
        let mut f = Nlp::objective(self.m, x);
        if let Some((target, weight)) = &self.track {
            for k in 0..x.len() {
                f += weight[k] * (x[k] - target[k]).powi(2);
            }
        }
        f
    }
    fn gradient(&self, x: &[f64]) -> Vec<f64> {
        let mut g = Nlp::gradient(self.m, x);
        if let Some((target, weight)) = &self.track {
            for k in 0..x.len() {
                g[k] += 2.0 * weight[k] * (x[k] - target[k]);
            }
        }
        g
    }
    fn eq(&self, x: &[f64]) -> Vec<f64> {
        self.m.eq(x)
    }
    fn eq_jacobian(&self, x: &[f64]) -> Triplets {
        self.m.eq_jacobian(x)
    }
    fn ineq(&self, x: &[f64]) -> Vec<f64> {
        self.m.ineq(x)
    }
    fn ineq_jacobian(&self, x: &[f64]) -> Triplets {
        self.m.ineq_jacobian(x)
    }
    fn hessian(&self, x: &[f64], sigma: f64, lambda: &[f64], mu: &[f64]) -> Triplets {
        let mut h = Nlp::hessian(self.m, x, sigma, lambda, mu);
        if let Some((_, weight)) = &self.track {
            h.extend(
                weight
                    .iter()
                    .enumerate()
                    .filter(|(_, w)| **w > 0.0)
                    .map(|(k, w)| (k, k, 2.0 * sigma * w)),
            );
        }
        h
    }
    fn kkt_order(&self) -> Option<(Vec<usize>, usize)> {
        self.m.kkt_order()
    }
}

/// The outcome of the iteration.
pub struct Trusted {
    /// The last accepted trajectory and its J — the first iterate when no boxed step was
    /// accepted; `None` when no first iterate was clear.
    pub best: Option<(Dmoc, f64)>,
    /// Interior-point iterations spent.
    pub iterations: usize,
    /// OCPs solved.
    pub solves: usize,
    /// Accepted boxed steps (after the first iterate).
    pub accepted: usize,
}

/// Weights of the tracking term that makes the first iterate (per m² of the farthest body
/// point's displacement from the path's grid), lightest first.
pub const TRACKING: [f64; 4] = [1e3, 1e5, 1e7, 1e9];

/// Runs the trust-region iteration for `m`; `x0` is the grid along a collision-free path
/// that the first iterate tracks ([`crate::leg::rest_to_rest_guess`]).
pub fn iterate(w: &WeldCell, m: &Move, x0: &[f64], opt: &nlp::Options, s: &TrustSettings) -> Trusted {
    let l = m.layout();
    let validity = robot_validity(w.cell, w.robot, w.cell.planning.clearance);
    let radii = joint_radii(w.cell, w.robot);
    let arm = w.robot.arm(&w.cell.world);
    let (base_lo, base_hi) = m.bounds();
    let mut out = Trusted {
        best: None,
        iterations: 0,
        solves: 0,
        accepted: 0,
    };
    // The first iterate: the dynamics' trajectory nearest the path (J plus the tracking term,
    // lightest first), kept when it is clear. It satisfies every constraint, so each boxed
    // problem after it has a solution (the iterate itself).
    let mut x = None;
    for rho in TRACKING {
        let mut weight = vec![0.0; l.vars()];
        for i in 1..l.steps {
            for j in 0..l.n {
                weight[l.q(i, j)] = rho * radii[j] * radii[j];
            }
        }
        let t = Shaped {
            m,
            lo: base_lo.clone(),
            hi: base_hi.clone(),
            track: Some((x0.to_vec(), weight)),
        };
        let sol = nlp::ipm::solve_from(&t, x0, opt);
        out.iterations += sol.iterations;
        out.solves += 1;
        let ok = matches!(sol.status, Status::Solved | Status::SolvedToAcceptableLevel);
        let clear = ok && crate::leg::clear(w, &unpack(m, &sol.x).q);
        if crate::sequence::verbose() {
            eprintln!("    tracking ρ {rho:.0e}: {:?}, clear {clear}", sol.status);
        }
        if clear {
            x = Some(sol.x);
            break;
        }
    }
    let Some(mut x) = x else {
        return out;
    };
    // The boxes' scale: 1 is the paper's (grid points clear to first order); doubled after an accepted
    // iterate, halved after a rejected one (the dense check decides).
    let verbose = crate::sequence::verbose();
    let mut scale: f64 = 1.0;
    let mut last = Nlp::objective(m, &x);
    out.best = Some((unpack(m, &x), last));
    while out.accepted < s.iterations {
        // φ(q_i^k) − d_c and the weights w(q_i^k) per grid point.
        let (room, weights): (Vec<f64>, Vec<Vec<f64>>) = (0..=l.steps)
            .map(|i| {
                let q: Vec<f64> = (0..l.n).map(|j| x[l.q(i, j)]).collect();
                let (scene, own) = validity.scene_and_self_clearance(&q);
                let room = (scene.min(0.5 * own) - s.extra_clearance).max(0.0);
                (room, point_speed_weights(&arm, &q))
            })
            .unzip();
        let mut accepted = false;
        for _ in 0..=s.backtracks {
            let (mut lo, mut hi) = (base_lo.clone(), base_hi.clone());
            for i in 1..l.steps {
                for j in 0..l.n {
                    let k = l.q(i, j);
                    let half = scale * room[i] / (l.n as f64 * weights[i][j].max(1e-9));
                    lo[k] = (x[k] - half).max(base_lo[k]).min(x[k]);
                    hi[k] = (x[k] + half).min(base_hi[k]).max(x[k]);
                }
            }
            let b = Shaped {
                m,
                lo,
                hi,
                track: None,
            };
            let sol = nlp::ipm::solve_from(&b, &x, opt);
            out.iterations += sol.iterations;
            out.solves += 1;
            if !matches!(sol.status, Status::Solved | Status::SolvedToAcceptableLevel) {
                if verbose {
                    eprintln!("    trust region ×{scale}: {:?}", sol.status);
                }
                scale *= 0.5;
                continue;
            }
            let traj = unpack(m, &sol.x);
            if !crate::leg::clear(w, &traj.q) {
                if verbose {
                    eprintln!("    trust region ×{scale}: J {:.2}, collides", sol.objective);
                }
                scale *= 0.5;
                continue;
            }
            if sol.objective >= last {
                // No progress: keep the previous trajectory.
                break;
            }
            let gain = (last - sol.objective) / sol.objective.abs().max(1e-12);
            if verbose {
                eprintln!("    trust region ×{scale}: J {:.2} accepted", sol.objective);
            }
            x = sol.x;
            last = sol.objective;
            out.best = Some((traj, sol.objective));
            out.accepted += 1;
            accepted = gain >= s.min_gain;
            scale = (2.0 * scale).min(s.max_scale);
            break;
        }
        if !accepted {
            break;
        }
    }
    out
}
