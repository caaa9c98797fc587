//! Lower bounds of the makespan of a [`MinMaxProblem`], each a proof: no solution, whatever its
//! allocation, orders and nodes, ends sooner.
//!
//! Say `k` vehicles do something. Their routes are `k` cycles through the depot that visit
//! every task once, so their times add up to the service of every task plus the legs, and the
//! longest is at least the `k`-th of that sum. Two bounds of the legs follow:
//!
//! - **Entries** ([`Entries`]): every task is entered once; the `k` tasks entered first are
//!   entered from the depot and the `k` tasks left last are left for it, each `k` distinct.
//! - **Trees** ([`tree_bound`], Held and Karp's bound carried to `k` routes): the routes, seen
//!   as one graph on the tasks and the depot, are connected, have `n + k` edges, degree 2 at
//!   every task and `2k` at the depot. Such a graph costs at least a spanning tree plus the `k`
//!   cheapest further edges; with node prices `π` added to the edges at their ends and the
//!   degrees' worth taken off again, every choice of `π` gives a bound, and a subgradient
//!   ascent on `π` (a fixed number of steps: the result depends only on the problem) finds
//!   good ones. A leg costs at least the cheaper direction between the two tasks over the
//!   vehicles able to do both (no vehicle: no such leg).
//!
//! The bound is the largest of these (each the smallest over the numbers `k` of vehicles the
//! caps allow), of [`group_bound`] (the tasks only a group of vehicles can do are shared by
//! that group: its longest route is at least their share) and of
//! [`count_bound`]: the vehicles' numbers of tasks add up to `n`, and a vehicle doing `m` tasks
//! pays at least its `m` cheapest — which, when tasks are few per vehicle, is more than the
//! `k`-th of the sum (one of three equal vehicles does two of four tasks).
use super::MinMaxProblem;

/// Most tasks for which [`tree_bound`] runs (its matrix holds `n²` numbers).
const TREE_MAX_TASKS: usize = 4_000;

/// Work budget of the subgradient ascent per number of vehicles, in edge evaluations (each
/// step costs about `(n + 1)²`); at least [`TREE_MIN_STEPS`] and at most [`TREE_MAX_STEPS`]
/// steps.
const TREE_WORK: usize = 40_000_000;
const TREE_MIN_STEPS: usize = 20;
const TREE_MAX_STEPS: usize = 400;

/// A lower bound of the makespan of every solution of `p` (ignoring the balance limit).
pub fn lower_bound(p: &MinMaxProblem) -> f64 {
    if p.vehicles.is_empty() || p.tasks == 0 {
        return 0.0;
    }
    let legs = Legs::new(p);
    let fewest = fewest_vehicles(p);
    let most = p.vehicles.len().min(p.tasks);
    let mut best = group_bound(p, &legs).max(count_bound(p, &legs));
    if fewest <= most {
        let service: f64 = p.service.iter().sum();
        let entries = Entries::new(p, &legs);
        let shared = (fewest..=most)
            .map(|k| {
                let trees = legs.tree.as_ref().map_or(0.0, |t| tree_bound(t, k));
                (service + entries.bound(k).max(trees)) / k as f64
            })
            .fold(f64::INFINITY, f64::min);
        if shared.is_finite() {
            best = best.max(shared);
        }
    }
    best
}

/// The fewest vehicles whose caps hold every task.
fn fewest_vehicles(p: &MinMaxProblem) -> usize {
    let mut caps: Vec<usize> = p.vehicles.iter().map(|v| v.cap).collect();
    caps.sort_unstable_by(|a, b| b.cmp(a));
    let mut held = 0;
    for (i, c) in caps.iter().enumerate() {
        held += c;
        if held >= p.tasks {
            return i + 1;
        }
    }
    usize::MAX
}

