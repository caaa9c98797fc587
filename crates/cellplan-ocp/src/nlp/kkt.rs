//! The condensed primal-dual KKT system of the interior-point method, its assembly in the
//! problem's elimination order, its factorisation with inertia correction and its solution
//! with iterative refinement.
//!
//! Unknowns: `Δx` (n) and `Δy_c` (m). The slacks and the inequalities' multipliers are
//! eliminated, which adds `J_dᵀ D J_d` to the primal block with `D = 1/(1/(Σ_s + δ_w) + δ_c)`:
//!
//! `[W + Σ_x + J_dᵀ D J_d + δ_w I, J_cᵀ; J_c, −δ_c I]`.
//!
//! The right inertia is n positive and m negative eigenvalues (the eliminated pairs each
//! contribute one of either sign). Fixed variables get a unit row and column.
use super::Triplets;
use super::ldl::{BandedLdl, Inertia};

/// The structure: sizes, elimination order, fixed variables.
pub(crate) struct Kkt {
    n: usize,
    m: usize,
    /// Position of each unknown in the factorisation order.
    pos: Vec<usize>,
    /// Unknown at each position.
    order: Vec<usize>,
    /// Border size (the last positions).
    nc: usize,
    fixed: Vec<bool>,
}

/// The numbers of one Newton system.
pub(crate) struct KktValues<'a> {
    /// Lower triangle of the Lagrangian's Hessian.
    pub hess: &'a Triplets,
    /// Jacobians of the equalities and inequalities.
    pub jac_c: &'a Triplets,
    pub jac_d: &'a Triplets,
    /// Barrier diagonals of the variables and the inequalities' slacks.
    pub sigma_x: &'a [f64],
    pub sigma_s: &'a [f64],
}

/// A factored system.
pub(crate) struct Factored {
    ldl: BandedLdl,
    /// Lower-triangle entries in positions, for products in the refinement.
    entries: Vec<(usize, usize, f64)>,
    /// The inequalities' `D`.
    pub d_ineq: Vec<f64>,
    pub delta_w: f64,
}

/// Regularisation memory across iterations (IPOPT's δ_w^last).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Regularisation {
    pub last_delta_w: f64,
}

impl Kkt {
    pub fn new(n: usize, m: usize, order: Option<(Vec<usize>, usize)>, fixed: Vec<bool>) -> Self {
        let (order, nc) = order
            .filter(|(o, nc)| {
                let mut seen = vec![false; n + m];
                o.len() == n + m
                    && *nc <= o.len()
                    && o.iter()
                        .all(|&k| k < n + m && !std::mem::replace(&mut seen[k], true))
            })
            .unwrap_or_else(|| ((0..n + m).collect(), 0));
        let mut pos = vec![0; n + m];
        for (p, &k) in order.iter().enumerate() {
            pos[k] = p;
        }
        Kkt {
            n,
            m,
            pos,
            order,
            nc,
            fixed,
        }
    }

