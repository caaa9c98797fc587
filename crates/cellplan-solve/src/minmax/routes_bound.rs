//! A lower bound of the makespan from whole routes: column generation over ng-routes.
//!
//! [`lower_bound`](super::lower_bound) reasons about legs one at a time (entries, trees), so it
//! cannot see that a task's node is entered and left from the same place, nor that each
//! vehicle's legs form one tour it must pay for alone. This bound does, at a price.
//!
//! **The relaxation.** Choose for each vehicle `r` weights `λ_rp ≥ 0` over its routes `p` that
//! add up to one, so that every task is covered at least once in all and every vehicle's
//! weighted route time is at most `T`; minimise `T`. Every solution is such a choice (each
//! vehicle's own route with weight one), so the least `T` is a lower bound; this is the linear
//! relaxation of the set-partitioning model of min-max routing. Its routes are too many to
//! list: they are generated as needed (column generation), the restricted problem solved as a
//! linear program (clarabel), its duals pricing new routes.
//!
//! **The proof does not depend on the linear program.** For any prices `π ≥ 0` on the tasks
//! and weights `μ ≥ 0` on the vehicles with `Σ μ ≤ 1`, every solution (routes `p_r`, makespan
//! `T*`) satisfies `T* ≥ Σ_r μ_r·time(p_r) = Σ_i π_i + Σ_r (μ_r·time(p_r) − π(p_r))`, since the
//! routes cover every task once; so `T* ≥ Σ_i π_i + Σ_r min_p (μ_r·time(p) − π(p))` (the
//! Lagrangian bound). Any set of routes containing every route a solution can use gives a
//! minimum no larger, so the pricing may search a larger set than the elementary routes within
//! the cap:
//!
//! - **ng-routes** (Baldacci, Mingozzi and Roberti 2011): a route may come back to a task it
//!   visited only after passing a task that does not count that one among its `ng` nearest.
//!   Short cycles, which make the plain relaxation (q-routes) weak, are excluded; the
//!   labelling stays polynomial in practice.
//! - The node of a task is entered and left as one: a route visits nodes, not tasks.
//! - When a pricing passes its label budget, it answers with the q-route relaxation of the
//!   rest (the completion bounds below), which is still a bound.
//!
//! The duals the linear program gives are only made feasible (`π` and `μ` clipped at zero, `μ`
//! scaled to sum at most one), so a numerically rough solve weakens the bound but never makes
//! it wrong. The result is the best Lagrangian bound met, and at least `lower_bound`.
use super::{MinMaxProblem, Routes};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SupportedConeT};
use rayon::prelude::*;
use std::collections::HashSet;

/// Successors per node a quick round looks at (the cheapest arcs; exact rounds look at all).
const QUICK_SUCCESSORS: usize = 24;

/// Most routes one pricing offers the restricted problem.
const ROUTES_PER_PRICING: usize = 8;

/// The work [`route_bound`] may do.
#[derive(Clone, Debug)]
pub struct RouteBoundSettings {
    /// The size of each task's ng-neighbourhood (itself included): the tasks a route
    /// remembers having visited while it stays near them. At most 32.
    pub ng: usize,
    /// Most rounds of column generation.
    pub max_rounds: usize,
    /// Most labels one pricing may make (a pricing past it answers with its relaxation).
    pub max_labels: usize,
    /// Most work of all pricings, in arcs looked at: no round starts beyond it (the budget
    /// of the whole; every round's bound is a proof, so a cut run still gives one).
    pub max_work: u64,
    /// Most tasks: beyond, only [`lower_bound`](super::lower_bound) is given (the pricing's
    /// tables hold `tasks²` bytes per vehicle).
    pub max_tasks: usize,
    /// Most arcs between the vehicles' task nodes, summed over the vehicles: beyond, only
    /// [`lower_bound`](super::lower_bound) is given (the pricing keeps its own copy of them).
    pub max_arcs: usize,
    /// A wall clock: no round starts once it has passed (`None`: none; the result then
    /// depends on the problem and the settings only, else on the machine's speed too).
    pub deadline: Option<std::time::Instant>,
}

impl Default for RouteBoundSettings {
    fn default() -> Self {
        RouteBoundSettings {
            ng: 8,
            max_rounds: 400,
            max_labels: 3_000_000,
            max_work: 20_000_000_000,
            max_tasks: 1_000,
            max_arcs: 60_000_000,
            deadline: None,
        }
    }
}

