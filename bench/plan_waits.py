#!/usr/bin/env python3
"""Where a plan's robots wait, and for what.

Reads a plan document (`plan.json` as `cellplan plan` writes it) and prints, per robot, its
tasks, end, motion, measuring and waiting seconds; then every wait with the robot it waits
for and what that robot is doing when the wait ends (measuring an MP, moving on a leg,
waiting itself, or done at home), and what the waiting robot does next. The summary adds the
waits up by those two activities: a robot kept waiting by a neighbour that measures beside
its path needs the order or the allocation changed, one kept waiting by a neighbour's move
may need only a different passage order.

    python3 bench/plan_waits.py OUT/plan.json [--json]

Only the Python standard library. Not part of the Rust build.
"""
import argparse
import json
import sys


def task_name(stop):
    """A leg end as the plan names it: `home` or `{"task": "M12"}`."""
    if isinstance(stop, dict):
        return stop.get("task", "?")
    return str(stop)


def activity(robot, t):
    """What `robot` does at time `t` (s): (kind, detail)."""
    for w in robot["waits"]:
        if w["start_s"] <= t < w["start_s"] + w["duration_s"]:
            return ("waiting", f"for {w.get('for_robot')}")
    for task in robot["tasks"]:
        if task["arrive_s"] <= t < task["depart_s"]:
            return ("measuring", task["task"])
    if t >= robot["end_s"]:
        return ("home", "done")
    for leg in robot["legs"]:
        inside = sum(
            w["duration_s"]
            for w in robot["waits"]
            if leg["start_s"] <= w["start_s"] < leg["start_s"] + leg["duration_s"] + 1e-9
        )
        if leg["start_s"] <= t < leg["start_s"] + leg["duration_s"] + inside:
            return ("moving", f"{task_name(leg['from'])}->{task_name(leg['to'])}")
    return ("home", "before its first leg")


def analyse(plan):
    robots = plan["robots"]
    by_name = {r["name"]: r for r in robots}
    rows = [
        {
            "robot": r["name"],
            "tasks": len(r["tasks"]),
            "end_s": r["end_s"],
            "motion_s": r["motion_s"],
            "measuring_s": r["measuring_s"],
            "waiting_s": r["waiting_s"],
        }
        for r in robots
    ]
    waits = []
    for r in robots:
        for w in r["waits"]:
            end = w["start_s"] + w["duration_s"]
            other = by_name.get(w.get("for_robot"))
            theirs = activity(other, end - 1e-6) if other else ("?", "")
            mine = activity(r, end + 1e-6)
            waits.append(
                {
                    "robot": r["name"],
                    "start_s": w["start_s"],
                    "duration_s": w["duration_s"],
                    "leg": w["leg"],
                    "waypoint": w["waypoint"],
                    "for_robot": w.get("for_robot"),
                    "other_doing": theirs[0],
                    "other_detail": theirs[1],
                    "then": mine[0],
                    "then_detail": mine[1],
                }
            )
    summary = {}
    for w in waits:
        key = f"{w['other_doing']} / then {w['then']}"
        summary[key] = summary.get(key, 0.0) + w["duration_s"]
    last = max(robots, key=lambda r: r["end_s"]) if robots else None
    return {
        "cycle_time_s": plan.get("cycle_time_s"),
        "lower_bound_s": plan.get("lower_bound_s"),
        "last_robot": last["name"] if last else None,
        "robots": rows,
        "waits": waits,
        "seconds_by_activity": summary,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("plan", help="plan.json written by `cellplan plan`")
    ap.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = ap.parse_args()
    try:
        with open(args.plan) as f:
            plan = json.load(f)
        out = analyse(plan)
    except (OSError, ValueError, KeyError, TypeError) as e:
        print(f"error: {args.plan}: {e} (give a plan.json written by `cellplan plan`)", file=sys.stderr)
        sys.exit(2)
    if args.json:
        json.dump(out, sys.stdout, indent=1)
        print()
        return
    print(f"cycle {out['cycle_time_s']:.2f} s, lower bound {out['lower_bound_s']:.2f} s, last: {out['last_robot']}")
    print(f"{'robot':<8}{'MPs':>5}{'end s':>9}{'motion s':>10}{'meas. s':>9}{'wait s':>8}")
    for r in out["robots"]:
        print(
            f"{r['robot']:<8}{r['tasks']:>5}{r['end_s']:>9.2f}{r['motion_s']:>10.2f}"
            f"{r['measuring_s']:>9.2f}{r['waiting_s']:>8.2f}"
        )
    print()
    for w in out["waits"]:
        print(
            f"{w['robot']} waits {w['duration_s']:6.2f} s at {w['start_s']:6.2f} s (leg {w['leg']}, "
            f"waypoint {w['waypoint']}) for {w['for_robot']}: it is {w['other_doing']} "
            f"{w['other_detail']}; then {w['then']} {w['then_detail']}"
        )
    print()
    for k, v in sorted(out["seconds_by_activity"].items(), key=lambda kv: -kv[1]):
        print(f"{v:8.2f} s  other {k}")


if __name__ == "__main__":
    main()