/// Per vehicle and task, the cheapest legs that can enter and leave the task's nodes, and the
/// tasks' symmetric leg matrix for [`tree_bound`].
struct Legs {
    /// `from_task[v][t]`: the cheapest arc into a node of `t` from a node of another task.
    from_task: Vec<Vec<f64>>,
    /// `to_task[v][t]`: the cheapest arc from a node of `t` into a node of another task.
    to_task: Vec<Vec<f64>>,
    /// `near[v][t]`: the two cheapest arcs, either way, between a node of `t` and two distinct
    /// others (tasks or the depot) — the two legs at `t` of a route through two or more tasks.
    near: Vec<Vec<Nearest>>,
    /// `from_depot[v][t]`: the cheapest arc from the depot into a node of `t`.
    from_depot: Vec<Vec<f64>>,
    /// `home[v][t]`: the cheapest arc from a node of `t` to the depot.
    home: Vec<Vec<f64>>,
    /// Absent beyond [`TREE_MAX_TASKS`].
    tree: Option<Tree>,
}

/// The tasks and the depot (node `n`) as one symmetric graph: an edge's cost is the cheapest leg
/// between its ends, either way, over the vehicles able to do both (infinite when none is).
struct Tree {
    n: usize,
    cost: Vec<f64>,
}

impl Tree {
    fn get(&self, i: usize, j: usize) -> f64 {
        self.cost[i * (self.n + 1) + j]
    }
}

impl Legs {
    fn new(p: &MinMaxProblem) -> Legs {
        let (m, n) = (p.vehicles.len(), p.tasks);
        let mut legs = Legs {
            from_task: vec![vec![f64::INFINITY; n]; m],
            to_task: vec![vec![f64::INFINITY; n]; m],
            near: vec![vec![Nearest::default(); n]; m],
            from_depot: vec![vec![f64::INFINITY; n]; m],
            home: vec![vec![f64::INFINITY; n]; m],
            tree: (n <= TREE_MAX_TASKS).then(|| Tree {
                n,
                cost: vec![f64::INFINITY; (n + 1) * (n + 1)],
            }),
        };
        for (v, veh) in p.vehicles.iter().enumerate() {
            let tasks: Vec<usize> = (0..n).filter(|&t| p.can_do(v, t)).collect();
            for &t in &tasks {
                for &a in &veh.alternatives[t] {
                    legs.from_depot[v][t] = legs.from_depot[v][t].min(veh.costs.get(veh.depot, a));
                    legs.home[v][t] = legs.home[v][t].min(veh.costs.get(a, veh.depot));
                }
                for &s in &tasks {
                    if s == t {
                        continue;
                    }
                    let mut c = f64::INFINITY;
                    for &u in &veh.alternatives[s] {
                        for &a in &veh.alternatives[t] {
                            c = c.min(veh.costs.get(u, a));
                        }
                    }
                    legs.from_task[v][t] = legs.from_task[v][t].min(c);
                    legs.to_task[v][s] = legs.to_task[v][s].min(c);
                    legs.near[v][t].offer(c, s);
                    legs.near[v][s].offer(c, t);
                    if let Some(tree) = &mut legs.tree {
                        let w = n + 1;
                        tree.cost[s * w + t] = tree.cost[s * w + t].min(c);
                        tree.cost[t * w + s] = tree.cost[t * w + s].min(c);
                    }
                }
                legs.near[v][t].offer(legs.from_depot[v][t].min(legs.home[v][t]), n);
                if let Some(tree) = &mut legs.tree {
                    let w = n + 1;
                    let c = legs.from_depot[v][t].min(legs.home[v][t]);
                    tree.cost[n * w + t] = tree.cost[n * w + t].min(c);
                    tree.cost[t * w + n] = tree.cost[t * w + n].min(c);
                }
            }
        }
        legs
    }
}

/// The two cheapest arcs between a node and two distinct others (see [`Legs::near`]).
#[derive(Clone, Copy, Debug)]
struct Nearest([(f64, usize); 2]);

