//! The exact Jacobian and Hessian of [`Move`], step by step.
//!
//! Every term of the dynamics rows comes from one step `i` (between `a = q_i` and `b = q_{i+1}`)
//! through the Lagrangian at the midpoint `m = (a + b)/2` and velocity `v = (b − a)/h`:
//! step `i` adds `D1 L_d = s L_q − L_v` to row block `i` and `D2 L_d = s L_q + L_v` to row
//! block `i + 1` (`s = h/2`, `L_q = ∂L/∂q`, `L_v = ∂L/∂q̇ = M(m) v`). So the constraints'
//! part of the Lagrangian's Hessian is, step by step, the Hessian of
//!
//! `ψ = λ_iᵀ D1 L_d + λ_{i+1}ᵀ D2 L_d = s A(m, v) + B(m, v)`,
//! `A = αᵀ L_q = ½ vᵀ M_α(m) v − ∂_α V(m)`, `B = βᵀ M(m) v`,
//!
//! with `α = λ_i + λ_{i+1}`, `β = λ_{i+1} − λ_i` and `M_α`, `∂_α` the derivatives along `α`.
//! `L` is quadratic in `v`, so only `m` needs automatic derivatives: one Newton–Euler pass for
//! the momentum `M(m) v` and one for the potential, on [`Taylor2`] numbers over `m` (second
//! order) inside a one-direction dual along `α` (the third derivatives `A` needs). The
//! `v`-parts are closed forms in `M`, `M_α` and `(∂M) β`, and the chain rule from `(m, v)` to
//! `(a, b, h)` is done by hand. The Jacobian uses the same pass without the `α` direction.
//! Each step is evaluated once (a block-by-block evaluation would do every step twice).
// Index loops over several arrays at once read as the formulas do.
#![allow(clippy::needless_range_loop)]
use super::{Move, Triplets};
use crate::dmoc::MAX_DOF;
use crate::taylor::Taylor2;
use cellplan_kin::dynamics::{Dual, Dynamics, Real};

/// The Lagrangian's derivatives at one step's midpoint, from one pass over `m`.
struct StepFirst {
    /// `∂L/∂q`.
    lq: Vec<f64>,
    /// `∂L_q/∂m`, `∂L_q/∂v`, `∂L_v/∂m`, `∂L_v/∂v = M` (row = component, column = variable).
    lq_m: Vec<Vec<f64>>,
    lq_v: Vec<Vec<f64>>,
    lv_m: Vec<Vec<f64>>,
    mass: Vec<Vec<f64>>,
}

/// The momentum `p = M(m) v` and the Lagrangian `L = ½ vᵀ p − V(m)` at midpoint `m` (any
/// scalar: the derivatives ride on it) and velocity `v` (constants).
fn lagrangian<T: Real>(d: &Dynamics, m: &[T], v: &[f64]) -> (Vec<T>, T) {
    let vc: Vec<T> = v.iter().map(|&x| T::from_f64(x)).collect();
    let p = d.momentum(m, &vc);
    let mut lag = -d.potential(m);
    for (pj, &vj) in p.iter().zip(v) {
        lag = lag + *pj * T::from_f64(0.5 * vj);
    }
    (p, lag)
}

fn step_first<const K: usize, const P: usize>(d: &Dynamics, m: &[f64], v: &[f64]) -> StepFirst {
    let n = m.len();
    let mv: Vec<Taylor2<K, P>> = m
        .iter()
        .enumerate()
        .map(|(j, &x)| Taylor2::variable(x, j))
        .collect();
    let (p, lag) = lagrangian(d, &mv, v);
    StepFirst {
        lq: lag.g[..n].to_vec(),
        lq_m: (0..n).map(|j| (0..n).map(|l| lag.hess(j, l)).collect()).collect(),
        // ∂(½ vᵀ ∂_j M v)/∂v_k = ((∂_j M) v)_k = ∂p_k/∂m_j.
        lq_v: (0..n).map(|j| (0..n).map(|k| p[k].g[j]).collect()).collect(),
        lv_m: (0..n).map(|j| (0..n).map(|l| p[j].g[l]).collect()).collect(),
        mass: d.mass_matrix(m),
    }
}

/// `(M(q) + ∂(M(q) w)/∂q)`: the momentum's Jacobian in `q` at velocity `w` (row = component).
fn momentum_dq(d: &Dynamics, q: &[f64], w: &[f64]) -> Vec<Vec<f64>> {
    let n = q.len();
    let qd: Vec<Dual<MAX_DOF>> = q.iter().enumerate().map(|(j, &x)| Dual::variable(x, j)).collect();
    let wd: Vec<Dual<MAX_DOF>> = w.iter().map(|&x| Dual::constant(x)).collect();
    let p = d.momentum(&qd, &wd);
    (0..n).map(|j| p[j].d[..n].to_vec()).collect()
}

