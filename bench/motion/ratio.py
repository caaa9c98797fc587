#!/usr/bin/env python3
"""Issue 14's ratio, measured so that the VM's noise shows: ours and VAMP on the MBM UR5
problems, one after the other, for several rounds; per round the median time of the solved
queries of each and their ratio, then the medians pooled over every round.

    python3 bench/motion/ratio.py [--rounds 10] [--bin target/release/cellplan] [--out FILE]

Ours: `cellplan bench motion bench/motion/mbm-ur5/*.json --time-limit 10 --max-samples 100000
--threads 1 --json --no-simplify --no-exact` (the paths are the same every round: the exact
re-check of them is a separate run without `--no-exact`). VAMP: `bench/peers/motion_vamp.py
... --json` in `bench/peers/.venv` (see bench/peers/README.md), its own timer (`vamp_time_s`,
the time inside the planner call). Both single-threaded. The run-to-run spread on this VM is
larger than most changes (VAMP's own median moves 54-100 us between rounds minutes apart): the
pooled medians and the median of the round ratios are the figures to quote, with the spread.

Standard library only. `--out` writes the rounds and the pooled figures as JSON. Exit 2 when a
run fails or gives no solved query.
"""
import argparse
import json
import pathlib
import statistics as st
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
PROBLEMS = sorted(str(p) for p in (ROOT / "bench" / "motion" / "mbm-ur5").glob("*.json"))


def fail(message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(2)


def run(cmd):
    """The JSON a command prints; exit 2 naming the command when it fails."""
    try:
        done = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        fail(f"cannot run {cmd[0]}: {e}")
    if done.returncode != 0:
        fail(f"{' '.join(cmd[:3])} ... exited {done.returncode}: {done.stderr.strip()[-500:]}")
    try:
        return json.loads(done.stdout)
    except json.JSONDecodeError as e:
        fail(f"{' '.join(cmd[:3])} ... printed no JSON ({e})")


def solved_times(rows, key, who, k):
    times = [r[key] for r in rows if r.get("solved")]
    if not times:
        fail(f"{who} run of round {k} solved no query")
    return times


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=10)
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "cellplan"))
    ap.add_argument("--python", default=str(ROOT / "bench" / "peers" / ".venv" / "bin" / "python"))
    ap.add_argument("--out", help="write the rounds and pooled figures here (JSON)")
    args = ap.parse_args()
    if args.rounds < 1:
        fail("--rounds must be at least 1")
    if not PROBLEMS:
        fail("no problems in bench/motion/mbm-ur5")
    ours_cmd = [args.bin, "bench", "motion", *PROBLEMS, "--time-limit", "10", "--max-samples",
                "100000", "--threads", "1", "--json", "--no-simplify", "--no-exact"]
    vamp_cmd = [args.python, str(ROOT / "bench" / "peers" / "motion_vamp.py"), *PROBLEMS, "--json"]
    rounds, ours_all, vamp_all = [], [], []
    print("| round | ours solved | ours median | VAMP solved | VAMP median (own timer) | ratio |")
    print("|---|---|---|---|---|---|")
    for k in range(1, args.rounds + 1):
        ours_rows = run(ours_cmd)
        vamp_rows = run(vamp_cmd)
        ours = solved_times(ours_rows, "time_s", "our", k)
        vamp = solved_times(vamp_rows, "vamp_time_s", "VAMP's", k)
        ours_all += ours
        vamp_all += vamp
        r = {
            "round": k,
            "ours_solved": len(ours),
            "ours_problems": len(ours_rows),
            "ours_median_s": st.median(ours),
            "vamp_solved": len(vamp),
            "vamp_problems": len(vamp_rows),
            "vamp_median_s": st.median(vamp),
        }
        r["ratio"] = r["ours_median_s"] / r["vamp_median_s"]
        rounds.append(r)
        print(f"| {k} | {len(ours)} / {len(ours_rows)} | {1e3 * r['ours_median_s']:.3f} ms | "
              f"{len(vamp)} / {len(vamp_rows)} | {1e6 * r['vamp_median_s']:.1f} µs | {r['ratio']:.1f}× |",
              flush=True)
    ratios = [r["ratio"] for r in rounds]
    pooled = {
        "ours_median_s": st.median(ours_all),
        "vamp_median_s": st.median(vamp_all),
        "median_round_ratio": st.median(ratios),
        "rounds_at_most_20x": sum(x <= 20.0 for x in ratios),
        "rounds": len(rounds),
        "lowest_ratio": min(ratios),
        "highest_ratio": max(ratios),
    }
    pooled["ratio"] = pooled["ours_median_s"] / pooled["vamp_median_s"]
    print(f"\npooled over {len(rounds)} rounds: ours {1e3 * pooled['ours_median_s']:.3f} ms, VAMP "
          f"{1e6 * pooled['vamp_median_s']:.1f} µs, ratio {pooled['ratio']:.1f}× (round ratios "
          f"{pooled['lowest_ratio']:.1f}–{pooled['highest_ratio']:.1f}×, median "
          f"{pooled['median_round_ratio']:.1f}×; {pooled['rounds_at_most_20x']} of {len(rounds)} "
          f"at most 20×)")
    if args.out:
        pathlib.Path(args.out).write_text(json.dumps({"rounds": rounds, "pooled": pooled}, indent=1) + "\n")


if __name__ == "__main__":
    main()