/// What [`route_bound`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct RouteBound {
    /// The bound: no solution has a shorter makespan.
    pub bound: f64,
    /// [`lower_bound`](super::lower_bound), the leg bound `bound` started from.
    pub legs: f64,
    /// The last restricted linear program's value (an upper bound of the relaxation's; equal
    /// to it when `converged`).
    pub master: f64,
    /// Rounds of column generation made.
    pub rounds: usize,
    /// Routes generated (the start's included).
    pub columns: usize,
    /// Whether the relaxation was solved: the last pricing of every vehicle was exact and
    /// found no route to add.
    pub converged: bool,
    /// Arcs looked at by all pricings (the work done: the completion bounds' and the
    /// labelling's).
    pub work: u64,
    /// The duals (per task `π`, per vehicle `μ`) of the round whose value is `bound`; `None`
    /// when no round beat the leg bound. [`lagrangian_bound`] gives `bound` again from them,
    /// with one exact pricing per vehicle: a certificate of the bound.
    pub duals: Option<(Vec<f64>, Vec<f64>)>,
    /// Whether the deadline stopped it (a round left to make, [`RouteBoundSettings::deadline`]
    /// passed): the same settings with `max_rounds` set to `rounds` give the same result.
    pub clock_cut: bool,
}

/// The route bound of `p`, starting from the routes of a solution (`start`, which must be a
/// valid solution of `p`: it makes the first restricted problem feasible).
pub fn route_bound(p: &MinMaxProblem, start: &Routes, settings: &RouteBoundSettings) -> RouteBound {
    let base = super::lower_bound(p);
    let m = p.vehicles.len();
    let mut out = RouteBound {
        bound: base,
        legs: base,
        master: start.makespan(p),
        rounds: 0,
        columns: 0,
        converged: false,
        work: 0,
        clock_cut: false,
        duals: None,
    };
    if !priceable(p, settings) || start.tours.len() != m {
        return out;
    }
    let ng = settings.ng.clamp(1, 32);
    let graphs: Vec<Graph> = (0..m).map(|v| Graph::new(p, v, ng)).collect();
    let mut columns: Vec<Column> = Vec::new();
    let mut seen: HashSet<(usize, Vec<usize>)> = HashSet::new();
    for (v, g) in graphs.iter().enumerate() {
        columns.push(Column {
            vehicle: v,
            time: 0.0,
            tasks: Vec::new(),
        });
        seen.insert((v, Vec::new()));
        let nodes: Vec<usize> = start.tours[v]
            .iter()
            .filter_map(|&(_, node)| g.local_of(node))
            .collect();
        if nodes.len() == start.tours[v].len() && !nodes.is_empty() {
            columns.push(g.column(p, v, &nodes));
            seen.insert((v, nodes));
        }
    }
    // Rounds price quickly (one label per node along each node's cheapest arcs: a heuristic,
    // which proves nothing) until they find no route, then exactly; an exact round that finds
    // routes goes back to quick ones.
    let mut quick = true;
    for round in 0..settings.max_rounds {
        if settings.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            out.clock_cut = true;
            break;
        }
        out.rounds = round + 1;
        let Some(duals) = solve_master(p, &columns) else {
            break;
        };
        out.master = duals.value;
        let mut value: f64 = duals.pi.iter().sum();
        let mut added = 0;
        let mut exact = true;
        // The vehicles priced side by side, their answers taken in order.
        let priced: Vec<Priced> = graphs
            .par_iter()
            .enumerate()
            .map(|(v, g)| g.price(duals.mu[v], &duals.pi, &p.service, settings.max_labels, quick))
            .collect();
        for (v, (g, priced)) in graphs.iter().zip(priced).enumerate() {
            out.work += priced.work;
            exact &= priced.exact;
            value += priced.value.min(0.0);
            for nodes in priced.routes {
                let key = (v, nodes);
                if !seen.contains(&key) {
                    columns.push(g.column(p, v, &key.1));
                    seen.insert(key);
                    added += 1;
                }
            }
        }
        if value > out.bound {
            out.bound = value;
            out.duals = Some((duals.pi.clone(), duals.mu.clone()));
        }
        // The bound has reached the restricted problem's value, which is at least the
        // relaxation's: solved, however the routes were priced.
        if out.bound >= duals.value - 1e-9 * duals.value.max(1.0) {
            out.converged = true;
            break;
        }
        if added == 0 && !quick {
            out.converged = exact;
            break;
        }
        // A quick round that found nothing is followed by an exact one, a round that found
        // routes by a quick one; past the budget, by none.
        quick = added > 0;
        if out.work >= settings.max_work {
            break;
        }
    }
    out.columns = columns.len();
    out
}