impl Default for Nearest {
    fn default() -> Self {
        Nearest([(f64::INFINITY, usize::MAX); 2])
    }
}

impl Nearest {
    /// An arc of cost `c` to `other` (the cheaper of its arcs to `other` is kept).
    fn offer(&mut self, c: f64, other: usize) {
        let x = &mut self.0;
        if let Some(i) = x.iter().position(|e| e.1 == other) {
            x[i].0 = x[i].0.min(c);
        } else if c < x[1].0 {
            x[1] = (c, other);
        }
        if x[1].0 < x[0].0 {
            x.swap(0, 1);
        }
    }

    /// Half the two cheapest arcs: what a route through `t` and others pays at `t`.
    fn half(&self) -> f64 {
        0.5 * (self.0[0].0 + self.0[1].0)
    }
}

/// The legs of routes by their entries (see [`Entries::bound`]), per task over the vehicles
/// able to do it.
struct Entries {
    /// The sum over tasks of the cheapest entry, from the depot or another task.
    base: f64,
    /// Per task, the extra cost of entering it from the depot instead, ascending.
    extra: Vec<f64>,
    /// Per task, the cheapest way home from it, ascending.
    home: Vec<f64>,
}

impl Entries {
    fn new(p: &MinMaxProblem, legs: &Legs) -> Entries {
        let mut e = Entries {
            base: 0.0,
            extra: Vec::with_capacity(p.tasks),
            home: Vec::with_capacity(p.tasks),
        };
        for t in 0..p.tasks {
            let who = p.capable(t);
            let cheapest = |of: &[Vec<f64>]| who.iter().map(|&v| of[v][t]).fold(f64::INFINITY, f64::min);
            let depot = cheapest(&legs.from_depot);
            let entry = cheapest(&legs.from_task).min(depot);
            e.base += entry;
            e.extra.push(depot - entry);
            e.home.push(cheapest(&legs.home));
        }
        e.extra.sort_by(f64::total_cmp);
        e.home.sort_by(f64::total_cmp);
        e
    }

    /// The legs of `k` routes: every task's cheapest entry, the `k` smallest extra costs of
    /// entering a task from the depot instead, and the `k` smallest costs of going home from a
    /// task.
    fn bound(&self, k: usize) -> f64 {
        self.base + self.extra.iter().take(k).sum::<f64>() + self.home.iter().take(k).sum::<f64>()
    }
}

/// The legs of `k` routes by Held and Karp's trees (see the module).
fn tree_bound(tree: &Tree, k: usize) -> f64 {
    let n = tree.n;
    let nodes = n + 1;
    let want = |i: usize| if i == n { 2.0 * k as f64 } else { 2.0 };
    let steps = (TREE_WORK / (nodes * nodes)).clamp(TREE_MIN_STEPS, TREE_MAX_STEPS);
    let mut price = vec![0.0; nodes];
    let mut last = vec![0.0; nodes];
    let mut best = f64::NEG_INFINITY;
    let mut step = 0.0;
    let mut stale = 0;
    for i in 0..steps {
        let (value, degree) = priced_tree(tree, &price, k);
        let value = value - (0..nodes).map(|j| want(j) * price[j]).sum::<f64>();
        if !value.is_finite() {
            return 0.0;
        }
        if value > best + 1e-12 {
            best = value;
            stale = 0;
        } else {
            stale += 1;
        }
        if i == 0 {
            // First step: a hundredth of the average edge of the tree per unit of degree.
            step = 0.01 * value.abs().max(1e-9) / nodes as f64;
        } else if stale >= nodes.div_ceil(4).max(4) {
            step *= 0.5;
            stale = 0;
        }
        let g: Vec<f64> = (0..nodes).map(|j| degree[j] as f64 - want(j)).collect();
        if g.iter().all(|x| *x == 0.0) {
            break; // the tree is k routes: the bound is their cost
        }
        for ((p, g), l) in price.iter_mut().zip(&g).zip(&mut last) {
            *p += step * (0.7 * g + 0.3 * *l);
            *l = *g;
        }
    }
    best.max(0.0)
}

