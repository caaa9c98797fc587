//! Problem data: [`CostMatrix`], the generalised TSP [`Gtsp`] with its [`Tour`], and
//! [`SetCover`].
use crate::error::{CostMatrixError, CoverError, Depot, GtspError, TourError};

/// A dense `n × n` matrix of travel costs, row-major: `get(i, j)` is the cost of going from node
/// `i` to node `j`. It may be asymmetric. Every entry is finite and non-negative.
#[derive(Clone, Debug, PartialEq)]
pub struct CostMatrix {
    n: usize,
    data: Vec<f64>,
}

impl CostMatrix {
    /// A matrix of `n` nodes from `data` in row-major order. Fails unless `data.len() == n * n`
    /// and every entry is finite and non-negative.
    pub fn new(n: usize, data: Vec<f64>) -> Result<Self, CostMatrixError> {
        let want = n.checked_mul(n).ok_or(CostMatrixError::Overflow { n })?;
        if data.len() != want {
            return Err(CostMatrixError::Size {
                n,
                want,
                got: data.len(),
            });
        }
        if let Some(k) = data.iter().position(|c| !c.is_finite() || *c < 0.0) {
            return Err(CostMatrixError::Entry {
                row: k / n,
                col: k % n,
                value: data[k],
            });
        }
        Ok(CostMatrix { n, data })
    }

    /// A matrix of `n` nodes whose entry `(i, j)` is `f(i, j)`.
    ///
    /// # Panics
    /// If `f` returns a negative or non-finite value (use [`CostMatrix::new`] for fallible
    /// construction).
    pub fn from_fn(n: usize, mut f: impl FnMut(usize, usize) -> f64) -> Self {
        let mut data = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                let c = f(i, j);
                assert!(
                    c.is_finite() && c >= 0.0,
                    "cost ({i}, {j}) = {c} is negative or not finite"
                );
                data.push(c);
            }
        }
        CostMatrix { n, data }
    }

    /// The matrix of the nodes `nodes` (indices into this one, repeats allowed): entry
    /// `(i, j)` is `get(nodes[i], nodes[j])`. Its entries were checked when this one was made.
    ///
    /// # Panics
    /// If a node is not below [`CostMatrix::n`].
    pub fn sub(&self, nodes: &[usize]) -> Self {
        // Runs of consecutive nodes (a task's alternatives mostly are) are copied a slice at
        // a time.
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for &j in nodes {
            match runs.last_mut() {
                Some((from, to)) if *to == j => *to = j + 1,
                _ => runs.push((j, j + 1)),
            }
        }
        let mut data = Vec::with_capacity(nodes.len() * nodes.len());
        for &i in nodes {
            let row = &self.data[i * self.n..(i + 1) * self.n];
            for &(from, to) in &runs {
                data.extend_from_slice(&row[from..to]);
            }
        }
        CostMatrix { n: nodes.len(), data }
    }

    /// Number of nodes.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The cost from node `i` to node `j`.
    ///
    /// # Panics
    /// If `i` or `j` is not below [`CostMatrix::n`].
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        debug_assert!(i < self.n && j < self.n);
        self.data[i * self.n + j]
    }

    /// The cost from `i` to `j`, or `None` when either index is out of range.
    #[inline]
    pub fn try_get(&self, i: usize, j: usize) -> Option<f64> {
        (i < self.n && j < self.n).then(|| self.data[i * self.n + j])
    }

    /// All entries, row-major.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// Whether `|get(i, j) − get(j, i)| <= tol` for every pair.
    pub fn is_symmetric(&self, tol: f64) -> bool {
        (0..self.n).all(|i| (i + 1..self.n).all(|j| (self.get(i, j) - self.get(j, i)).abs() <= tol))
    }
}

