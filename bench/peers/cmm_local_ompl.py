#!/usr/bin/env python3
"""OMPL's RRT* (PyPI `ompl`) on the local paths of a 5-axis CMM inspection plan, beside
cellplan's own RRT* on the same problems.

A local path runs from an MP's root to its approach position at the group's fixed head angles
(a, b), so each problem is a 3-D search over the head's A-axis centre c = (x, y, z) within the
problem's `bounds` (cellplan: the box of the two ends widened by 8 cm, within the travel). The
input is the JSON that cellplan's exporter writes (format in bench/peers/README.md;
bench/cmm/local_problems.sample.json is a hand-made one).

Validity, reproduced from crates/cellplan-cmm/src/classify.rs (`probe_bodies`, `body_poses`):
probe direction d = (sin a cos b, sin a sin b, -cos a), reach = l1 + l2, R the shortest-arc
rotation taking +Z to d; bodies ball (sphere Ø ball_diameter at c + d reach), stem (cylinder
Ø stem_diameter, length l2, at c + d (l1 + reach)/2, rotated by R), extension (cylinder
Ø extension_diameter, length l1, at c + d l1/2, rotated by R), head (cylinder Ø head[0],
height head[1], at c + (0, 0, head[1]/2), not rotated), ram (box ram[0] x ram[0] x ram[1], at
c + (0, 0, head[1] + ram[1]/2)). A state is valid when it is within bounds and every body is
more than `clearance` from every static object. Distances by python-fcl: the part mesh as a
BVHModel (OBBRSS; a triangle surface, so a body wholly inside the solid would not count — it
cannot happen here: the bodies form one chain that always reaches up out of the part through
the ram), boxes and the probe's bodies as fcl primitives. A bounding sphere per body against
an AABB per static skips pairs that cannot be within the clearance (exact: a lower bound).

OMPL setup, per problem: RealVectorStateSpace(3) with the bounds; RRT* (og.RRTstar) minimising
path length with OMPL's defaults (goal bias 0.05, rewire factor 1.1, delayed collision checking)
except:
- range: OMPL's default, 0.2 x the space's extent (the local box's diagonal). This is what
  cellplan's local RRT* uses too (crates/cellplan-cmm/src/mrnc.rs leaves PlannerParams::range
  at 0, which means 0.2 x extent); MrncSettings::range (0.08 m) is the step of the root search,
  not of RRT*. `--range` overrides it.
- neighbours: the radius (r-disc) rule, as cellplan's RRT*, instead of OMPL's default k-nearest
  (setKNearest(False)); both cap the radius at the range. The radii still differ: OMPL's is
  1.1 (2 (1 + 1/d) mu/zeta_d)^(1/d) (ln n / n)^(1/d) with d = 3, cellplan's
  1.1 * 2 (1 + 1/d)^(1/d) (mu/zeta_d)^(1/d) (ln n / n)^(1/d) with d = 5 (its JointSpace keeps
  the fixed head axes as joints of zero range), which stays at the range cap throughout a
  local problem's 8000 samples, while OMPL's shrinks to a few cm: cellplan rewires over many
  more neighbours per sample.
- motion checking: OMPL's discrete motion validator with
  setStateValidityCheckingResolution(--resolution / extent), i.e. states at most 1 mm apart
  along every edge by default. The probe only translates, so a path checked this way keeps at
  least clearance - resolution/2 (cellplan's segment check is exact, and it asks for
  clearance + 0.1 mm, its `min_clearance`). Each OMPL path is also
  re-checked here exactly (conservative advancement, see `path_margin`) and the smallest
  margin found is reported.
Two runs per problem:
- "iter": RRT* stopped after as many iterations as cellplan drew samples (`ours.samples`; a
  problem with none, one cellplan solved by its straight segment, gets `--samples`, cellplan's
  default budget of 8000). The Python bindings have no IterationTerminationCondition; the
  planner's own counter is read instead: PlannerTerminationCondition(lambda:
  planner.numIterations() >= n), RRTstar tests it once per iteration.
- "time": RRT* for a wall-clock budget of `--time` seconds.
Lengths: the raw RRT* path (PathGeometric.length(), Euclidean in m), and apart from it after
SimpleSetup.simplifySolution() (PathSimplifier::simplifyMax: vertex reduction, shortcuts,
B-spline smoothing, each change motion-checked). cellplan's `ours.length_m` is after its own
shortcutting (PlannerParams::simplify, 100 random shortcuts), so the simplified column is the
like-for-like one. time_s is wall-clock around SimpleSetup.solve() with the validity checker in
Python; the simplification's time is reported apart.

Determinism: OMPL's RNG is seeded once with --seed (ompl.util.RNG.setSeed) before any planner
exists; the "iter" runs are then repeatable, the "time" runs depend on the machine's speed.

Usage: cmm_local_ompl.py PROBLEMS_JSON [--time S] [--seed N] [--samples N] [--range M]
                         [--resolution M] [--json OUT]
"""
import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import fcl
import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

