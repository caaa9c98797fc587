//! The interior-point iteration (see the [module notes](super)).
use super::kkt::{Kkt, Regularisation};
use super::{Nlp, Triplets};

/// Tunables, IPOPT's names and defaults where they exist.
#[derive(Clone, Debug)]
pub struct Options {
    /// Convergence tolerance on the scaled optimality error (IPOPT `tol`).
    pub tol: f64,
    /// Iteration limit (IPOPT `max_iter`).
    pub max_iter: usize,
    /// Largest unscaled constraint violation accepted at convergence (`constr_viol_tol`).
    pub constr_viol_tol: f64,
    /// "Acceptable" level and how many consecutive iterations must reach it.
    pub acceptable_tol: f64,
    /// See `acceptable_tol`.
    pub acceptable_iter: usize,
    /// Initial barrier parameter.
    pub mu_init: f64,
    /// Largest gradient entry after scaling (`nlp_scaling_max_gradient`).
    pub scaling_max_gradient: f64,
    /// Print one line per iteration to stderr.
    pub verbose: bool,
    /// Run the feasibility restoration phase when the line search fails (off inside the
    /// restoration phase itself).
    pub restoration: bool,
    /// The equalities' multipliers start at the least-squares estimate (IPOPT §3.6) unless
    /// it is larger than this; 0 starts them at zero (IPOPT `constr_mult_init_max`; the
    /// restoration phase uses 0, as IPOPT's does).
    pub constr_mult_init_max: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tol: 1e-8,
            max_iter: 3000,
            constr_viol_tol: 1e-4,
            acceptable_tol: 1e-6,
            acceptable_iter: 15,
            mu_init: 0.1,
            scaling_max_gradient: 100.0,
            verbose: false,
            restoration: true,
            constr_mult_init_max: 1000.0,
        }
    }
}

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// The optimality error is below `tol`.
    Solved,
    /// Below `acceptable_tol` for `acceptable_iter` iterations, then stuck.
    SolvedToAcceptableLevel,
    /// `max_iter` reached.
    MaxIterations,
    /// The restoration phase converged to a point of locally least infeasibility.
    LocallyInfeasible,
    /// The line search failed and the restoration phase could not help.
    RestorationFailed,
    /// The KKT system could not be regularised, or the functions returned NaN.
    NumericalFailure,
    /// Bounds cross (`x_L > x_U` or `d_L > d_U`) or sizes disagree.
    InvalidProblem,
}

/// The result of [`solve`].
#[derive(Clone, Debug)]
pub struct Solution {
    /// How it ended.
    pub status: Status,
    /// The last iterate.
    pub x: Vec<f64>,
    /// `f(x)` (unscaled).
    pub objective: f64,
    /// Multipliers of the equalities and inequalities (unscaled; `∇f + J_cᵀλ + J_dᵀμ − z_L +
    /// z_U = 0` at a solution).
    pub lambda: Vec<f64>,
    /// See `lambda`.
    pub lambda_ineq: Vec<f64>,
    /// Bound multipliers (unscaled).
    pub z_lower: Vec<f64>,
    /// See `z_lower`.
    pub z_upper: Vec<f64>,
    /// Iterations taken (restoration iterations included).
    pub iterations: usize,
    /// Largest unscaled violation of an equality or inequality.
    pub constraint_violation: f64,
    /// Scaled optimality error at the end (`μ = 0`).
    pub optimality_error: f64,
}

/// The problem with its scaling and the variables' bound bookkeeping.
pub(crate) struct Scaled<'a, P: Nlp + ?Sized> {
    pub nlp: &'a P,
    pub n: usize,
    pub m: usize,
    pub md: usize,
    pub xl: Vec<f64>,
    pub xu: Vec<f64>,
    pub dl: Vec<f64>,
    pub du: Vec<f64>,
    pub fixed: Vec<bool>,
    pub obj_scale: f64,
    pub c_scale: Vec<f64>,
    pub d_scale: Vec<f64>,
}

/// One point's evaluations (scaled).
#[derive(Clone)]
pub(crate) struct Eval {
    pub f: f64,
    pub c: Vec<f64>,
    pub d: Vec<f64>,
}

