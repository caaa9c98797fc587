#!/usr/bin/env python3
"""Cross-check motionlib's exact model against VAMP's UR5 model on the MBM problems: forward
kinematics, validity of every start and goal, and agreement on random configurations.

    bench/peers/.venv/bin/python bench/motion/crosscheck_vamp.py bench/motion/mbm-ur5/*.json
        [--problems 20] [--samples 400] [--seed 0]

Needs vamp-planner (bench/peers/vamp_offline/build.sh). Prints, per scene: starts/goals in contact
on the meshes and invalid for VAMP; on uniformly random configurations (in [-pi, pi]^6) that
VAMP's self-collision model accepts, how often the two agree on obstacle contact, and the depth
(deepest surface sample, mm) of the mesh contacts VAMP misses. Then the FK difference and, in an
empty scene, the share of random configurations each model rejects (self-collision).
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "peers"))
import motionlib  # noqa: E402
from motion_vamp import problem_to_vamp  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--problems", type=int, default=20, help="problems per scene for random samples")
    ap.add_argument("--samples", type=int, default=400, help="random configurations per problem")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    import vamp

    vmod = vamp.ur5
    rng = np.random.default_rng(a.seed)
    empty = vamp.Environment()
    robot = None
    for f in a.files:
        doc = motionlib.load_problems(f)
        if robot is None:
            robot = motionlib.Robot(doc["urdf_path"], doc["srdf_path"], doc["joints"], doc["base_tf"])
        mesh_bad = vamp_bad = 0
        agree = total = 0
        missed, extra = [], 0
        for k, p in enumerate(doc["problems"]):
            model = motionlib.CollisionModel(robot, p["obstacles"])
            env = problem_to_vamp(vamp, doc["scene"], p["obstacles"])
            ends = [p["start"]] + p["goals"]
            mesh_bad += any(model.check_batch(np.array(ends), with_depth=False))
            vamp_bad += not all(vmod.validate(q, env) for q in ends)
            if k >= a.problems:
                continue
            qs = rng.uniform(-np.pi, np.pi, (a.samples, len(doc["joints"])))
            qs = np.array([q for q in qs if vmod.validate(q, empty)])
            for q, contacts in zip(qs, model.check_batch(qs)):
                env_contacts = [c for c in contacts if c[0] == "env"]
                m, v = bool(env_contacts), not vmod.validate(q, env)
                total += 1
                agree += m == v
                if m and not v:
                    missed.append(max(c[4] for c in env_contacts) * 1000)
                extra += v and not m
        missed.sort()
        print(f"{doc['scene']}: starts/goals in contact on the meshes {mesh_bad}/{len(doc['problems'])}, "
              f"invalid for VAMP {vamp_bad}; random: agree {agree}/{total} ({100 * agree / max(total, 1):.2f} %), "
              f"VAMP misses {len(missed)} (depth mm: median {np.median(missed) if missed else 0:.1f}, "
              f"max {missed[-1] if missed else 0:.1f}), VAMP-only contacts {extra}")
    qs = rng.uniform(-np.pi, np.pi, (2000, 6))
    fk = robot.fk(qs)
    err = max(float(np.linalg.norm(np.asarray(vmod.eefk(q))[:3, 3] - fk[vmod.end_effector()][i][:3, 3]))
              for i, q in enumerate(qs[:200]))
    model = motionlib.CollisionModel(robot, [])
    mesh = sum(bool(c) for c in model.check_batch(qs, with_depth=False))
    vam = sum(not vmod.validate(q, empty) for q in qs)
    print(f"FK: largest end-effector position difference to VAMP's eefk over 200 configurations "
          f"{err * 1000:.3f} mm; empty scene, 2000 random configurations: meshes+SRDF reject {mesh}, "
          f"VAMP rejects {vam}")


if __name__ == "__main__":
    main()
