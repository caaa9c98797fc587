#!/usr/bin/env python3
"""Solve TSPLIB instances with elkai (LKH-3) on the exact TSPLIB integer distances.

Distances follow TSPLIB95 (Reinelt): EUC_2D (nint), CEIL_2D, ATT (pseudo-Euclidean), GEO, and
EXPLICIT with FULL_MATRIX, UPPER_ROW, LOWER_ROW, UPPER_DIAG_ROW or LOWER_DIAG_ROW. The tour
cost is recomputed from that matrix and the tour checked to be a permutation.

Usage: tsp_elkai.py FILE... [--runs R] [--json]   (elkai has no time limit; `runs` is LKH's)
"""
import argparse
import json
import math
import sys
import time


def parse_tsplib(path):
    with open(path) as f:
        toks_by_line = [l.split() for l in f]
    spec = {}
    i = 0
    coords, weights = [], []
    while i < len(toks_by_line):
        line = " ".join(toks_by_line[i])
        i += 1
        if not line or line == "EOF":
            continue
        if line.startswith("NODE_COORD_SECTION"):
            n = int(spec["DIMENSION"])
            for _ in range(n):
                t = toks_by_line[i]
                i += 1
                coords.append((float(t[1]), float(t[2])))
            continue
        if line.startswith("EDGE_WEIGHT_SECTION"):
            while i < len(toks_by_line) and toks_by_line[i] and toks_by_line[i][0][0] in "0123456789-.":
                weights.extend(float(x) for x in toks_by_line[i])
                i += 1
            continue
        if line.startswith("DISPLAY_DATA_SECTION"):
            n = int(spec["DIMENSION"])
            i += n
            continue
        if ":" in line:
            k, v = line.split(":", 1)
            spec[k.strip()] = v.strip()
    return spec, coords, weights


def nint(x):
    return int(x + 0.5)


def geo_rad(x):
    deg = int(x)  # TSPLIB: truncation toward zero
    return math.pi * (deg + 5.0 * (x - deg) / 3.0) / 180.0


def matrix(spec, coords, weights):
    n = int(spec["DIMENSION"])
    kind = spec["EDGE_WEIGHT_TYPE"]
    d = [[0] * n for _ in range(n)]
    if kind == "EXPLICIT":
        fmt = spec["EDGE_WEIGHT_FORMAT"]
        w = iter(int(x) for x in weights)
        if fmt == "FULL_MATRIX":
            for a in range(n):
                for b in range(n):
                    d[a][b] = next(w)
        else:
            pairs = {
                "UPPER_ROW": [(a, b) for a in range(n) for b in range(a + 1, n)],
                "LOWER_ROW": [(a, b) for a in range(n) for b in range(a)],
                "UPPER_DIAG_ROW": [(a, b) for a in range(n) for b in range(a, n)],
                "LOWER_DIAG_ROW": [(a, b) for a in range(n) for b in range(a + 1)],
            }[fmt]
            for a, b in pairs:
                d[a][b] = d[b][a] = next(w)
        return d
    for a in range(n):
        xa, ya = coords[a]
        for b in range(a + 1, n):
            xb, yb = coords[b]
            dx, dy = xa - xb, ya - yb
            if kind == "EUC_2D":
                c = nint(math.sqrt(dx * dx + dy * dy))
            elif kind == "CEIL_2D":
                c = math.ceil(math.sqrt(dx * dx + dy * dy))
            elif kind == "ATT":
                r = math.sqrt((dx * dx + dy * dy) / 10.0)
                t = nint(r)
                c = t + 1 if t < r else t
            elif kind == "GEO":
                rrr = 6378.388
                la, lo = geo_rad(xa), geo_rad(ya)
                lb, lob = geo_rad(xb), geo_rad(yb)
                q1 = math.cos(lo - lob)
                q2 = math.cos(la - lb)
                q3 = math.cos(la + lb)
                c = int(rrr * math.acos(0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3)) + 1.0)
            else:
                raise SystemExit(f"unsupported EDGE_WEIGHT_TYPE {kind}")
            d[a][b] = d[b][a] = c
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--runs", type=int, default=10, help="LKH runs (elkai's only effort knob)")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    import elkai

    rows = []
    for path in a.files:
        spec, coords, weights = parse_tsplib(path)
        d = matrix(spec, coords, weights)
        n = len(d)
        t0 = time.time()
        tour = elkai.DistanceMatrix(d).solve_tsp(runs=a.runs)
        dt = time.time() - t0
        if tour and len(tour) == n + 1 and tour[0] == tour[-1]:
            tour = tour[:-1]
        if sorted(tour) != list(range(n)):
            raise SystemExit(f"{path}: elkai returned a tour that is not a permutation")
        cost = sum(d[tour[k]][tour[(k + 1) % n]] for k in range(n))
        name = path.rsplit("/", 1)[-1].rsplit(".", 1)[0]
        rows.append(dict(instance=name, solver="elkai", cost=cost, time_s=dt, runs=a.runs))
        if not a.json:
            print(f"{name}: {cost} ({dt:.2f} s, {a.runs} runs)")
    if a.json:
        print(json.dumps(rows))


if __name__ == "__main__":
    main()