/// Whether `p` has tasks and stays within `settings`' size limits (tasks, and arcs between
/// the vehicles' nodes), so that its vehicles can be priced.
fn priceable(p: &MinMaxProblem, settings: &RouteBoundSettings) -> bool {
    let arcs: usize = p
        .vehicles
        .iter()
        .map(|v| v.alternatives.iter().map(Vec::len).sum::<usize>().pow(2))
        .sum();
    p.tasks > 0 && p.tasks <= settings.max_tasks && arcs <= settings.max_arcs
}

/// The Lagrangian bound of `p` at duals `pi` (per task) and `mu` (per vehicle):
/// `Σπ + Σ_v min(0, least μ_v·time(r) − π(r) over v's ng-routes r)`, each vehicle priced as the
/// exact rounds of [`route_bound`] price it (`settings`' ng-neighbourhoods and label limit; past
/// that limit the pricing's relaxation). Every `π, μ ≥ 0` with `Σμ ≤ 1` gives a lower bound of
/// every solution's makespan, so this checks a stated bound from its duals alone. `None` when the
/// duals are not such (wrong lengths, negative, not finite, `Σμ` above one by more than 10⁻¹²,
/// the rounding of [`route_bound`]'s scaling), so large that the value is not finite, or `p`
/// passes the size limits.
pub fn lagrangian_bound(
    p: &MinMaxProblem,
    pi: &[f64],
    mu: &[f64],
    settings: &RouteBoundSettings,
) -> Option<f64> {
    let m = p.vehicles.len();
    let finite = |x: &f64| x.is_finite() && *x >= 0.0;
    if pi.len() != p.tasks || mu.len() != m || !pi.iter().all(finite) || !mu.iter().all(finite) {
        return None;
    }
    // Scaled to sum one, the duals may sum a rounding above it: weaker by as little.
    if mu.iter().sum::<f64>() > 1.0 + 1e-12 {
        return None;
    }
    if !priceable(p, settings) {
        return None;
    }
    let ng = settings.ng.clamp(1, 32);
    let priced: Vec<f64> = (0..m)
        .into_par_iter()
        .map(|v| {
            Graph::new(p, v, ng)
                .price(mu[v], pi, &p.service, settings.max_labels, false)
                .value
        })
        .collect();
    let mut value: f64 = pi.iter().sum();
    for v in priced {
        value += v.min(0.0);
    }
    // Duals near the largest floats sum past them.
    value.is_finite().then_some(value)
}

/// One route of one vehicle, as the restricted problem sees it.
struct Column {
    vehicle: usize,
    /// Travel plus service.
    time: f64,
    /// The tasks visited, with repeats (an ng-route may visit a task twice).
    tasks: Vec<usize>,
}

/// The restricted problem's value and its duals, made feasible for the Lagrangian bound.
struct Duals {
    value: f64,
    /// Per task, `≥ 0`.
    pi: Vec<f64>,
    /// Per vehicle, `≥ 0`, summing to at most one.
    mu: Vec<f64>,
}

