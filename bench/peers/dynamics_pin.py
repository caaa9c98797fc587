#!/usr/bin/env python3
"""Reference inverse dynamics from Pinocchio (PyPI `pin`) on a URDF serial chain.

For a URDF and a tip link, builds the Pinocchio model of the chain from the URDF's root link to
the tip (`pin.buildModelFromXML` on the URDF text, fixed base: the root link is welded to
Pinocchio's "universe", no root joint), draws N random states and writes, per state, the joint
torques tau = rnea(q, v, a), the gravity torques g = computeGeneralizedGravity(q) and the joint
space inertia matrix M = crba(q) (Pinocchio fills the upper triangle; it is mirrored here).
cellplan's own recursive Newton-Euler implementation is checked against these files.

The model:
- Pinocchio's URDF parser merges every link attached by a fixed joint into the body of its
  nearest movable ancestor joint (mass, centre of mass and inertia added, "lumped"); links fixed
  to the root link go into the universe (joint 0), which a fixed-base rnea never moves, so their
  mass and the root link's own mass are reported (`universe_mass`) but do not enter tau, g or M.
- Joints: the movable joints on the path root -> tip, in that order. Anything Pinocchio would
  otherwise add beyond them (a movable joint off the path or past the tip, with its subtree) is
  cut out of the URDF text before building, and listed in `pruned_links`; fixed-joint subtrees
  (flange, tool0, base, ...) are kept, so they are lumped the way Pinocchio does by default.
  The script refuses joints whose nq != nv (continuous, floating, planar) and mimic joints.
- Gravity (0, 0, -9.81) m/s^2 in the root link's frame.

The states (numpy default_rng(seed); three draws of shape (N, n), in this order): q uniform in
[lower, upper] of each joint's URDF limit, v uniform in +-(URDF velocity limit) (+-3 rad/s where
a joint has none or 0), a uniform in +-10 rad/s^2.

Timing: `rnea_us` is the median over `--time-reps` batches of the mean time of one `pin.rnea`
call in a Python loop over the states (so it includes the Python -> C++ call and the numpy
argument conversion, which for a 6-joint arm is most of it); `rnea_loop_overhead_us` is the same
loop calling a trivial Python function with the same arguments, for scale.

Usage: dynamics_pin.py URDF --robot NAME --out FILE [--tip tool0] [--n 1000] [--seed 0]
       [--full-gM N] [--time-reps 200]
"""
import argparse
import json
import math
import os
import statistics
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
GRAVITY = [0.0, 0.0, -9.81]
DEFAULT_VMAX = 3.0
AMAX = 10.0
MOVABLE = ("revolute", "prismatic", "continuous", "floating", "planar")


def chain_of(root_xml, tip):
    """The URDF tree: (root link, joints by child link, joints by parent link, path of joint elements root->tip)."""
    links = [l.get("name") for l in root_xml.findall("link")]
    joints = root_xml.findall("joint")
    by_child = {j.find("child").get("link"): j for j in joints}
    by_parent = {}
    for j in joints:
        by_parent.setdefault(j.find("parent").get("link"), []).append(j)
    roots = [l for l in links if l not in by_child]
    if len(roots) != 1:
        sys.exit(f"URDF has {len(roots)} root links: {roots}")
    if tip not in links:
        sys.exit(f"tip link '{tip}' is not in the URDF")
    path = []
    link = tip
    while link in by_child:
        j = by_child[link]
        path.append(j)
        link = j.find("parent").get("link")
    path.reverse()
    return roots[0], by_child, by_parent, path


def prune(root_xml, tip):
    """Cut every movable joint not on root->tip (and its subtree) out of the URDF; returns
    (root link, path joints, names of the links removed)."""
    root, by_child, by_parent, path = chain_of(root_xml, tip)
    on_path = {j.get("name") for j in path}
    removed_links = []

    def drop_subtree(link):
        removed_links.append(link)
        for j in by_parent.get(link, []):
            drop_subtree(j.find("child").get("link"))
            root_xml.remove(j)
        for l in root_xml.findall("link"):
            if l.get("name") == link:
                root_xml.remove(l)

    for j in list(root_xml.findall("joint")):
        if j.get("name") in on_path or j.get("type") not in MOVABLE:
            continue
        if j not in list(root_xml.findall("joint")):
            continue  # already removed with an ancestor
        drop_subtree(j.find("child").get("link"))
        root_xml.remove(j)
    return root, path, removed_links


