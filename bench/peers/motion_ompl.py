#!/usr/bin/env python3
"""Run OMPL (PyPI `ompl`, geometric planners) on cellplan motion-problem files
(bench/motion/README.md).

OMPL has no robot model; the state validity checker here is bench/motion/motionlib.py's exact
model: forward kinematics from the problem's URDF, every link's URDF collision geometry (for the
MBM UR5: the 7 UR5 STL meshes, the Robotiq FT-300 STL, the 9 Robotiq 2F-85 STL meshes, the
ee_link 1 cm box) as FCL triangle meshes (BVHModel, OBBRSS), checked with python-fcl against the
problem's primitives (fcl.Box / fcl.Cylinder / fcl.Sphere) and against the robot's other links
except the pairs the SRDF disables and parent-child pairs; a bounding-sphere test per link pair
first, FCL decides. A configuration is valid iff FCL reports no contact.

The space is RealVectorStateSpace(n) with the URDF's joint limits; OMPL's discrete motion check
samples every --resolution rad (default 1/32 rad, VAMP's UR5 resolution; OMPL's own default
would be 1 % of the space's extent, 0.154 rad here). time_s is wall-clock time around
SimpleSetup.solve() (plus simplifySolution() with --simplify), with the validity checker in
Python; validity_checks counts the checker's calls.

Usage: motion_ompl.py SCENE_JSON... [--planner RRTConnect] [--time-limit S] [--resolution R]
                      [--simplify] [--first N] [--seed S] [--json]
"""
import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "motion"))
import motionlib  # noqa: E402


def summarise(rows, out):
    by_scene = {}
    for r in rows:
        by_scene.setdefault(r["problem"].split("/")[0], []).append(r)
    for scene, rs in by_scene.items():
        solved = [r for r in rs if r["solved"]]
        med = statistics.median(r["time_s"] for r in solved) if solved else float("nan")
        medc = statistics.median(r["validity_checks"] for r in solved) if solved else float("nan")
        print(f"{scene}: solved {len(solved)}/{len(rs)}, median time {med:.3f} s, "
              f"median validity checks {medc:.0f}", file=out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--planner", default="RRTConnect", help="an ompl.geometric planner class")
    ap.add_argument("--time-limit", type=float, default=10.0, help="seconds per problem")
    ap.add_argument("--resolution", type=float, default=1 / 32, help="motion check step, rad")
    ap.add_argument("--simplify", action="store_true", help="also run simplifySolution()")
    ap.add_argument("--first", type=int, default=None, help="only the first N problems per file")
    ap.add_argument("--seed", type=int, default=None, help="OMPL's global RNG seed (default: random)")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    if a.seed is not None:
        ou.RNG.setSeed(a.seed)
    if hasattr(ou, "setLogLevel") and hasattr(ou, "LogLevel"):
        ou.setLogLevel(ou.LogLevel.LOG_WARN)
    name = f"ompl-{a.planner}" + ("+simplify" if a.simplify else "")
    robots = {}
    rows = []
    for path in a.files:
        doc = motionlib.load_problems(path)
        key = (str(doc["urdf_path"]), str(doc["srdf_path"]), tuple(doc["joints"]))
        if key not in robots:
            robots[key] = motionlib.Robot(doc["urdf_path"], doc["srdf_path"], doc["joints"], doc["base_tf"])
        robot = robots[key]
        lo, hi = robot.limits()
        n = len(doc["joints"])
        for p in doc["problems"][: a.first]:
            model = motionlib.CollisionModel(robot, p["obstacles"], p.get("margin", 0.0))
            space = ob.RealVectorStateSpace(n)
            bounds = ob.RealVectorBounds(n)
            for i in range(n):
                bounds.setLow(i, float(lo[i]))
                bounds.setHigh(i, float(hi[i]))
            space.setBounds(bounds)
            ss = og.SimpleSetup(space)
            si = ss.getSpaceInformation()
            count = [0]

            def valid(state, model=model, count=count):
                count[0] += 1
                return model.valid([state[i] for i in range(n)])

            ss.setStateValidityChecker(valid)
            si.setStateValidityCheckingResolution(a.resolution / si.getMaximumExtent())
            planner = getattr(og, a.planner)(si)
            ss.setPlanner(planner)
            start = space.allocState()
            for i in range(n):
                start[i] = float(p["start"][i])
            ss.setStartState(start)
            if len(p["goals"]) == 1:
                goal = space.allocState()
                for i in range(n):
                    goal[i] = float(p["goals"][0][i])
                ss.setGoalState(goal)
            else:
                gs = ob.GoalStates(si)
                for g in p["goals"]:
                    st = space.allocState()
                    for i in range(n):
                        st[i] = float(g[i])
                    gs.addState(st)
                ss.setGoal(gs)
            ss.setup()
            count[0] = 0
            t0 = time.perf_counter()
            status = ss.solve(a.time_limit)
            solved = bool(ss.haveExactSolutionPath())
            if solved and a.simplify:
                ss.simplifySolution()
            dt = time.perf_counter() - t0
            row = {"problem": p["name"], "planner": name, "solved": solved,
                   "status": status.asString(), "time_s": dt, "path_length": None,
                   "validity_checks": count[0], "path": None}
            if solved:
                sol = ss.getSolutionPath()
                q = [[float(s[i]) for i in range(n)] for s in sol.getStates()]
                row.update(path=q, path_length=motionlib.path_length(q))
            rows.append(row)
            if not a.json:
                pl = f"{row['path_length']:.3f}" if row["path_length"] is not None else "-"
                print(f"{p['name']}: {row['status']} {dt:.3f} s, {count[0]} checks, length {pl}")
    if a.json:
        print(json.dumps(rows))
    summarise(rows, sys.stderr if a.json else sys.stdout)


if __name__ == "__main__":
    main()
