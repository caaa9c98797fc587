#!/usr/bin/env bash
# bad_inputs.sh [BIN]: runs the bad inputs of issue 13 against the cellplan binary and prints
# one line per case: exit code and the first line of the error. Scratch files go to a temp dir.
set -u
BIN=${1:-target/release/cellplan}
cd "$(dirname "$0")/.."
BIN=$(realpath "$BIN")
T=$(mktemp -d)
R=$PWD
cell() { # cell NAME EDIT-SED: the 2r example, edited, with absolute paths
  mkdir -p "$T/$1"
  sed -e "s#\.\./\.\./#$R/#g" -e "s#file = \"tasks.csv\"#file = \"$R/examples/autobody-2r/tasks.csv\"#" \
      examples/autobody-2r/cell.toml | sed -e "$2" > "$T/$1/cell.toml"
  echo "$T/$1/cell.toml"
}
run() { # run LABEL ARGS...
  local label=$1; shift
  local out; out=$(cd "$T" && NO_COLOR=1 timeout 120 "$BIN" "$@" 2>&1 >/dev/null)
  local rc=$?
  printf '%-44s exit %-3s %s\n' "$label" "$rc" "$(echo "$out" | grep -v '^\s*$' | grep -m1 -E '×|^error' | sed 's/^ *//' | cut -c1-150)"
}
run "spin_steps = 100000000" check "$(cell spin 's/^spin_steps = 8/spin_steps = 100000000/')"
run "task file is /dev/zero" check "$(cell zero "s#file = \"$R/examples/autobody-2r/tasks.csv\"#file = \"/dev/zero\"#")"
run "cell file is /dev/zero" check /dev/zero
printf 'id,x,y,z,nx,ny,nz,x\nA,1,2,3,0,0,1,4\n' > "$T/twice.csv"
run "CSV column named twice" check "$(cell twice "s#$R/examples/autobody-2r/tasks.csv#$T/twice.csv#")"
run "task_cap left in [process]" check "$(cell cap1 's/^measure_time = 1.5 .*/&\ntask_cap = 3/')"
run "check: caps plan refuses ([planning] 1)" check "$(cell cap2 's/^task_cap = 14 .*/task_cap = 1/')"
run "cell name ../../../x, plan without -o" plan "$(cell name '0,/^name = .*/s##name = "../../../x"#')" --quiet
run "cell name /abs, plan without -o" plan "$(cell abs '0,/^name = .*/s##name = "/tmp/abs"#')" --quiet
touch "$T/file"
run "unwritable -o" plan "$(cell out 's/x/x/')" -o "$T/file/out" --quiet
run "plan --time-limit 0" plan "$(cell tl 's/x/x/')" --time-limit 0
run "verify --time-step 1e-9" verify "$T/none.json" "$(cell vs 's/x/x/')" --time-step 1e-9
run "gen tasks --facing -y (must pass)" gen tasks --mesh "$R/data/parts/body-in-white/car5.obj" --count 3 --facing -y -o "$T/g.csv"
(cd "$T" && "$BIN" bench minmax --generate --vehicles 2 --tasks 4 --seed 1 -o "$T/g.minmax" 2>/dev/null)
for k in NODES VEHICLES TASKS; do
  sed "0,/^$k: [0-9]*/s//$k: 4000000000/" "$T/g.minmax" > "$T/$k.minmax"
  run "min-max $k: 4000000000" bench minmax "$T/$k.minmax"