def inertial_checks(root_xml):
    """Per URDF link: mass, whether <inertial> is there, and doubts (no <inertial> on a link with
    geometry, zero mass, inertia not positive definite, principal moments violating the triangle
    inequality)."""
    out = {}
    for l in root_xml.findall("link"):
        name = l.get("name")
        inr = l.find("inertial")
        if inr is None:
            # a bare frame (no geometry) without mass is normal (flange, tool0, base)
            geom = l.find("visual") is not None or l.find("collision") is not None
            out[name] = {"inertial": False, "mass": 0.0,
                         "doubts": ["no <inertial> on a link with geometry"] if geom else []}
            continue
        m = float(inr.find("mass").get("value"))
        e = inr.find("inertia")
        g = lambda k: float(e.get(k, "0"))
        I = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")], [g("ixz"), g("iyz"), g("izz")]])
        ev = np.linalg.eigvalsh(I)
        doubts = []
        if m <= 0:
            doubts.append(f"mass {m}")
        if ev[0] <= 0:
            doubts.append(f"inertia not positive definite (eigenvalues {ev.tolist()})")
        a, b, c = ev
        if a + b < c * (1 - 1e-9):
            doubts.append(f"principal moments {ev.tolist()} violate the triangle inequality")
        out[name] = {"inertial": True, "mass": m, "principal_moments": ev.tolist(), "doubts": doubts}
    return out


