#!/usr/bin/env python3
"""Solve a cellplan min-max instance (docs/minmax-format.md) with OR-Tools routing.

Model: one routing vehicle per robot. Every (robot, node) pair is its own routing node, so each
robot keeps its own cost matrix: robot v's depot is the start and end of routing vehicle v, and
every alternative node of v is allowed on vehicle v only (SetAllowedVehiclesForIndex's
effect; done on VehicleVar, see the comment there). Each
task is one disjunction over all its alternative nodes of all robots, max cardinality 1, with a
huge penalty (so exactly one is visited whenever the search can). Arc costs are the robot's
travel times; a "time" dimension adds the task's service time to every arc leaving one of its
nodes, and SetGlobalSpanCostCoefficient on it drives the longest route down (min-max); a
"count" dimension enforces the caps. Start: a cap-feasible assignment (augmenting paths) with
nearest-neighbour routes (`--first`, since OR-Tools' own first solutions leave tasks out when
caps are tight), then GUIDED_LOCAL_SEARCH until the time limit.

Costs are scaled to integers (x 10**4 by default: exact for files written with 4 decimals, as
`cellplan bench minmax --generate` does). The solution is checked and its makespan and total are
recomputed from the file's floating-point numbers.

Usage: minmax_ortools.py FILE [--time-limit S] [--scale K] [--json]
BALANCE_LIMIT is not modelled (reported when present).
"""
import argparse
import json
import sys
import time


def read_minmax(path):
    """The file as (header dict, service list, vehicles list of dicts)."""
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip()]
    pos = 0
    head = {}
    while lines[pos] != "SERVICE_SECTION":
        k, v = lines[pos].split(":", 1)
        head[k.strip()] = v.strip()
        pos += 1
    m, n = int(head["VEHICLES"]), int(head["TASKS"])
    service = [float(x) for x in lines[pos + 1 : pos + 1 + n]]
    pos += 1 + n
    vehicles = []
    for i in range(m):
        assert lines[pos].replace(" ", "") == f"VEHICLE:{i}", (path, lines[pos])
        pos += 1
        fields = {}
        while lines[pos] != "FULL_MATRIX":
            k, v = lines[pos].split(":", 1)
            fields[k.strip()] = int(v)
            pos += 1
        k = fields["NODES"]
        costs = [[float(x) for x in l.split()] for l in lines[pos + 1 : pos + 1 + k]]
        assert all(len(r) == k for r in costs)
        pos += 1 + k
        assert lines[pos] == "ALTERNATIVES", (path, lines[pos])
        pos += 1
        alts = [[int(x) for x in l.split(":", 1)[1].split()] for l in lines[pos : pos + n]]
        pos += n
        vehicles.append(
            dict(depot=fields["DEPOT"], cap=fields["CAP"], costs=costs, alternatives=alts)
        )
    return head, service, vehicles


def route_times(service, vehicles, tours):
    """tours[v] = [(task, node), ...]; the route time of every vehicle."""
    out = []
    for v, tour in enumerate(tours):
        c = vehicles[v]["costs"]
        prev = vehicles[v]["depot"]
        t = 0.0
        for task, node in tour:
            t += c[prev][node] + service[task]
            prev = node
        out.append(t + c[prev][vehicles[v]["depot"]])
    return out


def check(service, vehicles, tours):
    n = len(service)
    done = [None] * n
    for v, tour in enumerate(tours):
        veh = vehicles[v]
        if len(tour) > veh["cap"]:
            raise ValueError(f"vehicle {v} has {len(tour)} tasks, over its cap {veh['cap']}")
        for task, node in tour:
            if node not in veh["alternatives"][task]:
                raise ValueError(f"vehicle {v} does task {task} at node {node}, not an alternative")
            if done[task] is not None:
                raise ValueError(f"task {task} done twice")
            done[task] = v
    missing = [t for t in range(n) if done[t] is None]
    if missing:
        raise ValueError(f"tasks not done: {missing[:10]}")