done
printf 'v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n' > "$T/flat.obj"
run "OBJ of zero-area triangles" gen tasks --mesh "$T/flat.obj" --count 3
printf 'v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n' > "$T/far.obj"
run "OBJ vertex at 1e30" gen tasks --mesh "$T/far.obj" --count 3
# Sixtieth session: separators, joint speeds, stud-weld magnitudes, thread counts, outputs.
printf 'id;x;y;z;nx;ny;nz\nA;1,5;2;3;0;0;1\n' > "$T/semi.csv"
run "task CSV separated by ';'" check "$(cell semi "s#$R/examples/autobody-2r/tasks.csv#$T/semi.csv#")"
run "max_velocity of 1e9 deg/s" check "$(cell fast 's/^home = \(.*\)/home = \1\nmax_velocity = [100, 100, 100, 100, 100, 1e9]/')"
mkdir -p "$T/weld"
sed -e "s#\.\./\.\./#$R/#g" -e "s#\"studs.csv\"#\"$R/examples/studweld-kr210/studs.csv\"#" \
    -e 's/^weld_time = 2.0 /weld_time = 1e300 /' examples/studweld-kr210/cell.toml > "$T/weld/cell.toml"
run "stud-weld weld_time = 1e300" check "$T/weld/cell.toml"
run "--threads 100000" --threads 100000 check "$(cell th 's/x/x/')"
run "report onto a folder" report "$T/none.json" -o "$T"
run "gen tasks --translate 1e300,0,0" gen tasks --mesh "$R/data/parts/body-in-white/car5.obj" --count 3 --translate 1e300,0,0 -o "$T/t.csv"
# Edited plans: a real plan of the 4r example in which robots wait (fixed-priority), each
# edit verified (exit 2: refused when read, naming the place; exit 4: rejected, with the
# verifier's first violation).
mkdir -p "$T/plan4"
sed -e "s#\.\./\.\./#$R/#g" -e "s#file = \"tasks.csv\"#file = \"$R/examples/autobody-4r/tasks.csv\"#" \
    examples/autobody-4r/cell.toml > "$T/plan4/cell.toml"
P=$T/plan4/cell.toml
(cd "$T" && "$BIN" plan "$P" -o "$T/good" --coordination fixed-priority --quiet >/dev/null 2>&1)
runv() { # runv LABEL PYTHON-EDIT (d: the plan as JSON)
  python3 - "$T/good/plan.json" "$T/edited.json" "$2" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); r = next(x for x in d["robots"] if x["waits"]) if any(x["waits"] for x in d["robots"]) else d["robots"][0]
exec(sys.argv[3])
json.dump(d, open(sys.argv[2], "w"))
PY
  local out; out=$(cd "$T" && NO_COLOR=1 timeout 120 "$BIN" verify "$T/edited.json" "$P" 2>&1)
  local rc=$?
  printf '%-44s exit %-3s %s\n' "$1" "$rc" "$(echo "$out" | grep -v '^\s*$' | grep -m1 -E '×|^error|^[A-Z][a-zA-Z]+ ' | sed 's/^ *//' | cut -c1-150)"
}
runv "plan: a waypoint of 1e9" 'r["legs"][0]["waypoints"][0][0] = 1e9'
runv "plan: a sample shorter than the one before" 'r["trajectory"][5]["q"].pop()'
runv "plan: time going back" 'r["trajectory"][5]["t"] = 0.0'
runv "plan: a trajectory sample deleted" 'del r["trajectory"][len(r["trajectory"]) // 2]'
runv "plan: motion_s changed" 'r["motion_s"] += 0.5'
runv "plan: measuring_s changed" 'r["measuring_s"] += 0.5'
runv "plan: waiting_s changed" 'r["waiting_s"] += 0.5'
runv "plan: end_s changed" 'r["end_s"] += 0.5'
runv "plan: lower_bound_s changed" 'd["lower_bound_s"] *= 0.9'
runv "plan: joints reversed" 'r["joints"].reverse()'
runv "plan: a robot's waits deleted" 'r["waits"] = []'
runv "plan: a task measured and unmeasured" 'd["unmeasured"].append({"task": r["tasks"][0]["task"], "reason": "no-ik"})'
runv "plan: coordination record erased" 'del d["coordination"]'
runv "plan: version 2" 'd["version"] = 2'
rm -rf "$T"
