//! The paper's genetic algorithm (§2.2, §3.2, §4.1–4.2): one compound genome per solution —
//! for one robot a sequencing sub-genome, two CDS-allocation sub-genomes (here one permutation
//! of the types and empty bins over the bins of both feeders, cut in two) and a rendezvous
//! sub-genome; for two robots a sequencing sub-genome, the robot assignment and the rendezvous
//! sub-genome (bins as the cell gives them; else every type in both feeders where they have the
//! bins, or the types split by board side) — scored by the
//! assembly time of the cycle-time model, with the safety delays of the paper's collision rule
//! inside the fitness.
//!
//! The paper names the genome and the fitness but not the operators or rates; these are the
//! textbook ones for such genomes (Goldberg): tournament selection, order crossover (OX) on the
//! permutations, uniform crossover on the robot bits, blend crossover on the real genes, swap
//! and inversion mutation, Gaussian creep on the real genes, two elites. The rendezvous genes
//! are fractions in [0, 1] of each meeting's feasible range (per component: the carriage
//! position, and the table position in x and y; a fixed device has one gene for the whole run).
use crate::cell::PcbCell;
use crate::search::{default_slots, fix_devices, robot_can};
use crate::sim::{Decision, DelayRule, Given, simulate, slot_lookup};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// GA settings.
#[derive(Clone, Copy, Debug)]
pub struct GaSettings {
    /// Population size.
    pub population: usize,
    /// Fitness evaluations in all (the work budget).
    pub evaluations: usize,
    /// Crossover probability.
    pub crossover: f64,
    /// Mutation probability per sub-genome.
    pub mutation: f64,
    /// Seed.
    pub seed: u64,
    /// Wall-clock safety net.
    pub deadline: Option<std::time::Instant>,
}

impl Default for GaSettings {
    fn default() -> Self {
        GaSettings {
            population: 100,
            evaluations: 200_000,
            crossover: 0.9,
            mutation: 0.3,
            seed: 0,
            deadline: None,
        }
    }
}

#[derive(Clone, Debug)]
struct Genome {
    order: Vec<usize>,
    /// One robot without given bins: a permutation over all bins (values ≥ types are empty).
    alloc: Vec<usize>,
    robot: Vec<usize>,
    /// Per component: carriage, table x, table y fractions.
    rv: Vec<[f64; 3]>,
    /// Fixed devices: feeder 0, feeder 1, table x, table y fractions.
    fixed: [f64; 4],
}

/// The progress of a run: (evaluations, best assembly time) each time the best improves.
pub type Trace = Vec<(usize, f64)>;

