#!/usr/bin/env python3
"""Paper 004's GA against ours at equal compute time, on real boards (standard library only).

For each cell, robot count and configuration: ours runs with --evaluations E; the GA is first
timed on E simulations, then run again with as many simulations as fit in ours' compute time
(a GA simulation is cheaper than one of ours). Reported: both assembly times, their ratio, the
gap of each to the lower bound, and the time ours needs to reach the GA's result (the smallest
of the budgets E/32 … E at which ours is at least as short). Every plan is verified by `plan`.

    cargo build --release
    python3 bench/pcb/ga_vs_ours.py [--evaluations 200000] [--cells pcb-bitsy-1r,pcb-icebreaker-2r] [--seeds 0,1,2]

With several seeds, each row gives the means over the seeds and the worst (largest) ratio.
"""
import argparse, json, os, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "target", "release", "cellplan")
CELLS = {
    "pcb-bitsy-1r": "examples/pcb-bitsy-1r/cell.toml",
    "pcb-icebreaker-2r": "examples/pcb-icebreaker-2r/cell.toml",
    "icebreaker-37": "bench/pcb/icebreaker-37/cell.toml",
    "pcb-paper-6": "examples/pcb-paper-6/cell.toml",
}


def plan(cell, optimizer, evals, robots, conf, seed):
    with tempfile.TemporaryDirectory() as out:
        args = [BIN, "plan", cell, "-o", out, "--json", "--no-report", "--optimizer", optimizer,
                "--evaluations", str(int(evals)), "--robots", str(robots), "--configuration", conf,
                "--seed", str(seed)]
        r = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{' '.join(args)}: {r.stderr}")
        return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--evaluations", type=int, default=200000)
    ap.add_argument("--cells", default="pcb-bitsy-1r,pcb-icebreaker-2r")
    ap.add_argument("--seeds", default="0")
    a = ap.parse_args()
    E = a.evaluations
    rows = []
    seeds = [int(x) for x in a.seeds.split(",")]
    print("| cell | robots | configuration | GA s | ours s | ours/GA (worst) | GA gap | ours gap | bound s | GA sims | ours compute s | ours reaches GA at |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in a.cells.split(","):
        cell = CELLS[name]
        n_robots = 2 if name.endswith("2r") or name == "icebreaker-37" else 1
        cases = [(1, c) for c in ["all-fixed", "moving-cds", "moving-table", "all-moving"]]
        if n_robots == 2:
            cases.append((2, "all-moving"))
        for robots, conf in cases:
            runs = []
            for seed in seeds:
                ours = plan(cell, "best", E, robots, conf, seed)
                t_ours = ours["compute_s"]
                probe = plan(cell, "ga", E, robots, conf, seed)
                ga_evals = max(1000, E * t_ours / max(probe["compute_s"], 1e-6))
                ga = plan(cell, "ga", ga_evals, robots, conf, seed)
                reach = None
                for k in [32, 16, 8, 4, 2, 1]:
                    o = plan(cell, "best", E / k, robots, conf, seed)
                    if o["cycle_time_s"] <= ga["cycle_time_s"] + 1e-9:
                        reach = (E // k, o["compute_s"])
                        break
                runs.append((ga, ours, ga_evals, t_ours, reach))
            mean = lambda xs: sum(xs) / len(xs)
            lb = runs[0][1]["lower_bound_s"]
            ga_s = mean([r[0]["cycle_time_s"] for r in runs])
            ours_s = mean([r[1]["cycle_time_s"] for r in runs])
            ratios = [r[1]["cycle_time_s"] / r[0]["cycle_time_s"] for r in runs]
            reached = [r[4] for r in runs if r[4]]
            row = dict(cell=name, robots=robots, configuration=conf, ga_s=ga_s, ours_s=ours_s,
                       ratio=mean(ratios), worst_ratio=max(ratios), lower_bound_s=lb,
                       ga_evaluations=int(mean([r[2] for r in runs])), ours_compute_s=mean([r[3] for r in runs]),
                       reach_s=[r[1] for r in reached], seeds=seeds)
            rows.append(row)
            reach_s = (f"{max(r[1] for r in reached):.2f} s (≤ {max(r[0] for r in reached)} sims)"
                       + ("" if len(reached) == len(runs) else f"; {len(runs) - len(reached)} seed(s) not within E")) if reached else "not within E"
            print(f"| {name} | {robots} | {conf} | {ga_s:.3f} | {ours_s:.3f} | {row['ratio']:.3f} ({row['worst_ratio']:.3f}) | "
                  f"{100 * (ga_s / lb - 1):.1f} % | {100 * (ours_s / lb - 1):.1f} % | {lb:.3f} | {row['ga_evaluations']} | {row['ours_compute_s']:.2f} | {reach_s} |",
                  flush=True)
    json.dump(rows, open(os.path.join(tempfile.gettempdir(), "pcb_ga_vs_ours.json"), "w"), indent=1)


if __name__ == "__main__":
    main()
