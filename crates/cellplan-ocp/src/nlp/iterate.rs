//! One barrier iteration after another: the μ update, the Newton step, the filter line search
//! with second-order corrections, the multiplier updates (IPOPT paper §2–3).
use super::Nlp;
use super::ipm::{Driver, Eval, Iterate, Status, mul, mul_t, norm_inf, push_inside};
use super::kkt::{Factored, KktValues};

const KAPPA_EPS: f64 = 10.0;
const KAPPA_MU: f64 = 0.2;
const THETA_MU: f64 = 1.5;
const GAMMA_THETA: f64 = 1e-5;
const GAMMA_PHI: f64 = 1e-8;
const S_THETA: f64 = 1.1;
const S_PHI: f64 = 2.3;
const ETA_PHI: f64 = 1e-4;
const DELTA: f64 = 1.0;
const GAMMA_ALPHA: f64 = 0.05;
const KAPPA_SIGMA: f64 = 1e10;
const KAPPA_SOC: f64 = 0.99;
const MAX_SOC: usize = 4;

/// The Newton step of bound multipliers `z` on slacks `slack` (0 where `active` is false): the
/// primal-dual step `(μ − z·slack − sign·z·d)/slack`, where the slack changes by `sign·d` along
/// the primal step `d` (+1 for a lower bound, −1 for an upper one).
fn dual_step(
    active: impl Fn(usize) -> bool,
    z: &[f64],
    slack: &[f64],
    d: &[f64],
    sign: f64,
    mu: f64,
) -> Vec<f64> {
    (0..z.len())
        .map(|i| {
            if active(i) {
                (mu - z[i] * slack[i] - sign * z[i] * d[i]) / slack[i]
            } else {
                0.0
            }
        })
        .collect()
}

/// A Newton direction over every part of the iterate.
struct Step {
    dx: Vec<f64>,
    ds: Vec<f64>,
    dyc: Vec<f64>,
    dyd: Vec<f64>,
}

/// What the restoration phase needs to hand back a point the main iteration accepts.
pub(crate) type EarlyStop<'a> = &'a dyn Fn(&[f64], f64) -> bool;

/// The filter: pairs (θ, φ) no trial point may be at least as bad in both as.
#[derive(Default)]
struct Filter(Vec<(f64, f64)>);

impl Filter {
    fn rejects(&self, theta: f64, phi: f64) -> bool {
        self.0.iter().any(|&(t, f)| theta >= t && phi >= f)
    }
}

