#!/usr/bin/env python3
"""How much a written plan's sampled legs turn their joints beyond what they must, and how much
of that is whole turns a joint range wider than a turn lets a waypoint take back.

usage: python3 bench/leg_turns.py PLAN.json URDF   (standard library only)

For every leg that is not the direct segment: its duration, its time at full joint speed along
its waypoints (the sum over segments of max_j |dq_j| / v_j, speeds from the URDF's joint
limits), and that time with its interior waypoints unwound (per joint whose range exceeds 2*pi,
the values a whole number of turns apart that move it least; the ends fixed; not checked for
collision). The robots of a plan are assumed to share the URDF. Exit 2 on unreadable input.
"""
import json
import math
import re
import sys

TAU = 2.0 * math.pi


def fail(message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(2)


def limits(urdf_path):
    """(lower, upper, velocity) of each movable joint, in file order."""
    try:
        text = open(urdf_path, encoding="utf-8").read()
    except OSError as e:
        fail(f"{urdf_path}: {e}")
    out = []
    for joint in re.findall(r"<joint\b[^>]*>.*?</joint>", text, re.S):
        kind = re.search(r'type="(\w+)"', joint)
        limit = re.search(r"<limit\b[^>]*/?>", joint)
        if not kind or kind.group(1) == "fixed" or not limit:
            continue
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', limit.group(0)))
        try:
            out.append((float(attrs["lower"]), float(attrs["upper"]), float(attrs["velocity"])))
        except (KeyError, ValueError):
            fail(f"{urdf_path}: a joint limit without lower, upper and velocity")
    return out


def speed_time(q, lim):
    return sum(max(abs(b[j] - a[j]) / lim[j][2] for j in range(len(a))) for a, b in zip(q, q[1:]))


def unwound(q, lim):
    q = [list(w) for w in q]
    n = len(q)
    for j, (lo, hi, _) in enumerate(lim):
        if hi - lo <= TAU or n < 3:
            continue
        choices = [[q[0][j]]]
        for w in q[1:-1]:
            v = w[j]
            ks = range(math.ceil((lo - v) / TAU - 1e-12), math.floor((hi - v) / TAU + 1e-12) + 1)
            choices.append([v] + [v + k * TAU for k in ks if k != 0])
        choices.append([q[-1][j]])
        cost, back = [0.0], []
        for prev, nxt in zip(choices, choices[1:]):
            step = [min((cost[a] + abs(v - u), a) for a, u in enumerate(prev)) for v in nxt]
            cost = [c for c, _ in step]
            back.append([a for _, a in step])
        at = 0
        for k in range(n - 1, 0, -1):
            q[k][j] = choices[k][at]
            at = back[k - 1][at]
    return q


def main():
    if len(sys.argv) != 3:
        fail("usage: python3 bench/leg_turns.py PLAN.json URDF")
    try:
        plan = json.load(open(sys.argv[1], encoding="utf-8"))
    except (OSError, ValueError) as e:
        fail(f"{sys.argv[1]}: {e}")
    lim = limits(sys.argv[2])
    total = [0.0, 0.0, 0.0]
    print("| robot | leg | duration s | at full speed s | unwound s | joint travel / net (rad) |")
    print("|---|---|---|---|---|---|")
    for robot in plan.get("robots", []):
        for k, leg in enumerate(robot.get("legs", [])):
            if leg.get("straight", True):
                continue
            q = [w["q"] if isinstance(w, dict) else w for w in leg["waypoints"]]
            if any(len(w) != len(lim) for w in q):
                fail(f"{sys.argv[2]} has {len(lim)} joints, robot {robot['name']}'s legs {len(q[0])}")
            before, after = speed_time(q, lim), speed_time(unwound(q, lim), lim)
            travel = " ".join(
                f"{sum(abs(b[j] - a[j]) for a, b in zip(q, q[1:])):.2f}/{abs(q[-1][j] - q[0][j]):.2f}"
                for j in range(len(lim))
            )
            mark = " **" if after < before - 1e-6 else ""
            print(f"| {robot['name']} | {k}{mark} | {leg['duration_s']:.2f} | {before:.2f} | {after:.2f} | {travel} |")
            total = [total[0] + leg["duration_s"], total[1] + before, total[2] + after]
    print(f"\nsampled legs: {total[0]:.2f} s, {total[1]:.2f} s at full speed, {total[2]:.2f} s unwound")


if __name__ == "__main__":
    main()
