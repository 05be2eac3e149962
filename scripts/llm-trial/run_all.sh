#!/bin/bash
# Runs every t*.mprog of PROGDIR with `mprog run --seed 1 --no-baseline` (the default
# solver, guide), writing OUTDIR/<id>.npy, .json, .meta.json and .log; skips outputs that
# exist, so it resumes. Run from anywhere; BIN is the mprog binary.
# Run it from the repository root (the binary finds models/default there).
# usage: run_all.sh BIN PROGDIR OUTDIR [extra mprog run args]
set -u
BIN=$(realpath "$1"); PROGS=$(realpath "$2"); OUT=$(realpath -m "$3"); shift 3
mkdir -p "$OUT"
for f in "$PROGS"/t*.mprog; do
  id=$(basename "$f" .mprog)
  [ -f "$OUT/$id.npy" ] && continue
  start=$(date +%s.%N)
  "$BIN" run "$f" --seed 1 --no-baseline "$@" -o "$OUT/$id.npy" "$OUT/$id.json" > "$OUT/$id.log" 2>&1
  echo "$id rc=$? $(echo "$(date +%s.%N) - $start" | bc) s" >> "$OUT/times.txt"
done
echo done >> "$OUT/times.txt"
