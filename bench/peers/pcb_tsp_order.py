#!/usr/bin/env python3
"""PCB assembly (paper 004): the placement order a user's tool would give — the shortest path
through the components' board positions, by LKH-3 (elkai) — against cellplan's own plan.

What machine software commonly does is order the placements as a travelling-salesperson path
over the board. This script computes that path with elkai, hands it to `cellplan plan --order`
(which keeps the order and chooses the rest as ours does: bins, robots, meetings, fixed
positions), and runs `cellplan plan` unconstrained beside it; both plans are verified.

    cargo build --release
    bench/peers/.venv/bin/python bench/peers/pcb_tsp_order.py examples/pcb-bitsy-1r/cell.toml [--configuration all-moving] [--robots 1]
"""
import argparse, json, math, os, subprocess, sys, tempfile

import elkai

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "target", "release", "cellplan")


def plan(cell, out, extra):
    args = [BIN, "plan", cell, "-o", out, "--json", "--no-report"] + extra
    r = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(args)}: {r.stderr}")
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("cell")
    ap.add_argument("--configuration", default="all-moving")
    ap.add_argument("--robots", default="1")
    ap.add_argument("--evaluations", default="200000")
    a = ap.parse_args()
    common = ["--configuration", a.configuration, "--robots", a.robots, "--evaluations", a.evaluations]
    with tempfile.TemporaryDirectory() as tmp:
        ours = plan(a.cell, os.path.join(tmp, "ours"), common)
        doc = json.load(open(os.path.join(tmp, "ours", "plan.json")))
        refs = [p["component"] for p in doc["placements"]]
        # Board positions: the place point less the table's position.
        pos = [(p["place"]["point"][0] - p["place"]["device"][0], p["place"]["point"][1] - p["place"]["device"][1])
               for p in doc["placements"]]
        n = len(refs)
        # An open path: a dummy node at distance 0 from all (µm, integers for LKH).
        m = [[0] * (n + 1) for _ in range(n + 1)]
        for i in range(n):
            for j in range(n):
                m[i][j] = int(round(1e6 * math.dist(pos[i], pos[j])))
        tour = elkai.DistanceMatrix(m).solve_tsp()
        if len(tour) > 1 and tour[0] == tour[-1]:
            tour = tour[:-1]  # elkai closes the tour
        k = tour.index(n)
        path = [t for t in tour[k + 1:] + tour[:k] if t != n]
        order_file = os.path.join(tmp, "order.txt")
        with open(order_file, "w") as f:
            f.write("\n".join(refs[i] for i in path) + "\n")
        length = sum(math.dist(pos[path[i]], pos[path[i + 1]]) for i in range(n - 1))
        peer = plan(a.cell, os.path.join(tmp, "peer"), common + ["--order", order_file])
    print(f"{os.path.basename(os.path.dirname(a.cell))} {a.robots} robot(s) {a.configuration}: "
          f"LKH path {1e3 * length:.1f} mm -> {peer['cycle_time_s']:.3f} s (verified {peer['verified']}); "
          f"cellplan {ours['cycle_time_s']:.3f} s (verified {ours['verified']}); "
          f"ratio cellplan / LKH order {ours['cycle_time_s'] / peer['cycle_time_s']:.3f}; bound {ours['lower_bound_s']:.3f} s")


if __name__ == "__main__":
    main()
