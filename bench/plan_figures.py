#!/usr/bin/env python3
"""Issue-4 figures: `cellplan plan` on the example cells with every allocation strategy.

For each cell and strategy: cycle time, Δt, lower bound and ratio, legs planned / sampled,
compute time per stage (the run with the smallest total of `--runs`, wall clock, release
build), and `cellplan verify --no-robot-robot` on the plan (robot-robot conflicts are the
coordination stage's job). Needs only the release binary:

    cargo build --release && python3 bench/plan_figures.py [--runs 3]
"""
import argparse, json, subprocess, sys, tempfile, pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
BIN = ROOT / "target" / "release" / "cellplan"
CELLS = ["autobody-4r", "autobody-2r"]
STRATEGIES = ["proximity", "local-robust", "balanced"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--extra", nargs="*", default=[], help="more arguments for cellplan plan")
    args = ap.parse_args()
    rows = []
    for cell in CELLS:
        path = ROOT / "examples" / cell / "cell.toml"
        for strategy in STRATEGIES:
            best = None
            with tempfile.TemporaryDirectory() as out:
                for _ in range(args.runs):
                    r = subprocess.run([str(BIN), "plan", str(path), "-o", out, "--allocation", strategy,
                                        "--json", *args.extra], capture_output=True, text=True)
                    if r.returncode != 0:
                        sys.exit(f"{cell} {strategy}: {r.stderr}")
                    s = json.loads(r.stdout)
                    if best is not None and abs(s["cycle_time_s"] - best["cycle_time_s"]) > 1e-9:
                        sys.exit(f"{cell} {strategy}: not deterministic")
                    if best is None or s["compute_s"] < best["compute_s"]:
                        best = s
                v = subprocess.run([str(BIN), "verify", str(pathlib.Path(out) / "plan.json"), str(path),
                                    "--no-robot-robot", "--json"], capture_output=True, text=True)
                best["verified"] = v.returncode == 0
            rows.append((cell, strategy, best))
    print("| cell | allocation | cycle s | Δt s | lower bound s | ratio | legs (sampled) | load | candidates | costs | allocation | sequencing+motion | timing | total s | verify |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for cell, strategy, s in rows:
        st = s["compute_stages_s"]
        print(f"| {cell} | {strategy} | {s['cycle_time_s']:.2f} | {s['delta_t_s']:.2f} | {s['lower_bound_s']:.2f} | "
              f"{s['ratio_to_lower_bound']:.3f} | {s['legs_planned']} ({s['legs_sampled']}) | {st['load']:.2f} | "
              f"{st['candidates']:.2f} | {st['costs']:.2f} | {st['allocation']:.2f} | {st['sequencing_motion']:.2f} | "
              f"{st['timing']:.3f} | {st['total']:.2f} | {'clean' if s['verified'] else 'VIOLATIONS'} |")


if __name__ == "__main__":
    main()
