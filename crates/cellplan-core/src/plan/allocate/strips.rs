//! [`crate::plan::Allocation::Zones`] along [`PlanSettings::sweep`]: strips per row of robots.
use super::super::graph::RobotGraph;
use super::{Tour, ZONE_SEARCH_WORK, cap_error, hand_over, load, penalty};
use crate::plan::{PlanError, PlanSettings};
use cellplan_model::Cell;
use cellplan_model::tasks::TaskId;
use glam::DVec3;

/// [`crate::plan::Allocation::Zones`] along [`PlanSettings::sweep`]: strips across the line of the robots,
/// per row of robots ([`crate::plan::robot_rows`]; each MP with the row of the nearest robot that
/// can measure it). A row's MPs sorted by their place along the line are cut into one run per
/// robot, in the robots' order along it ([`cut_row`]; an MP its run's robot cannot measure
/// goes to the robot of the nearest run of the row that can, else to the nearest robot that
/// can). Then, while the busiest robot finishes sooner by giving the MP at an end of its run
/// to its neighbour in the row on that side (lower-bound tours, as the zones search edits
/// them, and the task penalties), it does: runs stay runs.
pub(super) fn strips(
    cell: &Cell,
    graphs: &[RobotGraph],
    capable: &[Vec<usize>],
    settings: &PlanSettings,
    tasks: &mut [Vec<TaskId>],
) -> Result<(), PlanError> {
    let m = graphs.len();
    let cap = cell.planning.task_cap;
    let key = crate::plan::sweep_keys(cell, settings.sweep);
    let [dx, dy] = settings.sweep.unwrap_or([1.0, 0.0]);
    let place = |p: DVec3| p.x * dx + p.y * dy;
    // Each row's robots in their order along the line.
    let mut rows = crate::plan::robot_rows(cell).map_or_else(|| vec![(0..m).collect()], |(_, rows)| rows);
    for row in &mut rows {
        row.sort_by(|&a, &b| {
            place(cell.robots[a].base.translation)
                .total_cmp(&place(cell.robots[b].base.translation))
                .then(a.cmp(&b))
        });
    }
    let mut row_of = vec![(0usize, 0usize); m];
    for (i, row) in rows.iter().enumerate() {
        for (j, &r) in row.iter().enumerate() {
            row_of[r] = (i, j);
        }
    }
    let dist = |r: usize, t: usize| (cell.robots[r].base.translation - cell.tasks[t].position).length();
    // Each MP to the row of the nearest robot that can measure it, in order along the line.
    let mut row_tasks = vec![Vec::new(); rows.len()];
    for (t, who) in capable.iter().enumerate() {
        if let Some(&r) = who
            .iter()
            .min_by(|&&a, &&b| dist(a, t).total_cmp(&dist(b, t)).then(a.cmp(&b)))
        {
            row_tasks[row_of[r].0].push(t);
        }
    }
    let mut foreign = Vec::new();
    for (robots, order) in rows.iter().zip(&mut row_tasks) {
        order.sort_by(|&a, &b| key[a].total_cmp(&key[b]).then(a.cmp(&b)));
        foreign.extend(cut_row(cell, capable, robots, order, tasks)?);
    }
    for (t, run) in foreign {
        // A robot of the nearest run of its row that can measure it and has room, then the
        // nearest robot elsewhere.
        let mut who = capable[t].clone();
        who.sort_by(|&a, &b| {
            let rank = |r: usize| {
                let (i, j) = row_of[r];
                if i == row_of[run].0 {
                    (0, j.abs_diff(row_of[run].1))
                } else {
                    (1, 0)
                }
            };
            rank(a)
                .cmp(&rank(b))
                .then(dist(a, t).total_cmp(&dist(b, t)))
                .then(a.cmp(&b))
        });
        let r = who
            .into_iter()
            .find(|&r| tasks[r].len() < cap)
            .ok_or_else(|| cap_error(cell, t, cap))?;
        tasks[r].push(TaskId(t));
    }
    for list in tasks.iter_mut() {
        list.sort();
    }
    let n = tasks.iter().map(Vec::len).sum::<usize>();
    // Balance the ends of the runs on the lower-bound tours and the task penalties.
    let pen = |t: TaskId, r: usize| penalty(settings, t, r);
    let load = |r: usize, tasks: &[TaskId]| load(settings, r, tasks);
    let seed = settings.seed;
    let mut tours: Vec<Tour> = (0..m).map(|r| Tour::new(&graphs[r], &tasks[r], seed)).collect();
    let mut since = 0;
    let mut work = 0usize;
    for _ in 0..4 * n {
        if work > ZONE_SEARCH_WORK {
            break;
        }
        let times: Vec<f64> = (0..m).map(|r| tours[r].time + load(r, &tasks[r])).collect();
        // The busiest robot (the first on ties) gives an end of its run away, or nobody does.
        let from = (0..m)
            .max_by(|&a, &b| times[a].total_cmp(&times[b]).then(b.cmp(&a)))
            .expect("robots");
        let (i, j) = row_of[from];
        let row = &rows[i];
        let by_key = |a: &TaskId, b: &TaskId| key[a.0].total_cmp(&key[b.0]).then(a.0.cmp(&b.0));
        let ends = [
            (j.checked_sub(1), tasks[from].iter().copied().min_by(by_key)),
            (
                (j + 1 < row.len()).then_some(j + 1),
                tasks[from].iter().copied().max_by(by_key),
            ),
        ];
        let mut pick = None;
        for (side, t) in ends {
            let (Some(side), Some(t)) = (side, t) else {
                continue;
            };
            let to = row[side];
            if !capable[t.0].contains(&to) || tasks[to].len() >= cap {
                continue;
            }
            work +=
                (tours[to].nodes.len() + 1) * graphs[to].alternatives[t.0].len() + tours[from].nodes.len();
            let gone = tours[from].without(&graphs[from], t) + load(from, &tasks[from]) - pen(t, from);
            let came = tours[to].with(&graphs[to], t) + load(to, &tasks[to]) + pen(t, to);
            // Only while it lowers the larger of the two robots' times.
            if came.max(gone) < times[from].max(times[to]) - 1e-6 {
                pick = Some((from, to, t));
                break;
            }
        }
        let Some((from, to, t)) = pick else {
            break;
        };
        hand_over(graphs, tasks, &mut tours, (from, to, t), &mut since, seed);
    }
    Ok(())
}

