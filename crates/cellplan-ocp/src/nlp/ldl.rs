//! A symmetric LDLᵀ factorisation without pivoting for banded matrices with a dense border
//! (arrow structure): `K = [B Cᵀ; C E]` with `B` banded (half-bandwidth `w`) and the border
//! `E` small. `B = L D Lᵀ` in band storage, then the Schur complement `S = E − C B⁻¹ Cᵀ` is
//! factored densely, also without pivoting. The inertia of `K` is the sum of the inertias of
//! `B` and `S` (Haynsworth), read from the signs of the pivots (Sylvester).
//!
//! Without pivoting the factorisation exists for quasi-definite matrices in any order
//! (Vanderbei 1995), which the interior-point method's regularised KKT systems are once
//! their inertia is right; a pivot too small to trust is reported as a zero eigenvalue, which
//! the caller answers with more regularisation. Work is `O(dim · w²)` for `B` plus
//! `O(dim · w · border)` for the border.

/// The inertia: positive, negative and (numerically) zero pivots.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Inertia {
    /// Positive eigenvalues.
    pub positive: usize,
    /// Negative eigenvalues.
    pub negative: usize,
    /// Zero (or untrustworthy) pivots.
    pub zero: usize,
}

/// A symmetric matrix in banded-plus-border form, filled entry by entry, then factored.
#[derive(Clone, Debug)]
pub struct BandedLdl {
    /// Size of the banded part.
    nb: usize,
    /// Half-bandwidth.
    w: usize,
    /// Border size.
    nc: usize,
    /// Band: row i, column j ∈ [i − w, i] at `i (w + 1) + (j + w − i)`; after factoring, L
    /// below the diagonal and D on it.
    band: Vec<f64>,
    /// The border rows `C` (nc × nb), then `B⁻¹ Cᵀ` columns after factoring.
    border: Vec<f64>,
    /// `E` (nc × nc, full), then its Schur complement's factors.
    corner: Vec<f64>,
    factored: bool,
}

impl BandedLdl {
    /// A zero matrix of size `nb + nc` with half-bandwidth `w` in its first `nb` rows.
    pub fn new(nb: usize, w: usize, nc: usize) -> Self {
        let w = w.min(nb.saturating_sub(1));
        BandedLdl {
            nb,
            w,
            nc,
            band: vec![0.0; nb * (w + 1)],
            border: vec![0.0; nc * nb],
            corner: vec![0.0; nc * nc],
            factored: false,
        }
    }

    /// The matrix's size.
    pub fn dim(&self) -> usize {
        self.nb + self.nc
    }

    /// Half-bandwidth of the banded part.
    pub fn bandwidth(&self) -> usize {
        self.w
    }

    /// Sets every entry to zero (keeps the structure).
    pub fn clear(&mut self) {
        self.band.fill(0.0);
        self.border.fill(0.0);
        self.corner.fill(0.0);
        self.factored = false;
    }

