#!/usr/bin/env bash
# Makes every timeline program here and four long `gen` walks/runs, then prints the seam
# table (scripts/timelines/seams.py) and the 20 s program's judge.
#   scripts/timelines/run_all.sh OUT_DIR [MPROG_BINARY]
set -euo pipefail
out=${1:?output folder}
bin=${2:-target/release/mprog}
here=$(dirname "$0")
py=${PYTHON:-python3}
mkdir -p "$out"
for p in "$here"/programs/*.mprog; do
  name=$(basename "$p" .mprog)
  [ -f "$out/$name.npy" ] && continue
  /usr/bin/time -f "$name %e s" "$bin" run "$p" --no-baseline -o "$out/$name.npy" "$out/$name.png" \
    > "$out/$name.txt" 2>&1 || echo "$name failed"
done
gen() { # name text seconds seed
  [ -f "$out/$1.npy" ] && return
  /usr/bin/time -f "$1 %e s" "$bin" gen --text "$2" --seconds "$3" --seed "$4" -o "$out/$1.npy" "$out/$1.png" \
    > "$out/$1.txt" 2>&1 || echo "$1 failed"
}
gen gen_walk30_s1 "a person walks forward" 30 1
gen gen_walk30_s2 "a person walks forward" 30 2
gen gen_run30_s1 "a person runs forward" 30 1
gen gen_walk60_s1 "a person walks forward" 60 1
"$py" "$here/seams.py" "$out"/*.npy
"$py" "$here/judge_wrw.py" "$out/walk_run_wave.npy"