/// A generalised travelling-salesman problem: the nodes are partitioned (in part) into
/// `clusters`, and a tour visits exactly one node of every cluster.
///
/// - Without depots (`start` and `end` both `None`) the tour is a closed cycle through the
///   clusters.
/// - With `start = Some(s)` the tour leaves `s`, visits the clusters and returns to `end`, or to
///   `s` again when `end` is `None`. Depots belong to no cluster. `end` without `start` is
///   refused by [`Gtsp::with_depots`].
/// - `service[v]` is a time added when node `v` is visited (depots included, the start once, the
///   end once more when it differs from the start); zeros by default.
///
/// The fields are public for reading; build and change instances through [`Gtsp::new`],
/// [`Gtsp::with_depots`] and [`Gtsp::with_service`], which validate.
#[derive(Clone, Debug, PartialEq)]
pub struct Gtsp {
    /// Travel costs between all nodes, depots included.
    pub costs: CostMatrix,
    /// The clusters; each is a non-empty list of node indices, and no node is in two.
    pub clusters: Vec<Vec<usize>>,
    /// The depot the tour starts from, if fixed.
    pub start: Option<usize>,
    /// The depot the tour ends at, if fixed (with `start` but no `end`, the tour returns to
    /// `start`).
    pub end: Option<usize>,
    /// Service time of every node, `costs.n()` entries.
    pub service: Vec<f64>,
}

impl Gtsp {
    /// A GTSP without depots and with zero service times. Fails if a cluster is empty, names a
    /// node `>= costs.n()`, or shares a node with another cluster (or repeats one).
    pub fn new(costs: CostMatrix, clusters: Vec<Vec<usize>>) -> Result<Self, GtspError> {
        let n = costs.n();
        let mut owner: Vec<Option<usize>> = vec![None; n];
        for (k, cluster) in clusters.iter().enumerate() {
            if cluster.is_empty() {
                return Err(GtspError::EmptyCluster { cluster: k });
            }
            for &v in cluster {
                if v >= n {
                    return Err(GtspError::NodeOutOfRange {
                        cluster: k,
                        node: v,
                        nodes: n,
                    });
                }
                if let Some(other) = owner[v] {
                    return Err(GtspError::SharedNode {
                        node: v,
                        first: other,
                        second: k,
                    });
                }
                owner[v] = Some(k);
            }
        }
        Ok(Gtsp {
            costs,
            clusters,
            start: None,
            end: None,
            service: vec![0.0; n],
        })
    }

    /// A plain TSP on all nodes of `costs`: one singleton cluster per node.
    pub fn tsp(costs: CostMatrix) -> Self {
        let n = costs.n();
        Gtsp {
            costs,
            clusters: (0..n).map(|v| vec![v]).collect(),
            start: None,
            end: None,
            service: vec![0.0; n],
        }
    }

    /// The same problem with fixed depots. Fails if a depot is out of range or in a cluster, or
    /// if `end` is given without `start`.
    pub fn with_depots(mut self, start: Option<usize>, end: Option<usize>) -> Result<Self, GtspError> {
        if start.is_none() && end.is_some() {
            return Err(GtspError::EndWithoutStart);
        }
        let owner = self.node_clusters();
        for (which, d) in [(Depot::Start, start), (Depot::End, end)] {
            if let Some(d) = d {
                if d >= self.costs.n() {
                    return Err(GtspError::DepotOutOfRange {
                        which,
                        depot: d,
                        nodes: self.costs.n(),
                    });
                }
                if let Some(k) = owner[d] {
                    return Err(GtspError::DepotInCluster {
                        which,
                        depot: d,
                        cluster: k,
                    });
                }
            }
        }
        self.start = start;
        self.end = end;
        Ok(self)
    }

    /// The same problem with service times, one per node. Fails unless there are `costs.n()`
    /// values, all finite and non-negative.
    pub fn with_service(mut self, service: Vec<f64>) -> Result<Self, GtspError> {
        if service.len() != self.costs.n() {
            return Err(GtspError::ServiceCount {
                given: service.len(),
                nodes: self.costs.n(),
            });
        }
        if let Some(v) = service.iter().position(|s| !s.is_finite() || *s < 0.0) {
            return Err(GtspError::ServiceValue {
                node: v,
                value: service[v],
            });
        }
        self.service = service;
        Ok(self)
    }

    /// For every node, the index of its cluster (`None` for nodes in no cluster, e.g. depots).
    pub fn node_clusters(&self) -> Vec<Option<usize>> {
        let mut owner = vec![None; self.costs.n()];
        for (k, cluster) in self.clusters.iter().enumerate() {
            for &v in cluster {
                if let Some(o) = owner.get_mut(v) {
                    *o = Some(k);
                }
            }
        }
        owner
    }

