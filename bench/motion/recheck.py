#!/usr/bin/env python3
"""Independent exact re-check of joint paths against cellplan motion problems.

Each path (a list of configurations, joined by straight joint-space segments) is sampled so that
between consecutive samples no joint moves more than --max-joint-step (0.005 rad) and no vertex of
the robot's collision geometry moves more than --max-vertex-step (1 mm): per segment the step
count is max(max|dq| / 0.005, sum_j |dq_j| R_j / 0.001), with R_j a bound on the distance of any
collision vertex downstream of joint j from its axis (motionlib.Robot._bounds). At every sample
the URDF collision meshes (exact triangles, placed by forward kinematics from the URDF) are tested
with python-fcl against the problem's primitives and against the other links (pairs disabled by
the SRDF and parent-child pairs excluded). Nothing of the planner's own model is used.

A path is valid iff no sample has a contact, it starts at the problem's start and ends at one of
its goals (within --endpoint-tol rad, default 1e-4: VAMP returns float32). Per path: the first
contact (path parameter as a fraction of the joint-space length, segment index, links/obstacle),
the number of colliding samples, and the largest penetration over the path:
depth_m = the deepest surface sample (mesh vertices, edge midpoints, face centroids) of a link
inside an obstacle, a lower bound on how far the surface enters it; fcl_depth_m = FCL's largest
contact penetration_depth (per triangle, EPA; for self-contacts the only measure).

Usage: recheck.py SCENE_JSON... PATHS_JSON [--json] [--max-joint-step R] [--max-vertex-step M]
PATHS_JSON: the output of bench/peers/motion_vamp.py / motion_ompl.py --json (a list of objects
with "problem" and "path"), or one such object per line.
"""
import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import motionlib  # noqa: E402


def read_paths(path):
    text = Path(path).read_text()
    try:
        data = json.loads(text)
        return data if isinstance(data, list) else [data]
    except json.JSONDecodeError:
        return [json.loads(l) for l in text.splitlines() if l.strip().startswith("{")]


def recheck_path(robot, problem, path, max_joint_step, max_vertex_step, endpoint_tol, chunk=4000):
    q = np.asarray(path, dtype=float)
    out = {"problem": problem["name"], "exact_valid": None, "samples": 0,
           "start_ok": bool(np.abs(q[0] - problem["start"]).max() <= endpoint_tol),
           "goal_ok": bool(min(np.abs(q[-1] - np.asarray(g)).max() for g in problem["goals"]) <= endpoint_tol),
           "colliding_samples": 0, "first_contact": None, "depth_m": 0.0, "fcl_depth_m": 0.0}
    model = motionlib.CollisionModel(robot, problem["obstacles"], problem.get("margin", 0.0))
    qs, ts = motionlib.densify(robot, q, max_joint_step=max_joint_step, max_vertex_step=max_vertex_step)
    out["samples"] = len(qs)
    seg = np.linalg.norm(np.diff(q, axis=0), axis=1) if len(q) > 1 else np.zeros(0)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = cum[-1] if cum[-1] > 0 else 1.0
    for c0 in range(0, len(qs), chunk):
        res = model.check_batch(qs[c0:c0 + chunk])
        for k, contacts in enumerate(res):
            if not contacts:
                continue
            i = c0 + k
            out["colliding_samples"] += 1
            for kind, a, b, fd, vd in contacts:
                out["fcl_depth_m"] = max(out["fcl_depth_m"], fd or 0.0)
                out["depth_m"] = max(out["depth_m"], vd or 0.0)
            if out["first_contact"] is None:
                s = int(min(ts[i], len(seg) - 1)) if len(seg) else 0
                frac = ts[i] - s if len(seg) else 0.0
                at = (cum[s] + frac * seg[s]) / total if len(seg) else 0.0
                out["first_contact"] = {
                    "s": float(at), "segment": s, "sample": int(i),
                    "contacts": [{"kind": kind, "link": a, "with": b,
                                  "depth_m": vd, "fcl_depth_m": fd} for kind, a, b, fd, vd in contacts],
                }
    out["exact_valid"] = out["colliding_samples"] == 0 and out["start_ok"] and out["goal_ok"]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+", help="SCENE_JSON... PATHS_JSON")
    ap.add_argument("--max-joint-step", type=float, default=0.005)
    ap.add_argument("--max-vertex-step", type=float, default=0.001)
    ap.add_argument("--endpoint-tol", type=float, default=1e-4)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    if len(a.files) < 2:
        ap.error("need SCENE_JSON... PATHS_JSON")
    problems, robots = {}, {}
    for f in a.files[:-1]:
        doc = motionlib.load_problems(f)
        key = (str(doc["urdf_path"]), str(doc["srdf_path"]), tuple(doc["joints"]))
        if key not in robots:
            robots[key] = motionlib.Robot(doc["urdf_path"], doc["srdf_path"], doc["joints"], doc["base_tf"])
        for p in doc["problems"]:
            problems[p["name"]] = (robots[key], p)
    rows = []
    t0 = time.time()
    for r in read_paths(a.files[-1]):
        if not r.get("path"):
            continue
        if r["problem"] not in problems:
            continue
        robot, p = problems[r["problem"]]
        out = recheck_path(robot, p, r["path"], a.max_joint_step, a.max_vertex_step, a.endpoint_tol)
        out["planner"] = r.get("planner")
        rows.append(out)
        if not a.json:
            fc = out["first_contact"]
            where = ""
            if fc:
                c = fc["contacts"][0]
                where = (f" first contact at s={fc['s']:.3f} ({c['link']} / {c['with']}), "
                         f"{out['colliding_samples']} colliding samples, depth {out['depth_m'] * 1000:.1f} mm "
                         f"(FCL {out['fcl_depth_m'] * 1000:.1f} mm)")
            ends = "" if out["start_ok"] and out["goal_ok"] else f" start_ok={out['start_ok']} goal_ok={out['goal_ok']}"
            print(f"{out['problem']}: {'valid' if out['exact_valid'] else 'INVALID'} "
                  f"({out['samples']} samples){where}{ends}")
    if a.json:
        print(json.dumps(rows))
    bad = [r for r in rows if not r["exact_valid"]]
    coll = [r for r in rows if r["colliding_samples"]]
    msg = f"{len(rows)} paths re-checked in {time.time() - t0:.0f} s: {len(bad)} invalid, {len(coll)} with contacts"
    if coll:
        d = sorted(r["depth_m"] * 1000 for r in coll)
        fd = sorted(r["fcl_depth_m"] * 1000 for r in coll)
        self_only = sum(all(c["kind"] == "self" for c in r["first_contact"]["contacts"]) for r in coll)
        msg += (f" ({self_only} first touching itself); depth median {statistics.median(d):.1f} mm, "
                f"max {d[-1]:.1f} mm; FCL depth median {statistics.median(fd):.1f} mm, max {fd[-1]:.1f} mm")
    print(msg, file=sys.stderr if a.json else sys.stdout)


if __name__ == "__main__":
    main()
