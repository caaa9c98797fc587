//! `cellplan compare` on a CMM cell: paper 003's Table 3 (the GA against ours) and Table 4
//! (three ways of inspecting random subsets again).
use super::*;

/// One row of `compare` on a CMM cell: a strategy's means over the random subsets.
#[derive(Serialize, Clone)]
struct StrategyRow {
    strategy: &'static str,
    subsets: usize,
    motion_time_s: f64,
    movement_s: f64,
    rotation_s: f64,
    inspection_s: f64,
    compute_s: f64,
    /// Mean of this strategy's motion time over re-planning's, subset by subset.
    ratio_to_replan: f64,
    worst_ratio_to_replan: f64,
    verified: bool,
}

#[derive(Serialize)]
struct PlanRow {
    order: &'static str,
    groups: usize,
    motion_time_s: f64,
    movement_s: f64,
    rotation_s: f64,
    compute_s: f64,
    /// Of it, the orderings alone (the GA or ours on the same groups).
    order_compute_s: f64,
    verified: bool,
}

#[derive(Serialize)]
struct SubsetRow {
    tasks: Vec<String>,
    reuse_roots_s: f64,
    reuse_initial_path_s: f64,
    replan_s: f64,
    reuse_compute_s: f64,
    replan_compute_s: f64,
}

#[derive(Serialize)]
struct CompareOut {
    cell: String,
    mps: usize,
    seed: u64,
    plans: Vec<PlanRow>,
    strategies: Vec<StrategyRow>,
    subsets: Vec<SubsetRow>,
}

/// `cellplan compare` on a CMM cell: the whole job ordered by paper 003's GA and by ours
/// (Table 3), then `--random-tasks K` (default 20) random subsets of 3–20 MPs inspected again by
/// the three strategies of Table 4, every plan verified.
pub fn compare(args: &crate::compare_cmd::CompareArgs) -> Result<(), Failure> {
    let cell = load(&args.cell)?;
    let k = args.random_tasks.unwrap_or(20);
    if !(1..=1000).contains(&k) {
        return Err(Failure::Usage("--random-tasks must be between 1 and 1000".into()));
    }
    let show = !args.quiet && !args.json;
    let pb = crate::spinner(show, "planning the whole job (paper 003's GA, ours)");
    let mut plans = Vec::new();
    let mut base: Option<CmmPlan> = None;
    for order in [GtspMethod::Ga, GtspMethod::Ils] {
        let req = Request {
            order,
            classification: None,
            seed: args.seed,
            subset: None,
        };
        let out = run(&cell, &req).map_err(|e| Failure::Other(e.to_string()))?;
        let doc = document(&cell, &out, &req, Strategy::Plan);
        let verdict = verify_cmm(&cell, &doc);
        plans.push(PlanRow {
            order: if order == GtspMethod::Ga { "ga" } else { "ours" },
            groups: doc.groups.len(),
            motion_time_s: doc.motion_time_s,
            movement_s: doc.movement_s,
            rotation_s: doc.rotation_s,
            compute_s: doc.compute_s,
            order_compute_s: out.job.order_s,
            verified: verdict.ok,
        });
        base = Some(doc);
    }
    let base = base.ok_or_else(|| Failure::Other("no plan".into()))?;
    let measured: Vec<usize> = base.tasks.iter().filter_map(|id| cell.mp(id)).collect();
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(args.seed);
    let mut rows = Vec::new();
    let mut sums: [[f64; 5]; 3] = [[0.0; 5]; 3];
    let mut ratios: [Vec<f64>; 3] = Default::default();
    let mut verified = [true; 3];
    for s in 0..k {
        pb.set_message(format!("subset {} of {k}", s + 1));
        let hi = 20.min(measured.len());
        let size = rng.random_range(3.min(hi)..=hi);
        let mut subset = measured.clone();
        for i in (1..subset.len()).rev() {
            subset.swap(i, rng.random_range(0..=i));
        }
        subset.truncate(size);
        let roots = reuse(&cell, &base, &subset, Strategy::ReuseRoots)
            .map_err(|e| Failure::Other(format!("{e:?}")))?;
        let initial = reuse(&cell, &base, &subset, Strategy::ReuseInitialPath)
            .map_err(|e| Failure::Other(format!("{e:?}")))?;
        let req = Request {
            order: GtspMethod::Ils,
            classification: None,
            seed: args.seed,
            subset: Some(subset.clone()),
        };
        let out = run(&cell, &req).map_err(|e| Failure::Other(e.to_string()))?;
        let replan = document(&cell, &out, &req, Strategy::Replan);
        let docs = [&roots, &initial, &replan];
        for (j, d) in docs.iter().enumerate() {
            let verdict = verify_cmm(&cell, d);
            let whole = d.tasks.len() == subset.len();
            if !(verdict.ok && whole) {
                pb.suspend(|| {
                    eprintln!(
                        "subset {}: the {} plan {}",
                        s + 1,
                        d.strategy.name(),
                        match verdict.violations.first() {
                            Some(v) => format!("is not verified: {}", describe(v)),
                            None => format!(
                                "leaves MPs unmeasured: {}",
                                d.unmeasured
                                    .iter()
                                    .map(|u| format!("{} ({})", u.id, u.reason))
                                    .collect::<Vec<_>>()
                                    .join("; ")
                            ),
                        }
                    )
                });
            }
            verified[j] &= verdict.ok && whole;
            sums[j][0] += d.motion_time_s;
            sums[j][1] += d.movement_s;
            sums[j][2] += d.rotation_s;
            sums[j][3] += d.inspection_s;
            sums[j][4] += d.compute_s;
            ratios[j].push(d.motion_time_s / replan.motion_time_s);
        }
        rows.push(SubsetRow {
            tasks: roots.tasks.clone(),
            reuse_roots_s: roots.motion_time_s,
            reuse_initial_path_s: initial.motion_time_s,
            replan_s: replan.motion_time_s,
            reuse_compute_s: roots.compute_s,
            replan_compute_s: replan.compute_s,
        });
    }
    pb.finish_and_clear();
    let n = k as f64;
    let strategies = [Strategy::ReuseRoots, Strategy::ReuseInitialPath, Strategy::Replan]
        .iter()
        .enumerate()
        .map(|(j, s)| StrategyRow {
            strategy: s.name(),
            subsets: k,
            motion_time_s: sums[j][0] / n,
            movement_s: sums[j][1] / n,
            rotation_s: sums[j][2] / n,
            inspection_s: sums[j][3] / n,
            compute_s: sums[j][4] / n,
            ratio_to_replan: ratios[j].iter().sum::<f64>() / n,
            worst_ratio_to_replan: ratios[j].iter().copied().fold(0.0, f64::max),
            verified: verified[j],
        })
        .collect();
    let out = CompareOut {
        cell: cell.name.clone(),
        mps: cell.mps.len(),
        seed: args.seed,
        plans,
        strategies,
        subsets: rows,
    };
    let text = serde_json::to_string_pretty(&out).map_err(|e| Failure::Other(e.to_string()))?;
    let table = compare_table(&out);
    crate::finish_compare(args.output.as_deref(), args.json, &text, &table, || {
        let table4: Vec<cellplan_report::cmm::Table4Row> = out
            .strategies
            .iter()
            .map(|r| cellplan_report::cmm::Table4Row {
                strategy: r.strategy.to_string(),
                subsets: r.subsets,
                motion_time_s: r.motion_time_s,
                compute_s: r.compute_s,
                ratio_to_replan: r.ratio_to_replan,
                verified: r.verified,
            })
            .collect();
        let verdict = verify_cmm(&cell, &base);
        vec![(
            "report.html",
            cellplan_report::cmm::html(&base, &cell, Some(&verdict), Some(&table4)),
        )]
    })
}

