#!/usr/bin/env python3
"""Plans every hard benchmark cell of bench/cells/, verifies each plan, checks that the plan does
not depend on the number of worker threads, and prints a table.

For each cell and seed S (release binary, `cargo build --release` first; standard library
only):

1. `cellplan plan CELL -o OUT --json --no-report --seed S`: exit code (0 every MP measured, 3 some MPs
   unmeasured — both fine; anything else is a failure and its last error line is reported),
   wall time and peak RSS (`/usr/bin/time -f '%e %M'`, else the clock and getrusage), cycle
   time, lower bound, ratio, Δt, MPs, robots, unmeasured MPs, the leg queries that found
   no path (the plan's `stats.legs_failed`) and, with `--json`, the cycle of the same paths
   without waits (`uncoordinated_cycle_time_s`);
2. `cellplan verify OUT/plan.json CELL --json` must exit 0;
3. `cellplan --threads 1 plan CELL -o OUT1 --json --no-report --seed S` must give the same exit code and a
   plan.json equal to the first apart from compute times (`compute_s` and wall-time fields are
   removed before comparing).

    python3 bench/hard_cells.py                 # the default set (every cell not marked long)
    python3 bench/hard_cells.py --all           # every cell, the long ones too
    python3 bench/hard_cells.py --quick         # three fast cells, a smoke test
    python3 bench/hard_cells.py --cells crowded-6r,facing-4r-roof --json
    python3 bench/hard_cells.py --seeds 0,1,2,3  # each cell with each seed: how much the plan
                                                # owes to one seed (a row per cell and seed,
                                                # then each cell's spread and each seed's mean)
    python3 bench/hard_cells.py --cells examples/autobody-4r --seeds 0,1,2,3 --no-threads1
    python3 bench/hard_cells.py --all --seeds 0,1,2 --no-threads1 --json --bin /tmp/old/cellplan > old.json
                                                # another build, for bench/paired.py

A cell is a folder of bench/cells (by name) or any folder holding a cell.toml (by path from the
repository root, e.g. the examples).

Exit code 0 when every selected cell planned (0 or 3), verified and matched with one thread;
1 otherwise (the table says which and why).
"""
import argparse
import json
import os
import pathlib
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
BIN = ROOT / "target" / "release" / "cellplan"
# Extra arguments of every `plan` (from --route-bound).
EXTRA = []
CELLS_DIR = ROOT / "bench" / "cells"

# Cells, in table order. `long`: left out of the default run (minutes per plan; run with --all
# or --cells).
CELLS = [
    ("facing-4r-roof", False),
    ("underbody-3r", False),
    ("ur10-backdoor-2r", False),
    ("crowded-6r-home-out", False),
    ("crowded-6r", False),
    ("side-4r-260", False),
    ("abb6640-6r", False),
    ("track-2r", False),
    ("hulls-6r", True),
    ("door-opening-4r", True),
    ("dense-8r-120", True),
    ("dense-8r-250", True),
    ("side-4r-2000", True),
    ("dense-8r-1000", True),
]
QUICK = ["facing-4r-roof", "underbody-3r", "ur10-backdoor-2r"]

# Keys whose values are compute or wall times: removed before comparing two plans.
TIME_KEYS = {"compute_s", "compute_stages_s"}


def strip_times(o):
    if isinstance(o, dict):
        return {k: strip_times(v) for k, v in o.items()
                if k not in TIME_KEYS and "wall" not in k and not k.startswith("compute")}
    if isinstance(o, list):
        return [strip_times(v) for v in o]
    return o


def first_difference(a, b, path="$"):
    """Where two JSON values first differ (a path and both values, shortened)."""
    if type(a) is not type(b):
        return f"{path}: {str(a)[:80]} vs {str(b)[:80]}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}.{k}: only in one plan"
            d = first_difference(a[k], b[k], f"{path}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path}: {len(a)} vs {len(b)} items"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}[{i}]")
            if d:
                return d
        return None
    return None if a == b else f"{path}: {str(a)[:80]} vs {str(b)[:80]}"


