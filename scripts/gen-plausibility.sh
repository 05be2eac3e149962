#!/usr/bin/env bash
# Plausibility of unguided `mprog gen` samples (issue 48, "gen's outputs are too"):
# ten prompts, seeds 1 and 2, --count 4 each (80 motions at the prompts' own lengths),
# as gen writes them and with --raw. Prints one line per (prompt, seed) and the totals.
# Usage: scripts/gen-plausibility.sh [BIN] [OUT] [-- extra gen args]
set -euo pipefail
BIN=${1:-target/release/mprog}
OUT=${2:-target/gen-plausibility}
shift $(( $# < 2 ? $# : 2 )); [ "${1:-}" = "--" ] && shift
mkdir -p "$OUT"
prompts=(
  "a person walks forward"
  "a person runs forward"
  "a person jumps up and down in place"
  "a person kicks with the right leg"
  "a person waves with the right hand"
  "a person squats down"
  "a person picks something up from the floor"
  "a person turns around"
  "a person walks in a circle"
  "a person dances"
)
for variant in cleaned raw; do
  flag=(); [ "$variant" = raw ] && flag=(--raw)
  ok=0; all=0
  for i in "${!prompts[@]}"; do
    for seed in 1 2; do
      log="$OUT/$variant-p$i-s$seed.log"
      [ -s "$log" ] || "$BIN" gen --text "${prompts[$i]}" --seed "$seed" --count 4 "${flag[@]}" "$@" \
        -o "$OUT/$variant-p$i-s$seed.npy" > "$log" 2>&1
      good=$(grep -c "plausibility: ok" "$log" || true)
      n=$(grep -c "plausibility:" "$log" || true)
      ok=$((ok + good)); all=$((all + n))
      echo "$variant | ${prompts[$i]} | seed $seed | $good of $n plausible"
      grep -E "^  person|^  motion|: .* > " "$log" | head -4 || true
    done
  done
  echo "== $variant: $ok of $all plausible"
done
