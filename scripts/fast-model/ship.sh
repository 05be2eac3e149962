#!/bin/sh
# Ships a distillation run's bundle (`mprog train --config models/train-distil.toml`) as
# models/fast: its weights, manifest and text side, with the teacher's data-derived files
# (the envelope, the length prior, the pose coverage: the same training data made them).
# Usage: scripts/fast-model/ship.sh [RUN_BUNDLE] [TEACHER] [OUT]
set -eu
run=${1:-runs/distil/bundle}
teacher=${2:-models/default}
out=${3:-models/fast}
tmp="$out.new"
rm -rf "$tmp"
mkdir -p "$tmp"
for f in config.toml manifest.json model.safetensors mean.npy std.npy captions.safetensors actions.json; do
    cp "$run/$f" "$tmp/"
done
for f in envelope.json lengths.json coverage.bin; do
    cp "$teacher/$f" "$tmp/"
done
# The model card stays with the shipped folder.
if [ -f "$out/MODEL_CARD.md" ]; then cp "$out/MODEL_CARD.md" "$tmp/"; fi
rm -rf "$out"
mv "$tmp" "$out"
echo "shipped $(grep -o '"weights_id": "[^"]*"' "$out/manifest.json") to $out"