/// The second-order terms of one step: the Hessians of `A` and `B` over `y = (m, v)`.
struct StepSecond {
    /// `s ∇A + ∇B` and `∇A` over `y`.
    grad_f: Vec<f64>,
    grad_a: Vec<f64>,
    /// `s ∇²A + ∇²B`, dense `2n × 2n`.
    hess_f: Vec<Vec<f64>>,
}

fn step_second<const K: usize, const P: usize>(
    d: &Dynamics,
    m: &[f64],
    v: &[f64],
    alpha: &[f64],
    beta: &[f64],
    s: f64,
) -> StepSecond {
    type T<const K: usize, const P: usize> = Dual<1, Taylor2<K, P>>;
    let n = m.len();
    // m + ε + t α: Taylor2 over ε, the dual along t.
    let mv: Vec<T<K, P>> = (0..n)
        .map(|j| Dual {
            v: Taylor2::variable(m[j], j),
            d: [Taylor2::constant(alpha[j])],
        })
        .collect();
    let (p, lag) = lagrangian(d, &mv, v);
    // A = ∂_α L as a function of m; ∇_v A = M_α v; ∇²_v A = M_α.
    let a = lag.d[0];
    let a_v: Vec<f64> = p.iter().map(|x| x.d[0].v).collect();
    let m_alpha: Vec<Vec<f64>> = {
        let qd: Vec<Dual<1>> = (0..n)
            .map(|j| Dual {
                v: m[j],
                d: [alpha[j]],
            })
            .collect();
        d.mass_matrix(&qd)
            .into_iter()
            .map(|row| row.into_iter().map(|x| x.d[0]).collect())
            .collect()
    };
    // B = βᵀ M v; ∇_v B = M β; ∂²B/∂v_j∂m_l = ((∂_l M) β)_j.
    let mass = d.mass_matrix(m);
    let b_v: Vec<f64> = (0..n)
        .map(|j| (0..n).map(|k| mass[j][k] * beta[k]).sum())
        .collect();
    let b_vm = momentum_dq(d, m, beta);
    let (mut b_m, mut b_mm) = (vec![0.0; n], vec![vec![0.0; n]; n]);
    for (j, &bj) in beta.iter().enumerate() {
        let pj = p[j].v;
        for l in 0..n {
            b_m[l] += bj * pj.g[l];
            for k in 0..n {
                b_mm[l][k] += bj * pj.hess(l, k);
            }
        }
    }
    let mut grad_f = vec![0.0; 2 * n];
    let mut grad_a = vec![0.0; 2 * n];
    let mut hess_f = vec![vec![0.0; 2 * n]; 2 * n];
    for l in 0..n {
        grad_a[l] = a.g[l];
        grad_a[n + l] = a_v[l];
        grad_f[l] = s * a.g[l] + b_m[l];
        grad_f[n + l] = s * a_v[l] + b_v[l];
        for k in 0..n {
            hess_f[l][k] = s * a.hess(l, k) + b_mm[l][k];
            // (v_j = n + l, m_k): s ∂(M_α v)_l/∂m_k + ((∂_k M) β)_l.
            let vm = s * p[l].d[0].g[k] + b_vm[l][k];
            hess_f[n + l][k] = vm;
            hess_f[k][n + l] = vm;
            hess_f[n + l][n + k] = s * m_alpha[l][k];
        }
    }
    StepSecond {
        grad_f,
        grad_a,
        hess_f,
    }
}