impl<P: Nlp + ?Sized> Driver<'_, '_, P> {
    /// Iterates from `it` with barrier parameter `mu` until converged, out of iterations or
    /// stuck. `early` (the restoration phase's test of the original problem at `x` after each
    /// accepted step) ends the run as `Solved` when it returns true.
    pub(crate) fn run(
        &mut self,
        mut it: Iterate,
        mut mu: f64,
        early: Option<EarlyStop>,
    ) -> (Status, Iterate) {
        let p = self.p;
        let Some(mut e) = p.eval(&it.x) else {
            return (Status::NumericalFailure, it);
        };
        let theta_start = self.p.merit(&it.x, &it.s, &e, mu).1;
        let theta_max = 1e4 * theta_start.max(1.0);
        let theta_min = 1e-4 * theta_start.max(1.0);
        let mut tau = (1.0 - mu).max(0.99);
        let mut filter = Filter::default();
        let mut acceptable = 0;
        loop {
            let grad = p.gradient(&it.x);
            let jc = p.jac_c(&it.x);
            let jd = p.jac_d(&it.x);
            let (err, dual, primal, compl) = self.errors(&it, &e, &grad, 0.0);
            let viol = self.unscaled_violation(&it.x);
            if self.opt.verbose {
                eprintln!(
                    "{:4} f {:+.10e} inf_pr {:.2e} inf_du {:.2e} compl {:.2e} mu {:.1e} δ_w {:.1e}",
                    self.iterations, e.f, primal, dual, compl, mu, self.reg.last_delta_w
                );
            }
            if err <= self.opt.tol && viol <= self.opt.constr_viol_tol {
                return (Status::Solved, it);
            }
            acceptable = if err <= self.opt.acceptable_tol && viol <= self.opt.constr_viol_tol {
                acceptable + 1
            } else {
                0
            };
            if acceptable >= self.opt.acceptable_iter {
                return (Status::SolvedToAcceptableLevel, it);
            }
            if self.iterations >= self.opt.max_iter {
                return (Status::MaxIterations, it);
            }
            // Fiacco–McCormick: a smaller μ once the barrier problem is solved well enough.
            let mu_min = self.opt.tol / 10.0;
            while mu > mu_min && self.errors(&it, &e, &grad, mu).0 <= KAPPA_EPS * mu {
                mu = (KAPPA_MU * mu).min(mu.powf(THETA_MU)).max(mu_min);
                tau = (1.0 - mu).max(0.99);
                filter = Filter::default();
            }
            let hess = p.hessian(&it.x, 1.0, &it.yc, &it.yd);
            let [sl, su, tl, tu] = self.slacks(&it);
            let sigma_x: Vec<f64> = (0..p.n)
                .map(|i| {
                    let mut s = 0.0;
                    if self.p.has_lower(i) {
                        s += it.zl[i] / sl[i];
                    }
                    if self.p.has_upper(i) {
                        s += it.zu[i] / su[i];
                    }
                    s
                })
                .collect();
            let sigma_s: Vec<f64> = (0..p.md)
                .map(|r| {
                    let mut s = 0.0;
                    if p.dl[r].is_finite() {
                        s += it.vl[r] / tl[r];
                    }
                    if p.du[r].is_finite() {
                        s += it.vu[r] / tu[r];
                    }
                    s
                })
                .collect();
            let values = KktValues {
                hess: &hess,
                jac_c: &jc,
                jac_d: &jd,
                sigma_x: &sigma_x,
                sigma_s: &sigma_s,
            };
            let Some(fact) = self.kkt.factor_corrected(&values, mu, &mut self.reg) else {
                return (Status::NumericalFailure, it);
            };
            // The residuals with the bound multipliers at their central values μ/slack.
            let a = mul_t(&jc, &it.yc, p.n);
            let b = mul_t(&jd, &it.yd, p.n);
            let rx: Vec<f64> = (0..p.n)
                .map(|i| {
                    if p.fixed[i] {
                        return 0.0;
                    }
                    let mut r = grad[i] + a[i] + b[i];
                    if self.p.has_lower(i) {
                        r -= mu / sl[i];
                    }
                    if self.p.has_upper(i) {
                        r += mu / su[i];
                    }
                    r
                })
                .collect();
            let rs: Vec<f64> = (0..p.md)
                .map(|r| {
                    let mut v = -it.yd[r];
                    if p.dl[r].is_finite() {
                        v -= mu / tl[r];
                    }
                    if p.du[r].is_finite() {
                        v += mu / tu[r];
                    }
                    v
                })
                .collect();
            let rd: Vec<f64> = (0..p.md).map(|r| e.d[r] - it.s[r]).collect();
            let step = self.newton_step(&fact, &jd, &sigma_s, &rx, &rs, &e.c, &rd);
            // The barrier function's slope along the step.
            let dphi: f64 = (0..p.n).map(|i| (rx[i] - a[i] - b[i]) * step.dx[i]).sum::<f64>()
                + (0..p.md).map(|r| (rs[r] + it.yd[r]) * step.ds[r]).sum::<f64>();
            let alpha_max = self.fraction_to_boundary(&it, &step.dx, &step.ds, tau);
            let (phi0, theta0) = self.p.merit(&it.x, &it.s, &e, mu);
            let tiny = (0..p.n).all(|i| step.dx[i].abs() <= 10.0 * f64::EPSILON * (1.0 + it.x[i].abs()));
            let accepted = if tiny {
                let xt: Vec<f64> = (0..p.n).map(|i| it.x[i] + alpha_max * step.dx[i]).collect();
                let st: Vec<f64> = (0..p.md).map(|r| it.s[r] + alpha_max * step.ds[r]).collect();
                p.eval(&xt).map(|et| (alpha_max, xt, st, et))
            } else {
                let ctx = Search {
                    phi0,
                    theta0,
                    dphi,
                    theta_min,
                    theta_max,
                    mu,
                    tau,
                };
                self.line_search(
                    &it,
                    &e,
                    &step,
                    alpha_max,
                    &ctx,
                    &mut filter,
                    &fact,
                    &jd,
                    &sigma_s,
                    &rx,
                    &rs,
                )
            };
            let Some((alpha, xt, st, et)) = accepted else {
                if self.iterations >= self.opt.max_iter {
                    return (Status::MaxIterations, it);
                }
                if !self.opt.restoration {
                    return (Status::RestorationFailed, it);
                }
                // Restoration: the current point joins the filter, and the original
                // iteration resumes at the first point that cuts θ to 0.9 and passes it.
                filter
                    .0
                    .push(((1.0 - GAMMA_THETA) * theta0, phi0 - GAMMA_PHI * theta0));
                let filter_now = &filter;
                let accept = |x: &[f64]| -> bool {
                    let Some(ex) = p.eval(x) else { return false };
                    let sx: Vec<f64> = (0..p.md)
                        .map(|r| push_inside(ex.d[r], p.dl[r], p.du[r]))
                        .collect();
                    let (phi, theta) = p.merit(x, &sx, &ex, mu);
                    theta <= 0.9 * theta0 && !filter_now.rejects(theta, phi)
                };
                match self.restore(&it, mu, &accept) {
                    Ok(next) => {
                        it = next;
                        let Some(en) = p.eval(&it.x) else {
                            return (Status::NumericalFailure, it);
                        };
                        e = en;
                        continue;
                    }
                    Err(status) => return (status, it),
                }
            };
            // Bound multipliers: their Newton steps, the fraction to the boundary, κ_Σ.
            let dzl = dual_step(|i| p.has_lower(i), &it.zl, &sl, &step.dx, 1.0, mu);
            let dzu = dual_step(|i| p.has_upper(i), &it.zu, &su, &step.dx, -1.0, mu);
            let dvl = dual_step(|r| p.dl[r].is_finite(), &it.vl, &tl, &step.ds, 1.0, mu);
            let dvu = dual_step(|r| p.du[r].is_finite(), &it.vu, &tu, &step.ds, -1.0, mu);
            let mut alpha_z: f64 = 1.0;
            for (z, dz) in [(&it.zl, &dzl), (&it.zu, &dzu), (&it.vl, &dvl), (&it.vu, &dvu)] {
                for (zi, di) in z.iter().zip(dz.iter()) {
                    if *di < 0.0 && *zi > 0.0 {
                        alpha_z = alpha_z.min(-tau * zi / di);
                    }
                }
            }
            it.x = xt;
            it.s = st;
            for (y, dy) in it.yc.iter_mut().zip(&step.dyc) {
                *y += alpha * dy;
            }
            for (y, dy) in it.yd.iter_mut().zip(&step.dyd) {
                *y += alpha * dy;
            }
            let [sl, su, tl, tu] = self.slacks(&it);
            let clamp = |z: f64, slack: f64| -> f64 {
                z.min(KAPPA_SIGMA * mu / slack).max(mu / (KAPPA_SIGMA * slack))
            };
            for i in 0..p.n {
                if self.p.has_lower(i) {
                    it.zl[i] = clamp(it.zl[i] + alpha_z * dzl[i], sl[i]);
                }
                if self.p.has_upper(i) {
                    it.zu[i] = clamp(it.zu[i] + alpha_z * dzu[i], su[i]);
                }
            }
            for r in 0..p.md {
                if p.dl[r].is_finite() {
                    it.vl[r] = clamp(it.vl[r] + alpha_z * dvl[r], tl[r]);
                }
                if p.du[r].is_finite() {
                    it.vu[r] = clamp(it.vu[r] + alpha_z * dvu[r], tu[r]);
                }
            }
            e = et;
            self.iterations += 1;
            if let Some(stop) = early
                && stop(&it.x, mu)
            {
                return (Status::Solved, it);
            }
        }
    }

