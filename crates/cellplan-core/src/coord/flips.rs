//! `best`'s search over tour directions one flip at a time (see `ours::directions`).

/// One search of [`flip_one_at_a_time`]: per robot whether its tour is turned, to what the
/// search found for those directions (if anything) and the nodes it took.
pub(super) type DirectionSearch<'a, T> = dyn Fn(&[bool]) -> (Option<T>, usize) + Sync + 'a;

/// The search over tour directions one flip at a time: from `start`, each robot but the first
/// in turn gets its direction flipped, and the flip is kept when `search` finds a schedule
/// whose `span` is shorter (by 1 ms) than the shortest so far; up to `rounds` rounds, stopping
/// after a round that kept none. Returns every schedule found, in the order searched (the
/// start's first), and the nodes of those searches.
///
/// The flips of robots `i` and `i + 1` are searched side by side, both from the directions as
/// they stand: the second is taken only when the first is not kept (else it is dropped,
/// uncounted, and searched again from the new directions), so what is returned is what
/// searching one flip after the other returns.
pub(super) fn flip_one_at_a_time<T: Send>(
    start: Vec<bool>,
    rounds: usize,
    search: &DirectionSearch<'_, T>,
    span: &dyn Fn(&T) -> f64,
) -> (Vec<T>, usize) {
    let m = start.len();
    let mut turn = start;
    let (first, mut spent) = search(&turn);
    let mut now = first.as_ref().map(span);
    let mut taken: Vec<T> = first.into_iter().collect();
    let flipped = |turn: &[bool], i: usize| {
        let mut t = turn.to_vec();
        t[i] = !t[i];
        t
    };
    for _ in 0..rounds {
        let mut changed = false;
        let mut i = 1;
        while i < m {
            let (first, second) = rayon::join(
                || search(&flipped(&turn, i)),
                || (i + 1 < m).then(|| search(&flipped(&turn, i + 1))),
            );
            // One search taken for the flip of robot `at`: whether the flip is kept.
            let mut take = |(d, n): (Option<T>, usize), at: usize| {
                spent += n;
                let shorter = d.as_ref().is_some_and(|d| now.is_none_or(|n| span(d) < n - 1e-3));
                if shorter {
                    now = d.as_ref().map(span);
                    turn[at] = !turn[at];
                    changed = true;
                }
                taken.extend(d);
                shorter
            };
            // The second was searched from the directions the first leaves when not kept;
            // else it is dropped, and searched again from the new directions.
            let kept = take(first, i);
            i += match second {
                Some(second) if !kept => {
                    take(second, i + 1);
                    2
                }
                _ => 1,
            };
        }
        if !changed {
            break;
        }
    }
    (taken, spent)
}

#[cfg(test)]
mod tests {
    use super::flip_one_at_a_time;

    /// One flip after the other, without searching ahead: what [`flip_one_at_a_time`] must
    /// return.
    fn one_after_the_other(
        start: Vec<bool>,
        rounds: usize,
        search: &super::DirectionSearch<'_, (Vec<bool>, f64)>,
    ) -> (Vec<(Vec<bool>, f64)>, usize) {
        let m = start.len();
        let mut turn = start;
        let (d, mut spent) = search(&turn);
        let mut now = d.as_ref().map(|d| d.1);
        let mut taken: Vec<_> = d.into_iter().collect();
        for _ in 0..rounds {
            let mut changed = false;
            for i in 1..m {
                turn[i] = !turn[i];
                let (d, n) = search(&turn);
                spent += n;
                match d {
                    Some(d) if now.is_none_or(|x| d.1 < x - 1e-3) => {
                        now = Some(d.1);
                        taken.push(d);
                        changed = true;
                    }
                    Some(d) => {
                        taken.push(d);
                        turn[i] = !turn[i];
                    }
                    None => turn[i] = !turn[i],
                }
            }
            if !changed {
                break;
            }
        }
        (taken, spent)
    }

    /// Flips searched two at a time give what flipping one robot after the other gives — the
    /// schedules in the same order and the same nodes — on made-up searches whose spans and
    /// failures depend on the directions alone (kept and dropped flips both happen).
    #[test]
    fn flips_searched_side_by_side_are_the_flips_one_after_the_other() {
        let (mut kept_some, mut dropped_some) = (0, 0);
        for seed in 0..200u64 {
            let search = |flip: &[bool]| {
                let mut h = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
                for &f in flip {
                    h = (h ^ u64::from(f)).wrapping_mul(0x100_0000_01B3).rotate_left(17);
                }
                let span = (h % 10_000) as f64 / 100.0;
                let found = (h % 7 != 0).then(|| (flip.to_vec(), span));
                (found, (h % 97) as usize)
            };
            let m = 2 + (seed % 8) as usize;
            let start: Vec<bool> = (0..m).map(|i| i > 0 && (seed >> i) & 1 == 1).collect();
            let want = one_after_the_other(start.clone(), 2, &search);
            let got = flip_one_at_a_time(start.clone(), 2, &search, &|d: &(Vec<bool>, f64)| d.1);
            assert_eq!(got, want, "seed {seed}, {m} robots");
            // A schedule shorter than the start's was kept (its flip with it).
            let first = want.0.first().map_or(f64::INFINITY, |d| d.1);
            kept_some += usize::from(want.0.iter().any(|d| d.1 < first - 1e-3));
            // A schedule found no shorter than the start's: its flip was dropped.
            dropped_some += usize::from(want.0.iter().skip(1).any(|d| d.1 >= first - 1e-3));
        }
        assert!(
            (20..200).contains(&dropped_some),
            "flips were dropped in {dropped_some} of 200 searches"
        );
        assert!(
            (20..200).contains(&kept_some),
            "flips were kept in {kept_some} of 200 searches"
        );
    }
}
