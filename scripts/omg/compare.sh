#!/bin/sh
# OMG's design against the shipped text model (issue 49; book/src/omg.md): `mprog eval`
# (FID, R-precision; 32 test captions, seed 1, raw samples) at guidance 2.5 and at OMG's
# 4.5, then the held-out paraphrase set (`bench paraphrases --quick`, seed 1, two
# wordings per caption) and `bench actions`, each for both bundles on the same prompts
# and seeds. Every table goes to OUT_DIR; one line per eval row is printed.
# Usage: scripts/omg/compare.sh BIN OUT_DIR OMG_BUNDLE [DEFAULT_BUNDLE] [DATA]
set -eu
bin=$1
out=$2
omg=$3
base=${4:-models/default}
data=${5:-data/humanml}
mkdir -p "$out"
row() {
    name=$1
    shift
    "$bin" eval --data "$data" --count 32 "$@" --out "$out/$name.md" > "$out/$name.log" 2>&1
    echo "$name: $(grep '^| model' "$out/$name.md")"
}
for g in 2.5 4.5; do
    row "text-model-g$g" --model "$base" --guidance $g
    row "omg-g$g" --model "$omg" --guidance $g
done
grep '^| real' "$out/text-model-g2.5.md"
"$bin" bench paraphrases --quick --bundle "$base" -o "$out/paraphrases-text-model.md" > "$out/paraphrases-text-model.log" 2>&1
"$bin" bench paraphrases --quick --bundle "$omg" -o "$out/paraphrases-omg.md" > "$out/paraphrases-omg.log" 2>&1
"$bin" bench actions --model "$base" > "$out/actions-text-model.md" 2>&1
"$bin" bench actions --model "$omg" > "$out/actions-omg.md" 2>&1
for f in paraphrases-text-model paraphrases-omg; do
    echo "$f:"
    grep -A8 '^### Totals' "$out/$f.md" | tail -7
done