ROOT = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------- geometry


def quat_matrix(q):
    """Rotation matrix of the unit quaternion (x, y, z, w)."""
    x, y, z, w = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def arc_matrix(d):
    """The shortest-arc rotation taking +Z to the unit vector d (glam's from_rotation_arc;
    for d = -Z any half turn, which a cylinder about its axis does not tell apart)."""
    z = np.array([0.0, 0.0, 1.0])
    c = float(np.dot(z, d))
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross(z, d)
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + k + k @ k / (1 + c)


def read_obj(path):
    """Vertices and triangles of an OBJ file (faces fanned into triangles)."""
    verts, tris = [], []
    for line in Path(path).read_text().splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "v":
            verts.append([float(t) for t in f[1:4]])
        elif f[0] == "f":
            idx = [int(t.split("/")[0]) for t in f[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            tris.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    return np.array(verts, dtype=float), np.array(tris, dtype=np.int64)


def sphere_box_gap(centre, radius, lo, hi):
    """A lower bound of the distance between a ball and an axis-aligned box."""
    return math.dist(centre, np.clip(centre, lo, hi)) - radius


class Scene:
    """The statics and the probe at fixed head angles, in python-fcl."""

    def __init__(self, scene):
        self.clearance = float(scene["clearance"])
        # Statics: fcl objects and their world AABBs.
        self.statics = []
        for s in scene["statics"]:
            rot = quat_matrix(s["pose"]["quat"])
            xyz = np.asarray(s["pose"]["xyz"], dtype=float)
            if "mesh" in s:
                path = Path(s["mesh"])
                verts, tris = read_obj(path if path.is_absolute() else ROOT / path)
                verts *= float(s.get("mesh_scale", 1.0))
                geom = fcl.BVHModel()
                geom.beginModel(len(verts), len(tris))
                geom.addSubModel(verts, tris)
                geom.endModel()
                corners = verts
            else:
                size = np.asarray(s["box"], dtype=float)
                geom = fcl.Box(*size)
                corners = np.array([[i, j, k] for i in (-.5, .5) for j in (-.5, .5) for k in (-.5, .5)]) * size
            world = corners @ rot.T + xyz
            obj = fcl.CollisionObject(geom, fcl.Transform(rot, xyz))
            self.statics.append((s["name"], obj, world.min(axis=0), world.max(axis=0)))
        # Probe bodies (name, fcl geometry, bounding radius); placed by `set_angles`.
        p = scene["probe"]
        self.l1, self.l2 = float(p["l1"]), float(p["l2"])
        head_d, head_h = map(float, p["head"])
        ram_side, ram_h = map(float, p["ram"])
        self.head_h, self.ram_h = head_h, ram_h

        def cylinder(diameter, length):
            return fcl.Cylinder(diameter / 2, length), math.hypot(diameter / 2, length / 2)

        ball_r = float(p["ball_diameter"]) / 2
        self.bodies = [
            ("ball", fcl.Sphere(ball_r), ball_r),
            ("stem", *cylinder(float(p["stem_diameter"]), self.l2)),
            ("extension", *cylinder(float(p["extension_diameter"]), self.l1)),
            ("head", *cylinder(head_d, head_h)),
            ("ram", fcl.Box(ram_side, ram_side, ram_h), math.sqrt(2 * (ram_side / 2) ** 2 + (ram_h / 2) ** 2)),
        ]
        self.objects = [fcl.CollisionObject(g) for _, g, _ in self.bodies]

    def set_angles(self, a, b):
        """Fix the head angles: each body's offset from c and its rotation."""
        d = np.array([math.sin(a) * math.cos(b), math.sin(a) * math.sin(b), -math.cos(a)])
        reach = self.l1 + self.l2
        turn = arc_matrix(d)
        up = np.array([0.0, 0.0, 1.0])
        self.placing = [
            (d * reach, np.eye(3)),
            (d * (self.l1 + reach) / 2, turn),
            (d * self.l1 / 2, turn),
            (up * self.head_h / 2, np.eye(3)),
            (up * (self.head_h + self.ram_h / 2), np.eye(3)),
        ]

    def distance(self, c, cap, stop=-math.inf):
        """min(the distance from the probe at centre c to the statics, cap); returns as soon
        as a distance at or below `stop` is found."""
        best = cap
        c = np.asarray(c, dtype=float)
        for (_, _, radius), obj, (offset, rot) in zip(self.bodies, self.objects, self.placing):
            centre = c + offset
            placed = False
            for _, static, lo, hi in self.statics:
                if sphere_box_gap(centre, radius, lo, hi) >= best:
                    continue
                if not placed:
                    obj.setTransform(fcl.Transform(rot, centre))
                    placed = True
                best = min(best, fcl.distance(obj, static, fcl.DistanceRequest(), fcl.DistanceResult()))
                if best <= stop:
                    return best
        return best

    def valid(self, c):
        cap = self.clearance + 1e-3
        return self.distance(c, cap, stop=self.clearance) > self.clearance

    def path_margin(self, path, floor_step=1e-5, violation_step=1e-4):
        """The smallest (distance - clearance) found along the polyline `path`, by
        conservative advancement: the probe only translates, so the distance changes no faster
        than c moves, and a margin m > 0 at a point proves the next m of the segment clear.
        Steps are at least `floor_step`; where the margin is not positive, `violation_step`.
        fcl gives -1 for a contact (no depth), hence -1 - clearance for a path that hits."""
        worst = math.inf
        cap = self.clearance + 0.05
        for a, b in zip(path, path[1:]):
            a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
            length = float(np.linalg.norm(b - a))
            s = 0.0
            while True:
                m = self.distance(a + (b - a) * (s / length if length else 0.0), cap) - self.clearance
                worst = min(worst, m)
                if s >= length:
                    break
                s = min(length, s + (max(m, floor_step) if m > 0 else violation_step))
        return worst


# ---------------------------------------------------------------- OMPL


def plan(scene, problem, budget, args):
    """One RRT* run on `problem`; `budget` is ("iter", n) or ("time", seconds)."""
    lower, upper = problem["bounds"]["lower"], problem["bounds"]["upper"]
    space = ob.RealVectorStateSpace(3)
    bounds = ob.RealVectorBounds(3)
    for i in range(3):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    checks = [0]

    # (The checker must not hold `si` or `ss`: OMPL keeps the checker, and nanobind cannot
    # collect such a cycle; it would report it as a leak at exit.)
    def valid(state):
        checks[0] += 1
        c = (state[0], state[1], state[2])
        return all(lo <= x <= hi for lo, x, hi in zip(lower, c, upper)) and scene.valid(c)

    ss.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(args.resolution / si.getMaximumExtent())
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    planner = og.RRTstar(si)
    planner.setKNearest(False)
    if args.range:
        planner.setRange(args.range)
    ss.setPlanner(planner)
    start, goal = space.allocState(), space.allocState()
    for i in range(3):
        start[i] = float(problem["start"][i])
        goal[i] = float(problem["goal"][i])
    ss.setStartAndGoalStates(start, goal)
    ss.setup()
    checks[0] = 0
    kind, amount = budget
    t0 = time.perf_counter()
    if kind == "iter":
        status = ss.solve(ob.PlannerTerminationCondition(lambda: planner.numIterations() >= amount))
    else:
        status = ss.solve(float(amount))
    elapsed = time.perf_counter() - t0
    row = {"status": str(status), "solved": bool(ss.haveExactSolutionPath()), "time_s": elapsed,
           "iterations": planner.numIterations(), "range_m": planner.getRange(),
           "validity_checks": checks[0], "length_m": None, "margin_m": None,
           "simplified_length_m": None, "simplified_margin_m": None, "simplify_time_s": None,
           "path": None}
    if row["solved"]:
        path = [[s[i] for i in range(3)] for s in ss.getSolutionPath().getStates()]
        row.update(length_m=ss.getSolutionPath().length(), path=path, margin_m=scene.path_margin(path))
        t0 = time.perf_counter()
        ss.simplifySolution()
        row["simplify_time_s"] = time.perf_counter() - t0
        simple = [[s[i] for i in range(3)] for s in ss.getSolutionPath().getStates()]
        row.update(simplified_length_m=ss.getSolutionPath().length(),
                   simplified_margin_m=scene.path_margin(simple))
    return row


# ---------------------------------------------------------------- report


def mm(x):
    return "-" if x is None else f"{1000 * x:.1f}"


def table(rows):
    head = ["group", "mp", "straight", "line ok", "ours ok", "ours mm", "ours s",
            "iter ok", "iter n", "iter mm", "iter simpl mm", "iter s",
            "time ok", "time mm", "time simpl mm", "time s"]
    lines = [head]
    for r in rows:
        o, i, t = r["ours"], r["ompl_iter"], r["ompl_time"]
        ours_len = o.get("length_m") if o.get("solved") else None
        lines.append([
            str(r["group"]), r["mp"], "yes" if o.get("straight") else "no",
            "yes" if r["line_margin_m"] > 0 else "no",
            "yes" if o.get("solved") else "no", mm(ours_len),
            "-" if o.get("time_s") is None else f"{o['time_s']:.3f}",
            "yes" if i["solved"] else "no", str(i["iterations"]), mm(i["length_m"]),
            mm(i["simplified_length_m"]), f"{i['time_s']:.2f}",
            "yes" if t["solved"] else "no", mm(t["length_m"]), mm(t["simplified_length_m"]),
            f"{t['time_s']:.2f}",
        ])
    widths = [max(len(l[k]) for l in lines) for k in range(len(head))]
    for n, l in enumerate(lines):
        print("  ".join(s.rjust(w) for s, w in zip(l, widths)))
        if n == 0:
            print("  ".join("-" * w for w in widths))


def ratios(rows, variant, key):
    """ours / OMPL length over the problems both solved."""
    out = []
    for r in rows:
        o, p = r["ours"], r[variant]
        if o.get("solved") and o.get("length_m") and p[key]:
            out.append(o["length_m"] / p[key])
    return out


def summary(rows):
    n = len(rows)
    ours_solved = sum(1 for r in rows if r["ours"].get("solved"))
    known = [r["ours"]["time_s"] for r in rows if r["ours"].get("time_s") is not None]
    ours_time = sum(known) if known else None
    out = {"problems": n, "ours": {"solved": ours_solved, "total_time_s": ours_time}}
    for variant in ("ompl_iter", "ompl_time"):
        ps = [r[variant] for r in rows]
        s = {"solved": sum(p["solved"] for p in ps),
             "total_time_s": sum(p["time_s"] for p in ps),
             "total_simplify_time_s": sum(p["simplify_time_s"] or 0.0 for p in ps),
             "paths_within_clearance": sum(1 for p in ps if p["solved"] and p["margin_m"] <= 0),
             "simplified_within_clearance": sum(1 for p in ps if p["solved"] and p["simplified_margin_m"] <= 0)}
        for key, name in (("length_m", "raw"), ("simplified_length_m", "simplified")):
            rs = ratios(rows, variant, key)
            s[f"ratio_{name}"] = {"both_solved": len(rs),
                                  "median": statistics.median(rs) if rs else None,
                                  "mean": statistics.fmean(rs) if rs else None}
        out[variant] = s
    return out


def print_summary(s, args):
    def r(x):
        return "-" if x is None else f"{x:.3f}"

    t = s["ours"]["total_time_s"]
    print(f"\n{s['problems']} problems; ours solved {s['ours']['solved']}, "
          f"total {'-' if t is None else f'{t:.3f}'} s")
    for variant, label in (("ompl_iter", "OMPL RRT*, ours' samples as iterations"),
                           ("ompl_time", f"OMPL RRT*, {args.time:g} s each")):
        v = s[variant]
        print(f"{label}: solved {v['solved']}, total {v['total_time_s']:.2f} s "
              f"(+ {v['total_simplify_time_s']:.2f} s simplifying)")
        for name in ("raw", "simplified"):
            q = v[f"ratio_{name}"]
            print(f"  ours / OMPL {name:10s}: median {r(q['median'])}, mean {r(q['mean'])} "
                  f"over {q['both_solved']} both solved")
        print(f"  paths within the clearance (exact re-check): raw {v['paths_within_clearance']}, "
              f"simplified {v['simplified_within_clearance']}")


def main():
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("problems", help="local-problem JSON written by cellplan")
    ap.add_argument("--time", type=float, default=1.0, help="wall-clock budget of the timed run, s")
    ap.add_argument("--seed", type=int, default=1, help="OMPL's RNG seed (OMPL replaces 0 by 1)")
    ap.add_argument("--samples", type=int, default=8000,
                    help="iterations for a problem whose `ours.samples` is 0 or missing")
    ap.add_argument("--range", type=float, default=None, help="RRT* range, m (default: OMPL's)")
    ap.add_argument("--resolution", type=float, default=0.001, help="motion check step, m")
    ap.add_argument("--json", metavar="OUT", help="write settings, rows and summary here")
    args = ap.parse_args()

    ou.RNG.setSeed(args.seed)
    ou.setLogLevel(ou.LogLevel.LOG_WARN)
    doc = json.loads(Path(args.problems).read_text())
    scene = Scene(doc["scene"])
    rows = []
    for p in doc["problems"]:
        scene.set_angles(*p["angles"])
        ours = p.get("ours") or {}
        iterations = ours.get("samples") or args.samples
        row = {"group": p["group"], "mp": p["mp"], "angles": p["angles"], "ours": ours,
               "start_margin_m": scene.distance(p["start"], 1.0) - scene.clearance,
               "goal_margin_m": scene.distance(p["goal"], 1.0) - scene.clearance,
               "line_margin_m": scene.path_margin([p["start"], p["goal"]]),
               "ompl_iter": plan(scene, p, ("iter", iterations), args),
               "ompl_time": plan(scene, p, ("time", args.time), args)}
        rows.append(row)
        print(f"{p['group']}/{p['mp']}: iter {row['ompl_iter']['status']} "
              f"{row['ompl_iter']['time_s']:.2f} s, time {row['ompl_time']['status']}", file=sys.stderr)
    print(f"{doc.get('cell', '?')}: {len(rows)} local problems, clearance {mm(scene.clearance)} mm, "
          f"lengths in mm, 'line ok' = the straight segment keeps the clearance in this model")
    table(rows)
    s = summary(rows)
    print_summary(s, args)
    if args.json:
        settings = {k: getattr(args, k) for k in ("problems", "time", "seed", "samples", "range", "resolution")}
        Path(args.json).write_text(json.dumps({"settings": settings, "rows": rows, "summary": s}, indent=1))


if __name__ == "__main__":
    main()
