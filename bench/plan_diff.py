#!/usr/bin/env python3
"""Compare two trees of plan.json files (as bench/plan_matrix.sh writes them) for equality of
everything planned: compute times are dropped, and what changed spelling between document
versions (settings.measure_time_s in version 1; settings.process in version 2; typed stops and
activities, derived wait places and conflict legs, the wait count, in version 3) is set aside.
Usage: plan_diff.py OLD NEW (two plan.json files, or two trees of them); exit 1 when any plan
differs, 2 when there is nothing to compare."""
import json, sys, pathlib

def stop(v):
    """A leg end as version 3 writes it ("home" or {"task": id}) from either version."""
    if isinstance(v, dict):
        return v["task"]
    return v

def norm(doc):
    """Version 2 and 3 to one form: what is planned, not how the document spells it."""
    doc.pop("compute_s", None)
    doc.pop("version", None)
    c = doc.get("coordination", {})
    c.pop("compute_s", None)
    # Version 3 moved the count of resolutions to stats and counts the waits the programs
    # hold (version 2 counted waits added; one added where one stood lengthens it).
    doc.get("stats", {}).pop("conflicts_resolved", None)
    c.pop("conflicts_resolved", None)
    c.pop("waits", None)
    for conflict in c.get("conflicts_before", []) + c.get("conflicts_after", []):
        # Version 2 stated activities as text with legs and tasks; version 3 types them.
        for k in ("activity", "legs", "tasks"):
            conflict.pop(k, None)
    s = doc.get("settings", {})
    for k in ("measure_time_s", "process", "alternatives", "roomy_m"):
        s.pop(k, None)
    for r in doc.get("robots", []):
        for w in r.get("waits", []):
            w.pop("at", None)
        for leg in r.get("legs", []):
            leg["from"], leg["to"] = stop(leg["from"]), stop(leg["to"])
    return doc

def diff(a, b, path=""):
    if type(a) != type(b):
        return [f"{path}: {a!r} vs {b!r}"]
    if isinstance(a, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'new' if k in b else 'old'}")
            else:
                out += diff(a[k], b[k], f"{path}.{k}")
        return out
    if isinstance(a, list):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} vs {len(b)}"]
        out = []
        for i, (x, y) in enumerate(zip(a, b)):
            out += diff(x, y, f"{path}[{i}]")
        return out
    return [] if a == b else [f"{path}: {a!r} vs {b!r}"]

old, new = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
# Two plan files, or two trees of them (every plan.json under OLD against the same path under NEW).
if old.is_file() and new.is_file():
    pairs = [(old, new, old.name)]
else:
    pairs = [(p, new / p.relative_to(old), p.parent.relative_to(old)) for p in sorted(old.rglob("plan.json"))]
if not pairs:
    print(f"no plan.json under {old}: give two plan files or two trees of them", file=sys.stderr)
    sys.exit(2)
bad = 0
for p, q, name in pairs:
    if not q.exists():
        print(f"{name}: missing in new"); bad += 1; continue
    d = diff(norm(json.loads(p.read_text())), norm(json.loads(q.read_text())))
    print(f"{name}: {'identical' if not d else f'{len(d)} differences'}")
    for line in d[:5]:
        print("   ", line)
    bad += bool(d)
sys.exit(1 if bad else 0)
