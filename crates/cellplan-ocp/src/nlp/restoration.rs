//! The feasibility restoration phase (IPOPT paper §3.3): when the filter line search fails,
//! minimise the constraint violation near the current point,
//!
//! `min ρ Σ (p + n) + ζ/2 ‖D_R (x − x_R)‖²  s.t.  c(x) − p + n = 0,  d_L ≤ d(x) ≤ d_U,
//!  x_L ≤ x ≤ x_U,  p, n ≥ 0`,
//!
//! with ρ = 1000, ζ = √μ, `D_R = diag(min(1, 1/|x_R|))`, by the same interior-point method,
//! until the original problem's filter accepts a point that cuts the violation to 0.9 of what
//! it was. If the restoration problem converges first, its solution is a point of locally
//! least violation: the problem is reported locally infeasible.
use super::ipm::{Driver, Iterate, Options, Status, push_inside, solve_with};
use super::{Nlp, Triplets};

const RHO: f64 = 1000.0;

/// The restoration problem over `[x, p, n]`.
struct Restoration<'a, P: Nlp + ?Sized> {
    nlp: &'a P,
    x_ref: Vec<f64>,
    d_ref: Vec<f64>,
    zeta: f64,
    x0: Vec<f64>,
}

impl<P: Nlp + ?Sized> Nlp for Restoration<'_, P> {
    fn num_vars(&self) -> usize {
        self.nlp.num_vars() + 2 * self.nlp.num_eq()
    }
    fn num_eq(&self) -> usize {
        self.nlp.num_eq()
    }
    fn num_ineq(&self) -> usize {
        self.nlp.num_ineq()
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut lo, mut hi) = self.nlp.bounds();
        let m = self.nlp.num_eq();
        lo.extend(std::iter::repeat_n(0.0, 2 * m));
        hi.extend(std::iter::repeat_n(f64::INFINITY, 2 * m));
        (lo, hi)
    }
    fn ineq_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        self.nlp.ineq_bounds()
    }
    fn initial_point(&self) -> Vec<f64> {
        self.x0.clone()
    }
    fn objective(&self, x: &[f64]) -> f64 {
        let n = self.nlp.num_vars();
        let pn: f64 = x[n..].iter().sum();
        let prox: f64 = (0..n)
            .map(|i| (self.d_ref[i] * (x[i] - self.x_ref[i])).powi(2))
            .sum();
        RHO * pn + 0.5 * self.zeta * prox
    }
    fn gradient(&self, x: &[f64]) -> Vec<f64> {
        let n = self.nlp.num_vars();
        let mut g: Vec<f64> = (0..n)
            .map(|i| self.zeta * self.d_ref[i].powi(2) * (x[i] - self.x_ref[i]))
            .collect();
        g.extend(std::iter::repeat_n(RHO, x.len() - n));
        g
    }
    fn eq(&self, x: &[f64]) -> Vec<f64> {
        let (n, m) = (self.nlp.num_vars(), self.nlp.num_eq());
        let mut c = self.nlp.eq(&x[..n]);
        for r in 0..m {
            c[r] += -x[n + r] + x[n + m + r];
        }
        c
    }
    fn eq_jacobian(&self, x: &[f64]) -> Triplets {
        let (n, m) = (self.nlp.num_vars(), self.nlp.num_eq());
        let mut t = self.nlp.eq_jacobian(&x[..n]);
        for r in 0..m {
            t.push((r, n + r, -1.0));
            t.push((r, n + m + r, 1.0));
        }
        t
    }
    fn ineq(&self, x: &[f64]) -> Vec<f64> {
        self.nlp.ineq(&x[..self.nlp.num_vars()])
    }
    fn ineq_jacobian(&self, x: &[f64]) -> Triplets {
        self.nlp.ineq_jacobian(&x[..self.nlp.num_vars()])
    }
    fn hessian(&self, x: &[f64], sigma: f64, lambda: &[f64], mu: &[f64]) -> Triplets {
        let n = self.nlp.num_vars();
        let mut t = self.nlp.hessian(&x[..n], 0.0, lambda, mu);
        for i in 0..n {
            t.push((i, i, sigma * self.zeta * self.d_ref[i].powi(2)));
        }
        t
    }
    fn kkt_order(&self) -> Option<(Vec<usize>, usize)> {
        // p_r and n_r just before the multiplier of row r.
        let (n, m) = (self.nlp.num_vars(), self.nlp.num_eq());
        let (inner, border) = self.nlp.kkt_order().unwrap_or_else(|| ((0..n + m).collect(), 0));
        let mut order = Vec::with_capacity(inner.len() + 2 * m);
        let mut border_out = 0;
        let first_border = inner.len() - border;
        for (pos, &k) in inner.iter().enumerate() {
            let ks: Vec<usize> = if k < n {
                vec![k]
            } else {
                let r = k - n;
                vec![n + r, n + m + r, n + 2 * m + r]
            };
            if pos >= first_border {
                border_out += ks.len();
            }
            order.extend(ks);
        }
        Some((order, border_out))
    }
}

