#!/usr/bin/env python3
"""Extract the MotionBenchMaker (MBM) UR5 problems from vamp-planner's PyPI source package
into cellplan's motion-problem format (bench/motion/README.md): one JSON file per scene, and
the robot model the problems use (URDF, SRDF, collision and visual meshes).

    python3 bench/motion/extract_mbm.py [--sdist vamp_planner-0.6.4.tar.gz] [--out DIR]

Without --sdist, `pip download --no-deps --no-binary vamp-planner vamp-planner==0.6.4` fetches
the source package (65 MB) into a temporary folder. Needs PyYAML (bench/peers/requirements.txt).

Source data: resources/ur5/problems.tar.bz2 inside the sdist holds problems/<scene>_ur5/
sceneNNNN.yaml (a MoveIt PlanningScene: world.collision_objects with one primitive each) and
requestNNNN.yaml (a MoveIt MotionPlanRequest: start_state.joint_state, one goal with a joint
constraint per arm joint). Conversion, as VAMP's resources/problem_tar_to_pkl_json.py reads the
same files:
  - quaternions in the YAML are [x, y, z, w] (robowflex's YAML encoding);
  - an object's world pose = its `pose` (if present) composed with primitive_poses[0];
  - box `dimensions` are full sizes -> half_extents = dimensions / 2;
  - cylinder `dimensions` are [height, radius] (MoveIt SolidPrimitive), axis = the primitive's
    local z, centred on the pose -> "length" = height;
  - sphere `dimensions` are [radius].
Every value is copied at full double precision; nothing is rounded, filtered or reordered
(problems are sorted by their index 1..100).
"""

import argparse
import hashlib
import io
import json
import math
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
from collections import Counter
from pathlib import Path

import yaml

try:
    from yaml import CSafeLoader as Loader
except ImportError:  # pragma: no cover
    from yaml import SafeLoader as Loader

VAMP_VERSION = "0.6.4"
SCENES = [
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "box",
    "cage",
    "table_pick",
    "table_under_pick",
]
# Arm joints in the order of the URDF chain (the problems' joint order).
JOINTS = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
# The robot model files the URDF references (everything else in resources/ur5 is left out:
# ur5_spherized.urdf is VAMP's sphere model, the *_coarse.STL gripper meshes are unused).
ROBOT_FILES = [
    "ur5.urdf",
    "ur5.srdf",
    "meshes/robotiq_fts300.stl",
    "meshes/ur5/collision/base.stl",
    "meshes/ur5/collision/shoulder.stl",
    "meshes/ur5/collision/upperarm.stl",
    "meshes/ur5/collision/forearm.stl",
    "meshes/ur5/collision/wrist1.stl",
    "meshes/ur5/collision/wrist2.stl",
    "meshes/ur5/collision/wrist3.stl",
    "meshes/ur5/visual/base.dae",
    "meshes/ur5/visual/shoulder.dae",
    "meshes/ur5/visual/upperarm.dae",
    "meshes/ur5/visual/forearm.dae",
    "meshes/ur5/visual/wrist1.dae",
    "meshes/ur5/visual/wrist2.dae",
    "meshes/ur5/visual/wrist3.dae",
    "meshes/robotiq/robotiq_85_base_link_fine.STL",
    "meshes/robotiq/outer_knuckle_fine.STL",
    "meshes/robotiq/outer_finger_fine.STL",
    "meshes/robotiq/inner_knuckle_fine.STL",
    "meshes/robotiq/inner_finger_fine.STL",
]


