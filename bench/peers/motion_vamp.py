#!/usr/bin/env python3
"""Run VAMP (vamp-planner, UR5 module) on cellplan motion-problem files (bench/motion/README.md).

Each problem's obstacles go to VAMP exactly as VAMP's own MBM benchmark passes them
(vamp.problem_dict_to_vamp): boxes as cuboids, cylinders as capsules that contain them, except in
the `box` scene where cylinders become cuboids (VAMP's own special case, for top-down grasps of
the can), orientations as static-xyz Euler angles of the pose. The robot is VAMP's compiled UR5
sphere model (ur5_spherized.urdf), not the meshes. As VAMP's evaluate_mbm.py does, a problem whose
start or goal VAMP itself reports invalid is not planned (status invalid_start/invalid_goal), the
Halton sampler is reset before each problem, and settings are VAMP's defaults for the UR5
(RRT-Connect range 1.5, dynamic domain on, 1,000,000 iterations at most).

time_s is wall-clock time measured around the solve call (and, with --simplify, the simplify call
as well); vamp_time_s is VAMP's own nanoseconds. VAMP does not count validity checks
(validity_checks is null); `iterations` and `tree_sizes` are its own counters.

Usage: motion_vamp.py SCENE_JSON... [--planner rrtc] [--simplify] [--first N] [--json]
"""
import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "motion"))
import motionlib  # noqa: E402


def problem_to_vamp(vamp, scene, obstacles):
    """The problem dict vamp.problem_dict_to_vamp reads (as resources/problem_tar_to_pkl_json.py
    writes it), built from cellplan's obstacle list."""
    from vamp import transformations as vt

    d = {"problem": scene, "sphere": [], "cylinder": [], "box": []}
    for o in obstacles:
        m = vt.quaternion_matrix(o["pose"]["quat_xyzw"])  # vamp.transformations: [x, y, z, w]
        m[:3, 3] = o["pose"]["xyz"]
        common = {
            "name": o["name"],
            "position": list(o["pose"]["xyz"]),
            "orientation_euler_xyz": list(vt.euler_from_matrix(m)),
        }
        if o["shape"] == "box":
            d["box"].append({**common, "half_extents": list(o["half_extents"])})
        elif o["shape"] == "cylinder":
            d["cylinder"].append({**common, "radius": o["radius"], "length": o["length"]})
        elif o["shape"] == "sphere":
            d["sphere"].append({**common, "radius": o["radius"]})
        else:
            raise ValueError(o["shape"])
    return vamp.problem_dict_to_vamp(d)


def summarise(rows, out):
    by_scene = {}
    for r in rows:
        by_scene.setdefault(r["problem"].split("/")[0], []).append(r)
    for scene, rs in by_scene.items():
        solved = [r for r in rs if r["solved"]]
        planned = [r for r in rs if r["status"] not in ("invalid_start", "invalid_goal")]
        med = statistics.median(r["time_s"] for r in solved) if solved else float("nan")
        print(f"{scene}: solved {len(solved)}/{len(rs)} ({len(planned)} planned), "
              f"median time {med * 1e6:.0f} us", file=out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--planner", default="rrtc", help="VAMP planner: rrtc, prm, fcit, aorrtc")
    ap.add_argument("--simplify", action="store_true", help="run VAMP's path simplification too")
    ap.add_argument("--first", type=int, default=None, help="only the first N problems per file")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    import vamp

    robot = "ur5"
    vmod, planner_func, plan_settings, simp_settings = vamp.configure_robot_and_planner_with_kwargs(
        robot, a.planner)
    sampler = vmod.halton()
    name = f"vamp-{a.planner}" + ("+simplify" if a.simplify else "")
    rows = []
    for path in a.files:
        doc = motionlib.load_problems(path)
        if list(doc["joints"]) != list(vmod.joint_names()):
            raise SystemExit(f"{path}: joints {doc['joints']} are not VAMP's UR5 joints")
        for p in doc["problems"][: a.first]:
            env = problem_to_vamp(vamp, doc["scene"], p["obstacles"])
            row = {"problem": p["name"], "planner": name, "solved": False, "status": None,
                   "time_s": None, "vamp_time_s": None, "path_length": None,
                   "validity_checks": None, "iterations": None, "tree_sizes": None, "path": None}
            if not vmod.validate(p["start"], env):
                row["status"] = "invalid_start"
            elif not any(vmod.validate(g, env) for g in p["goals"]):
                row["status"] = "invalid_goal"
            else:
                goals = [g for g in p["goals"] if vmod.validate(g, env)]
                sampler.reset()
                t0 = time.perf_counter()
                res = planner_func(p["start"], goals, env, plan_settings, sampler)
                ns = res.nanoseconds
                out = res
                if a.simplify and res.solved:
                    out = vmod.simplify(res.path, env, simp_settings, sampler)
                    ns += out.nanoseconds
                dt = time.perf_counter() - t0
                row.update(time_s=dt, vamp_time_s=ns * 1e-9, iterations=res.iterations,
                           tree_sizes=list(res.size))
                if res.solved:
                    q = [[float(x) for x in s] for s in out.path.numpy()]
                    row.update(solved=True, status="solved", path=q,
                               path_length=motionlib.path_length(q))
                else:
                    row["status"] = "failed"
            rows.append(row)
            if not a.json:
                t = f"{row['time_s'] * 1e6:.0f} us" if row["time_s"] is not None else "-"
                pl = f"{row['path_length']:.3f}" if row["path_length"] is not None else "-"
                print(f"{p['name']}: {row['status']} {t} length {pl}")
    if a.json:
        print(json.dumps(rows))
    summarise(rows, sys.stderr if a.json else sys.stdout)


if __name__ == "__main__":
    main()