    /// Largest unscaled violation of the constraints at `x`.
    pub(crate) fn unscaled_violation(&self, x: &[f64]) -> f64 {
        let p = self.p;
        let c = p.nlp.eq(x);
        let d = p.nlp.ineq(x);
        let (dl, du) = p.nlp.ineq_bounds();
        let dv = (0..p.md)
            .map(|r| (dl[r] - d[r]).max(d[r] - du[r]).max(0.0))
            .fold(0.0, f64::max);
        norm_inf(&c).max(dv)
    }

    /// Solves the condensed system for residuals `(r_x, r_s, r_c, r_d)` and recovers the
    /// eliminated parts.
    #[allow(clippy::too_many_arguments)]
    fn newton_step(
        &self,
        fact: &Factored,
        jd: &super::Triplets,
        sigma_s: &[f64],
        rx: &[f64],
        rs: &[f64],
        rc: &[f64],
        rd: &[f64],
    ) -> Step {
        let p = self.p;
        let st: Vec<f64> = sigma_s.iter().map(|s| s + fact.delta_w).collect();
        let w: Vec<f64> = (0..p.md)
            .map(|r| fact.d_ineq[r] * (rd[r] + rs[r] / st[r]))
            .collect();
        let jw = mul_t(jd, &w, p.n);
        let mut rhs = vec![0.0; p.n + p.m];
        for i in 0..p.n {
            rhs[i] = if p.fixed[i] { 0.0 } else { -rx[i] - jw[i] };
        }
        for r in 0..p.m {
            rhs[p.n + r] = -rc[r];
        }
        let sol = self.kkt.solve(fact, &rhs, 3);
        let dx: Vec<f64> = (0..p.n).map(|i| if p.fixed[i] { 0.0 } else { sol[i] }).collect();
        let dyc = sol[p.n..].to_vec();
        let jdx = mul(jd, &dx, p.md);
        let dyd: Vec<f64> = (0..p.md)
            .map(|r| fact.d_ineq[r] * (jdx[r] + rd[r] + rs[r] / st[r]))
            .collect();
        let ds: Vec<f64> = (0..p.md).map(|r| (dyd[r] - rs[r]) / st[r]).collect();
        Step { dx, ds, dyc, dyd }
    }

