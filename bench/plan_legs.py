#!/usr/bin/env python3
"""How far a plan's legs are from their straight-move bounds, robot by robot.

For every leg of an inspection plan (`plan.json`), the synchronised trapezoid time of a
straight joint move between its two end poses (the lower-bound move time the allocation and the
lower bound use: URDF velocities or the cell's `max_velocity`, and `max_acceleration` or
velocity / 0.25 s) against the leg's duration. Per robot: its motion, the same legs on their
bounds, and its work on bounds (bounds plus measuring) — the longest of which is what the plan's
allocation and tours cost on the lower-bound costs, without detours or waits.

    python3 bench/plan_legs.py OUT/plan.json [--cell CELL.toml] [--json]

The cell defaults to the plan's `cell_file` (as it was given to `plan`, relative to where that
ran). Exit 2 with a message when a file cannot be read.
"""
import argparse
import json
import math
import sys
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

RAMP_S = 0.25  # default acceleration: velocity / 0.25 s (cellplan-model's spec)


def joint_min_time(d, v, a):
    d = abs(d)
    return 2.0 * math.sqrt(d / a) if d * a <= v * v else d / v + v / a


def move_time(x, y, vel, acc):
    return max((joint_min_time(b - a, v, c) for a, b, v, c in zip(x, y, vel, acc)), default=0.0)


def limits(cell_path, cell, robot_name, joints):
    """Velocity and acceleration per joint (SI) of the robot named `robot_name`."""
    spec = next((r for r in cell.get("robots", []) if r.get("name") == robot_name), None)
    if spec is None:
        raise ValueError(f"{cell_path}: no robot named {robot_name}")
    units = cell.get("units", {})
    angle = math.pi / 180.0 if units.get("angle", "rad") == "deg" else 1.0
    length = {"mm": 1e-3, "m": 1.0}.get(units.get("length", "m"), 1.0)
    urdf = (cell_path.parent / spec["urdf"]).resolve()
    root = ET.parse(urdf).getroot()
    kinds, vel = {}, {}
    for j in root.iter("joint"):
        lim = j.find("limit")
        kinds[j.get("name")] = j.get("type")
        if lim is not None and lim.get("velocity") is not None:
            vel[j.get("name")] = float(lim.get("velocity"))
    scale = [length if kinds.get(n) == "prismatic" else angle for n in joints]
    if "max_velocity" in spec:
        v = [x * s for x, s in zip(spec["max_velocity"], scale)]
    else:
        missing = [n for n in joints if n not in vel]
        if missing:
            raise ValueError(f"{urdf}: no velocity limit for joints {missing}")
        v = [vel[n] for n in joints]
    if "max_acceleration" in spec:
        a = [x * s for x, s in zip(spec["max_acceleration"], scale)]
    else:
        a = [x / RAMP_S for x in v]
    return v, a


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("plan")
    ap.add_argument("--cell", help="the cell file (default: the plan's cell_file)")
    ap.add_argument("--json", action="store_true", help="print the rows as JSON")
    args = ap.parse_args()
    try:
        plan = json.loads(Path(args.plan).read_text())
        cell_path = Path(args.cell or plan["cell_file"])
        try:
            cell = tomllib.loads(cell_path.read_text())
        except OSError as e:
            raise ValueError(f"{e} (the plan names its cell as given on the command line; pass it with --cell)")
        rows = []
        for r in plan["robots"]:
            vel, acc = limits(cell_path, cell, r["name"], r["joints"])
            # (leg, its straight-move time) for every leg.
            legs = [(l, move_time(l["waypoints"][0], l["waypoints"][-1], vel, acc)) for l in r["legs"]]
            sampled = [(l, b) for l, b in legs if not l["straight"]]
            bound = sum(b for _, b in legs)
            rows.append({
                "robot": r["name"],
                "mps": len(r["tasks"]),
                "legs": len(legs),
                "sampled_legs": len(sampled),
                "motion_s": r["motion_s"],
                "motion_bound_s": bound,
                "sampled_s": sum(l["duration_s"] for l, _ in sampled),
                "sampled_bound_s": sum(b for _, b in sampled),
                "measuring_s": r["measuring_s"],
                "waiting_s": r["waiting_s"],
                "work_on_bounds_s": bound + r["measuring_s"],
                "end_s": r["end_s"],
            })
    except KeyError as e:
        print(f"plan_legs: {args.plan}: not an inspection plan (no field {e})", file=sys.stderr)
        return 2
    except (OSError, ValueError, json.JSONDecodeError, tomllib.TOMLDecodeError, ET.ParseError) as e:
        print(f"plan_legs: {e}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    print(f"{'robot':<8} {'MPs':>4} {'legs':>5} {'sampled':>8} {'motion s':>9} {'on bounds':>10} "
          f"{'measuring':>10} {'work on bounds':>15} {'waits':>6} {'end s':>7}")
    for x in rows:
        print(f"{x['robot']:<8} {x['mps']:>4} {x['legs']:>5} {x['sampled_legs']:>8} {x['motion_s']:>9.2f} "
              f"{x['motion_bound_s']:>10.2f} {x['measuring_s']:>10.2f} {x['work_on_bounds_s']:>15.2f} "
              f"{x['waiting_s']:>6.2f} {x['end_s']:>7.2f}")
    motion = sum(x["motion_s"] for x in rows)
    bound = sum(x["motion_bound_s"] for x in rows)
    detour = sum(x["sampled_s"] - x["sampled_bound_s"] for x in rows)
    longest = max((x["work_on_bounds_s"] for x in rows), default=0.0)
    print(f"motion {motion:.2f} s, on bounds {bound:.2f} s (the sampled legs' detours {detour:.2f} s); "
          f"longest work on bounds {longest:.2f} s; cycle {plan.get('cycle_time_s', 0.0):.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