def run(cmd, timeout):
    """Runs cmd; returns (exit code or None on timeout, stdout, stderr, wall s, peak RSS MB)."""
    gnu_time = shutil.which("time", path="/usr/bin")
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        full = [gnu_time, "-f", "%e %M", "-o", tf.name, *cmd] if gnu_time else cmd
        t0 = time.monotonic()
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        p = subprocess.Popen(full, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True)
        try:
            out, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            out, err = p.communicate()
            return None, out, err, time.monotonic() - t0, None
        wall = time.monotonic() - t0
        rss = None
        if gnu_time:
            fields = tf.read().split()
            if len(fields) >= 2:
                wall, rss = float(fields[-2]), int(fields[-1]) / 1024
            # GNU time prefixes "Command exited with non-zero status N" on its own line.
        else:
            after = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
            rss = after / 1024 if after > before else None  # a maximum over all children so far
        return p.returncode, out, err, wall, rss


def last_error(err):
    lines = [l.strip() for l in err.splitlines() if l.strip() and not l.startswith("Command exited")]
    for l in reversed(lines):
        if l.startswith("error") or "panicked" in l or "×" in l:
            return l
    return lines[-1] if lines else ""


def count_mps(cell_dir):
    csv = cell_dir / "tasks.csv"
    rows = [l for l in csv.read_text().splitlines() if l.strip() and not l.startswith("#")]
    return len(rows) - 1


def count_robots(cell_toml):
    return sum(1 for l in cell_toml.read_text().splitlines() if l.strip() == "[[robots]]")


def cell_dir_of(name):
    """The folder of a cell given by name (bench/cells) or by path (from the repository root)."""
    if (CELLS_DIR / name / "cell.toml").exists():
        return CELLS_DIR / name
    return (ROOT / name).resolve()


def bench_cell(name, out_root, timeout, threads1, seed=0):
    cell_dir = cell_dir_of(name)
    cell = cell_dir / "cell.toml"
    row = {"cell": name, "seed": seed, "robots": count_robots(cell), "mps": count_mps(cell_dir),
           "ok": True, "problems": []}
    label = name.strip("/").replace("/", "_") + f"-seed{seed}"
    out = out_root / label
    seeded = ["--seed", str(seed)] + EXTRA
    rc, so, se, wall, rss = run([str(BIN), "plan", str(cell), "-o", str(out), "--json", "--no-report"]
                                + seeded, timeout)
    row.update(exit=rc, wall_s=wall, peak_rss_mb=rss)
    # What the run printed besides its JSON (progress, a temporary build's traces), kept with
    # the plan (with --out, where it outlives the run).
    out.mkdir(parents=True, exist_ok=True)
    (out / "plan.stderr").write_text(se or "")
    if rc not in (0, 3):
        row["ok"] = False
        row["problems"].append("plan timed out" if rc is None else f"plan exit {rc}: {last_error(se)}")
        if rc is None or "failed verification" not in se:
            return row
        # The planner's own verification refused the plan: plan again with --no-verify for the
        # numbers, and let `verify` say what is wrong (the row stays a failure).
        rc, so, se, _, _ = run([str(BIN), "plan", str(cell), "-o", str(out), "--json", "--no-report",
                                "--no-verify"] + seeded, timeout)
        if rc not in (0, 3):
            row["problems"].append("plan --no-verify timed out" if rc is None else
                                   f"plan --no-verify exit {rc}: {last_error(se)}")
            return row
        row["no_verify_exit"] = rc
        threads1 = False
    s = json.loads(so)
    row.update(cycle_time_s=s["cycle_time_s"], lower_bound_s=s["lower_bound_s"],
               ratio=s["ratio_to_lower_bound"], delta_t_s=s["delta_t_s"],
               robots=len(s["robots"]), unmeasured=len(s["unmeasured"]),
               mps=sum(r["tasks"] for r in s["robots"]) + len(s["unmeasured"]))
    if s.get("route_bound"):
        rb = s["route_bound"]
        row.update(leg_bound_s=rb["legs_s"], route_bound_s=rb["bound_s"],
                   route_bound_converged=rb["converged"], route_bound_rounds=rb["rounds"],
                   route_bound_work=rb["work"])
    try:
        doc = json.loads((out / "plan.json").read_text())
        stats = doc["stats"]
        row.update(legs_failed=stats["legs_failed"], legs_planned=stats["legs_planned"])
        # The same paths without a wait (every leg stopping at its waypoints): what
        # coordination cost, against the cycle.
        coord = doc.get("coordination") or {}
        if coord.get("uncoordinated_cycle_time_s") is not None:
            row.update(uncoordinated_cycle_time_s=coord["uncoordinated_cycle_time_s"])
        # How ours went (plans that state it): counts, and the seconds of its parts.
        if stats.get("ours") and doc["compute_s"].get("ours"):
            row.update(ours=stats["ours"], ours_s=doc["compute_s"]["ours"])
    except (OSError, ValueError, KeyError):
        pass
    vrc, vo, ve, vwall, _ = run([str(BIN), "verify", str(out / "plan.json"), str(cell), "--json"],
                                timeout)
    row["verify_exit"] = vrc
    if vrc != 0:
        row["ok"] = False
        if vrc is None:
            row["problems"].append("verify timed out")
        else:
            try:
                v = json.loads(vo)
                found = [" ".join((f"at {x[k]:.2f} s" if k == "time_s" else str(x[k]))
                          for k in ("kind", "robot", "task", "time_s", "detail")
                          if x.get(k) is not None)[:200] for x in v.get("violations", [])]
            except (json.JSONDecodeError, AttributeError):
                found = [last_error(ve)[:200]]
            row["problems"].append(f"verify exit {vrc}: " + "; ".join(found[:3]) +
                                   (f" (+{len(found) - 3} more)" if len(found) > 3 else ""))
    if not threads1:
        return row
    out1 = out_root / (label + "-threads1")
    rc1, so1, se1, wall1, rss1 = run([str(BIN), "--threads", "1", "plan", str(cell), "-o", str(out1),
                                      "--json", "--no-report"] + seeded, timeout)
    row.update(threads1_exit=rc1, threads1_wall_s=wall1)
    if rc1 != rc:
        row["ok"] = False
        row["threads1_same"] = False
        row["problems"].append("--threads 1 timed out" if rc1 is None else
                               f"--threads 1: exit {rc1} (not {rc}) {last_error(se1)}")
        return row
    a = strip_times(json.loads((out / "plan.json").read_text()))
    b = strip_times(json.loads((out1 / "plan.json").read_text()))
    row["threads1_same"] = a == b
    if a != b:
        row["ok"] = False
        row["problems"].append("--threads 1 plan differs at " + first_difference(a, b))
    return row


