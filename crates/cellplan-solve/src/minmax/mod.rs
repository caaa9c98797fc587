//! Min-max multi-vehicle routing with alternative nodes: the joint allocation and sequencing of
//! a multi-robot inspection cell (paper 000 §3). Each vehicle (robot) has its own cost matrix,
//! a home depot (start = end), a task cap φ and, per task, the nodes (alternative
//! configurations) with which it can do the task. Every task is done exactly once, by one
//! vehicle, at one of that vehicle's nodes; the objective is the longest route time (travel plus
//! service), then the total. An optional balance limit γ bounds the spread of the route times.
//!
//! Service times are **per task** (the same whichever vehicle or node does it); the depot has
//! none. Methods ([`MinMaxMethod`]): the proximity baseline, paper 000's Algorithm 1 generalised
//! to m vehicles, and an iterated local search between routes on top of the GTSP solver.
use std::sync::Arc;
use std::time::Duration;

use crate::problem::CostMatrix;

pub use crate::error::{MinMaxError, RoutesError, VehicleError};

mod bound;
mod construct;
mod generate;
mod ils;
mod route;
mod routes_bound;
#[cfg(test)]
mod tests;

pub use bound::lower_bound;
pub use generate::{TooLarge, generate, generate_within};
pub use routes_bound::{RouteBound, RouteBoundSettings, lagrangian_bound, route_bound};

/// One vehicle (robot).
#[derive(Clone, Debug, PartialEq)]
pub struct Vehicle {
    /// Travel times between the vehicle's own nodes (depot included); shared, so that a
    /// problem made again from the same matrices (or cloned) does not copy them.
    pub costs: Arc<CostMatrix>,
    /// The home node: every route starts and ends here. In no task's alternatives.
    pub depot: usize,
    /// Most tasks the vehicle may take (φ).
    pub cap: usize,
    /// `alternatives[t]`: the nodes with which this vehicle does task `t` (empty when it
    /// cannot). One entry per task; a node serves at most one task.
    pub alternatives: Vec<Vec<usize>>,
}

impl Vehicle {
    /// A vehicle, validated on its own: depot and nodes in range, the depot in no alternative
    /// list, no node serving two tasks (or listed twice).
    pub fn new(
        costs: impl Into<Arc<CostMatrix>>,
        depot: usize,
        cap: usize,
        alternatives: Vec<Vec<usize>>,
    ) -> Result<Self, VehicleError> {
        let v = Vehicle {
            costs: costs.into(),
            depot,
            cap,
            alternatives,
        };
        v.validate()?;
        Ok(v)
    }

    fn validate(&self) -> Result<(), VehicleError> {
        let n = self.costs.n();
        if self.depot >= n {
            return Err(VehicleError::DepotOutOfRange {
                depot: self.depot,
                nodes: n,
            });
        }
        let mut owner: Vec<Option<usize>> = vec![None; n];
        for (t, alts) in self.alternatives.iter().enumerate() {
            for &a in alts {
                if a >= n {
                    return Err(VehicleError::NodeOutOfRange {
                        task: t,
                        node: a,
                        nodes: n,
                    });
                }
                if a == self.depot {
                    return Err(VehicleError::DepotAsAlternative { task: t, depot: a });
                }
                if let Some(o) = owner[a] {
                    return Err(VehicleError::SharedNode {
                        node: a,
                        first: o,
                        second: t,
                    });
                }
                owner[a] = Some(t);
            }
        }
        Ok(())
    }
}

/// A min-max allocation and routing problem; build through [`MinMaxProblem::new`].
#[derive(Clone, Debug, PartialEq)]
pub struct MinMaxProblem {
    /// The vehicles.
    pub vehicles: Vec<Vehicle>,
    /// Number of tasks.
    pub tasks: usize,
    /// Service time of every task (`tasks` entries), whichever vehicle does it.
    pub service: Vec<f64>,
    /// When given, the largest allowed difference between route times (γ); solutions meeting
    /// it are preferred to any that do not.
    pub balance_limit: Option<f64>,
}

impl MinMaxProblem {
    /// A validated problem: every vehicle valid with one alternative list per task, service
    /// times finite and non-negative, every task doable by some vehicle, and the caps admit an
    /// assignment of all tasks (checked by matching, so total cap ≥ tasks and more).
    pub fn new(
        vehicles: Vec<Vehicle>,
        tasks: usize,
        service: Vec<f64>,
        balance_limit: Option<f64>,
    ) -> Result<Self, MinMaxError> {
        let p = MinMaxProblem {
            vehicles,
            tasks,
            service,
            balance_limit,
        };
        p.validate()?;
        Ok(p)
    }