    /// The cost of `tour`: its edges (from the start depot, between consecutive nodes, to the end
    /// depot — or the closing edge back to the first node when there are no depots) plus the
    /// service time of every visited node and depot. Does not check that the tour is feasible
    /// (see [`Gtsp::check`]); returns infinity if it names a node out of range.
    pub fn tour_cost(&self, tour: &Tour) -> f64 {
        let c = |u: usize, v: usize| self.costs.try_get(u, v).unwrap_or(f64::INFINITY);
        let s = |v: usize| self.service.get(v).copied().unwrap_or(f64::INFINITY);
        let nodes = &tour.nodes;
        let mut total: f64 = nodes.windows(2).map(|w| c(w[0], w[1])).sum();
        total += nodes.iter().map(|&v| s(v)).sum::<f64>();
        match self.start {
            Some(st) => {
                let end = self.end.unwrap_or(st);
                total += s(st);
                if end != st {
                    total += s(end);
                }
                match (nodes.first(), nodes.last()) {
                    (Some(&first), Some(&last)) => total += c(st, first) + c(last, end),
                    _ => total += c(st, end),
                }
            }
            None => {
                if let (Some(&first), Some(&last)) = (nodes.first(), nodes.last()) {
                    total += c(last, first);
                }
            }
        }
        total
    }

    /// Ok if `tour` visits exactly one node of every cluster (in any order) and nothing else.
    pub fn check(&self, tour: &Tour) -> Result<(), TourError> {
        let owner = self.node_clusters();
        let mut seen: Vec<Option<usize>> = vec![None; self.clusters.len()];
        for (pos, &v) in tour.nodes.iter().enumerate() {
            let Some(slot) = owner.get(v) else {
                return Err(TourError::OutOfRange {
                    position: pos,
                    node: v,
                    nodes: self.costs.n(),
                });
            };
            let Some(k) = *slot else {
                return Err(TourError::NoCluster {
                    position: pos,
                    node: v,
                });
            };
            if let Some(prev) = seen[k] {
                return Err(TourError::ClusterTwice {
                    cluster: k,
                    first_node: tour.nodes[prev],
                    first_position: prev,
                    node: v,
                    position: pos,
                });
            }
            seen[k] = Some(pos);
        }
        if let Some(k) = seen.iter().position(Option::is_none) {
            return Err(TourError::ClusterMissing { cluster: k });
        }
        Ok(())
    }
}

/// A GTSP tour: the visited nodes in order, one per cluster, depots excluded.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Tour {
    /// The visited nodes in order.
    pub nodes: Vec<usize>,
}

/// A weighted set-cover instance: choose columns of least total cost so that every row is
/// covered by at least one chosen column.
#[derive(Clone, Debug, PartialEq)]
pub struct SetCover {
    /// Number of rows to cover.
    pub rows: usize,
    /// Number of columns to choose from.
    pub columns: usize,
    /// Cost of each column (`columns` entries).
    pub costs: Vec<f64>,
    /// For each row, the 0-based columns covering it (sorted, without repeats).
    pub covers: Vec<Vec<usize>>,
}

impl SetCover {
    /// For each column, the rows it covers (the transpose of `covers`).
    pub fn column_rows(&self) -> Vec<Vec<usize>> {
        let mut out = vec![Vec::new(); self.columns];
        for (r, cols) in self.covers.iter().enumerate() {
            for &c in cols {
                if let Some(v) = out.get_mut(c) {
                    v.push(r);
                }
            }
        }
        out
    }

