//! [`Move`] as an [`Nlp`] for the interior-point solver, with the KKT system ordered by time
//! stage: stage k holds `q_k` (and `q̇_0` at the start), `u_{k+½}` (`q̇_N` at the end) and the
//! multipliers of row block k. Row block k couples `q_{k−1}, q_k, q_{k+1}, u_{k−½}, u_{k+½}`,
//! the Hessian couples neighbouring grid points and the velocity rows `q_i, q_{i+1}`, so the
//! matrix is banded (half-bandwidth about six blocks of n) except for `h`, which touches every
//! stage and forms a border of one.
use super::Move;
use crate::nlp::{Nlp, Triplets};

impl Nlp for Move<'_> {
    fn num_vars(&self) -> usize {
        self.layout().vars()
    }
    fn num_eq(&self) -> usize {
        self.layout().equalities()
    }
    fn num_ineq(&self) -> usize {
        2 * self.layout().n * self.steps
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        Move::bounds(self)
    }
    fn ineq_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let k = self.num_ineq();
        (vec![f64::NEG_INFINITY; k], vec![0.0; k])
    }
    fn initial_point(&self) -> Vec<f64> {
        self.initial_guess()
    }
    fn objective(&self, x: &[f64]) -> f64 {
        Move::objective(self, x)
    }
    fn gradient(&self, x: &[f64]) -> Vec<f64> {
        Move::gradient(self, x)
    }
    fn eq(&self, x: &[f64]) -> Vec<f64> {
        self.constraints(x)
    }
    fn eq_jacobian(&self, x: &[f64]) -> Triplets {
        self.jacobian(x)
    }
    fn ineq(&self, x: &[f64]) -> Vec<f64> {
        let mut d = vec![0.0; self.num_ineq()];
        for (r, c, v) in self.inequalities() {
            d[r] += v * x[c];
        }
        d
    }
    fn ineq_jacobian(&self, _x: &[f64]) -> Triplets {
        self.inequalities()
    }
    fn hessian(&self, x: &[f64], sigma: f64, lambda: &[f64], _mu: &[f64]) -> Triplets {
        // The inequalities are linear.
        Move::hessian(self, x, lambda, sigma)
    }
    fn kkt_order(&self) -> Option<(Vec<usize>, usize)> {
        let l = self.layout();
        let nv = l.vars();
        let mut order = Vec::with_capacity(nv + l.equalities());
        for k in 0..=l.steps {
            order.extend((0..l.n).map(|j| l.q(k, j)));
            if k == 0 {
                order.extend((0..l.n).map(|j| l.qd0(j)));
            }
            if k < l.steps {
                order.extend((0..l.n).map(|j| l.u(k, j)));
            } else {
                order.extend((0..l.n).map(|j| l.qdn(j)));
            }
            order.extend((0..l.n).map(|j| nv + k * l.n + j));
        }
        order.push(l.h());
        Some((order, 1))
    }
}