    /// The checks of [`MinMaxProblem::new`], for a problem built field by field.
    pub fn validate(&self) -> Result<(), MinMaxError> {
        if self.service.len() != self.tasks {
            return Err(MinMaxError::ServiceCount {
                given: self.service.len(),
                tasks: self.tasks,
            });
        }
        if let Some(t) = self.service.iter().position(|s| !s.is_finite() || *s < 0.0) {
            return Err(MinMaxError::ServiceValue {
                task: t,
                value: self.service[t],
            });
        }
        if let Some(g) = self.balance_limit
            && (!g.is_finite() || g < 0.0)
        {
            return Err(MinMaxError::BalanceLimit { value: g });
        }
        for (i, v) in self.vehicles.iter().enumerate() {
            if v.alternatives.len() != self.tasks {
                return Err(MinMaxError::AlternativeLists {
                    vehicle: i,
                    lists: v.alternatives.len(),
                    tasks: self.tasks,
                });
            }
            v.validate()
                .map_err(|error| MinMaxError::Vehicle { vehicle: i, error })?;
        }
        if let Some(t) = (0..self.tasks).find(|&t| self.capable(t).is_empty()) {
            return Err(MinMaxError::Undoable { task: t });
        }
        let cap: usize = self.vehicles.iter().map(|v| v.cap).sum();
        if cap < self.tasks {
            return Err(MinMaxError::TotalCap {
                cap,
                tasks: self.tasks,
            });
        }
        let caps: Vec<usize> = self.vehicles.iter().map(|v| v.cap).collect();
        assign_within_caps(self.tasks, &caps, |v, t| self.can_do(v, t))
            .map(|_| ())
            .map_err(|task| MinMaxError::NoAssignment { task })
    }

    /// Whether vehicle `v` can do task `t`.
    pub fn can_do(&self, v: usize, t: usize) -> bool {
        !self.vehicles[v].alternatives[t].is_empty()
    }

    /// The vehicles that can do task `t`.
    pub fn capable(&self, t: usize) -> Vec<usize> {
        (0..self.vehicles.len()).filter(|&v| self.can_do(v, t)).collect()
    }

    /// Time of vehicle `v` driving `tour` (depot → nodes → depot, plus the tasks' service).
    pub fn route_time(&self, v: usize, tour: &[(usize, usize)]) -> f64 {
        let veh = &self.vehicles[v];
        let mut prev = veh.depot;
        let mut time = 0.0;
        for &(task, node) in tour {
            time += veh.costs.get(prev, node) + self.service[task];
            prev = node;
        }
        time + veh.costs.get(prev, veh.depot)
    }
}

/// An assignment of `tasks` tasks to vehicles, vehicle `v` taking at most `caps[v]` and only
/// tasks it `can_do(v, t)` (a b-matching by augmenting paths). `Err(t)`: task `t` is the first
/// that no assignment can place.
pub fn assign_within_caps(
    tasks: usize,
    caps: &[usize],
    can_do: impl Fn(usize, usize) -> bool,
) -> Result<Vec<Vec<usize>>, usize> {
    let mut sets = vec![Vec::new(); caps.len()];
    for t in 0..tasks {
        let (v0, moves) = construct::augment_by(caps, &can_do, &sets, t).ok_or(t)?;
        for &(u, from, to) in &moves {
            sets[from].retain(|&x| x != u);
            sets[to].push(u);
        }
        sets[v0].push(t);
    }
    Ok(sets)
}

/// One route per vehicle: the (task, node) visits in order, depots excluded.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Routes {
    /// `tours[v]`: vehicle `v`'s visits.
    pub tours: Vec<Vec<(usize, usize)>>,
}

impl Routes {
    /// Route times, one per vehicle.
    pub fn times(&self, p: &MinMaxProblem) -> Vec<f64> {
        self.tours
            .iter()
            .enumerate()
            .map(|(v, t)| p.route_time(v, t))
            .collect()
    }

    /// The longest route time.
    pub fn makespan(&self, p: &MinMaxProblem) -> f64 {
        self.times(p).into_iter().fold(0.0, f64::max)
    }