impl<P: Nlp + ?Sized> Scaled<'_, P> {
    pub fn eval(&self, x: &[f64]) -> Option<Eval> {
        let f = self.obj_scale * self.nlp.objective(x);
        let c: Vec<f64> = self
            .nlp
            .eq(x)
            .iter()
            .zip(&self.c_scale)
            .map(|(v, s)| v * s)
            .collect();
        let d: Vec<f64> = self
            .nlp
            .ineq(x)
            .iter()
            .zip(&self.d_scale)
            .map(|(v, s)| v * s)
            .collect();
        let finite = f.is_finite() && c.iter().chain(&d).all(|v| v.is_finite());
        finite.then_some(Eval { f, c, d })
    }
    pub fn gradient(&self, x: &[f64]) -> Vec<f64> {
        self.nlp
            .gradient(x)
            .into_iter()
            .map(|g| g * self.obj_scale)
            .collect()
    }
    pub fn jac_c(&self, x: &[f64]) -> Triplets {
        let mut t = self.nlp.eq_jacobian(x);
        for e in t.iter_mut() {
            e.2 *= self.c_scale[e.0];
        }
        t
    }
    pub fn jac_d(&self, x: &[f64]) -> Triplets {
        let mut t = self.nlp.ineq_jacobian(x);
        for e in t.iter_mut() {
            e.2 *= self.d_scale[e.0];
        }
        t
    }
    /// The Hessian of the scaled Lagrangian `σ f_s + y_cᵀ c_s + y_dᵀ d_s`.
    pub fn hessian(&self, x: &[f64], sigma: f64, yc: &[f64], yd: &[f64]) -> Triplets {
        let lc: Vec<f64> = yc.iter().zip(&self.c_scale).map(|(y, s)| y * s).collect();
        let ld: Vec<f64> = yd.iter().zip(&self.d_scale).map(|(y, s)| y * s).collect();
        self.nlp.hessian(x, sigma * self.obj_scale, &lc, &ld)
    }
}

impl<P: Nlp + ?Sized> Scaled<'_, P> {
    /// Whether variable `i` has a lower bound with a barrier (finite, and the variable not
    /// fixed).
    pub fn has_lower(&self, i: usize) -> bool {
        self.xl[i].is_finite() && !self.fixed[i]
    }

    /// Whether variable `i` has an upper bound with a barrier.
    pub fn has_upper(&self, i: usize) -> bool {
        self.xu[i].is_finite() && !self.fixed[i]
    }

    /// The barrier function `φ_μ` and infeasibility `θ` (1-norm) at a point.
    pub fn merit(&self, x: &[f64], s: &[f64], e: &Eval, mu: f64) -> (f64, f64) {
        let p = self;
        let mut phi = e.f;
        for i in 0..p.n {
            if p.has_lower(i) {
                phi -= mu * (x[i] - p.xl[i]).ln();
            }
            if p.has_upper(i) {
                phi -= mu * (p.xu[i] - x[i]).ln();
            }
        }
        for r in 0..p.md {
            if p.dl[r].is_finite() {
                phi -= mu * (s[r] - p.dl[r]).ln();
            }
            if p.du[r].is_finite() {
                phi -= mu * (p.du[r] - s[r]).ln();
            }
        }
        let theta =
            e.c.iter().map(|v| v.abs()).sum::<f64>() + (0..p.md).map(|r| (e.d[r] - s[r]).abs()).sum::<f64>();
        (phi, theta)
    }
}

/// `A x` and `Aᵀ y` for triplets.
pub(crate) fn mul(t: &Triplets, x: &[f64], rows: usize) -> Vec<f64> {
    let mut out = vec![0.0; rows];
    for &(r, c, v) in t {
        out[r] += v * x[c];
    }
    out
}
pub(crate) fn mul_t(t: &Triplets, y: &[f64], cols: usize) -> Vec<f64> {
    let mut out = vec![0.0; cols];
    for &(r, c, v) in t {
        out[c] += v * y[r];
    }
    out
}
pub(crate) fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// The whole primal-dual state.
#[derive(Clone)]
pub(crate) struct Iterate {
    pub x: Vec<f64>,
    pub s: Vec<f64>,
    pub yc: Vec<f64>,
    pub yd: Vec<f64>,
    pub zl: Vec<f64>,
    pub zu: Vec<f64>,
    pub vl: Vec<f64>,
    pub vu: Vec<f64>,
}

