#!/bin/sh
# The few-step model against its teacher on `mprog eval` (32 test captions, seed 1, raw
# samples): the teacher on its own 50-step chain and cut to 4 DDIM steps, the student at
# 1, 2 and 4 steps; each row with the seconds its generation took.
# Usage: scripts/fast-model/eval.sh BIN OUT_DIR [FAST_MODEL] [DATA]
set -eu
bin=$1
out=$2
fast=${3:-models/fast}
data=${4:-data/humanml}
mkdir -p "$out"
row() {
    name=$1
    shift
    "$bin" eval --data "$data" --count 32 "$@" --out "$out/$name.md" > "$out/$name.log" 2>&1
    secs=$(grep -o '[0-9.]* s generating' "$out/$name.md" | head -1)
    echo "$name ($secs): $(grep '^| model' "$out/$name.md")"
}
row teacher-ddim50
row teacher-ddim4 --steps 4
for s in 1 2 4; do
    row "fast-$s" --model "$fast" --steps $s
done
grep '^| real' "$out/teacher-ddim50.md"
