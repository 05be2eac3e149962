#!/usr/bin/env bash
# Makes bench actions' 13 prompts with `mprog gen` at S seconds, seeds 1 and 2, into OUT;
# judge them with scripts/action-length/judge.py OUT.
#   scripts/action-length/gen_all.sh MPROG_BINARY OUT S
set -euo pipefail
BIN=$1; OUT=$2; SEC=$3; mkdir -p $OUT
while IFS='|' read -r text kind; do
  for s in 1 2; do $BIN gen --text "$text" --seconds $SEC --seed $s -o $OUT/${kind}_s$s.npy > $OUT/${kind}_s$s.log 2>&1; done
done <<'LIST'
a person jumps up and down in place|jump
a man kicks forward with his right leg|kick
a person crouches down low and stands back up|crouch
a person picks something up from the floor|pick
a person lies down on the floor|lie
a person runs forward|run
a person walks forward|walk
a person walks and turns left|left
a person walks and turns right|right
a person strolls|stroll
a person hurries|hurry
a person raises both hands|raise
a person elevates both arms|elevate
LIST
