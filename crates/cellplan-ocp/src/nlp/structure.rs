//! A fixed sparsity structure for solvers that ask for it once (IPOPT's C interface, ripopt):
//! [`Nlp`]'s triplets list only the nonzeros of the point they are evaluated at.
//!
//! [`Structure::of`] takes the union of the entries at the start and at three points near it
//! with every multiplier 1 — each derivative of the DMOC transcription that can be nonzero is
//! nonzero there. [`Structure::scatter`] places later triplets and says when one falls
//! outside, so that a caller can stop instead of dropping it.
use super::{Nlp, Triplets};
use std::collections::BTreeMap;

/// `(row, col)` → position, and the rows and columns by position.
#[derive(Clone, Debug, Default)]
pub struct Structure {
    index: BTreeMap<(usize, usize), usize>,
    /// Row of each position.
    pub rows: Vec<usize>,
    /// Column of each position.
    pub cols: Vec<usize>,
    /// `rows` as C ints.
    pub rows_i32: Vec<i32>,
    /// `cols` as C ints.
    pub cols_i32: Vec<i32>,
}

impl Structure {
    /// The union of the entries of `samples`, in order of first appearance.
    pub fn new(samples: impl IntoIterator<Item = Triplets>) -> Structure {
        let mut s = Structure::default();
        for t in samples {
            for (r, c, _) in t {
                let next = s.index.len();
                if let std::collections::btree_map::Entry::Vacant(e) = s.index.entry((r, c)) {
                    e.insert(next);
                    s.rows.push(r);
                    s.cols.push(c);
                }
            }
        }
        s.rows_i32 = s.rows.iter().map(|&v| v as i32).collect();
        s.cols_i32 = s.cols.iter().map(|&v| v as i32).collect();
        s
    }

    /// The structures of the Jacobian of `[c; d]` ([`stacked_jacobian`]) and of the lower
    /// triangle of the Lagrangian's Hessian, from `x0` and three points near it.
    pub fn of(nlp: &dyn Nlp, x0: &[f64]) -> (Structure, Structure) {
        let m_eq = nlp.num_eq();
        let points: Vec<Vec<f64>> = std::iter::once(x0.to_vec())
            .chain((1..=3).map(|k| nearby(x0, k)))
            .collect();
        let ones_eq = vec![1.0; m_eq];
        let ones_in = vec![1.0; nlp.num_ineq()];
        let jac = Structure::new(points.iter().map(|x| stacked_jacobian(nlp, x, m_eq)));
        let hess = Structure::new(points.iter().map(|x| nlp.hessian(x, 1.0, &ones_eq, &ones_in)));
        (jac, hess)
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Adds `t` into `values` (zeroed first); false when an entry is outside the structure.
    pub fn scatter(&self, t: &Triplets, values: &mut [f64]) -> bool {
        values.fill(0.0);
        for &(r, c, v) in t {
            match self.index.get(&(r, c)) {
                Some(&k) if k < values.len() => values[k] += v,
                _ => return false,
            }
        }
        true
    }
}

/// `g = [c; d]`, the form IPOPT's and ripopt's interfaces take.
pub fn stacked_constraints(nlp: &dyn Nlp, x: &[f64]) -> Vec<f64> {
    let mut g = nlp.eq(x);
    g.extend(nlp.ineq(x));
    g
}

/// The bounds `(g_L, g_U)` of [`stacked_constraints`]: 0 for the equalities, then `d_L`, `d_U`.
pub fn stacked_bounds(nlp: &dyn Nlp) -> (Vec<f64>, Vec<f64>) {
    let m = nlp.num_eq();
    let (dl, du) = nlp.ineq_bounds();
    let lo = std::iter::repeat_n(0.0, m).chain(dl).collect();
    let hi = std::iter::repeat_n(0.0, m).chain(du).collect();
    (lo, hi)
}

/// The Jacobian of `[c; d]` (the inequalities' rows after the equalities').
pub fn stacked_jacobian(nlp: &dyn Nlp, x: &[f64], m_eq: usize) -> Triplets {
    let mut t = nlp.eq_jacobian(x);
    t.extend(nlp.ineq_jacobian(x).into_iter().map(|(r, c, v)| (r + m_eq, c, v)));
    t
}

/// A point near `x0` (a deterministic spread of 1e-3 relative) where the derivatives take
/// their generic nonzeros.
fn nearby(x0: &[f64], k: usize) -> Vec<f64> {
    x0.iter()
        .enumerate()
        .map(|(i, v)| {
            let wiggle = ((i * 7 + k * 13) % 11) as f64 / 11.0 - 0.45;
            v + 1e-3 * wiggle * v.abs().max(1.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_outside_the_structure_are_reported_and_repeats_add_up() {
        let s = Structure::new([vec![(0, 0, 1.0), (2, 1, 3.0)], vec![(2, 1, 5.0), (1, 1, 0.5)]]);
        assert_eq!(s.len(), 3);
        assert_eq!((s.rows.clone(), s.cols.clone()), (vec![0, 2, 1], vec![0, 1, 1]));
        let mut v = vec![9.0; 3];
        assert!(s.scatter(&vec![(2, 1, 1.0), (2, 1, 2.0)], &mut v));
        assert_eq!(v, vec![0.0, 3.0, 0.0]);
        assert!(!s.scatter(&vec![(1, 0, 1.0)], &mut v));
    }
}
