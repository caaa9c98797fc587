#!/usr/bin/env python3
"""Bound a cellplan min-max instance (docs/minmax-format.md) from below with OR-Tools CP-SAT.

The exact model: per vehicle one circuit (AddCircuit) over its depot and nodes, an unvisited node
on its own loop, the depot on its own loop when the vehicle stays home (then no node of it is
visited); arcs only between nodes of different tasks and between the depot and the nodes; every
task at exactly one of its nodes over all vehicles; the caps; each route's time (its arcs and its
tasks' service) at most the makespan, which is minimised. BALANCE_LIMIT is not modelled (it only
removes solutions, so the bound stays a bound of the problem with it).

Costs and service times are rounded *down* to integer multiples of 1/--scale, so that every
solution of the file costs at least its rounded cost: CP-SAT's proven bound on the rounded model
(`bound`) is a lower bound of the file's makespan. A solution found (`cost`) is recomputed from
the file's numbers. Meant for the cells' allocation problems (`cellplan check CELL --minmax-out
FILE`): does any proof get above cellplan's own lower bound, or below its ILS?

Usage: minmax_cpsat.py FILE [--time-limit S] [--workers N] [--scale K] [--json]
"""
import argparse
import json
import math
import sys
import time

from minmax_ortools import read_minmax


def solve(path, time_limit, workers, scale):
    from ortools.sat.python import cp_model

    t0 = time.time()
    head, service, vehicles = read_minmax(path)
    n = len(service)
    read_s = time.time() - t0
    model = cp_model.CpModel()
    down = lambda x: int(math.floor(x * scale))
    horizon = down(sum(service)) + sum(
        down(max(max(row) for row in v["costs"])) for v in vehicles
    ) * (n + 1)
    makespan = model.NewIntVar(0, horizon, "makespan")
    at_task = [[] for _ in range(n)]
    arc_count = 0
    # Per vehicle, (literal, the file's cost) of every arc and visit: its route time, rounded
    # down in the model and exact for a solution.
    exact = []
    for vi, v in enumerate(vehicles):
        costs, depot = v["costs"], v["depot"]
        task_of = {}
        for t, nodes in enumerate(v["alternatives"]):
            for a in nodes:
                task_of[a] = t
        nodes = sorted(task_of)
        arcs, visits, spent = [], [], []
        home = model.NewBoolVar(f"home{vi}")
        arcs.append((depot, depot, home))
        for a in nodes:
            skip = model.NewBoolVar(f"skip{vi}_{a}")
            arcs.append((a, a, skip))
            seen = skip.Not()
            visits.append(seen)
            at_task[task_of[a]].append(seen)
            model.AddImplication(seen, home.Not())
            spent.append((seen, service[task_of[a]]))
            outs = [(depot, costs[a][depot])] + [(b, costs[a][b]) for b in nodes if task_of[b] != task_of[a]]
            for b, c in outs:
                lit = model.NewBoolVar("")
                arcs.append((a, b, lit))
                spent.append((lit, c))
            lit = model.NewBoolVar("")
            arcs.append((depot, a, lit))
            spent.append((lit, costs[depot][a]))
        model.AddCircuit(arcs)
        model.Add(sum(visits) <= v["cap"])
        model.Add(sum(down(c) * x for x, c in spent) <= makespan)
        arc_count += len(arcs)
        exact.append(spent)
    for t in range(n):
        model.AddExactlyOne(at_task[t])
    model.Minimize(makespan)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = time_limit
    solver.parameters.num_workers = workers
    status = solver.Solve(model)
    row = dict(
        instance=head.get("NAME", path),
        solver="cp-sat",
        status=solver.StatusName(status),
        bound=solver.BestObjectiveBound() / scale,
        arcs=arc_count,
        vehicles=len(vehicles),
        tasks=n,
        time_limit_s=time_limit,
        time_s=time.time() - t0,
        read_s=read_s,
        scale=scale,
    )
    if status in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        times = [sum(c for lit, c in spent if solver.BooleanValue(lit)) for spent in exact]
        row["cost"] = max(times)
        row["route_times"] = times
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scale", type=int, default=1000)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    row = solve(a.file, a.time_limit, a.workers, a.scale)
    if a.json:
        print(json.dumps(row))
    else:
        for k, v in row.items():
            print(f"{k}: {v}")


if __name__ == "__main__":
    sys.exit(main())