def initial_routes(service, vehicles):
    """A cap-feasible start: tasks to robots by augmenting paths (least-loaded capable robot
    first), each route by nearest neighbour over the tasks' nodes."""
    m, n = len(vehicles), len(service)
    capable = [[v for v in range(m) if vehicles[v]["alternatives"][t]] for t in range(n)]
    members = [[] for _ in range(m)]

    def place(t, seen):
        for v in sorted(capable[t], key=lambda v: len(members[v])):
            if v in seen:
                continue
            seen.add(v)
            if len(members[v]) < vehicles[v]["cap"]:
                members[v].append(t)
                return True
            for u in list(members[v]):
                if place(u, seen):
                    members[v].remove(u)
                    members[v].append(t)
                    return True
        return False

    for t in range(n):
        if not place(t, set()):
            raise SystemExit(f"no cap-feasible assignment (task {t})")
    tours = []
    for v, veh in enumerate(vehicles):
        c, here, left, tour = veh["costs"], veh["depot"], set(members[v]), []
        while left:
            d, t, a = min((c[here][a], t, a) for t in left for a in veh["alternatives"][t])
            tour.append((t, a))
            left.remove(t)
            here = a
        tours.append(tour)
    return tours


def solve(head, service, vehicles, time_limit, scale, first):
    from ortools.constraint_solver import pywrapcp, routing_enums_pb2
    from ortools.util.optional_boolean_pb2 import BOOL_TRUE

    m, n = len(vehicles), len(service)
    # Routing nodes: per vehicle its depot, then its alternative nodes.
    owner, local, task_of = [], [], []
    depot_index = []
    node_of = {}
    for v, veh in enumerate(vehicles):
        depot_index.append(len(owner))
        owner.append(v)
        local.append(veh["depot"])
        task_of.append(None)
        for t, alts in enumerate(veh["alternatives"]):
            for a in alts:
                node_of[(v, a)] = len(owner)
                owner.append(v)
                local.append(a)
                task_of.append(t)
    size = len(owner)
    big = 10**9
    # Integer matrices per vehicle (travel), and service per routing node, scaled.
    icost = [[[round(c * scale) for c in row] for row in veh["costs"]] for veh in vehicles]
    iserv = [0 if t is None else round(service[t] * scale) for t in task_of]

    manager = pywrapcp.RoutingIndexManager(size, m, depot_index, depot_index)
    routing = pywrapcp.RoutingModel(manager)

    travel_cb, time_cb = [], []
    for v in range(m):
        cv = icost[v]

        def travel(i, j, v=v, cv=cv):
            a, b = manager.IndexToNode(i), manager.IndexToNode(j)
            if owner[a] != v or owner[b] != v:
                return big
            return cv[local[a]][local[b]]

        def timed(i, j, v=v, cv=cv):
            a, b = manager.IndexToNode(i), manager.IndexToNode(j)
            if owner[a] != v or owner[b] != v:
                return big
            return cv[local[a]][local[b]] + iserv[a]

        travel_cb.append(routing.RegisterTransitCallback(travel))
        time_cb.append(routing.RegisterTransitCallback(timed))
        routing.SetArcCostEvaluatorOfVehicle(travel_cb[v], v)

    horizon = big
    routing.AddDimensionWithVehicleTransits(time_cb, 0, horizon, True, "time")
    time_dim = routing.GetDimensionOrDie("time")
    # Min-max: the span term (max end - min start) dominates the total travel.
    time_dim.SetGlobalSpanCostCoefficient(100)

    count_cb = routing.RegisterUnaryTransitCallback(
        lambda i: 0 if task_of[manager.IndexToNode(i)] is None else 1
    )
    routing.AddDimensionWithVehicleCapacity(
        count_cb, 0, [veh["cap"] for veh in vehicles], True, "count"
    )

    by_task = [[] for _ in range(n)]
    for node in range(size):
        if task_of[node] is not None:
            idx = manager.NodeToIndex(node)
            # SetAllowedVehiclesForIndex in effect: its SWIG wrapper in ortools 9.15 rejects
            # every Python sequence for its absl::Span argument, so restrict the vehicle
            # variable directly (-1 = not performed, allowed since the node is optional).
            routing.VehicleVar(idx).SetValues([-1, owner[node]])
            by_task[task_of[node]].append(idx)
    penalty = 10**12
    for t in range(n):
        routing.AddDisjunction(by_task[t], penalty, 1)

    params = pywrapcp.DefaultRoutingSearchParameters()
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    # Moving a task to another robot swaps one node of its disjunction for another (one
    # becomes inactive, one active, on different routes): switch on the operators that do that.
    ops = params.local_search_operators
    for name in [
        "use_extended_swap_active",
        "use_relocate_and_make_active",
        "use_exchange_and_make_active",
        "use_inactive_lns",
        "use_path_lns",
        "use_global_cheapest_insertion_close_nodes_lns",
    ]:
        setattr(ops, name, BOOL_TRUE)
    params.time_limit.FromMilliseconds(int(time_limit * 1000))
    # Tight caps defeat OR-Tools' own first solutions (a robot filled with shared tasks leaves
    # one of its exclusive tasks out, and no single move repairs that): start it from a
    # cap-feasible assignment instead (see initial_routes), when asked to.
    if first == "CAP_FEASIBLE":
        routing.CloseModelWithParameters(params)
        routes = [
            [manager.NodeToIndex(node_of[(v, a)]) for _, a in tour]
            for v, tour in enumerate(initial_routes(service, vehicles))
        ]
        start = routing.ReadAssignmentFromRoutes(routes, True)
        if start is None:
            raise SystemExit("OR-Tools rejected the cap-feasible start")
        sol = routing.SolveFromAssignmentWithParameters(start, params)
    else:
        params.first_solution_strategy = getattr(routing_enums_pb2.FirstSolutionStrategy, first)
        sol = routing.SolveWithParameters(params)
    if sol is None:
        return None
    tours = []
    for v in range(m):
        tour = []
        i = sol.Value(routing.NextVar(routing.Start(v)))
        while not routing.IsEnd(i):
            node = manager.IndexToNode(i)
            tour.append((task_of[node], local[node]))
            i = sol.Value(routing.NextVar(i))
        tours.append(tour)
    return tours


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file")
    ap.add_argument("--time-limit", type=float, default=10.0)
    ap.add_argument("--scale", type=float, default=1e4, help="cost scale to integers")
    ap.add_argument(
        "--first",
        default="CAP_FEASIBLE",
        help="CAP_FEASIBLE (our start) or an OR-Tools FirstSolutionStrategy name",
    )
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    t0 = time.time()
    head, service, vehicles = read_minmax(a.file)
    t_read = time.time() - t0
    t1 = time.time()
    # The limit is the search's (OR-Tools' own); time_s also counts building the model.
    tours = solve(head, service, vehicles, a.time_limit, a.scale, a.first)
    t_solve = time.time() - t1
    name = a.file.rsplit("/", 1)[-1].rsplit(".", 1)[0]
    if tours is None:
        print(f"{name}: OR-Tools found no solution in {a.time_limit} s", file=sys.stderr)
        sys.exit(1)
    check(service, vehicles, tours)
    times = route_times(service, vehicles, tours)
    row = dict(
        instance=name,
        solver="ortools",
        cost=max(times),
        total=sum(times),
        vehicles=len(vehicles),
        tasks=len(service),
        time_limit_s=a.time_limit,
        time_s=t_solve,
        read_s=t_read,
        balance_limit=head.get("BALANCE_LIMIT"),
    )
    if a.json:
        print(json.dumps(row))
    else:
        print(
            f"{name}: makespan {row['cost']:.4f} total {row['total']:.4f} "
            f"({len(vehicles)} vehicles, {len(service)} tasks, {t_solve:.1f} s)"
        )
        if "BALANCE_LIMIT" in head:
            print("note: BALANCE_LIMIT is not modelled", file=sys.stderr)


if __name__ == "__main__":
    main()
