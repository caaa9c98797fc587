#!/usr/bin/env bash
# plan_matrix.sh BIN OUTDIR: plans both example cells with every allocation x coordination
# strategy into OUTDIR/<cell>/<allocation>-<coordination>/ (for bench/plan_diff.py).
BIN=$1; OUT=$2
cd "$(dirname "$0")/.."
for cell in autobody-2r autobody-4r; do
 for a in proximity local-robust balanced; do
  for c in none delay-startup fixed-priority pose-perturbation best; do
   d=$OUT/$cell/$a-$c
   mkdir -p $d
   $BIN plan examples/$cell/cell.toml -o $d --allocation $a --coordination $c --no-verify --quiet --no-cache > $d/stdout 2> $d/stderr
   echo "$cell $a $c rc=$?" >> $OUT/log
  done
 done
done
echo DONE >> $OUT/log