    fn assemble(&self, v: &KktValues, delta_w: f64, delta_c: f64) -> (Vec<(usize, usize, f64)>, Vec<f64>) {
        let (n, m) = (self.n, self.m);
        let mut e: Vec<(usize, usize, f64)> =
            Vec::with_capacity(v.hess.len() + v.jac_c.len() + 3 * v.jac_d.len() + n + m);
        let mut put = |a: usize, b: usize, val: f64| {
            let (pa, pb) = (self.pos[a], self.pos[b]);
            e.push((pa.max(pb), pa.min(pb), val));
        };
        for &(r, c, val) in v.hess {
            if !self.fixed[r] && !self.fixed[c] {
                put(r, c, val);
            }
        }
        for k in 0..n {
            let diag = if self.fixed[k] {
                1.0
            } else {
                v.sigma_x[k] + delta_w
            };
            put(k, k, diag);
        }
        for &(r, c, val) in v.jac_c {
            if !self.fixed[c] {
                put(n + r, c, val);
            }
        }
        for r in 0..m {
            put(n + r, n + r, -delta_c);
        }
        // J_dᵀ D J_d, row by row of J_d.
        let d_ineq: Vec<f64> = v
            .sigma_s
            .iter()
            .map(|&s| 1.0 / (1.0 / (s + delta_w) + delta_c))
            .collect();
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); d_ineq.len()];
        for &(r, c, val) in v.jac_d {
            if !self.fixed[c] {
                rows[r].push((c, val));
            }
        }
        for (r, row) in rows.iter_mut().enumerate() {
            // Repeated columns add up first (the product needs each column once).
            row.sort_by_key(|&(c, _)| c);
            row.dedup_by(|b, a| {
                let same = a.0 == b.0;
                if same {
                    a.1 += b.1;
                }
                same
            });
            for (i, &(a, va)) in row.iter().enumerate() {
                for &(b, vb) in &row[..=i] {
                    put(a, b, d_ineq[r] * va * vb);
                }
            }
        }
        (e, d_ineq)
    }

    /// Assembles and factors; `None` when the factorisation breaks down.
    fn factor(&self, v: &KktValues, delta_w: f64, delta_c: f64) -> (Factored, Inertia) {
        let (entries, d_ineq) = self.assemble(v, delta_w, delta_c);
        let dim = self.n + self.m;
        let nb = dim - self.nc;
        let w = entries
            .iter()
            .filter(|&&(r, _, _)| r < nb)
            .map(|&(r, c, _)| r - c)
            .max()
            .unwrap_or(0);
        let mut ldl = BandedLdl::new(nb, w, self.nc);
        for &(r, c, val) in &entries {
            ldl.add(r, c, val);
        }
        let inertia = ldl.factor(1e-13);
        (
            Factored {
                ldl,
                entries,
                d_ineq,
                delta_w,
            },
            inertia,
        )
    }

    /// Factors without regularisation; `None` unless the inertia is the right one (n
    /// positive, m negative, no zero pivot).
    pub fn factor_exact(&self, v: &KktValues) -> Option<Factored> {
        let (f, inertia) = self.factor(v, 0.0, 0.0);
        (inertia.zero == 0 && (inertia.positive, inertia.negative) == (self.n, self.m)).then_some(f)
    }

    /// Factors with IPOPT's inertia correction: δ_w = δ_c = 0 first; a zero pivot brings
    /// δ_c = 1e-8 μ^¼; a wrong inertia raises δ_w (from 1e-4, or a third of the last one, by
    /// ×100 or ×8). `None` when δ_w passes 1e40.
    pub fn factor_corrected(&self, v: &KktValues, mu: f64, reg: &mut Regularisation) -> Option<Factored> {
        let want = (self.n, self.m);
        let mut delta_c = 0.0;
        let mut delta_w = 0.0;
        let (f, inertia) = self.factor(v, delta_w, delta_c);
        if inertia.zero == 0 && (inertia.positive, inertia.negative) == want {
            return Some(f);
        }
        if inertia.zero > 0 {
            delta_c = 1e-8 * mu.powf(0.25);
        }
        delta_w = if reg.last_delta_w == 0.0 {
            1e-4
        } else {
            (reg.last_delta_w / 3.0).max(1e-20)
        };
        loop {
            let (f, inertia) = self.factor(v, delta_w, delta_c);
            if inertia.zero == 0 && (inertia.positive, inertia.negative) == want {
                reg.last_delta_w = delta_w;
                return Some(f);
            }
            if inertia.zero > 0 && delta_c == 0.0 {
                delta_c = 1e-8 * mu.powf(0.25);
            }
            delta_w *= if reg.last_delta_w == 0.0 { 100.0 } else { 8.0 };
            if delta_w > 1e40 {
                return None;
            }
        }
    }

    /// Solves the factored system for a right-hand side over (x, y_c), with up to `refine`
    /// steps of iterative refinement against the factored (regularised) matrix.
    pub fn solve(&self, f: &Factored, rhs: &[f64], refine: usize) -> Vec<f64> {
        let dim = self.n + self.m;
        let b: Vec<f64> = (0..dim).map(|p| rhs[self.order[p]]).collect();
        let mut x = b.clone();
        f.ldl.solve(&mut x);
        let bnorm = b.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        for _ in 0..refine {
            let mut r = b.clone();
            for &(i, j, v) in &f.entries {
                r[i] -= v * x[j];
                if i != j {
                    r[j] -= v * x[i];
                }
            }
            let rn = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            if rn <= 1e-14 * bnorm {
                break;
            }
            f.ldl.solve(&mut r);
            for (xi, ri) in x.iter_mut().zip(&r) {
                *xi += ri;
            }
        }
        let mut out = vec![0.0; dim];
        for (p, v) in x.into_iter().enumerate() {
            out[self.order[p]] = v;
        }
        out
    }
}