/// The cheapest spanning tree plus `k` further edges (each edge at most twice among them) under
/// `price`, and each node's degree in it. The value includes the prices on the edges.
fn priced_tree(tree: &Tree, price: &[f64], k: usize) -> (f64, Vec<usize>) {
    let nodes = tree.n + 1;
    let c = |i: usize, j: usize| tree.get(i, j) + price[i] + price[j];
    // Prim from the depot.
    let mut inside = vec![false; nodes];
    let mut near = vec![f64::INFINITY; nodes];
    let mut parent = vec![usize::MAX; nodes];
    let mut degree = vec![0usize; nodes];
    let mut value = 0.0;
    let root = tree.n;
    near[root] = 0.0;
    for _ in 0..nodes {
        let mut pick = usize::MAX;
        for j in 0..nodes {
            if !inside[j] && (pick == usize::MAX || near[j] < near[pick]) {
                pick = j;
            }
        }
        if !near[pick].is_finite() {
            return (f64::INFINITY, degree);
        }
        inside[pick] = true;
        value += near[pick];
        if parent[pick] != usize::MAX {
            degree[pick] += 1;
            degree[parent[pick]] += 1;
        }
        for j in 0..nodes {
            if !inside[j] {
                let w = c(pick, j);
                if w < near[j] {
                    near[j] = w;
                    parent[j] = pick;
                }
            }
        }
    }
    // The k cheapest further edges, each edge usable twice (a route of one task runs its depot
    // edge both ways); ties to the lower pair of nodes.
    let mut extra: Vec<(f64, usize, usize)> = Vec::with_capacity(k + 2);
    for i in 0..nodes {
        for j in (i + 1)..nodes {
            let w = c(i, j);
            if !w.is_finite() {
                continue;
            }
            for _ in 0..2 {
                if extra.len() < k || w < extra[extra.len() - 1].0 {
                    let at = extra.partition_point(|e| e.0 <= w);
                    extra.insert(at, (w, i, j));
                    extra.truncate(k);
                }
            }
        }
    }
    if extra.len() < k {
        return (f64::INFINITY, degree);
    }
    for &(w, i, j) in &extra {
        value += w;
        degree[i] += 1;
        degree[j] += 1;
    }
    (value, degree)
}

/// The bound by the numbers of tasks: the vehicles' numbers of tasks add up to `n`, and a
/// vehicle doing `m` tasks (at most its cap and the tasks it can do) takes at least the largest
/// of [`route_by_ends`] read with entries, read with exits, and (from two tasks on)
/// [`route_by_halves`] (nothing when `m` is 0).
/// The makespan is at least the smallest time `T` at which the most tasks each vehicle could do
/// within `T` add up to `n`: the relaxation lets vehicles share tasks and cheap legs, never
/// exceed `T`. (With equal vehicles it says that one of them does `⌈n / vehicles⌉` tasks.)
fn count_bound(p: &MinMaxProblem, legs: &Legs) -> f64 {
    // Per vehicle, what `m = 1, 2, …` tasks take at least (non-decreasing in `m`).
    let times: Vec<Vec<f64>> = p
        .vehicles
        .iter()
        .enumerate()
        .map(|(v, veh)| {
            let tasks: Vec<usize> = (0..p.tasks).filter(|&t| p.can_do(v, t)).collect();
            let most = tasks.len().min(veh.cap);
            let entries = route_by_ends(p, &tasks, &legs.from_task[v], &legs.from_depot[v], &legs.home[v]);
            let exits = route_by_ends(p, &tasks, &legs.to_task[v], &legs.home[v], &legs.from_depot[v]);
            let halves = route_by_halves(p, &tasks, &legs.near[v], &legs.from_depot[v], &legs.home[v]);
            let mut at = 0.0f64;
            (0..most)
                .map(|i| {
                    // Monotone as it must be (rounding aside).
                    let by_halves = if i > 0 { halves[i] } else { 0.0 };
                    at = at.max(entries[i].max(exits[i]).max(by_halves));
                    at
                })
                .collect()
        })
        .collect();
    // How many tasks the vehicles could do in all within `t`.
    let within = |t: f64| -> usize { times.iter().map(|f| f.partition_point(|&x| x <= t)).sum() };
    let mut candidates: Vec<f64> = times
        .iter()
        .flatten()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    candidates.sort_by(f64::total_cmp);
    // The smallest candidate time within which `n` tasks fit (a time between two candidates
    // fits no more than the lower one).
    let at = candidates.partition_point(|&t| within(t) < p.tasks);
    candidates.get(at).copied().unwrap_or(0.0)
}