/// Solves the restricted problem over `columns` (variables `T`, then one weight per column):
/// `min T` subject to, per vehicle, its weights summing to one (zero cone) and, as `≤ 0` rows
/// (nonnegative cone), each task covered at least once, each vehicle's weighted time at most
/// `T`, and every variable nonnegative. `None` when the solver gives no usable point.
fn solve_master(p: &MinMaxProblem, columns: &[Column]) -> Option<Duals> {
    let (m, n, k) = (p.vehicles.len(), p.tasks, columns.len());
    let vars = 1 + k;
    // Rows: [0, m) convexity; [m, m + n) cover; [m + n, 2m + n) time; then one per variable.
    let (cover, time, bounds) = (m, m + n, 2 * m + n);
    let rows = bounds + vars;
    let mut colptr = Vec::with_capacity(vars + 1);
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    colptr.push(0);
    for r in 0..m {
        rowval.push(time + r);
        nzval.push(-1.0);
    }
    rowval.push(bounds);
    nzval.push(-1.0);
    colptr.push(rowval.len());
    let mut counts = vec![0usize; n];
    for (j, c) in columns.iter().enumerate() {
        rowval.push(c.vehicle);
        nzval.push(1.0);
        for &t in &c.tasks {
            counts[t] += 1;
        }
        let mut tasks: Vec<usize> = c.tasks.clone();
        tasks.sort_unstable();
        tasks.dedup();
        for &t in &tasks {
            rowval.push(cover + t);
            nzval.push(-(counts[t] as f64));
            counts[t] = 0;
        }
        rowval.push(time + c.vehicle);
        nzval.push(c.time);
        rowval.push(bounds + 1 + j);
        nzval.push(-1.0);
        colptr.push(rowval.len());
    }
    let a = CscMatrix::new(rows, vars, colptr, rowval, nzval);
    let mut b = vec![0.0; rows];
    b[..m].fill(1.0);
    b[cover..cover + n].fill(-1.0);
    let mut q = vec![0.0; vars];
    q[0] = 1.0;
    let pm = CscMatrix::zeros((vars, vars));
    let cones = [
        SupportedConeT::ZeroConeT(m),
        SupportedConeT::NonnegativeConeT(rows - m),
    ];
    let settings = DefaultSettingsBuilder::default().verbose(false).build().ok()?;
    let mut solver = DefaultSolver::new(&pm, &q, &a, &b, &cones, settings).ok()?;
    solver.solve();
    let z = &solver.solution.z;
    if z.len() != rows || !z.iter().all(|x| x.is_finite()) {
        return None;
    }
    let value = solver.solution.obj_val;
    let pi: Vec<f64> = (0..n).map(|t| z[cover + t].max(0.0)).collect();
    let mut mu: Vec<f64> = (0..m).map(|r| z[time + r].max(0.0)).collect();
    let sum: f64 = mu.iter().sum();
    if sum > 1.0 {
        mu.iter_mut().for_each(|x| *x /= sum);
    }
    Some(Duals {
        value: if value.is_finite() { value } else { f64::INFINITY },
        pi,
        mu,
    })
}

/// One vehicle's nodes that do tasks, for pricing.
struct Graph {
    /// Per local node, the vehicle's node.
    node: Vec<usize>,
    /// Per local node, its task.
    task: Vec<usize>,
    /// `cost[a * len + b]`: travel between local nodes (infinite within one task).
    cost: Vec<f64>,
    /// From the depot to each node, and back.
    out: Vec<f64>,
    back: Vec<f64>,
    /// The longest route searched: the cap, at most the tasks the vehicle can do.
    longest: usize,
    /// The tasks the vehicle can do.
    doable: Vec<usize>,
    /// Per task, its ng-neighbourhood (itself first), and `slot[t * n + u]`: `u`'s place in
    /// `t`'s neighbourhood plus one (zero: not in it).
    near: Vec<Vec<usize>>,
    slot: Vec<u8>,
    /// Per local node, its [`QUICK_SUCCESSORS`] cheapest successors: the only arcs quick
    /// rounds look at.
    successors: Vec<Vec<u32>>,
}

/// The outcome of one pricing.
struct Priced {
    /// A lower bound of the least `μ·time − π` over the vehicle's routes (the empty one, 0,
    /// included).
    value: f64,
    /// The best routes found (local nodes), each of negative value, the best first.
    routes: Vec<Vec<usize>>,
    /// Whether `value` is the least over ng-routes (not the relaxation of a cut search).
    exact: bool,
    /// Arcs looked at.
    work: u64,
}

/// A partial route in the labelling: at `node`, having visited the tasks of `memory` (bits
/// over the node's task's neighbourhood), at reduced cost `value`, coming from label `parent`.
#[derive(Clone, Copy)]
struct Label {
    node: u32,
    memory: u32,
    value: f64,
    parent: u32,
}