fn compare_table(out: &CompareOut) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "{} — {} MPs, seed {}\n\nThe whole job (paper 003 Table 3):\n\n| order | groups | movement s | rotation s | motion s | compute s | of it ordering s | verified |\n|---|---|---|---|---|---|---|---|\n",
        out.cell, out.mps, out.seed
    );
    for p in &out.plans {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.3} | {} |",
            if p.order == "ga" {
                "paper 003's GA"
            } else {
                "ours (ILS)"
            },
            p.groups,
            p.movement_s,
            p.rotation_s,
            p.motion_time_s,
            p.compute_s,
            p.order_compute_s,
            if p.verified { "yes" } else { "NO" }
        );
    }
    let k = out.strategies.first().map_or(0, |r| r.subsets);
    let _ = write!(
        s,
        "\nRe-inspecting {k} random subsets of 3–20 MPs (paper 003 Table 4; means):\n\n| strategy | motion s | movement s | rotation s | × re-planning (mean, worst) | compute | verified |\n|---|---|---|---|---|---|---|\n"
    );
    for r in &out.strategies {
        let compute = if r.compute_s < 0.01 {
            format!("{:.1} µs", r.compute_s * 1e6)
        } else {
            format!("{:.2} s", r.compute_s)
        };
        let _ = writeln!(
            s,
            "| {} | {:.1} | {:.1} | {:.1} | {:.3}, {:.3} | {} | {} |",
            r.strategy,
            r.motion_time_s,
            r.movement_s,
            r.rotation_s,
            r.ratio_to_replan,
            r.worst_ratio_to_replan,
            compute,
            if r.verified { "yes" } else { "NO" }
        );
    }
    s
}