impl Move<'_> {
    fn step_point(&self, x: &[f64], i: usize) -> (Vec<f64>, Vec<f64>) {
        let l = self.layout();
        let h = x[l.h()];
        let m = (0..l.n)
            .map(|j| 0.5 * (x[l.q(i, j)] + x[l.q(i + 1, j)]))
            .collect();
        let v = (0..l.n).map(|j| (x[l.q(i + 1, j)] - x[l.q(i, j)]) / h).collect();
        (m, v)
    }

    /// The Jacobian of `c`, exact, as triplets (row, column, value); an entry may appear more
    /// than once (the steps on either side of a grid point both touch it): add them up.
    pub fn jacobian(&self, x: &[f64]) -> Triplets {
        assert!(self.start.len() <= MAX_DOF, "at most {MAX_DOF} joints");
        if self.start.len() <= 6 {
            self.jacobian_k::<6, 21>(x)
        } else {
            self.jacobian_k::<8, 36>(x)
        }
    }

    fn jacobian_k<const K: usize, const P: usize>(&self, x: &[f64]) -> Triplets {
        let l = self.layout();
        let n = l.n;
        let d = self.dynamics;
        let h = x[l.h()];
        let s = 0.5 * h;
        let mut t: Triplets = Vec::with_capacity(l.steps * (4 * n * n + 6 * n) + 4 * n * n);
        for i in 0..l.steps {
            let (m, v) = self.step_point(x, i);
            let f = step_first::<K, P>(d, &m, &v);
            // ∂D1/∂z into block i and ∂D2/∂z into block i+1, z = (q_i, q_{i+1}, h).
            for (row0, sign) in [(i * n, -1.0), ((i + 1) * n, 1.0)] {
                for r in 0..n {
                    let mut dh = 0.5 * f.lq[r];
                    for j in 0..n {
                        // ∂y/∂a: m ½, v −1/h; ∂y/∂b: m ½, v 1/h.
                        let q_m = s * f.lq_m[r][j] + sign * f.lv_m[r][j];
                        let q_v = s * f.lq_v[r][j] + sign * f.mass[r][j];
                        t.push((row0 + r, l.q(i, j), 0.5 * q_m - q_v / h));
                        t.push((row0 + r, l.q(i + 1, j), 0.5 * q_m + q_v / h));
                        dh -= q_v * v[j] / h;
                    }
                    t.push((row0 + r, l.h(), dh));
                }
            }
            // The forces h/2 u_{i+½} in both blocks.
            for row0 in [i * n, (i + 1) * n] {
                for j in 0..n {
                    t.push((row0 + j, l.u(i, j), s));
                    t.push((row0 + j, l.h(), 0.5 * x[l.u(i, j)]));
                }
            }
        }
        // The boundary momenta: +M(q_0) q̇_0 in block 0, −M(q_N) q̇_N in block N.
        for (grid, first, sign) in [(0, l.qd0(0), 1.0), (l.steps, l.qdn(0), -1.0)] {
            let q: Vec<f64> = (0..n).map(|j| x[l.q(grid, j)]).collect();
            let w: Vec<f64> = (0..n).map(|j| x[first + j]).collect();
            let dq = momentum_dq(d, &q, &w);
            let mass = d.mass_matrix(&q);
            for r in 0..n {
                for j in 0..n {
                    t.push((grid * n + r, l.q(grid, j), sign * dq[r][j]));
                    t.push((grid * n + r, first + j, sign * mass[r][j]));
                }
            }
        }
        t
    }

    /// The Hessian of the Lagrangian `σ ∇²f(x) + Σ λ_r ∇²c_r(x)`, exact, as triplets of its
    /// lower triangle (row ≥ column; an entry may appear more than once: add them up). The
    /// cost's part in closed form, the dynamics' step by step (see the module's notes).
    pub fn hessian(&self, x: &[f64], lambda: &[f64], sigma: f64) -> Triplets {
        assert!(self.start.len() <= MAX_DOF, "at most {MAX_DOF} joints");
        if self.start.len() <= 6 {
            self.hessian_k::<6, 21>(x, lambda, sigma)
        } else {
            self.hessian_k::<8, 36>(x, lambda, sigma)
        }
    }

    fn hessian_k<const K: usize, const P: usize>(&self, x: &[f64], lambda: &[f64], sigma: f64) -> Triplets {
        let l = self.layout();
        let n = l.n;
        let d = self.dynamics;
        let w = self.weights;
        let h = x[l.h()];
        let s = 0.5 * h;
        let mut t: Triplets = Vec::with_capacity(l.steps * (2 * n + 1) * (n + 1) * 2);
        let mut put = |a: usize, b: usize, v: f64| {
            if v != 0.0 {
                t.push((a.max(b), a.min(b), v));
            }
        };
        // The cost: h (c_t + c_e |u|²) + c_v |Δq|² / h per step.
        for i in 0..l.steps {
            let mut dq2 = 0.0;
            for j in 0..n {
                let (a, b) = (l.q(i, j), l.q(i + 1, j));
                let dq = x[b] - x[a];
                dq2 += dq * dq;
                let c = 2.0 * sigma * w.velocity / h;
                put(a, a, c);
                put(b, b, c);
                put(b, a, -c);
                let e = 2.0 * sigma * w.velocity * dq / (h * h);
                put(l.h(), b, -e);
                put(l.h(), a, e);
                let u = l.u(i, j);
                put(u, u, 2.0 * sigma * w.effort * h);
                put(l.h(), u, 2.0 * sigma * w.effort * x[u]);
            }
            put(l.h(), l.h(), 2.0 * sigma * w.velocity * dq2 / (h * h * h));
        }
        // The dynamics, step by step: ψ(a, b, h) = s A(m, v) + B(m, v).
        for i in 0..l.steps {
            let (m, v) = self.step_point(x, i);
            let lam = |k: usize, j: usize| lambda[k * n + j];
            let alpha: Vec<f64> = (0..n).map(|j| lam(i, j) + lam(i + 1, j)).collect();
            let beta: Vec<f64> = (0..n).map(|j| lam(i + 1, j) - lam(i, j)).collect();
            let sec = step_second::<K, P>(d, &m, &v, &alpha, &beta, s);
            // J = ∂y/∂z, y = (m, v), z = (a, b, h): dense 2n × (2n + 1).
            let nz = 2 * n + 1;
            let mut jac = vec![vec![0.0; nz]; 2 * n];
            for j in 0..n {
                jac[j][j] = 0.5;
                jac[j][n + j] = 0.5;
                jac[n + j][j] = -1.0 / h;
                jac[n + j][n + j] = 1.0 / h;
                jac[n + j][2 * n] = -v[j] / h;
            }
            // Jᵀ F_yy J.
            let fj: Vec<Vec<f64>> = (0..2 * n)
                .map(|r| {
                    (0..nz)
                        .map(|c| (0..2 * n).map(|k| sec.hess_f[r][k] * jac[k][c]).sum())
                        .collect()
                })
                .collect();
            let mut hz = vec![vec![0.0; nz]; nz];
            for r in 0..nz {
                for c in 0..=r {
                    hz[r][c] = (0..2 * n).map(|k| jac[k][r] * fj[k][c]).sum();
                }
            }
            // The explicit h in s = h/2: ∂²ψ/∂h∂y = ½ ∇A, through J.
            for c in 0..2 * n {
                hz[2 * n][c] += (0..2 * n).map(|k| 0.5 * sec.grad_a[k] * jac[k][c]).sum::<f64>();
            }
            hz[2 * n][2 * n] += 2.0
                * (0..2 * n)
                    .map(|k| 0.5 * sec.grad_a[k] * jac[k][2 * n])
                    .sum::<f64>();
            // Σ_k ∂ψ/∂v_k ∇²v_k: v_k = (b_k − a_k)/h.
            for k in 0..n {
                let g = sec.grad_f[n + k];
                hz[2 * n][n + k] -= g / (h * h);
                hz[2 * n][k] += g / (h * h);
                hz[2 * n][2 * n] += g * 2.0 * v[k] / (h * h);
            }
            let index = |z: usize| -> usize {
                if z < n {
                    l.q(i, z)
                } else if z < 2 * n {
                    l.q(i + 1, z - n)
                } else {
                    l.h()
                }
            };
            for (r, row) in hz.iter().enumerate() {
                for (c, &val) in row.iter().enumerate().take(r + 1) {
                    put(index(r), index(c), val);
                }
            }
            // λᵀ (h/2)(u…): ∂²/∂h∂u_{i+½, j} = (λ_i + λ_{i+1})_j / 2.
            for (j, aj) in alpha.iter().enumerate() {
                put(l.h(), l.u(i, j), 0.5 * aj);
            }
        }
        // The boundary momenta γᵀ M(q) w, γ = λ_0 at the start, −λ_N at the end.
        for (grid, first, sign) in [(0, l.qd0(0), 1.0), (l.steps, l.qdn(0), -1.0)] {
            let q: Vec<f64> = (0..n).map(|j| x[l.q(grid, j)]).collect();
            let wv: Vec<f64> = (0..n).map(|j| x[first + j]).collect();
            let gamma: Vec<f64> = (0..n).map(|j| sign * lambda[grid * n + j]).collect();
            let qt: Vec<Taylor2<K, P>> = q
                .iter()
                .enumerate()
                .map(|(j, &v)| Taylor2::variable(v, j))
                .collect();
            let gt: Vec<Taylor2<K, P>> = gamma.iter().map(|&v| Taylor2::constant(v)).collect();
            let pg = d.momentum(&qt, &gt);
            for a in 0..n {
                for b in 0..=a {
                    let v: f64 = (0..n).map(|j| wv[j] * pg[j].hess(a, b)).sum();
                    put(l.q(grid, a), l.q(grid, b), v);
                }
                // ∂²/∂w_j∂q_a = ((∂_a M) γ)_j.
                for (j, pj) in pg.iter().enumerate() {
                    put(first + j, l.q(grid, a), pj.g[a]);
                }
            }
        }
        t
    }
}