/// Pushes `v` strictly inside `[lo, hi]` (IPOPT's bound_push / bound_frac, κ = 1e-2).
pub(crate) fn push_inside(v: f64, lo: f64, hi: f64) -> f64 {
    let k = 1e-2;
    let (fl, fu) = (lo.is_finite(), hi.is_finite());
    if fl && fu {
        let pl = (k * lo.abs().max(1.0)).min(k * (hi - lo));
        let pu = (k * hi.abs().max(1.0)).min(k * (hi - lo));
        v.max(lo + pl).min(hi - pu)
    } else if fl {
        v.max(lo + k * lo.abs().max(1.0))
    } else if fu {
        v.min(hi - k * hi.abs().max(1.0))
    } else {
        v
    }
}

/// Solves `nlp` from its initial point.
pub fn solve<P: Nlp + ?Sized>(nlp: &P, opt: &Options) -> Solution {
    let x0 = nlp.initial_point();
    solve_from(nlp, &x0, opt)
}

/// Solves `nlp` from `x0`.
pub fn solve_from<P: Nlp + ?Sized>(nlp: &P, x0: &[f64], opt: &Options) -> Solution {
    solve_with(nlp, x0, opt, None)
}

/// Solves `nlp` from `x0`, ending as `Solved` as soon as `early` accepts an iterate.
pub(crate) fn solve_with<P: Nlp + ?Sized>(
    nlp: &P,
    x0: &[f64],
    opt: &Options,
    early: Option<super::iterate::EarlyStop>,
) -> Solution {
    let (n, m, md) = (nlp.num_vars(), nlp.num_eq(), nlp.num_ineq());
    let (xl, xu) = nlp.bounds();
    let (dl, du) = nlp.ineq_bounds();
    let invalid = xl.len() != n
        || xu.len() != n
        || dl.len() != md
        || du.len() != md
        || x0.len() != n
        || xl.iter().zip(&xu).any(|(a, b)| a > b)
        || dl
            .iter()
            .zip(&du)
            .any(|(a, b)| a > b || (a.is_infinite() && b.is_infinite()));
    let fail = |status| Solution {
        status,
        x: x0.to_vec(),
        objective: f64::NAN,
        lambda: vec![0.0; m],
        lambda_ineq: vec![0.0; md],
        z_lower: vec![0.0; n],
        z_upper: vec![0.0; n],
        iterations: 0,
        constraint_violation: f64::INFINITY,
        optimality_error: f64::INFINITY,
    };
    if invalid {
        return fail(Status::InvalidProblem);
    }
    let fixed: Vec<bool> = xl.iter().zip(&xu).map(|(a, b)| a == b).collect();
    // The starting point, inside the bounds.
    let x: Vec<f64> = (0..n)
        .map(|i| {
            if fixed[i] {
                xl[i]
            } else {
                push_inside(x0[i], xl[i], xu[i])
            }
        })
        .collect();
    // Gradient-based scaling at the start.
    let g0 = nlp.gradient(&x);
    let gmax = norm_inf(&g0);
    let obj_scale = if gmax > opt.scaling_max_gradient {
        opt.scaling_max_gradient / gmax
    } else {
        1.0
    };
    let row_scale = |t: Triplets, rows: usize| -> Vec<f64> {
        let mut mx = vec![0.0f64; rows];
        for (r, c, v) in t {
            if !fixed[c] {
                mx[r] = mx[r].max(v.abs());
            }
        }
        mx.into_iter()
            .map(|v| {
                if v > opt.scaling_max_gradient {
                    opt.scaling_max_gradient / v
                } else {
                    1.0
                }
            })
            .collect()
    };
    let c_scale = row_scale(nlp.eq_jacobian(&x), m);
    let d_scale = row_scale(nlp.ineq_jacobian(&x), md);
    let dl_s: Vec<f64> = dl.iter().zip(&d_scale).map(|(a, s)| a * s).collect();
    let du_s: Vec<f64> = du.iter().zip(&d_scale).map(|(a, s)| a * s).collect();
    let p = Scaled {
        nlp,
        n,
        m,
        md,
        xl,
        xu,
        dl: dl_s,
        du: du_s,
        fixed,
        obj_scale,
        c_scale,
        d_scale,
    };
    let Some(e0) = p.eval(&x) else {
        return fail(Status::NumericalFailure);
    };
    let s: Vec<f64> = (0..md).map(|r| push_inside(e0.d[r], p.dl[r], p.du[r])).collect();
    let mut it = Iterate {
        x,
        s,
        yc: vec![0.0; m],
        yd: vec![0.0; md],
        zl: (0..n).map(|i| if p.has_lower(i) { 1.0 } else { 0.0 }).collect(),
        zu: (0..n).map(|i| if p.has_upper(i) { 1.0 } else { 0.0 }).collect(),
        vl: (0..md)
            .map(|r| if p.dl[r].is_finite() { 1.0 } else { 0.0 })
            .collect(),
        vu: (0..md)
            .map(|r| if p.du[r].is_finite() { 1.0 } else { 0.0 })
            .collect(),
    };
    let kkt = Kkt::new(n, m, nlp.kkt_order(), p.fixed.clone());
    if m > 0
        && opt.constr_mult_init_max > 0.0
        && let Some(y) = least_squares_multipliers(&p, &kkt, &it)
        && norm_inf(&y) <= opt.constr_mult_init_max
    {
        it.yc = y;
    }
    let mut state = Driver {
        p: &p,
        kkt,
        opt: opt.clone(),
        reg: Regularisation::default(),
        iterations: 0,
    };
    let (status, it) = state.run(it, opt.mu_init, early);
    state.finish(status, it)
}