    /// Ok if there is one tour per vehicle, every task is done exactly once by a vehicle that
    /// can do it at one of its nodes for it, and no vehicle exceeds its cap.
    pub fn check(&self, p: &MinMaxProblem) -> Result<(), RoutesError> {
        if self.tours.len() != p.vehicles.len() {
            return Err(RoutesError::TourCount {
                tours: self.tours.len(),
                vehicles: p.vehicles.len(),
            });
        }
        let mut done: Vec<Option<usize>> = vec![None; p.tasks];
        for (v, tour) in self.tours.iter().enumerate() {
            let veh = &p.vehicles[v];
            if tour.len() > veh.cap {
                return Err(RoutesError::OverCap {
                    vehicle: v,
                    tasks: tour.len(),
                    cap: veh.cap,
                });
            }
            for &(t, node) in tour {
                if t >= p.tasks {
                    return Err(RoutesError::TaskOutOfRange { vehicle: v, task: t });
                }
                if !veh.alternatives[t].contains(&node) {
                    return Err(RoutesError::NotAlternative {
                        vehicle: v,
                        task: t,
                        node,
                    });
                }
                if let Some(w) = done[t] {
                    return Err(RoutesError::DoneTwice {
                        task: t,
                        first: w,
                        second: v,
                    });
                }
                done[t] = Some(v);
            }
        }
        if let Some(t) = done.iter().position(Option::is_none) {
            return Err(RoutesError::NotDone { task: t });
        }
        Ok(())
    }
}

/// Solution methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MinMaxMethod {
    /// Iterated local search between routes, from the better of the two constructions.
    Ils,
    /// Paper 000's Algorithm 1 generalised to m vehicles.
    Algorithm1,
    /// Every task to the vehicle whose depot is nearest (the paper's baseline).
    Proximity,
}

/// Parameters of [`solve`].
#[derive(Clone, Debug, PartialEq)]
pub struct MinMaxParams {
    /// Wall-clock limit (checked between ILS iterations; the constructions always finish).
    pub time_limit: Duration,
    /// Seed of all randomness.
    pub seed: u64,
    /// Stop the ILS after this many perturbations (the result then depends only on the
    /// instance and the seed, if the time limit does not cut first).
    pub max_iterations: Option<usize>,
    /// The method.
    pub method: MinMaxMethod,
}

impl Default for MinMaxParams {
    fn default() -> Self {
        MinMaxParams {
            time_limit: Duration::from_secs(1),
            seed: 0,
            max_iterations: None,
            method: MinMaxMethod::Ils,
        }
    }
}

/// Routes and their figures.
#[derive(Clone, Debug, PartialEq)]
pub struct MinMaxSolution {
    /// The routes.
    pub routes: Routes,
    /// The longest route time.
    pub makespan: f64,
    /// The sum of the route times.
    pub total: f64,
    /// Whether the route times differ by at most the balance limit (true without one).
    pub balanced: bool,
}

/// Solve `p` with `params.method`.
pub fn solve(p: &MinMaxProblem, params: &MinMaxParams) -> MinMaxSolution {
    let tours = match params.method {
        MinMaxMethod::Proximity => construct::proximity(p, params.seed),
        MinMaxMethod::Algorithm1 => construct::algorithm1(p, params.seed),
        MinMaxMethod::Ils => ils::run(p, params),
    };
    finish(p, Routes { tours })
}

fn finish(p: &MinMaxProblem, routes: Routes) -> MinMaxSolution {
    let times = routes.times(p);
    let makespan = times.iter().copied().fold(0.0, f64::max);
    let total = times.iter().sum();
    MinMaxSolution {
        routes,
        makespan,
        total,
        balanced: is_balanced(p, &times),
    }
}

fn is_balanced(p: &MinMaxProblem, times: &[f64]) -> bool {
    violation(p, times) <= 1e-9
}

/// How far the spread of `times` exceeds the balance limit (0 without one). A vehicle that can
/// do none of the tasks (its route is empty in every solution) is left out of the spread.
pub(crate) fn violation(p: &MinMaxProblem, times: &[f64]) -> f64 {
    match p.balance_limit {
        None => 0.0,
        Some(g) => {
            // Only an empty route (time 0) asks whether its vehicle could do anything.
            let counts = |v: usize| {
                times[v] > 0.0
                    || p.vehicles
                        .get(v)
                        .is_none_or(|x| x.alternatives.iter().any(|a| !a.is_empty()))
            };
            let spread = (0..times.len()).filter(|&v| counts(v)).map(|v| times[v]);
            let hi = spread.clone().fold(f64::NEG_INFINITY, f64::max);
            let lo = spread.fold(f64::INFINITY, f64::min);
            if hi.is_finite() {
                (hi - lo - g).max(0.0)
            } else {
                0.0
            }
        }
    }
}