def quat_mul(a, b):
    """Hamilton product of two [x, y, z, w] quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


def quat_rotate(q, v):
    x, y, z, w = q
    # v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx = y * v[2] - z * v[1]
    cy = z * v[0] - x * v[2]
    cz = x * v[1] - y * v[0]
    ccx = y * cz - z * cy
    ccy = z * cx - x * cz
    ccz = x * cy - y * cx
    return [v[0] + 2 * (w * cx + ccx), v[1] + 2 * (w * cy + ccy), v[2] + 2 * (w * cz + ccz)]


def normalised(q):
    n = math.sqrt(sum(c * c for c in q))
    if abs(n - 1.0) > 1e-6:
        raise ValueError(f"quaternion {q} has norm {n}")
    return [c / n for c in q]


def yaml_pose(p):
    return [float(c) for c in p["position"]], normalised([float(c) for c in p["orientation"]])


def convert_object(co):
    if len(co.get("primitives", [])) != 1 or len(co.get("primitive_poses", [])) != 1:
        raise ValueError(f"object {co.get('id')}: expected exactly one primitive")
    if co.get("meshes") or co.get("planes"):
        raise ValueError(f"object {co.get('id')}: meshes/planes are not handled")
    xyz, q = yaml_pose(co["primitive_poses"][0])
    if "pose" in co:
        bxyz, bq = yaml_pose(co["pose"])
        r = quat_rotate(bq, xyz)
        xyz = [bxyz[i] + r[i] for i in range(3)]
        q = normalised(quat_mul(bq, q))
    prim = co["primitives"][0]
    dims = [float(d) for d in prim["dimensions"]]
    kind = prim["type"]
    obj = {"name": co["id"], "shape": kind}
    if kind == "box":
        obj["half_extents"] = [d / 2 for d in dims]
    elif kind == "cylinder":
        obj["radius"] = dims[1]
        obj["length"] = dims[0]
    elif kind == "sphere":
        obj["radius"] = dims[0]
    else:
        raise ValueError(f"object {co['id']}: primitive type {kind}")
    obj["pose"] = {"xyz": xyz, "quat_xyzw": q}
    return obj


def convert_request(r):
    js = r["start_state"]["joint_state"]
    names = js["name"]
    start = [float(js["position"][names.index(j)]) for j in JOINTS]
    # The gripper joints are `fixed` in this URDF; the requests give them all 0 (checked).
    extra = [float(js["position"][i]) for i, n in enumerate(names) if n not in JOINTS]
    if any(v != 0.0 for v in extra):
        raise ValueError(f"start state has non-zero gripper joints {extra}")
    if len(r["goal_constraints"]) != 1:
        raise ValueError("expected one goal constraint set")
    cons = {c["joint_name"]: c for c in r["goal_constraints"][0]["joint_constraints"]}
    if sorted(cons) != sorted(JOINTS):
        raise ValueError(f"goal constrains {sorted(cons)}")
    goal = [float(cons[j]["position"]) for j in JOINTS]
    return start, goal


def srdf_pairs(text):
    return {
        tuple(sorted(m))
        for m in re.findall(r'<disable_collisions\s+link1="([^"]+)"\s+link2="([^"]+)"', text)
    }


def acm_pairs(acm):
    n, v = acm["entry_names"], acm["entry_values"]
    return {
        tuple(sorted((n[i], n[j])))
        for i in range(len(n))
        for j in range(i + 1, len(n))
        if v[i][j]
    }


def fetch_sdist(dest):
    subprocess.run(
        [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", "vamp-planner",
         f"vamp-planner=={VAMP_VERSION}", "-d", str(dest)],
        check=True,
    )
    found = sorted(Path(dest).glob("vamp*planner-*.tar.gz"))
    if not found:
        raise SystemExit("pip download produced no vamp-planner sdist")
    return found[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sdist", type=Path, help="vamp_planner-X.tar.gz (else pip download)")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "mbm-ur5")
    ap.add_argument("--no-robot", action="store_true", help="write the problems only")
    args = ap.parse_args()

    tmp = None
    sdist = args.sdist
    if sdist is None:
        tmp = tempfile.TemporaryDirectory()
        sdist = fetch_sdist(tmp.name)
    sha = hashlib.sha256(sdist.read_bytes()).hexdigest()

    with tarfile.open(sdist, "r:gz") as outer:
        root = outer.getnames()[0].split("/")[0]
        version = root.rsplit("-", 1)[-1]

        def member(rel):
            f = outer.extractfile(f"{root}/{rel}")
            if f is None:
                raise SystemExit(f"{rel} missing in {sdist}")
            return f.read()

        problems_tar = member("resources/ur5/problems.tar.bz2")
        robot_files = {} if args.no_robot else {rel: member(f"resources/ur5/{rel}") for rel in ROBOT_FILES}
        licence = member("LICENSE.txt")

    srdf = srdf_pairs(member_text(robot_files, "ur5.srdf")) if robot_files else None

    scenes, requests = {}, {}
    acms = Counter()
    with tarfile.open(fileobj=io.BytesIO(problems_tar), mode="r:bz2") as tar:
        for m in tar.getmembers():
            if not m.isfile():
                continue
            _, folder, filename = m.name.split("/")
            scene = folder.removesuffix("_ur5")
            index = int(re.findall(r"\d+", filename)[0])
            data = yaml.load(tar.extractfile(m).read(), Loader=Loader)
            if filename.startswith("scene"):
                acms[frozenset(acm_pairs(data["allowed_collision_matrix"]))] += 1
                objs = [convert_object(co) for co in data["world"]["collision_objects"]]
                scenes.setdefault(scene, {})[index] = objs
            elif filename.startswith("request"):
                requests.setdefault(scene, {})[index] = convert_request(data)
            else:
                raise SystemExit(f"unexpected file {m.name}")

    if sorted(scenes) != SCENES or sorted(requests) != SCENES:
        raise SystemExit(f"scenes {sorted(scenes)} / {sorted(requests)} differ from {SCENES}")

    args.out.mkdir(parents=True, exist_ok=True)
    source = (
        f"MotionBenchMaker UR5 problems from vamp-planner {version} (PyPI source package "
        f"{sdist.name}, sha256 {sha}), resources/ur5/problems.tar.bz2: "
        "problems/<scene>_ur5/sceneNNNN.yaml + requestNNNN.yaml; converted by "
        "bench/motion/extract_mbm.py"
    )
    counts = {}
    for scene in SCENES:
        if sorted(scenes[scene]) != sorted(requests[scene]):
            raise SystemExit(f"{scene}: scene and request indices differ")
        problems = []
        for index in sorted(scenes[scene]):
            start, goal = requests[scene][index]
            problems.append({
                "name": f"{scene}/{index:04d}",
                "start": start,
                "goals": [goal],
                "margin": 0.0,
                "obstacles": scenes[scene][index],
            })
        doc = {
            "format": "cellplan-motion-problems",
            "version": 1,
            "scene": scene,
            "source": source,
            "robot": {
                "urdf": "ur5/ur5.urdf",
                "srdf": "ur5/ur5.srdf",
                "base": {"xyz": [0.0, 0.0, 0.0], "rpy": [0.0, 0.0, 0.0]},
            },
            "joints": JOINTS,
            "problems": problems,
        }
        write_json(args.out / f"{scene}.json", doc)
        shapes = Counter(o["shape"] for p in problems for o in p["obstacles"])
        counts[scene] = (len(problems), dict(shapes))
        print(f"{scene}: {len(problems)} problems, obstacles {dict(sorted(shapes.items()))}")

    if robot_files:
        for rel, data in robot_files.items():
            if rel == "ur5.urdf":
                # The only change: mesh filenames made relative to the URDF's folder
                # ("package://meshes/..." -> "meshes/..."); see ur5/SOURCE.md.
                data = data.replace(b'filename="package://meshes/', b'filename="meshes/')
            path = args.out / "ur5" / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        (args.out / "ur5" / "LICENSE-vamp.txt").write_bytes(licence)
        print(f"robot model: {len(robot_files)} files -> {args.out / 'ur5'}")

    # The scenes' MoveIt allowed-collision matrices against the SRDF.
    for pairs, n in acms.items():
        msg = f"{n} scenes share one allowed-collision matrix of {len(pairs)} pairs"
        if srdf is not None:
            msg += f"; not in the SRDF: {sorted(pairs - srdf)}; SRDF pairs not in it: {sorted(srdf - pairs)}"
        print(msg)
    if tmp is not None:
        tmp.cleanup()


def member_text(files, rel):
    return files[rel].decode("utf-8")


def write_json(path, doc):
    """Indented, one obstacle per line, floats at full precision (repr)."""
    out = ["{"]
    head = {k: v for k, v in doc.items() if k != "problems"}
    for k, v in head.items():
        out.append(f"  {json.dumps(k)}: {json.dumps(v)},")
    out.append('  "problems": [')
    for i, p in enumerate(doc["problems"]):
        out.append("    {")
        for k in ("name", "start", "goals", "margin"):
            out.append(f"      {json.dumps(k)}: {json.dumps(p[k])},")
        out.append('      "obstacles": [')
        obs = [f"        {json.dumps(o)}" for o in p["obstacles"]]
        out.append(",\n".join(obs))
        out.append("      ]")
        out.append("    }" + ("," if i + 1 < len(doc["problems"]) else ""))
    out.append("  ]")
    out.append("}")
    text = "\n".join(out) + "\n"
    json.loads(text)  # must round-trip
    path.write_text(text)


if __name__ == "__main__":
    main()