    /// The total cost of `chosen` columns, or an error naming the first uncovered row or an
    /// out-of-range column.
    pub fn cover_cost(&self, chosen: &[usize]) -> Result<f64, CoverError> {
        let mut pick = vec![false; self.columns];
        for &c in chosen {
            *pick.get_mut(c).ok_or(CoverError::ColumnOutOfRange {
                column: c,
                columns: self.columns,
            })? = true;
        }
        if let Some(r) = self.covers.iter().position(|cols| !cols.iter().any(|&c| pick[c])) {
            return Err(CoverError::Uncovered { row: r });
        }
        Ok(pick
            .iter()
            .zip(&self.costs)
            .filter(|(p, _)| **p)
            .map(|(_, c)| c)
            .sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m3() -> CostMatrix {
        CostMatrix::new(3, vec![0., 1., 2., 3., 0., 4., 5., 6., 0.]).unwrap()
    }

    #[test]
    fn cost_matrix_validates() {
        assert!(CostMatrix::new(2, vec![0.0; 3]).is_err());
        assert!(CostMatrix::new(2, vec![0.0, -1.0, 0.0, 0.0]).is_err());
        assert!(CostMatrix::new(1, vec![f64::NAN]).is_err());
        let m = m3();
        assert_eq!(m.get(1, 2), 4.0);
        assert!(!m.is_symmetric(0.0));
        assert!(CostMatrix::from_fn(4, |i, j| i.abs_diff(j) as f64).is_symmetric(0.0));
        assert_eq!(m.try_get(3, 0), None);
    }

    #[test]
    fn a_sub_matrix_reads_the_nodes_given() {
        let m = m3();
        let s = m.sub(&[2, 0, 2]);
        assert_eq!(s.n(), 3);
        for (i, &a) in [2, 0, 2].iter().enumerate() {
            for (j, &b) in [2, 0, 2].iter().enumerate() {
                assert_eq!(s.get(i, j), m.get(a, b));
            }
        }
        assert_eq!(m.sub(&[]).n(), 0);
        // Runs of consecutive nodes (copied a slice at a time), repeats and turns back.
        let big = CostMatrix::from_fn(12, |i, j| if i == j { 0.0 } else { (7 * i + 3 * j) as f64 });
        let nodes = [0, 3, 4, 5, 5, 6, 11, 10, 1, 2, 3, 0];
        let s = big.sub(&nodes);
        for (i, &a) in nodes.iter().enumerate() {
            for (j, &b) in nodes.iter().enumerate() {
                assert_eq!(s.get(i, j), big.get(a, b), "({i}, {j})");
            }
        }
    }

    #[test]
    fn gtsp_validates() {
        assert!(Gtsp::new(m3(), vec![vec![]]).is_err());
        assert!(Gtsp::new(m3(), vec![vec![3]]).is_err());
        assert!(Gtsp::new(m3(), vec![vec![0, 1], vec![1]]).is_err());
        let g = Gtsp::new(m3(), vec![vec![1], vec![2]]).unwrap();
        assert!(g.clone().with_depots(Some(1), None).is_err());
        assert!(g.clone().with_depots(None, Some(0)).is_err());
        assert!(g.clone().with_depots(Some(5), None).is_err());
        assert!(g.clone().with_service(vec![0.0; 2]).is_err());
        assert!(g.clone().with_service(vec![0.0, -1.0, 0.0]).is_err());
        assert!(g.with_depots(Some(0), Some(0)).is_ok());
    }

    #[test]
    fn tour_cost_cycle_and_depots() {
        let g = Gtsp::tsp(m3());
        let t = Tour { nodes: vec![0, 1, 2] };
        assert!(g.check(&t).is_ok());
        assert_eq!(g.tour_cost(&t), 1.0 + 4.0 + 5.0);
        let g = Gtsp::new(m3(), vec![vec![1], vec![2]])
            .unwrap()
            .with_depots(Some(0), None)
            .unwrap()
            .with_service(vec![10.0, 20.0, 30.0])
            .unwrap();
        // 0->1->2->0 = 1 + 4 + 5, service 10 + 20 + 30.
        assert_eq!(g.tour_cost(&Tour { nodes: vec![1, 2] }), 10.0 + 60.0);
        let g = g.with_depots(Some(0), Some(2)).map(|_| ());
        assert!(g.is_err(), "node 2 is in a cluster");
    }

    #[test]
    fn check_rejects_bad_tours() {
        let g = Gtsp::new(m3(), vec![vec![0, 1], vec![2]]).unwrap();
        assert!(g.check(&Tour { nodes: vec![0, 2] }).is_ok());
        assert!(g.check(&Tour { nodes: vec![0, 1] }).is_err());
        assert!(g.check(&Tour { nodes: vec![0] }).is_err());
        assert!(g.check(&Tour { nodes: vec![0, 7] }).is_err());
        assert_eq!(g.tour_cost(&Tour { nodes: vec![0, 7] }), f64::INFINITY);
    }

    #[test]
    fn set_cover_cost() {
        let sc = SetCover {
            rows: 2,
            columns: 2,
            costs: vec![1.0, 2.0],
            covers: vec![vec![0], vec![0, 1]],
        };
        assert_eq!(sc.cover_cost(&[0]), Ok(1.0));
        assert!(sc.cover_cost(&[1]).is_err());
        assert_eq!(sc.column_rows(), vec![vec![0, 1], vec![1]]);
    }
}