impl Graph {
    fn new(p: &MinMaxProblem, v: usize, ng: usize) -> Graph {
        let veh = &p.vehicles[v];
        let n = p.tasks;
        let mut node = Vec::new();
        let mut task = Vec::new();
        let mut doable = Vec::new();
        for (t, alts) in veh.alternatives.iter().enumerate() {
            if !alts.is_empty() {
                doable.push(t);
            }
            for &a in alts {
                node.push(a);
                task.push(t);
            }
        }
        let len = node.len();
        let mut cost = vec![f64::INFINITY; len * len];
        let mut near_cost = vec![f64::INFINITY; n * n];
        for a in 0..len {
            for b in 0..len {
                if task[a] != task[b] {
                    let c = veh.costs.get(node[a], node[b]);
                    cost[a * len + b] = c;
                    let k = task[a] * n + task[b];
                    near_cost[k] = near_cost[k].min(c);
                    let k = task[b] * n + task[a];
                    near_cost[k] = near_cost[k].min(c);
                }
            }
        }
        let out = node.iter().map(|&a| veh.costs.get(veh.depot, a)).collect();
        let back = node.iter().map(|&a| veh.costs.get(a, veh.depot)).collect();
        let mut near = vec![Vec::new(); n];
        let mut slot = vec![0u8; n * n];
        for &t in &doable {
            let mut others: Vec<usize> = doable.iter().copied().filter(|&u| u != t).collect();
            others.sort_by(|&a, &b| {
                near_cost[t * n + a]
                    .total_cmp(&near_cost[t * n + b])
                    .then(a.cmp(&b))
            });
            let mut hood = vec![t];
            hood.extend(others.into_iter().take(ng - 1));
            for (i, &u) in hood.iter().enumerate() {
                slot[t * n + u] = i as u8 + 1;
            }
            near[t] = hood;
        }
        let successors = (0..len)
            .map(|a| {
                let row = &cost[a * len..(a + 1) * len];
                let mut next: Vec<u32> = (0..len as u32).filter(|&c| row[c as usize].is_finite()).collect();
                next.sort_unstable_by(|&x, &y| row[x as usize].total_cmp(&row[y as usize]).then(x.cmp(&y)));
                next.truncate(QUICK_SUCCESSORS);
                next
            })
            .collect();
        Graph {
            node,
            task,
            cost,
            out,
            back,
            longest: veh.cap.min(doable.len()),
            doable,
            near,
            slot,
            successors,
        }
    }

    /// The local node of vehicle node `a`.
    fn local_of(&self, a: usize) -> Option<usize> {
        self.node.iter().position(|&x| x == a)
    }

    /// The column of vehicle `vehicle`'s route through local `nodes`, timed as
    /// [`MinMaxProblem::route_time`] times routes.
    fn column(&self, p: &MinMaxProblem, vehicle: usize, nodes: &[usize]) -> Column {
        let tour: Vec<(usize, usize)> = nodes.iter().map(|&a| (self.task[a], self.node[a])).collect();
        Column {
            vehicle,
            time: p.route_time(vehicle, &tour),
            tasks: tour.iter().map(|&(t, _)| t).collect(),
        }
    }