/// IPOPT's least-squares estimate of the equalities' multipliers at the start (§3.6 of
/// Wächter & Biegler): `[I, J_cᵀ; J_c, 0] (w, y) = (−(∇f − z_L + z_U), 0)`, the inequalities'
/// multipliers left at zero. `None` when that system does not have the inertia of a
/// least-squares problem (J_c rank-deficient).
fn least_squares_multipliers<P: Nlp + ?Sized>(p: &Scaled<P>, kkt: &Kkt, it: &Iterate) -> Option<Vec<f64>> {
    let (n, m) = (p.n, p.m);
    let grad = p.gradient(&it.x);
    let identity: Triplets = (0..n).map(|i| (i, i, 1.0)).collect();
    let jac_c = p.jac_c(&it.x);
    let none: Triplets = Vec::new();
    let zeros_x = vec![0.0; n];
    let zeros_s = vec![0.0; p.md];
    let values = super::kkt::KktValues {
        hess: &identity,
        jac_c: &jac_c,
        jac_d: &none,
        sigma_x: &zeros_x,
        sigma_s: &zeros_s,
    };
    let fact = kkt.factor_exact(&values)?;
    let mut rhs = vec![0.0; n + m];
    for i in 0..n {
        if !p.fixed[i] {
            rhs[i] = -(grad[i] - it.zl[i] + it.zu[i]);
        }
    }
    let sol = kkt.solve(&fact, &rhs, 3);
    let y = sol[n..].to_vec();
    y.iter().all(|v| v.is_finite()).then_some(y)
}

/// The iteration's machinery, shared with the restoration phase.
pub(crate) struct Driver<'a, 'b, P: Nlp + ?Sized> {
    pub p: &'b Scaled<'a, P>,
    pub kkt: Kkt,
    pub opt: Options,
    pub reg: Regularisation,
    pub iterations: usize,
}