    /// The largest α ≤ 1 keeping every bound slack above (1 − τ) of its value.
    fn fraction_to_boundary(&self, it: &Iterate, dx: &[f64], ds: &[f64], tau: f64) -> f64 {
        let p = self.p;
        let [sl, su, tl, tu] = self.slacks(it);
        let mut a: f64 = 1.0;
        for i in 0..p.n {
            if self.p.has_lower(i) && dx[i] < 0.0 {
                a = a.min(-tau * sl[i] / dx[i]);
            }
            if self.p.has_upper(i) && dx[i] > 0.0 {
                a = a.min(tau * su[i] / dx[i]);
            }
        }
        for r in 0..p.md {
            if p.dl[r].is_finite() && ds[r] < 0.0 {
                a = a.min(-tau * tl[r] / ds[r]);
            }
            if p.du[r].is_finite() && ds[r] > 0.0 {
                a = a.min(tau * tu[r] / ds[r]);
            }
        }
        a
    }

    /// Backtracking filter line search (IPOPT §2.3) with second-order corrections on the
    /// first trial; `None` when α falls below α_min.
    #[allow(clippy::too_many_arguments)]
    fn line_search(
        &mut self,
        it: &Iterate,
        e: &Eval,
        step: &Step,
        alpha_max: f64,
        ctx: &Search,
        filter: &mut Filter,
        fact: &Factored,
        jd: &super::Triplets,
        sigma_s: &[f64],
        rx: &[f64],
        rs: &[f64],
    ) -> Option<(f64, Vec<f64>, Vec<f64>, Eval)> {
        let p = self.p;
        let (theta0, dphi) = (ctx.theta0, ctx.dphi);
        let alpha_min = if dphi < 0.0 {
            let base = GAMMA_THETA.min(GAMMA_PHI * theta0 / -dphi);
            GAMMA_ALPHA
                * if theta0 <= ctx.theta_min {
                    base.min(DELTA * theta0.powf(S_THETA) / (-dphi).powf(S_PHI))
                } else {
                    base
                }
        } else {
            GAMMA_ALPHA * GAMMA_THETA
        };
        let point = |alpha: f64, dx: &[f64], ds: &[f64]| -> (Vec<f64>, Vec<f64>) {
            (
                (0..p.n).map(|i| it.x[i] + alpha * dx[i]).collect(),
                (0..p.md).map(|r| it.s[r] + alpha * ds[r]).collect(),
            )
        };
        let mut alpha = alpha_max;
        let mut first = true;
        while alpha >= alpha_min {
            let (xt, st) = point(alpha, &step.dx, &step.ds);
            let Some(et) = p.eval(&xt) else {
                alpha *= 0.5;
                first = false;
                continue;
            };
            let (phi, theta) = self.p.merit(&xt, &st, &et, ctx.mu);
            if let Some(f_type) = self.accepts(ctx, alpha, phi, theta, filter) {
                if !f_type {
                    filter
                        .0
                        .push(((1.0 - GAMMA_THETA) * theta0, ctx.phi0 - GAMMA_PHI * theta0));
                }
                return Some((alpha, xt, st, et));
            }
            // Second-order corrections: the constraints' values at the trial point fed back.
            if first && theta >= theta0 {
                let mut c_soc: Vec<f64> = (0..p.m).map(|r| alpha * e.c[r] + et.c[r]).collect();
                let mut d_soc: Vec<f64> = (0..p.md)
                    .map(|r| alpha * (e.d[r] - it.s[r]) + et.d[r] - st[r])
                    .collect();
                let mut theta_old = theta;
                for _ in 0..MAX_SOC {
                    let soc = self.newton_step(fact, jd, sigma_s, rx, rs, &c_soc, &d_soc);
                    let a_soc = self.fraction_to_boundary(it, &soc.dx, &soc.ds, ctx.tau);
                    let (xs, ss) = point(a_soc, &soc.dx, &soc.ds);
                    let Some(es) = p.eval(&xs) else { break };
                    let (phi_s, theta_s) = self.p.merit(&xs, &ss, &es, ctx.mu);
                    if let Some(f_type) = self.accepts(ctx, alpha, phi_s, theta_s, filter) {
                        if !f_type {
                            filter
                                .0
                                .push(((1.0 - GAMMA_THETA) * theta0, ctx.phi0 - GAMMA_PHI * theta0));
                        }
                        // The multipliers follow the uncorrected step's length.
                        return Some((alpha, xs, ss, es));
                    }
                    if theta_s > KAPPA_SOC * theta_old {
                        break;
                    }
                    theta_old = theta_s;
                    for r in 0..p.m {
                        c_soc[r] = a_soc * c_soc[r] + es.c[r];
                    }
                    for r in 0..p.md {
                        d_soc[r] = a_soc * d_soc[r] + es.d[r] - ss[r];
                    }
                }
            }
            first = false;
            alpha *= 0.5;
        }
        None
    }

    /// The filter's acceptance test: `Some(f_type)` when accepted (`f_type`: by the Armijo
    /// condition under the switching condition, which does not augment the filter).
    fn accepts(&self, ctx: &Search, alpha: f64, phi: f64, theta: f64, filter: &Filter) -> Option<bool> {
        if !phi.is_finite() || theta > ctx.theta_max || filter.rejects(theta, phi) {
            return None;
        }
        let switching = ctx.dphi < 0.0 && alpha * (-ctx.dphi).powf(S_PHI) > DELTA * ctx.theta0.powf(S_THETA);
        if ctx.theta0 <= ctx.theta_min && switching {
            return (phi <= ctx.phi0 + ETA_PHI * alpha * ctx.dphi).then_some(true);
        }
        (theta <= (1.0 - GAMMA_THETA) * ctx.theta0 || phi <= ctx.phi0 - GAMMA_PHI * ctx.theta0)
            .then_some(false)
    }
}

/// The line search's fixed numbers.
struct Search {
    phi0: f64,
    theta0: f64,
    dphi: f64,
    theta_min: f64,
    theta_max: f64,
    mu: f64,
    tau: f64,
}