    /// The least `μ·time(route) − π(route)` over the vehicle's ng-routes of at most
    /// `longest` tasks (see the module's notes), or a lower bound of it.
    /// `quick`: [`Graph::price_quick`] instead, a heuristic.
    fn price(&self, mu: f64, pi: &[f64], service: &[f64], max_labels: usize, quick: bool) -> Priced {
        let len = self.node.len();
        if len == 0 || self.longest == 0 {
            return Priced {
                value: 0.0,
                routes: Vec::new(),
                exact: true,
                work: 0,
            };
        }
        if mu <= 0.0 {
            // Time is free: the best route takes the highest prices, one node each.
            let mut best: Vec<usize> = self.doable.clone();
            best.sort_by(|&a, &b| pi[b].total_cmp(&pi[a]).then(a.cmp(&b)));
            best.truncate(self.longest);
            best.retain(|&t| pi[t] > 0.0);
            let value = -best.iter().map(|&t| pi[t]).sum::<f64>();
            let route: Vec<usize> = best
                .iter()
                .filter_map(|&t| self.task.iter().position(|&x| x == t))
                .collect();
            return Priced {
                value,
                routes: if route.is_empty() { Vec::new() } else { vec![route] },
                exact: true,
                work: 0,
            };
        }
        if quick {
            return self.price_quick(mu, pi, service, max_labels);
        }
        let w: Vec<f64> = (0..len)
            .map(|a| mu * service[self.task[a]] - pi[self.task[a]])
            .collect();
        let arc = |a: usize, b: usize| mu * self.cost[a * len + b];
        // rest[k][a]: the least cost after `a` (its own paid) of at most `k` more nodes, then
        // home, without memory (q-routes): a bound of every completion.
        let mut work = (self.longest * len * len) as u64;
        let mut rest = vec![vec![0.0; len]; self.longest];
        for (r, back) in rest[0].iter_mut().zip(&self.back) {
            *r = mu * back;
        }
        for k in 1..self.longest {
            let (done, next) = rest.split_at_mut(k);
            let prev = &done[k - 1];
            for a in 0..len {
                let row = &self.cost[a * len..(a + 1) * len];
                let mut best = prev[a].min(done[0][a]);
                for b in 0..len {
                    let x = mu * row[b] + w[b] + prev[b];
                    if x < best {
                        best = x;
                    }
                }
                next[0][a] = best;
            }
        }
        let relaxed = (0..len)
            .map(|a| mu * self.out[a] + w[a] + rest[self.longest - 1][a])
            .fold(0.0f64, f64::min);
        let mut labels: Vec<Label> = Vec::new();
        let mut best = (0.0f64, u32::MAX);
        let mut layer: Vec<Vec<u32>> = vec![Vec::new(); len];
        for a in 0..len {
            let value = mu * self.out[a] + w[a];
            if value + rest[self.longest - 1][a] < -1e-12 {
                labels.push(Label {
                    node: a as u32,
                    memory: 1,
                    value,
                    parent: u32::MAX,
                });
                layer[a].push(labels.len() as u32 - 1);
            }
        }
        let n = pi.len();
        let mut exact = true;
        // The labels being made, per node: (value, memory, label) kept together for the
        // dominance scans.
        let mut next: Vec<Vec<(f64, u32, u32)>> = vec![Vec::new(); len];
        // Completed routes better than the empty one: (value, last label).
        let mut done: Vec<(f64, u32)> = Vec::new();
        // Per node, the next nodes worth trying from it (those whose arc, price and
        // completion bound leave room below the best), cheapest first.
        let mut ahead: Vec<(f64, u32)> = Vec::with_capacity(len);
        'layers: for depth in 1..=self.longest {
            for (a, bucket) in layer.iter().enumerate() {
                for &i in bucket {
                    let x = labels[i as usize].value + mu * self.back[a];
                    if x < -1e-12 {
                        done.push((x, i));
                    }
                    if x < best.0 {
                        best = (x, i);
                    }
                }
            }
            if depth == self.longest {
                break;
            }
            let left = self.longest - depth - 1;
            next.iter_mut().for_each(Vec::clear);
            for a in 0..len {
                let Some(least) = layer[a]
                    .iter()
                    .map(|&i| labels[i as usize].value)
                    .reduce(f64::min)
                else {
                    continue;
                };
                ahead.clear();
                work += len as u64;
                for c in 0..len {
                    let x = arc(a, c) + w[c] + rest[left][c];
                    if least + x < best.0 - 1e-12 {
                        ahead.push((x, c as u32));
                    }
                }
                // Sorted, a label's search stops at the first node with no room; worth it only
                // for several labels.
                let sorted = layer[a].len() > 2;
                if sorted {
                    ahead.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                }
                let t = self.task[a];
                let hood = &self.near[t];
                for k in 0..layer[a].len() {
                    let label = labels[layer[a][k] as usize];
                    work += ahead.len() as u64;
                    for &(x, c) in &ahead {
                        // (Values are finite or +inf, never NaN.)
                        if label.value + x >= best.0 - 1e-12 {
                            if sorted {
                                break;
                            }
                            continue;
                        }
                        let c = c as usize;
                        let u = self.task[c];
                        let s = self.slot[t * n + u];
                        if s != 0 && label.memory >> (s - 1) & 1 == 1 {
                            continue;
                        }
                        let value = label.value + arc(a, c) + w[c];
                        // The memory carried to `u`: what `u` counts among its neighbours.
                        let memory = self.carried(label.memory, hood, u);
                        let bucket = &mut next[c];
                        if bucket.iter().any(|o| o.0 <= value && o.1 & !memory == 0) {
                            continue;
                        }
                        bucket.retain(|o| !(value <= o.0 && memory & !o.1 == 0));
                        if labels.len() >= max_labels {
                            exact = false;
                            break 'layers;
                        }
                        labels.push(Label {
                            node: c as u32,
                            memory,
                            value,
                            parent: layer[a][k],
                        });
                        next[c].push((value, memory, labels.len() as u32 - 1));
                    }
                }
            }
            for (l, n) in layer.iter_mut().zip(&next) {
                l.clear();
                l.extend(n.iter().map(|o| o.2));
            }
        }
        let routes = best_routes(&labels, &mut done);
        Priced {
            value: if exact { best.0 } else { relaxed.min(best.0) },
            routes,
            exact,
            work,
        }
    }

    /// The memory a label with `memory` (bits over `hood`, its task's neighbourhood) carries to
    /// task `u`: what `u` counts among its neighbours, and `u` itself.
    fn carried(&self, memory: u32, hood: &[usize], u: usize) -> u32 {
        let n = self.near.len();
        let mut carried = 1u32;
        let mut bits = memory;
        while bits != 0 {
            let j = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let z = self.slot[u * n + hood[j]];
            if z != 0 {
                carried |= 1 << (z - 1);
            }
        }
        carried
    }

    /// A quick pricing for `μ > 0`: one label per node (the cheapest), along the
    /// [`QUICK_SUCCESSORS`] cheapest arcs of each node, with the ng memory. A heuristic: it finds
    /// routes to add, and its value is no bound (minus infinity).
    fn price_quick(&self, mu: f64, pi: &[f64], service: &[f64], max_labels: usize) -> Priced {
        let len = self.node.len();
        let n = pi.len();
        let w: Vec<f64> = (0..len)
            .map(|a| mu * service[self.task[a]] - pi[self.task[a]])
            .collect();
        let mut labels: Vec<Label> = (0..len)
            .map(|a| Label {
                node: a as u32,
                memory: 1,
                value: mu * self.out[a] + w[a],
                parent: u32::MAX,
            })
            .collect();
        let mut layer: Vec<u32> = (0..len as u32).collect();
        let mut best_at: Vec<u32> = vec![u32::MAX; len];
        let mut done: Vec<(f64, u32)> = Vec::new();
        let mut work = 0u64;
        for depth in 1..=self.longest {
            for &i in &layer {
                let l = &labels[i as usize];
                let x = l.value + mu * self.back[l.node as usize];
                if x < -1e-12 {
                    done.push((x, i));
                }
            }
            if depth == self.longest || labels.len() >= max_labels {
                break;
            }
            best_at.fill(u32::MAX);
            let made = labels.len();
            for &i in &layer {
                let label = labels[i as usize];
                let a = label.node as usize;
                let t = self.task[a];
                let hood = &self.near[t];
                work += self.successors[a].len() as u64;
                for &c in &self.successors[a] {
                    let c = c as usize;
                    let u = self.task[c];
                    let s = self.slot[t * n + u];
                    if s != 0 && label.memory >> (s - 1) & 1 == 1 {
                        continue;
                    }
                    let value = label.value + mu * self.cost[a * len + c] + w[c];
                    if best_at[c] != u32::MAX && labels[best_at[c] as usize].value <= value {
                        continue;
                    }
                    let memory = self.carried(label.memory, hood, u);
                    let made_here = Label {
                        node: c as u32,
                        memory,
                        value,
                        parent: i,
                    };
                    if best_at[c] != u32::MAX && best_at[c] as usize >= made {
                        labels[best_at[c] as usize] = made_here;
                    } else {
                        labels.push(made_here);
                        best_at[c] = labels.len() as u32 - 1;
                    }
                }
            }
            layer = best_at.iter().copied().filter(|&i| i != u32::MAX).collect();
        }
        let routes = best_routes(&labels, &mut done);
        Priced {
            value: f64::NEG_INFINITY,
            routes,
            exact: false,
            work,
        }
    }
}

/// The routes ending at the best of the completed labels `done` (value, last label), at most
/// [`ROUTES_PER_PRICING`], as local nodes.
fn best_routes(labels: &[Label], done: &mut [(f64, u32)]) -> Vec<Vec<usize>> {
    done.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    done.iter()
        .take(ROUTES_PER_PRICING)
        .map(|&(_, last)| {
            let mut nodes = Vec::new();
            let mut i = last;
            while i != u32::MAX {
                nodes.push(labels[i as usize].node as usize);
                i = labels[i as usize].parent;
            }
            nodes.reverse();
            nodes
        })
        .collect()
}
