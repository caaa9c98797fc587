#!/usr/bin/env python3
"""A large synthetic board as a KiCad position CSV, for scale tests of the PCB planner.

    python3 bench/pcb/gen_board.py --count 2000 --types 120 --size 250x180 --seed 1 > bench/pcb/large/board.csv

Components sit on a jittered grid over the board (as on dense real boards), with a skewed type
distribution (a few passives very common, many ICs rare), rotations in 90° steps.
"""
import argparse, random

ap = argparse.ArgumentParser()
ap.add_argument("--count", type=int, default=2000)
ap.add_argument("--types", type=int, default=120)
ap.add_argument("--size", default="250x180")
ap.add_argument("--seed", type=int, default=1)
a = ap.parse_args()
w, h = (float(x) for x in a.size.split("x"))
rng = random.Random(a.seed)
weights = [1.0 / (k + 1) ** 1.1 for k in range(a.types)]
print("Ref,Val,Package,PosX,PosY,Rot,Side")
for i in range(a.count):
    t = rng.choices(range(a.types), weights)[0]
    x, y = rng.uniform(2, w - 2), rng.uniform(2, h - 2)
    print(f"U{i + 1},V{t},FP{t % 17},{x:.3f},{y:.3f},{90 * rng.randrange(4)},top")