    /// Adds `v` at `(i, j)` (and its mirror). Panics if `(i, j)` is outside the structure.
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let (i, j) = (i.max(j), i.min(j));
        let nb = self.nb;
        if i < nb {
            assert!(i - j <= self.w, "({i}, {j}) outside the band {}", self.w);
            self.band[i * (self.w + 1) + (j + self.w - i)] += v;
        } else if j < nb {
            self.border[(i - nb) * nb + j] += v;
        } else {
            let (a, b) = (i - nb, j - nb);
            self.corner[a * self.nc + b] += v;
            if a != b {
                self.corner[b * self.nc + a] += v;
            }
        }
    }

    /// Factors in place; the inertia, with a pivot counted as zero (and replaced by a tiny
    /// one of its sign) when it is below `pivot_tol` times the terms that cancelled in it.
    pub fn factor(&mut self, pivot_tol: f64) -> Inertia {
        let (nb, w, nc) = (self.nb, self.w, self.nc);
        let wp = w + 1;
        let mut inertia = Inertia::default();
        // A pivot is zero when it is below the rounding noise of its own computation:
        // `pivot_tol` times the size of the terms that cancelled in it.
        let count = |d: f64, size: f64, inertia: &mut Inertia| -> f64 {
            let tiny = pivot_tol * size.max(1e-300);
            if !d.is_finite() || d.abs() <= tiny {
                inertia.zero += 1;
                return if d < 0.0 { -tiny } else { tiny };
            }
            if d > 0.0 {
                inertia.positive += 1;
            } else {
                inertia.negative += 1;
            }
            d
        };
        // Band: row-oriented (left-looking) LDLᵀ; `tmp[k] = L_ik d_k`.
        let mut tmp = vec![0.0; wp];
        for i in 0..nb {
            let lo = i.saturating_sub(w);
            let row = i * wp;
            for j in lo..i {
                // L_ij = (A_ij − Σ_{k<j} L_ik L_jk d_k) / d_j.
                let klo = lo.max(j.saturating_sub(w));
                let mut s = self.band[row + (j + w - i)];
                let jrow = j * wp;
                for k in klo..j {
                    s -= tmp[k - lo] * self.band[jrow + (k + w - j)];
                }
                let dj = self.band[jrow + w];
                tmp[j - lo] = s;
                self.band[row + (j + w - i)] = s / dj;
            }
            let mut d = self.band[row + w];
            let mut size = d.abs();
            for j in lo..i {
                let t = tmp[j - lo] * self.band[row + (j + w - i)];
                d -= t;
                size += t.abs();
            }
            self.band[row + w] = count(d, size, &mut inertia);
        }
        // Border: G = B⁻¹ Cᵀ column by column (stored over C's rows as they are done), and
        // S = E − C G: S_ab = E_ab − C_a · G_b, with G_b for b < a already in place of C_b.
        let mut g = vec![0.0; nb];
        for a in 0..nc {
            g.copy_from_slice(&self.border[a * nb..(a + 1) * nb]);
            self.band_solve(&mut g);
            let ca = &self.border[a * nb..(a + 1) * nb];
            let mut s_row = vec![0.0; a + 1];
            for (b, sb) in s_row.iter_mut().enumerate() {
                let gb = if b == a {
                    &g[..]
                } else {
                    &self.border[b * nb..(b + 1) * nb]
                };
                *sb = ca.iter().zip(gb).map(|(c, x)| c * x).sum();
            }
            for (b, sb) in s_row.into_iter().enumerate() {
                self.corner[a * nc + b] -= sb;
                if a != b {
                    self.corner[b * nc + a] -= sb;
                }
            }
            self.border[a * nb..(a + 1) * nb].copy_from_slice(&g);
        }
        // Dense LDLᵀ of S (no pivoting).
        for j in 0..nc {
            let mut d = self.corner[j * nc + j];
            let mut size = d.abs();
            for k in 0..j {
                let t = self.corner[j * nc + k].powi(2) * self.corner[k * nc + k];
                d -= t;
                size += t.abs();
            }
            let d = count(d, size, &mut inertia);
            self.corner[j * nc + j] = d;
            for i in j + 1..nc {
                let mut s = self.corner[i * nc + j];
                for k in 0..j {
                    s -= self.corner[i * nc + k] * self.corner[j * nc + k] * self.corner[k * nc + k];
                }
                self.corner[i * nc + j] = s / d;
            }
        }
        self.factored = true;
        inertia
    }

    /// Solves `B x = b` with the band's factors, in place.
    fn band_solve(&self, x: &mut [f64]) {
        let (nb, w) = (self.nb, self.w);
        let wp = w + 1;
        for i in 0..nb {
            let lo = i.saturating_sub(w);
            let row = i * wp;
            let mut s = x[i];
            for j in lo..i {
                s -= self.band[row + (j + w - i)] * x[j];
            }
            x[i] = s;
        }
        for i in 0..nb {
            x[i] /= self.band[i * wp + w];
        }
        for i in (0..nb).rev() {
            let xi = x[i];
            let row = i * wp;
            for j in i.saturating_sub(w)..i {
                x[j] -= self.band[row + (j + w - i)] * xi;
            }
        }
    }

    /// Solves `K x = b` in place (after [`factor`](Self::factor)).
    pub fn solve(&self, x: &mut [f64]) {
        assert!(self.factored, "factor first");
        let (nb, nc) = (self.nb, self.nc);
        // [B Cᵀ; C E] [y; z] = [r; t]: S z = t − Gᵀ r (as C B⁻¹ = Gᵀ), y = B⁻¹ r − G z.
        let (top, bottom) = x.split_at_mut(nb);
        for (a, t) in bottom.iter_mut().enumerate() {
            let ga = &self.border[a * nb..(a + 1) * nb];
            *t -= ga.iter().zip(top.iter()).map(|(g, r)| g * r).sum::<f64>();
        }
        for i in 0..nc {
            let s: f64 = (0..i).map(|k| self.corner[i * nc + k] * bottom[k]).sum();
            bottom[i] -= s;
        }
        for i in 0..nc {
            bottom[i] /= self.corner[i * nc + i];
        }
        for i in (0..nc).rev() {
            let s: f64 = (i + 1..nc).map(|k| self.corner[k * nc + i] * bottom[k]).sum();
            bottom[i] -= s;
        }
        self.band_solve(top);
        for (a, z) in bottom.iter().enumerate() {
            let ga = &self.border[a * nb..(a + 1) * nb];
            for (y, g) in top.iter_mut().zip(ga) {
                *y -= g * z;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric quasi-definite test matrix with an arrow structure, as dense rows.
    fn arrow(nb: usize, w: usize, nc: usize) -> Vec<Vec<f64>> {
        let n = nb + nc;
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..nb {
            for j in i.saturating_sub(w)..i {
                let v = ((i * 7 + j * 3) as f64).sin();
                a[i][j] = v;
                a[j][i] = v;
            }
            // Alternate signs on the diagonal: an indefinite (quasi-definite-like) matrix.
            a[i][i] = if i % 3 == 2 { -5.0 } else { 6.0 + (i as f64).cos() };
        }
        for r in nb..n {
            for j in 0..nb {
                let v = ((r * 5 + j) as f64).cos() * 0.3;
                a[r][j] = v;
                a[j][r] = v;
            }
            a[r][r] = -4.0 - r as f64;
        }
        a
    }

    #[test]
    fn solves_an_arrow_matrix_and_counts_its_inertia() {
        let (nb, w, nc) = (40, 5, 2);
        let a = arrow(nb, w, nc);
        let n = nb + nc;
        let mut m = BandedLdl::new(nb, w, nc);
        for i in 0..n {
            for j in 0..=i {
                if a[i][j] != 0.0 {
                    m.add(i, j, a[i][j]);
                }
            }
        }
        let inertia = m.factor(1e-14);
        let want: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin() + 0.5).collect();
        let mut b: Vec<f64> = (0..n).map(|i| (0..n).map(|j| a[i][j] * want[j]).sum()).collect();
        m.solve(&mut b);
        for (x, y) in b.iter().zip(&want) {
            assert!((x - y).abs() < 1e-10, "{x} vs {y}");
        }
        // The negative diagonal entries (every third band row and the border) dominate their
        // rows, so the inertia is that of the diagonal.
        let neg = (0..nb).filter(|i| i % 3 == 2).count() + nc;
        assert_eq!(
            inertia,
            Inertia {
                positive: n - neg,
                negative: neg,
                zero: 0
            }
        );
    }

    #[test]
    fn a_singular_matrix_reports_a_zero_pivot() {
        let mut m = BandedLdl::new(3, 2, 0);
        // Rows 0 and 1 equal: [1 1 0; 1 1 0; 0 0 1].
        m.add(0, 0, 1.0);
        m.add(1, 0, 1.0);
        m.add(1, 1, 1.0);
        m.add(2, 2, 1.0);
        assert_eq!(m.factor(1e-12).zero, 1);
    }
}
