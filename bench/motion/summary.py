#!/usr/bin/env python3
"""Markdown tables of peer runs (motion_vamp.py / motion_ompl.py --json) and their re-checks
(recheck.py --json), per scene.

    python3 bench/motion/summary.py --runs RUN_JSON... [--rechecks RECHECK_JSON...]

Runs: per planner and scene, problems, solved, median time_s of the solved (and VAMP's own
vamp_time_s, OMPL's validity_checks where present). Re-checks: per planner and scene, paths
re-checked, exact-invalid, median and largest depth_m of the invalid ones.
"""
import argparse
import json
import statistics
from collections import defaultdict


def load(paths):
    rows = []
    for p in paths:
        rows.extend(json.load(open(p)))
    return rows


def med(xs):
    return statistics.median(xs) if xs else None


def fmt_t(s):
    if s is None:
        return "-"
    return f"{s * 1e6:.0f} µs" if s < 0.01 else f"{s:.3f} s"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", nargs="*", default=[])
    ap.add_argument("--rechecks", nargs="*", default=[])
    a = ap.parse_args()
    if a.runs:
        groups = defaultdict(list)
        for r in load(a.runs):
            groups[(r["planner"], r["problem"].split("/")[0])].append(r)
        print("| planner | scene | problems | planned | solved | median time_s | median own time | median validity checks |")
        print("|---|---|---|---|---|---|---|---|")
        tot = defaultdict(list)
        for (planner, scene), rs in sorted(groups.items()):
            tot[planner].extend(rs)
        for (planner, scene), rs in sorted(groups.items()) + [((p, "**all**"), rs) for p, rs in sorted(tot.items())]:
            solved = [r for r in rs if r["solved"]]
            planned = [r for r in rs if r.get("status") not in ("invalid_start", "invalid_goal")]
            own = med([r["vamp_time_s"] for r in solved if r.get("vamp_time_s") is not None])
            checks = med([r["validity_checks"] for r in solved if r.get("validity_checks") is not None])
            print(f"| {planner} | {scene} | {len(rs)} | {len(planned)} | {len(solved)} | "
                  f"{fmt_t(med([r['time_s'] for r in solved]))} | {fmt_t(own)} | "
                  f"{'-' if checks is None else f'{checks:.0f}'} |")
    if a.rechecks:
        print()
        groups = defaultdict(list)
        for r in load(a.rechecks):
            groups[(r.get("planner"), r["problem"].split("/")[0])].append(r)
        tot = defaultdict(list)
        for (planner, scene), rs in sorted(groups.items()):
            tot[planner].extend(rs)
        print("| planner | scene | paths re-checked | exact-invalid | median depth (invalid) | max depth | median FCL depth |")
        print("|---|---|---|---|---|---|---|")
        for (planner, scene), rs in sorted(groups.items()) + [((p, "**all**"), rs) for p, rs in sorted(tot.items())]:
            bad = [r for r in rs if not r["exact_valid"]]
            d = [r["depth_m"] * 1000 for r in bad]
            fd = [r["fcl_depth_m"] * 1000 for r in bad]
            print(f"| {planner} | {scene} | {len(rs)} | {len(bad)} | "
                  f"{'-' if not d else f'{med(d):.1f} mm'} | {'-' if not d else f'{max(d):.1f} mm'} | "
                  f"{'-' if not fd else f'{med(fd):.1f} mm'} |")


if __name__ == "__main__":
    main()