def fmt(v, f="{:.2f}"):
    return "–" if v is None else f.format(v)


def exit_text(r):
    if r["exit"] is None:
        return "timeout"
    if "no_verify_exit" in r:
        return f"{r['exit']} (--no-verify: {r['no_verify_exit']})"
    return str(r["exit"])


def counted(r):
    """Whether a row's plan counts for the mean ratio: planned (0 or 3) and verified."""
    return r["exit"] in (0, 3) and r.get("verify_exit") == 0


def table(rows):
    seeds = sorted({r["seed"] for r in rows})
    many = len(seeds) > 1
    lines = ["| cell | " + ("seed | " if many else "") + "robots | MPs | exit | unmeasured | cycle s | "
             "lower bound s | ratio | Δt s | wall s | peak RSS MB | verify | threads 1 | threads-1 wall s | "
             "failed leg queries |",
             "|---|" + ("---|" if many else "") + "---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        same = r.get("threads1_same")
        lines.append(
            f"| {r['cell']} | " + (f"{r['seed']} | " if many else "") + f"{r['robots']} | {r['mps']} | {exit_text(r)} | "
            f"{fmt(r.get('unmeasured'), '{}')} | {fmt(r.get('cycle_time_s'))} | {fmt(r.get('lower_bound_s'))} | "
            f"{fmt(r.get('ratio'), '{:.3f}')} | {fmt(r.get('delta_t_s'))} | {fmt(r['wall_s'], '{:.1f}')} | "
            f"{fmt(r['peak_rss_mb'], '{:.0f}')} | "
            f"{'–' if 'verify_exit' not in r else ('ok' if r['verify_exit'] == 0 else 'FAIL')} | "
            f"{'–' if same is None else ('same' if same else 'DIFFERS')} | {fmt(r.get('threads1_wall_s'), '{:.1f}')} | "
            f"{fmt(r.get('legs_failed'), '{}')} |")
    ratios = [r["ratio"] for r in rows if counted(r)]
    lines.append("")
    lines.append(f"mean cycle/lower-bound ratio: {sum(ratios) / len(ratios):.3f} over the {len(ratios)} "
                 f"{'plans' if many else 'cells'} planned and verified" if ratios
                 else "mean cycle/lower-bound ratio: – (no cell planned and verified)")
    if many:
        lines.append("")
        lines.append("| cell | ratio min | ratio mean | ratio max | cycle s per seed |")
        lines.append("|---|---|---|---|---|")
        for cell in dict.fromkeys(r["cell"] for r in rows):
            mine = [r for r in rows if r["cell"] == cell and counted(r)]
            if not mine:
                continue
            rs = [r["ratio"] for r in mine]
            lines.append(f"| {cell} | {min(rs):.3f} | {sum(rs) / len(rs):.3f} | {max(rs):.3f} | "
                         + ", ".join(f"{r['cycle_time_s']:.2f} ({r['seed']})" for r in mine) + " |")
        lines.append("")
        for seed in seeds:
            rs = [r["ratio"] for r in rows if r["seed"] == seed and counted(r)]
            if rs:
                lines.append(f"seed {seed}: mean ratio {sum(rs) / len(rs):.3f} over {len(rs)} cells")
    problems = [(r["cell"], p) for r in rows for p in r["problems"]]
    if problems:
        lines.append("")
        lines.append("problems:")
        lines += [f"- {c}: {p}" for c, p in problems]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cells", help="comma-separated cell names (folders of bench/cells)")
    ap.add_argument("--all", action="store_true", help="every cell, the long ones too")
    ap.add_argument("--quick", action="store_true", help="only " + ", ".join(QUICK))
    ap.add_argument("--json", action="store_true", help="print the rows as JSON")
    ap.add_argument("--out", help="keep the plans (and each run's stderr, plan.stderr) in this folder (default: a temporary one)")
    ap.add_argument("--timeout", type=float, default=3600, help="seconds per command (default 3600)")
    ap.add_argument("--no-threads1", action="store_true", help="skip the --threads 1 comparison")
    ap.add_argument("--seeds", default="0",
                    help="comma-separated seeds (default 0): each cell is planned with each")
    ap.add_argument("--bin", help="the cellplan binary to run (default target/release/cellplan)")
    ap.add_argument("--route-bound", type=float, metavar="G",
                    help="plan with --route-bound G: the plans state the route bound too (its "
                         "pricings look at up to G billion arcs) and the ratio is to the larger bound")
    args = ap.parse_args()
    global BIN
    if args.route_bound is not None:
        EXTRA.extend(["--route-bound", str(args.route_bound)])
    if args.bin:
        BIN = pathlib.Path(args.bin).resolve()
    try:
        seeds = [int(x) for x in args.seeds.split(",") if x.strip()]
    except ValueError:
        sys.exit(f"--seeds takes whole numbers separated by commas, not {args.seeds!r}")
    if not seeds or any(x < 0 for x in seeds):
        sys.exit(f"--seeds takes one or more seeds of 0 or more, not {args.seeds!r}")
    if not BIN.exists():
        sys.exit(f"{BIN} is missing: run `cargo build --release` first (or give --bin)")
    known = [c for c, _ in CELLS]
    if args.cells:
        names = [c.strip() for c in args.cells.split(",") if c.strip()]
        unknown = [c for c in names if not (cell_dir_of(c) / "cell.toml").exists()]
        if unknown:
            sys.exit(f"unknown cell(s) {', '.join(unknown)}; known: {', '.join(known)}")
    elif args.quick:
        names = QUICK
    else:
        names = [c for c, long in CELLS if args.all or not long]
    tmp = None
    if args.out:
        out_root = pathlib.Path(args.out).resolve()
        out_root.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="hard-cells-")
        out_root = pathlib.Path(tmp.name)
    rows = []
    t0 = time.monotonic()
    for name in names:
        for seed in seeds:
            what = name if len(seeds) == 1 else f"{name} (seed {seed})"
            print(f"[{time.monotonic() - t0:7.1f} s] {what} ...", file=sys.stderr, flush=True)
            row = bench_cell(name, out_root, args.timeout, not args.no_threads1, seed)
            print(f"[{time.monotonic() - t0:7.1f} s] {what}: exit {row['exit']}, "
                  f"{'ok' if row['ok'] else '; '.join(row['problems'])}", file=sys.stderr, flush=True)
            rows.append(row)
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        print(table(rows))
        runs = f"{len(names)} cell(s) × {len(seeds)} seeds" if len(seeds) > 1 else f"{len(rows)} cell(s)"
        shown = BIN.relative_to(ROOT) if BIN.is_relative_to(ROOT) else BIN
        print(f"\n{runs} in {time.monotonic() - t0:.0f} s; binary {shown}")
    if tmp:
        tmp.cleanup()
    sys.exit(0 if all(r["ok"] for r in rows) else 1)


if __name__ == "__main__":
    main()