def se3(M):
    return {"rotation": M.rotation.tolist(), "translation": M.translation.tolist()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("urdf")
    ap.add_argument("--robot", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--tip", default="tool0")
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--full-gM", type=int, default=None,
                    help="store g and M for the first N states only (default: all)")
    ap.add_argument("--time-reps", type=int, default=200)
    args = ap.parse_args()

    urdf_abs = os.path.abspath(args.urdf)
    tree = ET.parse(urdf_abs)
    robot_xml = tree.getroot()
    link_checks = inertial_checks(robot_xml)
    root_link, path, pruned = prune(robot_xml, args.tip)
    chain_joints = [j for j in path if j.get("type") in MOVABLE]
    for j in chain_joints:
        if j.find("mimic") is not None:
            sys.exit(f"joint {j.get('name')} is a mimic joint: not supported")

    model = pin.buildModelFromXML(ET.tostring(robot_xml, encoding="unicode"))
    model.gravity = pin.Motion(np.array(GRAVITY), np.zeros(3))
    data = model.createData()
    names = list(model.names)[1:]
    want = [j.get("name") for j in chain_joints]
    if names != want:
        sys.exit(f"Pinocchio's joints {names} are not the chain's movable joints {want}")
    if model.nq != model.nv or model.nv != len(names):
        sys.exit(f"nq={model.nq}, nv={model.nv}, joints={len(names)}: only 1-dof joints supported")
    n = model.nv

    lo, hi, vmax, vsrc = [], [], [], []
    for j in chain_joints:
        lim = j.find("limit")
        if lim is None or j.get("type") == "continuous":
            sys.exit(f"joint {j.get('name')} has no position limits")
        lo.append(float(lim.get("lower")))
        hi.append(float(lim.get("upper")))
        v = float(lim.get("velocity", "0"))
        vmax.append(v if v > 0 else DEFAULT_VMAX)
        vsrc.append("urdf" if v > 0 else "default")
    lo, hi, vmax = np.array(lo), np.array(hi), np.array(vmax)
    assert np.allclose(lo, model.lowerPositionLimit) and np.allclose(hi, model.upperPositionLimit)

    rng = np.random.default_rng(args.seed)
    Q = rng.uniform(lo, hi, size=(args.n, n))
    V = rng.uniform(-vmax, vmax, size=(args.n, n))
    A = rng.uniform(-AMAX, AMAX, size=(args.n, n))

    n_gM = args.n if args.full_gM is None else min(args.full_gM, args.n)
    states = []
    for k in range(args.n):
        q, v, a = Q[k], V[k], A[k]
        tau = pin.rnea(model, data, q, v, a).copy()
        s = {"q": q.tolist(), "v": v.tolist(), "a": a.tolist(), "tau": tau.tolist()}
        if k < n_gM:
            g = pin.computeGeneralizedGravity(model, data, q).copy()
            M = pin.crba(model, data, q).copy()
            M = np.triu(M) + np.triu(M, 1).T
            # self-checks: rnea at zero v and a is g; M a = rnea(q, 0, a) - g
            assert np.allclose(pin.rnea(model, data, q, np.zeros(n), np.zeros(n)), g, rtol=1e-12, atol=1e-9)
            assert np.allclose(M @ a, pin.rnea(model, data, q, np.zeros(n), a) - g, rtol=1e-10, atol=1e-8)
            assert np.all(np.linalg.eigvalsh(M) > 0)
            s["g"] = g.tolist()
            s["M"] = M.tolist()
        states.append(s)

    # timing
    qs, vs, as_ = list(Q), list(V), list(A)
    def noop(m, d, q, v, a):
        return q
    def batch(f):
        t0 = time.perf_counter()
        for q, v, a in zip(qs, vs, as_):
            f(model, data, q, v, a)
        return (time.perf_counter() - t0) / len(qs) * 1e6
    batch(pin.rnea)
    rnea_us = statistics.median(batch(pin.rnea) for _ in range(args.time_reps))
    noop_us = statistics.median(batch(noop) for _ in range(args.time_reps))

    # what Pinocchio sees
    bodies = []
    for i in range(1, model.njoints):
        I = model.inertias[i]
        bodies.append({
            "joint": model.names[i],
            "type": model.joints[i].shortname(),
            "placement": se3(model.jointPlacements[i]),
            "mass": I.mass,
            "com": I.lever.tolist(),
            "inertia_com": I.inertia.tolist(),
        })
    tip_frame = model.frames[model.getFrameId(args.tip)]
    moving_mass = sum(model.inertias[i].mass for i in range(1, model.njoints))
    universe_mass = model.inertias[0].mass
    doubts = {k: v["doubts"] for k, v in link_checks.items() if v["doubts"]}

    print(f"{args.robot}: {os.path.relpath(urdf_abs, REPO)}  root '{root_link}'  tip '{args.tip}'  Pinocchio {pin.__version__}")
    print(f"  joints: {names}")
    for b in bodies:
        print(f"  {b['joint']:22s} {b['type']:14s} body mass {b['mass']!r} kg")
    print(f"  moving mass {moving_mass!r} kg; universe (root link + links fixed to it) {universe_mass!r} kg; "
          f"total {moving_mass + universe_mass!r} kg")
    if pruned:
        print(f"  pruned (off-chain movable subtrees): {pruned}")
    for k, v in doubts.items():
        print(f"  doubt: link {k}: {'; '.join(v)}")
    print(f"  rnea {rnea_us:.3f} us per call (median of {args.time_reps} batches of {args.n}; "
          f"loop + call overhead of a no-op Python function {noop_us:.3f} us)")

    doc = {
        "robot": args.robot,
        "urdf": os.path.relpath(urdf_abs, REPO),
        "root": root_link,
        "tip": args.tip,
        "joints": names,
        "gravity": GRAVITY,
        "seed": args.seed,
        "n": args.n,
        "sampling": {
            "rng": f"numpy.random.default_rng({args.seed}); Q, V, A drawn in that order, each shape (n, joints)",
            "q": "uniform in [lower, upper]", "lower": lo.tolist(), "upper": hi.tolist(),
            "v": "uniform in +-vmax", "vmax": vmax.tolist(), "vmax_source": vsrc,
            "a": f"uniform in +-{AMAX}",
        },
        "g_M_states": n_gM,
        "g_M_note": ("g and M are stored for every state" if n_gM == args.n else
                     f"g and M are stored for the first {n_gM} states only (file size); q, v, a, tau for all {args.n}"),
        "model": {
            "note": ("Pinocchio's model as built: per movable joint, its placement in the parent joint's "
                     "frame, and the body (the child link plus every link fixed to it, lumped) as mass, "
                     "centre of mass and rotational inertia about the centre of mass, in the joint frame"),
            "bodies": bodies,
            "tip_placement_in_last_joint": se3(tip_frame.placement),
            "moving_mass": moving_mass,
            "universe_mass": universe_mass,
            "total_mass": moving_mass + universe_mass,
        },
        "urdf_links": link_checks,
        "pruned_links": pruned,
        "states": states,
        "pin_version": pin.__version__,
        "rnea_us": rnea_us,
        "rnea_loop_overhead_us": noop_us,
        "timing_note": (f"median over {args.time_reps} batches of the mean of {args.n} pin.rnea calls from a "
                        "Python loop (includes the Python binding overhead)"),
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(doc, f)
        f.write("\n")
    print(f"  wrote {args.out} ({os.path.getsize(args.out)} bytes)")


if __name__ == "__main__":
    main()