impl<P: Nlp + ?Sized> Driver<'_, '_, P> {
    /// Runs the restoration phase from `it` (barrier `mu`); `accept(x)` tells whether the
    /// original iteration takes `x`. Returns the new iterate (multipliers of the constraints
    /// reset to zero) or the status to end with.
    pub(crate) fn restore(
        &mut self,
        it: &Iterate,
        mu: f64,
        accept: &dyn Fn(&[f64]) -> bool,
    ) -> Result<Iterate, Status> {
        let p = self.p;
        let nlp = p.nlp;
        let (n, m) = (p.n, p.m);
        let c = nlp.eq(&it.x);
        // p and n that minimise the restoration's barrier problem for the current c.
        let mut x0 = it.x.clone();
        let mu_r = mu.max(c.iter().fold(0.0f64, |a, v| a.max(v.abs()))).min(1e2);
        let nn: Vec<f64> = c
            .iter()
            .map(|&cr| {
                let a = (mu_r - RHO * cr) / (2.0 * RHO);
                a + (a * a + mu_r * cr / (2.0 * RHO)).sqrt()
            })
            .collect();
        x0.extend(c.iter().zip(&nn).map(|(cr, nr)| cr + nr));
        x0.extend(nn);
        let resto = Restoration {
            nlp,
            x_ref: it.x.clone(),
            d_ref: it.x.iter().map(|v| (1.0 / v.abs()).min(1.0)).collect(),
            zeta: mu.sqrt(),
            x0,
        };
        let opt = Options {
            mu_init: mu_r,
            restoration: false,
            constr_mult_init_max: 0.0,
            max_iter: self.opt.max_iter.saturating_sub(self.iterations),
            verbose: self.opt.verbose,
            ..self.opt.clone()
        };
        let early = |x: &[f64], _mu: f64| accept(&x[..n]);
        // Through `dyn Nlp`, so that a restoration's own restoration (switched off, but typed)
        // does not instantiate the solver for ever deeper wrapper types.
        let dynamic: &dyn Nlp = &resto;
        let s = solve_with(dynamic, &resto.x0, &opt, Some(&early));
        self.iterations += s.iterations;
        let _ = m;
        match s.status {
            Status::Solved if accept(&s.x[..n]) => {
                let x = s.x[..n].to_vec();
                let d = p.eval(&x).map(|e| e.d).unwrap_or_default();
                let mut next = it.clone();
                next.s = (0..p.md).map(|r| push_inside(d[r], p.dl[r], p.du[r])).collect();
                next.x = x;
                next.yc.fill(0.0);
                next.yd.fill(0.0);
                Ok(next)
            }
            // Converged without reaching an acceptable point: locally least violation, unless
            // the violation is (nearly) gone and only the filter objects.
            Status::Solved | Status::SolvedToAcceptableLevel => {
                let x = &s.x[..n];
                if self.unscaled_violation(x) > self.opt.constr_viol_tol {
                    Err(Status::LocallyInfeasible)
                } else {
                    Err(Status::RestorationFailed)
                }
            }
            Status::MaxIterations => Err(Status::MaxIterations),
            _ => Err(Status::RestorationFailed),
        }
    }
}