/// One row of [`strips`]: `order` (the row's MPs along the line) cut into one run per robot of
/// `robots` (in their order along the line) so that the largest measuring time of a run is
/// least, each run at most φ MPs; an MP its run's robot cannot measure weighs twice. The MPs
/// go to their runs' robots; those a run's robot cannot measure are returned with it.
fn cut_row(
    cell: &Cell,
    capable: &[Vec<usize>],
    robots: &[usize],
    order: &[usize],
    tasks: &mut [Vec<TaskId>],
) -> Result<Vec<(usize, usize)>, PlanError> {
    let (m, n) = (robots.len(), order.len());
    let cap = cell.planning.task_cap;
    if n == 0 {
        return Ok(Vec::new());
    }
    let dwell: Vec<f64> = order
        .iter()
        .map(|&t| crate::plan::dwell(cell, TaskId(t)))
        .collect();
    // prefix[j][i]: the weight of order[..i] for robots[j].
    let mut prefix = vec![vec![0.0; n + 1]; m];
    for (j, &r) in robots.iter().enumerate() {
        for (i, &t) in order.iter().enumerate() {
            let w = if capable[t].contains(&r) {
                dwell[i]
            } else {
                2.0 * dwell[i]
            };
            prefix[j][i + 1] = prefix[j][i] + w;
        }
    }
    // best[j][b]: the least largest weight of runs of robots[..=j] covering order[..b], and
    // where robots[j]'s run starts (the earliest on ties).
    let mut best = vec![vec![(f64::INFINITY, 0usize); n + 1]; m];
    for b in 0..=n.min(cap) {
        best[0][b] = (prefix[0][b], 0);
    }
    for j in 1..m {
        for b in 0..=n {
            for a in b.saturating_sub(cap)..=b {
                if !best[j - 1][a].0.is_finite() {
                    continue;
                }
                let v = best[j - 1][a].0.max(prefix[j][b] - prefix[j][a]);
                if v < best[j][b].0 {
                    best[j][b] = (v, a);
                }
            }
        }
    }
    if !best[m - 1][n].0.is_finite() {
        // Cutting every φ MPs would fit: only a row with more than φ MPs per robot gets here.
        return Err(cap_error(cell, order[n - 1], cap));
    }
    let mut foreign = Vec::new();
    let mut b = n;
    for j in (0..m).rev() {
        let a = if j == 0 { 0 } else { best[j][b].1 };
        for &t in &order[a..b] {
            if capable[t].contains(&robots[j]) {
                tasks[robots[j]].push(TaskId(t));
            } else {
                foreign.push((t, robots[j]));
            }
        }
        b = a;
    }
    foreign.sort_unstable();
    Ok(foreign)
}
