#!/usr/bin/env python3
"""Two runs of bench/hard_cells.py (`--json`, the same cells and seeds, two builds) compared
pair by pair: per cell and seed the cycle / lower-bound ratio of each, the difference, the
MPs left unmeasured and the wall time; then the mean ratios, how many pairs each side wins,
and the two-sided sign test on those wins (the chance of a split at least that uneven if
neither build were better).

usage: python3 bench/paired.py BEFORE.json AFTER.json   (standard library only)

On the long cells the seed alone moves a ratio by 0.1-0.3 (bench/cells/README.md,
twenty-first session): judge a change to legs, allocation or coordination over several seeds,
not one. A (cell, seed) that failed or was not verified in either run is listed. Exit 2 when
the files cannot be read or share no planned and verified pair.
"""
import json
import math
import sys

from hard_cells import counted


def fail(message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(2)


def load(path):
    """The rows of `path` that count (planned and verified), by (cell, seed), and the (cell,
    seed) of those that do not (failed, timed out or not verified)."""
    try:
        with open(path, encoding="utf-8") as f:
            rows = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}; give the output of `bench/hard_cells.py --json`")
    if not isinstance(rows, list):
        fail(f"{path}: not a list of rows; give the output of `bench/hard_cells.py --json`")
    out, failed = {}, []
    for r in rows:
        if not isinstance(r, dict) or "cell" not in r:
            fail(f"{path}: a row without a cell; give the output of `bench/hard_cells.py --json`")
        key = (r["cell"], r.get("seed", 0))
        if not counted(r):
            failed.append(key)
        elif isinstance(r.get("ratio"), (int, float)) and isinstance(r.get("wall_s"), (int, float)):
            out[key] = r
        else:
            fail(f"{path}: {key[0]} (seed {key[1]}) has no numeric ratio or wall_s; "
                 "give the output of `bench/hard_cells.py --json`")
    return out, failed


def sign_test(wins, losses):
    """Two-sided exact binomial test of `wins` against `losses` at one half (ties left out)."""
    n = wins + losses
    if n == 0:
        return 1.0
    k = min(wins, losses)
    tail = sum(math.comb(n, i) for i in range(k + 1)) / 2 ** n
    return min(1.0, 2 * tail)


def main(argv):
    if len(argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    (a, failed_a), (b, failed_b) = load(argv[1]), load(argv[2])
    keys = [k for k in a if k in b]
    if not keys:
        fail(f"{argv[1]} and {argv[2]} share no planned and verified (cell, seed)")
    print("| cell | seed | ratio before | ratio after | difference | unmeasured | wall s |")
    print("|---|---|---|---|---|---|---|")
    wins = losses = 0
    for cell, seed in keys:
        x, y = a[(cell, seed)], b[(cell, seed)]
        d = y["ratio"] - x["ratio"]
        if d < -1e-3:
            wins += 1
        elif d > 1e-3:
            losses += 1
        print(f"| {cell} | {seed} | {x['ratio']:.3f} | {y['ratio']:.3f} | {d:+.3f} | "
              f"{x.get('unmeasured')} → {y.get('unmeasured')} | {x['wall_s']:.1f} → {y['wall_s']:.1f} |")
    ma = sum(a[k]["ratio"] for k in keys) / len(keys)
    mb = sum(b[k]["ratio"] for k in keys) / len(keys)
    ties = len(keys) - wins - losses
    print()
    print(f"{len(keys)} pairs: mean ratio {ma:.3f} → {mb:.3f} ({mb - ma:+.3f}); after shorter on {wins}, "
          f"longer on {losses}, within 0.001 on {ties}; sign test p = {sign_test(wins, losses):.3f}")
    # A (cell, seed) that failed in one run is a result, not a row to drop quietly.
    for name, failed in ((argv[1], failed_a), (argv[2], failed_b)):
        if failed:
            print(f"not planned or not verified in {name}: "
                  + ", ".join(f"{c} (seed {s})" for c, s in failed))
    unpaired = len(a) + len(b) - 2 * len(keys)
    if unpaired:
        print(f"({unpaired} planned and verified rows without a partner left out)")


if __name__ == "__main__":
    main(sys.argv)