/// What a route through `m = 2, 3, …` of `tasks` costs at least (entry `m - 1`; entry 0 is
/// not a bound): every leg is half paid at each of its ends. Each task has two legs, to two
/// distinct others, so it pays at least [`Nearest::half`]; the depot has two, so at least the
/// cheapest depot arc. The `m` smallest of a task's service plus its half, plus that.
fn route_by_halves(
    p: &MinMaxProblem,
    tasks: &[usize],
    near: &[Nearest],
    from_depot: &[f64],
    home: &[f64],
) -> Vec<f64> {
    let cost = tasks.iter().map(|&t| p.service[t] + near[t].half()).collect();
    let depot = tasks
        .iter()
        .map(|&t| from_depot[t].min(home[t]))
        .fold(f64::INFINITY, f64::min);
    cheapest_sums(cost, depot)
}

/// For every `m = 1, 2, …`: the sum of the `m` smallest of `cost`, plus `fixed`.
fn cheapest_sums(mut cost: Vec<f64>, fixed: f64) -> Vec<f64> {
    cost.sort_by(f64::total_cmp);
    let mut sum = 0.0;
    cost.iter()
        .map(|c| {
            sum += c;
            sum + fixed
        })
        .collect()
}

/// What a route through `m = 1, 2, …` of `tasks` costs at least, for every `m`: the `m`
/// smallest of a task's service plus its cheapest `end` (an arc between it and another task),
/// or its `depot_end` where that is cheaper; plus the smallest extra of one task's `depot_end`
/// over that (one task's end is at the depot); plus the cheapest `other` (the route's other
/// depot arc, at any task). Read with entries (`end` the arcs in, `depot_end` from the depot,
/// `other` home) or backwards with exits.
fn route_by_ends(
    p: &MinMaxProblem,
    tasks: &[usize],
    end: &[f64],
    depot_end: &[f64],
    other: &[f64],
) -> Vec<f64> {
    let cost = tasks
        .iter()
        .map(|&t| p.service[t] + end[t].min(depot_end[t]))
        .collect();
    let extra = tasks
        .iter()
        .map(|&t| depot_end[t] - end[t].min(depot_end[t]))
        .fold(f64::INFINITY, f64::min);
    let other = tasks.iter().map(|&t| other[t]).fold(f64::INFINITY, f64::min);
    cheapest_sums(cost, extra + other)
}

/// Most vehicles for which [`group_bound`] looks at every group of them (`2^m` groups);
/// beyond, at each vehicle alone.
const GROUP_MAX_VEHICLES: usize = 16;

