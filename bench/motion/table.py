#!/usr/bin/env python3
"""Per-scene table of a `cellplan bench motion --json` run, against a VAMP run of the same session.

usage: python3 bench/motion/table.py CELLPLAN_RUN.json VAMP_RUN.json [OURS_RAW.json VAMP_SIMPLIFY.json]
(standard library only). With the two more files — ours with `--no-simplify` and VAMP with
`--simplify`, from the same session — it also prints the like-for-like ratios: raw paths against
raw paths, simplified against simplified.
"""
import collections
import json
import statistics as st
import sys


def main(ours_file, vamp_file):
    rows = json.load(open(ours_file))
    vamp = [x for x in json.load(open(vamp_file)) if x["solved"]]
    v_own = st.median(x["vamp_time_s"] for x in vamp)
    v_call = st.median(x["time_s"] for x in vamp)
    print("| scene | problems | solved | not solved (status) | median time | median checks (simplify) | exact re-check: colliding |")
    print("|---|---|---|---|---|---|---|")
    by = collections.defaultdict(list)
    for x in rows:
        by[x["problem"].split("/")[0]].append(x)
    for scene, xs in list(by.items()) + [("**all**", rows)]:
        solved = [x for x in xs if x["solved"]]
        why = collections.Counter(x["status"] for x in xs if not x["solved"])
        why = ", ".join(f"{k} {n}" for k, n in sorted(why.items())) or "—"
        if solved:
            ms = st.median(x["time_s"] for x in solved) * 1e3
            checks = st.median(x["validity_checks"] for x in solved)
            simplify = st.median(x["simplify_checks"] for x in solved)
        else:
            ms = checks = simplify = float("nan")
        bad = sum(1 for x in solved if not x["exact_valid"])
        print(f"| {scene} | {len(xs)} | {len(solved)} | {why} | {ms:.0f} ms | {checks:.0f} ({simplify:.0f}) | {bad} / {len(solved)} |")
    solved = [x for x in rows if x["solved"]]
    m = st.median(x["time_s"] for x in solved)
    print()
    print(
        f"solved {len(solved)}/{len(rows)} = {100 * len(solved) / len(rows):.1f} %; median {m * 1e3:.1f} ms; "
        f"VAMP: own {v_own * 1e6:.0f} us, around the call {v_call * 1e6:.0f} us; "
        f"ratio {m / v_own:.0f}x own, {m / v_call:.0f}x call"
    )


def like_for_like(ours_file, vamp_file, ours_raw_file, vamp_simplify_file):
    """Ours raw against VAMP raw, ours simplified against VAMP simplified (medians of solved)."""
    def median(f, key):
        return st.median(x[key] for x in json.load(open(f)) if x["solved"])

    print()
    for what, ours, vamp in [("raw", ours_raw_file, vamp_file), ("simplified", ours_file, vamp_simplify_file)]:
        m, v_own, v_call = median(ours, "time_s"), median(vamp, "vamp_time_s"), median(vamp, "time_s")
        print(
            f"like for like, {what}: ours {m * 1e3:.2f} ms; VAMP own {v_own * 1e6:.0f} us, "
            f"around the call {v_call * 1e6:.0f} us; ratio {m / v_own:.1f}x own, {m / v_call:.1f}x call"
        )


if __name__ == "__main__":
    if len(sys.argv) not in (3, 5):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
    if len(sys.argv) == 5:
        like_for_like(*sys.argv[1:5])
