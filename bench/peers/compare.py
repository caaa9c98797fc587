#!/usr/bin/env python3
"""cellplan against its peers, in one run, one instance at a time:

- min-max: `cellplan bench minmax --json --time-limit T FILE` against minmax_ortools.py with the
  same T (ratio = cellplan makespan / OR-Tools makespan; below 1 means cellplan is better);
- TSP: `cellplan bench tsp --json --time-limit T FILE` against tsp_elkai.py (LKH, `--elkai-runs`
  runs; it has no time limit, so its measured time is shown).

Usage (from the repository root, after `cargo build --release -p cellplan-cli`):
  bench/peers/.venv/bin/python bench/peers/compare.py \
      --minmax data/benchmarks/minmax/*.txt --tsp data/benchmarks/tsplib/berlin52.tsp ... \
      [--minmax-time auto|S] [--tsp-time S] [--elkai-runs R] [--cellplan target/release/cellplan]

`--minmax-time auto` gives 10 s to instances of at most 100 tasks and 30 s to larger ones.
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run_json(cmd, peer=False):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        msg = f"failed ({out.returncode}): {' '.join(cmd)}\n{out.stderr}"
        if not peer:
            raise SystemExit(msg)
        print(msg, file=sys.stderr)  # a peer failing is a result: shown as "-"
        return None
    return json.loads(out.stdout)


def tasks_of(path):
    with open(path) as f:
        for line in f:
            if line.startswith("TASKS"):
                return int(line.split(":", 1)[1])
            if line.startswith("SERVICE_SECTION"):
                break
    raise SystemExit(f"{path}: no TASKS line")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--minmax", nargs="*", default=[])
    ap.add_argument("--tsp", nargs="*", default=[])
    ap.add_argument("--minmax-time", default="auto")
    ap.add_argument("--tsp-time", type=float, default=10.0)
    ap.add_argument("--elkai-runs", type=int, default=1)
    ap.add_argument("--cellplan", default="target/release/cellplan")
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table")
    a = ap.parse_args()
    py = sys.executable
    rows = []
    for f in a.minmax:
        if a.minmax_time == "auto":
            t = 10.0 if tasks_of(f) <= 100 else 30.0
        else:
            t = float(a.minmax_time)
        c = run_json([a.cellplan, "bench", "minmax", "--json", "--time-limit", str(t), f])[0]
        p = run_json([py, os.path.join(HERE, "minmax_ortools.py"), "--json", "--time-limit", str(t), f], True)
        p = p or dict(cost=None, total=None, time_s=None)
        rows.append(
            dict(
                kind="minmax",
                instance=c["instance"],
                size=f"{c['vehicles']}x{c['tasks']}",
                peer="ortools",
                cellplan=c["cost"],
                peer_cost=p["cost"],
                ratio=c["cost"] / p["cost"] if p["cost"] else None,
                cellplan_total=c["total"],
                peer_total=p["total"],
                cellplan_time=c["time_s"],
                peer_time=p["time_s"],
                time_given=t,
            )
        )
        print(f"done {f}", file=sys.stderr)
    for f in a.tsp:
        t = a.tsp_time
        c = run_json([a.cellplan, "bench", "tsp", "--json", "--time-limit", str(t), f])[0]
        p = run_json([py, os.path.join(HERE, "tsp_elkai.py"), "--json", "--runs", str(a.elkai_runs), f], True)
        p = p[0] if p else dict(cost=None, time_s=None)
        rows.append(
            dict(
                kind="tsp",
                instance=c["instance"],
                size=str(c.get("optimum") or ""),
                peer=f"elkai({a.elkai_runs} runs)",
                cellplan=c["cost"],
                peer_cost=p["cost"],
                ratio=c["cost"] / p["cost"] if p["cost"] else None,
                cellplan_total=None,
                peer_total=None,
                cellplan_time=c["time_s"],
                peer_time=p["time_s"],
                time_given=t,
            )
        )
        print(f"done {f}", file=sys.stderr)

    def fmt(x, d=4):
        return "-" if x is None else f"{x:.{d}f}"

    head = [
        "kind", "instance", "size / optimum", "peer", "cellplan", "peer cost", "ratio",
        "cellplan total", "peer total", "limit s", "cellplan s", "peer s",
    ]
    table = [
        [
            r["kind"], r["instance"], r["size"], r["peer"],
            fmt(r["cellplan"], 4 if r["kind"] == "minmax" else 0),
            fmt(r["peer_cost"], 4 if r["kind"] == "minmax" else 0),
            fmt(r["ratio"], 4), fmt(r["cellplan_total"], 3), fmt(r["peer_total"], 3),
            fmt(r["time_given"], 0), fmt(r["cellplan_time"], 1), fmt(r["peer_time"], 1),
        ]
        for r in rows
    ]
    print(
        f"# {time.strftime('%Y-%m-%d')} on {platform.node()} ({os.cpu_count()} cores), "
        f"ratio = cellplan / peer (min-max: makespan), below 1 = cellplan better"
    )
    if a.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for t in table:
            print("| " + " | ".join(t) + " |")
    else:
        w = [max(len(h), *(len(t[i]) for t in table)) if table else len(h) for i, h in enumerate(head)]
        print("  ".join(h.ljust(w[i]) for i, h in enumerate(head)))
        for t in table:
            print("  ".join(x.ljust(w[i]) for i, x in enumerate(t)))


if __name__ == "__main__":
    main()
