//! A schedule for the search to start from: complete selections of orders by a fixed priority
//! of the robots, each evaluated at once.
use super::{Best, EPS, Search};

impl Search<'_> {
    /// A schedule from one complete selection of orders, chosen by `first_a(box)` (whether the
    /// box's first robot passes first; the other order where that one is impossible), with
    /// its times from the chain and every order, added box by box in the order robots reach
    /// them, and short waits lengthened: `None` on a positive cycle (the orders cannot all
    /// hold).
    fn selection(&mut self, first_a: impl Fn(usize) -> bool) -> Option<Best> {
        let mut x = self.initial();
        let open = self.all_open(&x).len();
        let mut order: Vec<usize> = (0..self.choices.len()).collect();
        order.sort_by(|&i, &j| self.entry[i].2.total_cmp(&self.entry[j].2).then(i.cmp(&j)));
        let mut chosen = Vec::with_capacity(order.len());
        let mut ok = true;
        for i in order {
            let c = self.choices[i];
            let (want, other) = if first_a(i) {
                (c.first_a, c.first_b)
            } else {
                (c.first_b, c.first_a)
            };
            let Some(e) = want.or(other) else {
                ok = false;
                break;
            };
            chosen.push(e);
            if !self.add(e, &mut x) {
                ok = false;
                break;
            }
        }
        while ok && let Some(v) = self.short_wait(&x) {
            ok = self.lengthen(v, &mut x);
        }
        for e in chosen.iter().rev() {
            self.out[e.from].pop();
        }
        self.hold.fill(0.0);
        ok.then(|| (self.makespan(&x), x, chosen, open))
    }

    /// The shortest of the schedules from a few complete selections (see [`Search::selection`]):
    /// robots in a fixed priority (track order, reversed, and longest path first — the robot
    /// that ends last does not wait). Orders by priority close no cycle but through a box that
    /// only one order can pass, so one of them nearly always holds: a search that finds no
    /// schedule of its own within its budget still has one. It is poor (on the 8 × 1,000 cell
    /// about twice what the search finds); first come, first passed, by where each robot
    /// enters the box, was tried and held on none of the benchmark diagrams.
    pub(super) fn incumbent(&mut self) -> Option<Best> {
        let m = self.paths.len();
        let mut longest: Vec<usize> = (0..m).collect();
        longest.sort_by(|&a, &b| self.paths[b].len.total_cmp(&self.paths[a].len).then(a.cmp(&b)));
        let mut ranks: Vec<Vec<usize>> = Vec::new();
        for order in [(0..m).collect::<Vec<_>>(), (0..m).rev().collect(), longest] {
            let mut rank = vec![0; m];
            for (k, &r) in order.iter().enumerate() {
                rank[r] = k;
            }
            if !ranks.contains(&rank) {
                ranks.push(rank);
            }
        }
        let entry = self.entry.clone();
        let mut best: Option<Best> = None;
        let mut keep = |found: Option<Best>| {
            if let Some(f) = found
                && best.as_ref().is_none_or(|b| f.0 < b.0 - EPS)
            {
                best = Some(f);
            }
        };
        for rank in &ranks {
            keep(self.selection(|i| rank[entry[i].0] < rank[entry[i].1]));
        }
        best
    }
}
