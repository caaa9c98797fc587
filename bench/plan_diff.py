#!/usr/bin/env python3
"""Compare two trees of plan.json files (as bench/plan_matrix.sh writes them) for equality of
everything planned: compute times are dropped, and the settings keys that moved between document
versions (settings.measure_time_s in version 1; settings.process in version 2) are set aside.
Usage: plan_diff.py OLD_DIR NEW_DIR; exit 1 when any plan differs."""
import json, sys, pathlib

def norm(doc):
    doc.pop("compute_s", None)
    doc.get("coordination", {}).pop("compute_s", None)
    s = doc.get("settings", {})
    s.pop("measure_time_s", None)
    s.pop("process", None)
    doc.pop("version", None)
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
bad = 0
for p in sorted(old.rglob("plan.json")):
    q = new / p.relative_to(old)
    if not q.exists():
        print(f"{p.relative_to(old)}: missing in new"); bad += 1; continue
    d = diff(norm(json.loads(p.read_text())), norm(json.loads(q.read_text())))
    print(f"{p.parent.relative_to(old)}: {'identical' if not d else f'{len(d)} differences'}")
    for line in d[:5]:
        print("   ", line)
    bad += bool(d)
sys.exit(1 if bad else 0)
