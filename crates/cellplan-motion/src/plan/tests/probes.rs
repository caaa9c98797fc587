//! The segment check's probes: how many a segment gets changes the work, never the answer.
use super::*;

/// How many probes a segment gets changes how soon a contact is met, never the answer: over
/// random segments among small discs, none, the usual [`validity::MAX_PROBES`] and a query's
/// direct [`validity::DIRECT_PROBES`] agree, and a long segment across a thin disc that the
/// usual probes step over is rejected by the direct ones with no covering.
#[test]
fn probes_change_the_work_not_the_answer() {
    let space = square(2, 10.0);
    // The answer and the calls (probes included) of one check with at most `probes` probes.
    let check = |v: &Discs, (a, b): (&[f64], &[f64]), probes: usize| {
        let mut calls = 0;
        (segment_valid(&space, v, (a, b), 1e-4, probes, &mut calls), calls)
    };
    let discs: Vec<(Vec<f64>, f64)> = (0..40)
        .map(|k| {
            let (x, y) = ((k * 37 % 97) as f64 / 9.7, (k * 61 % 89) as f64 / 8.9);
            (vec![x, y], 0.05 + 0.3 * ((k * 13 % 7) as f64 / 7.0))
        })
        .collect();
    let v = Discs::new(discs, 0.01);
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let (mut valid, mut invalid) = (0, 0);
    for _ in 0..400 {
        let a: Vec<f64> = (0..2).map(|_| rng.random_range(0.0..10.0)).collect();
        let b: Vec<f64> = (0..2).map(|_| rng.random_range(0.0..10.0)).collect();
        if v.clearance(&a) <= 1e-4 || v.clearance(&b) <= 1e-4 {
            continue;
        }
        let answers: Vec<bool> = [0, validity::MAX_PROBES, validity::DIRECT_PROBES]
            .into_iter()
            .map(|probes| check(&v, (&a, &b), probes).0)
            .collect();
        assert!(
            answers.iter().all(|&x| x == answers[0]),
            "{a:?} {b:?} {answers:?}"
        );
        if answers[0] {
            valid += 1;
        } else {
            invalid += 1;
        }
    }
    assert!(valid > 20 && invalid > 20, "{valid} valid, {invalid} invalid");
    // A thin disc at 17/32 of the way: the usual probes (halves to eighths, 1/16, 3/16) miss
    // it, the direct ones reach the 32nds and find it.
    let thin = Discs::new(vec![(vec![10.0 * 17.0 / 32.0, 5.0], 0.1)], 0.0);
    let (a, b) = ([0.0, 5.0], [10.0, 5.0]);
    let (usual_valid, usual) = check(&thin, (&a, &b), validity::MAX_PROBES);
    let (direct_valid, direct) = check(&thin, (&a, &b), validity::DIRECT_PROBES);
    assert!(!usual_valid && !direct_valid);
    // The usual check covers after its nine probes; the direct one meets the disc at its 24th
    // probe (the 15 up to the 16ths, then 1/32, 3/32, …, 17/32), with no covering.
    assert!(usual > validity::MAX_PROBES, "usual {usual} calls");
    assert_eq!(direct, 24);
}