/// The bound of each group `S` of vehicles: the tasks only vehicles of `S` can do (`T_S`) are
/// done by vehicles of `S`, each entered once by an arc of the vehicle that does it, so the
/// routes of `S` take together at least the sum over `T_S` of each task's service and cheapest
/// entry (from the depot or another task, over the vehicles able to do it). At most `|S|`
/// vehicles share that, and each also goes home once (arcs into the depot enter no task), from
/// any task it can do: the longest route of `S` is at least that sum over `|S|` plus the
/// cheapest way home of a vehicle of `S`. A vehicle alone (`|S| = 1`) is the bound by the tasks
/// only it can do. Groups are vehicles' bit sets; the sums over the groups' subsets are taken
/// in a fixed order (the bound depends on the problem only).
fn group_bound(p: &MinMaxProblem, legs: &Legs) -> f64 {
    let m = p.vehicles.len();
    let home: Vec<f64> = (0..m)
        .map(|v| legs.home[v].iter().copied().fold(f64::INFINITY, f64::min))
        .collect();
    // Per task: the vehicles able to do it, and its service plus cheapest entry.
    let tasks: Vec<(Vec<usize>, f64)> = (0..p.tasks)
        .map(|t| {
            let who = p.capable(t);
            let entry = who
                .iter()
                .map(|&v| legs.from_task[v][t].min(legs.from_depot[v][t]))
                .fold(f64::INFINITY, f64::min);
            (who, p.service[t] + entry)
        })
        .filter(|(who, w)| !who.is_empty() && w.is_finite())
        .collect();
    let bound = |work: f64, size: usize, home: f64| {
        let b = work / size as f64 + home;
        if b.is_finite() { b } else { 0.0 }
    };
    if m > GROUP_MAX_VEHICLES {
        let mut best: f64 = 0.0;
        for (v, &h) in home.iter().enumerate() {
            let work: f64 = tasks
                .iter()
                .filter(|(who, _)| who[..] == [v])
                .map(|(_, w)| w)
                .sum();
            if work > 0.0 {
                best = best.max(bound(work, 1, h));
            }
        }
        return best;
    }
    let groups = 1usize << m;
    // work[S]: the tasks whose vehicles are exactly S, then (summed over subsets) within S.
    let mut work = vec![0.0; groups];
    let mut any = vec![false; groups];
    for (who, w) in &tasks {
        let set = who.iter().fold(0usize, |s, &v| s | (1 << v));
        work[set] += w;
        any[set] = true;
    }
    for v in 0..m {
        let bit = 1 << v;
        for set in 0..groups {
            if set & bit != 0 {
                work[set] += work[set ^ bit];
                any[set] |= any[set ^ bit];
            }
        }
    }
    let mut cheapest_home = vec![f64::INFINITY; groups];
    let mut best: f64 = 0.0;
    for set in 1..groups {
        let low = set.trailing_zeros() as usize;
        cheapest_home[set] = cheapest_home[set & (set - 1)].min(home[low]);
        if any[set] {
            best = best.max(bound(work[set], set.count_ones() as usize, cheapest_home[set]));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::minmax::{MinMaxMethod, MinMaxParams, generate, solve};

    #[test]
    fn trees_bound_the_moves_tighter_than_entries_and_below_a_solution() {
        let mut tighter = 0;
        for seed in 0..5 {
            let p = generate(3, 30, (1, 3), seed);
            let legs = Legs::new(&p);
            let tree = legs.tree.as_ref().expect("30 tasks have a tree");
            let sol = solve(
                &p,
                &MinMaxParams {
                    method: MinMaxMethod::Ils,
                    seed,
                    max_iterations: Some(30),
                    ..MinMaxParams::default()
                },
            );
            let service: f64 = p.service.iter().sum();
            let moves: f64 = (0..3).map(|v| p.route_time(v, &sol.routes.tours[v])).sum::<f64>() - service;
            let used = sol.routes.tours.iter().filter(|t| !t.is_empty()).count();
            let trees = tree_bound(tree, used);
            assert!(
                trees <= moves + 1e-9,
                "seed {seed}: trees {trees} above the solution's moves {moves}"
            );
            tighter += usize::from(trees > Entries::new(&p, &legs).bound(used) + 1e-9);
            assert!(lower_bound(&p) <= sol.makespan + 1e-9);
        }
        assert!(tighter >= 3, "the trees beat the entries on {tighter} of 5");
    }

    #[test]
    fn counts_bound_a_route_of_the_busiest_vehicle() {
        // Three vehicles, four tasks on a line, legs as distances, service 1: whatever the
        // allocation one vehicle does two tasks: at least two services, its way out and home,
        // and one leg between two tasks (0.1 apart).
        let x: [f64; 5] = [0.0, 1.0, 1.1, 1.2, 1.3];
        let vehicle = || {
            let costs = crate::problem::CostMatrix::from_fn(5, |i, j| (x[i] - x[j]).abs());
            crate::minmax::Vehicle::new(costs, 0, 4, (1..5).map(|a| vec![a]).collect()).unwrap()
        };
        let p = MinMaxProblem::new(vec![vehicle(), vehicle(), vehicle()], 4, vec![1.0; 4], None).unwrap();
        let legs = Legs::new(&p);
        let counts = count_bound(&p, &legs);
        // The optimum: one vehicle 0 → 1.0 → 1.1 → 0, two services and legs 2.2, 4.2. The
        // bound by entries: two tasks at service 1 plus entry 0.1 each (2.2), the extra of
        // entering one from home (1.0 − 0.1 = 0.9) and the cheapest way home (1.0): 4.1.
        assert!((counts - 4.1).abs() < 1e-9, "count bound {counts}");
        // The k-th of the sum is lower: (4 + 0.4 + 3.0 + 3.3) / 3 = 3.57.
        assert!(lower_bound(&p) >= counts - 1e-12);
        let service: f64 = p.service.iter().sum();
        assert!((service + Entries::new(&p, &legs).bound(3)) / 3.0 < counts - 0.5);
    }

    #[test]
    fn a_group_shares_the_tasks_only_it_can_do() {
        // Four long tasks (service 10) only vehicles 0 and 1 can do, six short ones (service
        // 1) every vehicle can do, all on a line near the depot: whatever the allocation, 0 and
        // 1 share the 40 s of long tasks, so one of them takes at least 20 s plus its legs —
        // more than the third of all the work and more than the counts say.
        let x: [f64; 11] = [0.0, 1.0, 1.1, 1.2, 1.3, 0.5, 0.6, 0.7, 0.8, 0.9, 0.4];
        let vehicle = |long: bool| {
            let costs = crate::problem::CostMatrix::from_fn(11, |i, j| (x[i] - x[j]).abs());
            let alternatives = (1..11)
                .map(|a| if a <= 4 && !long { vec![] } else { vec![a] })
                .collect();
            crate::minmax::Vehicle::new(costs, 0, 10, alternatives).unwrap()
        };
        let service: Vec<f64> = (0..10).map(|t| if t < 4 { 10.0 } else { 1.0 }).collect();
        let p = MinMaxProblem::new(
            vec![vehicle(true), vehicle(true), vehicle(false)],
            10,
            service,
            None,
        )
        .unwrap();
        let legs = Legs::new(&p);
        let group = group_bound(&p, &legs);
        // Entries: 0.1 into each long task (a neighbour 0.1 away); home from 0.4 at least.
        assert!(
            (group - (0.5 * (40.0 + 0.4) + 0.4)).abs() < 1e-9,
            "group bound {group}"
        );
        assert!(count_bound(&p, &legs) < group - 5.0);
        let all: f64 = p.service.iter().sum();
        assert!((all + Entries::new(&p, &legs).bound(3)) / 3.0 < group - 2.0);
        assert!(lower_bound(&p) >= group - 1e-12);
        let sol = solve(
            &p,
            &MinMaxParams {
                method: MinMaxMethod::Ils,
                seed: 0,
                max_iterations: Some(50),
                ..MinMaxParams::default()
            },
        );
        assert!(
            lower_bound(&p) <= sol.makespan + 1e-9,
            "{} > {}",
            lower_bound(&p),
            sol.makespan
        );
    }
}
