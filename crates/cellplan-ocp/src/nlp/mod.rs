//! A primal-dual interior-point solver for nonlinear programs, in the manner of IPOPT
//! (Wächter & Biegler, *On the implementation of an interior-point filter line-search
//! algorithm for large-scale nonlinear programming*, Math. Prog. 106, 2006):
//!
//! `min f(x)  s.t.  c(x) = 0,  d_L ≤ d(x) ≤ d_U,  x_L ≤ x ≤ x_U`.
//!
//! - the bounds and the inequalities (through slacks `d(x) − s = 0`) carry a logarithmic
//!   barrier; μ falls by the Fiacco–McCormick (monotone) rule, `μ ← max(tol/10, min(κ_μ μ,
//!   μ^θ_μ))`, whenever the barrier problem is solved to `κ_ε μ`;
//! - each Newton step solves the primal-dual KKT system with the slacks and the inequalities'
//!   multipliers eliminated, `[W + Σ + J_dᵀ D J_d + δ_w I, J_cᵀ; J_c, −δ_c I]`, by a sparse
//!   LDLᵀ without pivoting ([`ldl`]) in the order the problem gives ([`Nlp::kkt_order`]: for
//!   the DMOC transcription by time stage, a band bordered by the final time), with inertia
//!   correction (δ_w, δ_c as IPOPT's Algorithm IC) and iterative refinement;
//! - the fraction-to-the-boundary rule (τ = max(0.99, 1 − μ)) for primal and dual steps;
//! - a filter line search (switching condition, Armijo on the barrier function, θ_max,
//!   second-order corrections) and, when it fails, a feasibility restoration that minimises the
//!   constraint violation; a restoration that ends at a point it cannot improve reports the
//!   problem locally infeasible;
//! - gradient-based scaling of the objective and the constraints at the start (as IPOPT's
//!   default): the tolerances apply to the scaled problem, the reported violations unscaled.
//!
//! The outcome is a [`Status`], never a panic.
// Index loops over several arrays at once read as the formulas do.
#![allow(clippy::needless_range_loop)]
pub mod ipm;
#[cfg(feature = "ipopt")]
pub mod ipopt;
mod iterate;
mod kkt;
pub mod ldl;
mod restoration;
pub mod structure;
#[cfg(test)]
mod tests;

pub use ipm::{Options, Solution, Status, solve};

/// A sparse matrix as (row, column, value) triplets; repeated entries add up.
pub type Triplets = Vec<(usize, usize, f64)>;

/// A nonlinear program with exact first and second derivatives.
///
/// Bounds that do not exist are `±f64::INFINITY`; a variable with equal bounds is fixed (taken
/// out of the Newton systems, as IPOPT's `make_parameter`).
pub trait Nlp {
    /// Number of variables.
    fn num_vars(&self) -> usize;
    /// Number of equality constraints `c(x) = 0`.
    fn num_eq(&self) -> usize;
    /// Number of inequality constraints `d_L ≤ d(x) ≤ d_U`.
    fn num_ineq(&self) -> usize {
        0
    }
    /// `(x_L, x_U)`.
    fn bounds(&self) -> (Vec<f64>, Vec<f64>);
    /// `(d_L, d_U)`.
    fn ineq_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (Vec::new(), Vec::new())
    }
    /// Where to start.
    fn initial_point(&self) -> Vec<f64>;
    /// `f(x)`.
    fn objective(&self, x: &[f64]) -> f64;
    /// `∇f(x)`.
    fn gradient(&self, x: &[f64]) -> Vec<f64>;
    /// `c(x)`.
    fn eq(&self, x: &[f64]) -> Vec<f64>;
    /// The Jacobian of `c`.
    fn eq_jacobian(&self, x: &[f64]) -> Triplets;
    /// `d(x)`.
    fn ineq(&self, _x: &[f64]) -> Vec<f64> {
        Vec::new()
    }
    /// The Jacobian of `d`.
    fn ineq_jacobian(&self, _x: &[f64]) -> Triplets {
        Vec::new()
    }
    /// The lower triangle of `σ ∇²f + Σ λ_r ∇²c_r + Σ μ_r ∇²d_r`.
    fn hessian(&self, x: &[f64], sigma: f64, lambda: &[f64], mu: &[f64]) -> Triplets;
    /// An elimination order for the KKT system's unknowns (`0 … n−1` the variables, `n + r`
    /// the multiplier of equality `r`) and how many of the last ones form a dense border;
    /// `None`: the natural order, no border (fine for small problems: the band is then full).
    fn kkt_order(&self) -> Option<(Vec<usize>, usize)> {
        None
    }
}
