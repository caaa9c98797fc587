#!/usr/bin/env python3
"""Per-scene table of a `cellplan bench motion --json` run, against a VAMP run of the same session.

usage: python3 bench/motion/table.py CELLPLAN_RUN.json VAMP_RUN.json   (standard library only)
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


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
