//! Second-order forward differentiation: a value with its gradient and its Hessian over `K`
//! variables, the Hessian stored once (upper triangle, packed by rows, `P = K(K+1)/2` entries).
//!
//! Nesting first-order duals (`Dual<K, Dual<K>>`) computes every mixed second derivative
//! twice; this type computes each once, and a product costs about `4P` multiplications. It
//! implements [`Real`], so the dynamics run on it unchanged, and it nests inside
//! [`cellplan_kin::dynamics::Dual`] for one more directional derivative (third derivatives
//! along one direction, as the Hessian of the discrete Euler–Lagrange equations needs).
use cellplan_kin::dynamics::Real;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A value, its gradient and its Hessian (upper triangle, packed) over `K` variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taylor2<const K: usize, const P: usize> {
    /// The value.
    pub v: f64,
    /// The gradient.
    pub g: [f64; K],
    /// The Hessian's upper triangle, row by row: (0,0), (0,1) … (0,K−1), (1,1), ….
    pub h: [f64; P],
}

impl<const K: usize, const P: usize> Taylor2<K, P> {
    /// The `k`-th variable at value `v` (beyond `K`: a constant).
    pub fn variable(v: f64, k: usize) -> Self {
        debug_assert_eq!(P, K * (K + 1) / 2, "P must be K(K+1)/2");
        let mut g = [0.0; K];
        if k < K {
            g[k] = 1.0;
        }
        Taylor2 { v, g, h: [0.0; P] }
    }

    /// A constant.
    pub fn constant(v: f64) -> Self {
        Taylor2 {
            v,
            g: [0.0; K],
            h: [0.0; P],
        }
    }

    /// The Hessian entry `(i, j)` (either order).
    pub fn hess(&self, i: usize, j: usize) -> f64 {
        let (i, j) = (i.min(j), i.max(j));
        // Rows 0 … i−1 hold K, K−1, …, K−i+1 entries.
        self.h[i * K - i * i.saturating_sub(1) / 2 + (j - i)]
    }

    /// `f(self)` from `f`, `f'`, `f''` at the value.
    fn apply(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut h = [0.0; P];
        let mut k = 0;
        for i in 0..K {
            for j in i..K {
                h[k] = df * self.h[k] + ddf * self.g[i] * self.g[j];
                k += 1;
            }
        }
        Taylor2 {
            v: f,
            g: self.g.map(|x| df * x),
            h,
        }
    }
}

impl<const K: usize, const P: usize> Add for Taylor2<K, P> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Taylor2 {
            v: self.v + o.v,
            g: std::array::from_fn(|k| self.g[k] + o.g[k]),
            h: std::array::from_fn(|k| self.h[k] + o.h[k]),
        }
    }
}

impl<const K: usize, const P: usize> Sub for Taylor2<K, P> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Taylor2 {
            v: self.v - o.v,
            g: std::array::from_fn(|k| self.g[k] - o.g[k]),
            h: std::array::from_fn(|k| self.h[k] - o.h[k]),
        }
    }
}

impl<const K: usize, const P: usize> Mul for Taylor2<K, P> {
    type Output = Self;
    // d²(ab) = a d²b + b d²a + da dbᵀ + db daᵀ.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, o: Self) -> Self {
        let mut h = [0.0; P];
        let mut k = 0;
        for i in 0..K {
            let (ai, bi) = (self.g[i], o.g[i]);
            for j in i..K {
                h[k] = self.h[k] * o.v + self.v * o.h[k] + ai * o.g[j] + bi * self.g[j];
                k += 1;
            }
        }
        Taylor2 {
            v: self.v * o.v,
            g: std::array::from_fn(|k| self.g[k] * o.v + self.v * o.g[k]),
            h,
        }
    }
}

impl<const K: usize, const P: usize> Div for Taylor2<K, P> {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.v;
        self * o.apply(inv, -inv * inv, 2.0 * inv * inv * inv)
    }
}

impl<const K: usize, const P: usize> Neg for Taylor2<K, P> {
    type Output = Self;
    fn neg(self) -> Self {
        Taylor2 {
            v: -self.v,
            g: self.g.map(|x| -x),
            h: self.h.map(|x| -x),
        }
    }
}

impl<const K: usize, const P: usize> Real for Taylor2<K, P> {
    fn from_f64(v: f64) -> Self {
        Taylor2::constant(v)
    }
    fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.apply(s, c, -s)
    }
    fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.apply(c, -s, -c)
    }
    fn value(self) -> f64 {
        self.v
    }
}