impl<P: Nlp + ?Sized> Driver<'_, '_, P> {
    fn finish(&self, status: Status, it: Iterate) -> Solution {
        let p = self.p;
        let (n, m, md) = (p.n, p.m, p.md);
        let e = p.eval(&it.x);
        let raw_c = p.nlp.eq(&it.x);
        let raw_d = p.nlp.ineq(&it.x);
        let (dl, du) = p.nlp.ineq_bounds();
        let viol = norm_inf(&raw_c).max(
            (0..md)
                .map(|r| (dl[r] - raw_d[r]).max(raw_d[r] - du[r]).max(0.0))
                .fold(0.0, f64::max),
        );
        let err = e
            .as_ref()
            .map(|e| self.errors(&it, e, &p.gradient(&it.x), 0.0).0)
            .unwrap_or(f64::INFINITY);
        let os = p.obj_scale;
        Solution {
            status,
            objective: p.nlp.objective(&it.x),
            lambda: (0..m).map(|r| it.yc[r] * p.c_scale[r] / os).collect(),
            lambda_ineq: (0..md).map(|r| it.yd[r] * p.d_scale[r] / os).collect(),
            z_lower: (0..n).map(|i| it.zl[i] / os).collect(),
            z_upper: (0..n).map(|i| it.zu[i] / os).collect(),
            iterations: self.iterations,
            constraint_violation: viol,
            optimality_error: err,
            x: it.x,
        }
    }

    /// Slacks of the bounds at `x` / `s`.
    pub fn slacks(&self, it: &Iterate) -> [Vec<f64>; 4] {
        let p = self.p;
        let sl = (0..p.n).map(|i| it.x[i] - p.xl[i]).collect();
        let su = (0..p.n).map(|i| p.xu[i] - it.x[i]).collect();
        let tl = (0..p.md).map(|r| it.s[r] - p.dl[r]).collect();
        let tu = (0..p.md).map(|r| p.du[r] - it.s[r]).collect();
        [sl, su, tl, tu]
    }

    /// `(E_μ, dual infeasibility, primal infeasibility, complementarity)`, IPOPT's (5).
    pub fn errors(&self, it: &Iterate, e: &Eval, grad: &[f64], mu: f64) -> (f64, f64, f64, f64) {
        let p = self.p;
        let jc = p.jac_c(&it.x);
        let jd = p.jac_d(&it.x);
        let gl = self.grad_lag(it, grad, &jc, &jd);
        let gs: Vec<f64> = (0..p.md).map(|r| -it.yd[r] - it.vl[r] + it.vu[r]).collect();
        let dual = norm_inf(&gl).max(norm_inf(&gs));
        let primal = norm_inf(&e.c).max((0..p.md).map(|r| (e.d[r] - it.s[r]).abs()).fold(0.0, f64::max));
        let [sl, su, tl, tu] = self.slacks(it);
        let mut compl = 0.0f64;
        let mut zsum = 0.0;
        let mut zcount = 0usize;
        for i in 0..p.n {
            if self.p.has_lower(i) {
                compl = compl.max((sl[i] * it.zl[i] - mu).abs());
                zsum += it.zl[i];
                zcount += 1;
            }
            if self.p.has_upper(i) {
                compl = compl.max((su[i] * it.zu[i] - mu).abs());
                zsum += it.zu[i];
                zcount += 1;
            }
        }
        for r in 0..p.md {
            if p.dl[r].is_finite() {
                compl = compl.max((tl[r] * it.vl[r] - mu).abs());
                zsum += it.vl[r];
                zcount += 1;
            }
            if p.du[r].is_finite() {
                compl = compl.max((tu[r] * it.vu[r] - mu).abs());
                zsum += it.vu[r];
                zcount += 1;
            }
        }
        let ysum: f64 = it.yc.iter().chain(&it.yd).map(|v| v.abs()).sum();
        let smax = 100.0;
        let sd = ((ysum + zsum) / ((p.m + p.md + zcount).max(1) as f64)).max(smax) / smax;
        let sc = (zsum / (zcount.max(1) as f64)).max(smax) / smax;
        ((dual / sd).max(primal).max(compl / sc), dual, primal, compl)
    }

    /// `∇f + J_cᵀ y_c + J_dᵀ y_d − z_L + z_U`, zero on fixed variables.
    pub fn grad_lag(&self, it: &Iterate, grad: &[f64], jc: &Triplets, jd: &Triplets) -> Vec<f64> {
        let p = self.p;
        let a = mul_t(jc, &it.yc, p.n);
        let b = mul_t(jd, &it.yd, p.n);
        (0..p.n)
            .map(|i| {
                if p.fixed[i] {
                    0.0
                } else {
                    grad[i] + a[i] + b[i] - it.zl[i] + it.zu[i]
                }
            })
            .collect()
    }
}
