#!/bin/bash
# Renders the shipped model's unconstrained motions for the book's "The model" page
# (`book/src/model.md`): one per action of the model card's done-when list, seed 1, 6 s,
# `mprog gen` defaults (DDIM 50, guidance 2.5, foot cleanup).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MPROG:-target/release/mprog}
out=book/src/images/model
mkdir -p "$out"
while IFS='|' read -r name text; do
  "$bin" gen --text "$text" --seconds 6 --seed 1 -o "$out/$name.png" 2>&1 | grep -v '^wrote'
done <<'LIST'
walk|a person walks forward
run|a person runs forward
wave|a person waves the right hand
raise_both|a person raises both hands
turn_left|a man walks and turns left
turn_right|a man walks and turns right
LIST