/// Runs the GA; returns the best decision, its assembly time, the trace and whether the
/// deadline stopped it.
pub fn run(cell: &PcbCell, settings: &GaSettings) -> (Decision, f64, Trace, bool) {
    let n = cell.len();
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed ^ 0x6a09_e667_f3bc_c908);
    let n_bins = cell.feeders[0].bins + cell.feeders[1].bins;
    let evolve_bins = cell.robots.len() == 1 && cell.given_bins.is_empty();
    let base_slots = default_slots(cell);
    let pop_n = settings.population.max(4);
    let random_genome = |rng: &mut ChaCha8Rng| {
        let mut order: Vec<usize> = (0..n).collect();
        shuffle(&mut order, rng);
        let mut alloc: Vec<usize> = (0..n_bins).collect();
        if evolve_bins {
            shuffle(&mut alloc, rng);
        }
        let robot = (0..n).map(|_| rng.random_range(0..2)).collect();
        let rv = (0..n)
            .map(|_| [rng.random(), rng.random(), rng.random()])
            .collect();
        let fixed = [rng.random(), rng.random(), rng.random(), rng.random()];
        Genome {
            order,
            alloc,
            robot,
            rv,
            fixed,
        }
    };
    let decode = |g: &Genome| decode(cell, g, evolve_bins, &base_slots);
    let fitness = |g: &Genome| -> f64 {
        let d = decode(g);
        match d {
            Some(d) => simulate(cell, &d, &mut Given(&d), rule(cell)).makespan,
            None => f64::INFINITY,
        }
    };
    let mut pop: Vec<Genome> = (0..pop_n).map(|_| random_genome(&mut rng)).collect();
    let mut fit: Vec<f64> = pop.par_iter().map(fitness).collect();
    let mut evals = pop_n;
    let mut trace: Trace = Vec::new();
    let mut best_i = argmin(&fit);
    trace.push((evals, fit[best_i]));
    let mut hit = false;
    while evals < settings.evaluations {
        if settings.deadline.is_some_and(|d| std::time::Instant::now() > d) {
            hit = true;
            break;
        }
        let mut order_idx: Vec<usize> = (0..pop_n).collect();
        order_idx.sort_by(|&a, &b| fit[a].total_cmp(&fit[b]));
        let mut next: Vec<Genome> = order_idx.iter().take(2).map(|&i| pop[i].clone()).collect();
        let tournament = |rng: &mut ChaCha8Rng| {
            let a = rng.random_range(0..pop_n);
            let b = rng.random_range(0..pop_n);
            if fit[a] <= fit[b] { a } else { b }
        };
        while next.len() < pop_n {
            let pa = &pop[tournament(&mut rng)];
            let pb = &pop[tournament(&mut rng)];
            let mut child = if rng.random::<f64>() < settings.crossover {
                crossover(pa, pb, &mut rng)
            } else {
                pa.clone()
            };
            mutate(&mut child, settings.mutation, evolve_bins, &mut rng);
            next.push(child);
        }
        let new_fit: Vec<f64> = next[2..].par_iter().map(fitness).collect();
        evals += new_fit.len();
        let elite_fit: Vec<f64> = order_idx.iter().take(2).map(|&i| fit[i]).collect();
        fit = elite_fit.into_iter().chain(new_fit).collect();
        pop = next;
        let b = argmin(&fit);
        if fit[b] < trace.last().map_or(f64::INFINITY, |t| t.1) - 1e-12 {
            trace.push((evals, fit[b]));
        }
        best_i = b;
    }
    let best = decode(&pop[best_i]).unwrap_or_else(|| crate::search::initial(cell));
    let value = simulate(cell, &best, &mut Given(&best), rule(cell)).makespan;
    (best, value, trace, hit)
}

/// The delay rule of the paper's GA.
pub fn rule(cell: &PcbCell) -> DelayRule {
    if cell.robots.len() == 2 && cell.collision_avoidance {
        DelayRule::Paper
    } else {
        DelayRule::Off
    }
}

fn argmin(v: &[f64]) -> usize {
    (0..v.len()).min_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap_or(0)
}

fn shuffle(v: &mut [usize], rng: &mut ChaCha8Rng) {
    for i in (1..v.len()).rev() {
        let j = rng.random_range(0..=i);
        v.swap(i, j);
    }
}

/// Order crossover (OX): a slice of `a`, the rest in `b`'s order.
fn ox(a: &[usize], b: &[usize], rng: &mut ChaCha8Rng) -> Vec<usize> {
    let n = a.len();
    if n < 2 {
        return a.to_vec();
    }
    let i = rng.random_range(0..n);
    let j = rng.random_range(0..n);
    let (lo, hi) = (i.min(j), i.max(j));
    let mut taken = vec![false; n];
    let mut child = vec![usize::MAX; n];
    for k in lo..=hi {
        child[k] = a[k];
        taken[a[k]] = true;
    }
    let mut fill = b.iter().filter(|&&x| !taken[x]);
    for (k, slot) in child.iter_mut().enumerate() {
        if !(lo..=hi).contains(&k) {
            *slot = *fill.next().unwrap_or(&0);
        }
    }
    child
}

fn crossover(a: &Genome, b: &Genome, rng: &mut ChaCha8Rng) -> Genome {
    let order = ox(&a.order, &b.order, rng);
    let alloc = ox(&a.alloc, &b.alloc, rng);
    let robot = a
        .robot
        .iter()
        .zip(&b.robot)
        .map(|(&x, &y)| if rng.random::<bool>() { x } else { y })
        .collect();
    let blend = |x: f64, y: f64, rng: &mut ChaCha8Rng| {
        let w: f64 = rng.random();
        (w * x + (1.0 - w) * y).clamp(0.0, 1.0)
    };
    let rv =
        a.rv.iter()
            .zip(&b.rv)
            .map(|(x, y)| {
                [
                    blend(x[0], y[0], rng),
                    blend(x[1], y[1], rng),
                    blend(x[2], y[2], rng),
                ]
            })
            .collect();
    let mut fixed = [0.0; 4];
    for (k, slot) in fixed.iter_mut().enumerate() {
        *slot = blend(a.fixed[k], b.fixed[k], rng);
    }
    Genome {
        order,
        alloc,
        robot,
        rv,
        fixed,
    }
}

fn mutate(g: &mut Genome, p: f64, evolve_bins: bool, rng: &mut ChaCha8Rng) {
    let n = g.order.len();
    if n >= 2 && rng.random::<f64>() < p {
        let i = rng.random_range(0..n);
        let j = rng.random_range(0..n);
        if rng.random::<bool>() {
            g.order.swap(i, j);
        } else {
            g.order[i.min(j)..=i.max(j)].reverse();
        }
    }
    if evolve_bins && g.alloc.len() >= 2 && rng.random::<f64>() < p {
        let i = rng.random_range(0..g.alloc.len());
        let j = rng.random_range(0..g.alloc.len());
        g.alloc.swap(i, j);
    }
    if n > 0 && rng.random::<f64>() < p {
        let i = rng.random_range(0..n);
        g.robot[i] = 1 - g.robot[i];
    }
    if n > 0 && rng.random::<f64>() < p {
        let per = (1.0 / n as f64).max(0.02);
        for genes in &mut g.rv {
            for x in genes.iter_mut() {
                if rng.random::<f64>() < per {
                    *x = (*x + 0.1 * gauss(rng)).clamp(0.0, 1.0);
                }
            }
        }
    }
    if rng.random::<f64>() < p {
        let k = rng.random_range(0..4);
        g.fixed[k] = (g.fixed[k] + 0.1 * gauss(rng)).clamp(0.0, 1.0);
    }
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller.
    let u: f64 = rng.random::<f64>().max(1e-12);
    let v: f64 = rng.random();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

fn lerp(r: [f64; 2], u: f64) -> f64 {
    r[0] + u * (r[1] - r[0])
}

/// A genome as a decision; `None` where it cannot be made valid (a fixed device with no common
/// position).
fn decode(cell: &PcbCell, g: &Genome, evolve_bins: bool, base: &[Vec<Option<usize>>; 2]) -> Option<Decision> {
    let n = cell.len();
    let slots = if evolve_bins {
        let nt = cell.types.len();
        let b0 = cell.feeders[0].bins;
        let s0 = g.alloc[..b0].iter().map(|&v| (v < nt).then_some(v)).collect();
        let s1 = g.alloc[b0..].iter().map(|&v| (v < nt).then_some(v)).collect();
        [s0, s1]
    } else {
        base.clone()
    };
    let mut d = Decision {
        order: g.order.clone(),
        robot: vec![0; n],
        feeder: vec![0; n],
        slots,
        carriage: vec![0.0; n],
        table: vec![[0.0; 2]; n],
    };
    let lookup = slot_lookup(cell, &d);
    for c in 0..n {
        let t = cell.type_of[c];
        let (r, f) = if cell.robots.len() == 1 {
            // The robot gene chooses the feeder where both hold the type.
            let f = match (lookup[0][t].is_some(), lookup[1][t].is_some()) {
                (true, true) => g.robot[c],
                (false, true) => 1,
                _ => 0,
            };
            (0, f)
        } else {
            // The robot gene, repaired where that robot cannot do it.
            let want = g.robot[c];
            let r = if robot_can(cell, &lookup, want, c) {
                want
            } else {
                1 - want
            };
            (r, r)
        };
        d.robot[c] = r;
        d.feeder[c] = f;
        let slot = lookup[f][t]?;
        let range = cell.pick_range(r, f, slot)?;
        d.carriage[c] = lerp(range, g.rv[c][0]);
        let bx = cell.place_box(r, c)?;
        d.table[c] = [lerp(bx[0], g.rv[c][1]), lerp(bx[1], g.rv[c][2])];
    }
    fix_devices(cell, &mut d, Some(g.fixed))?;
    Some(d)
}
