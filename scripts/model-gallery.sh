#!/bin/bash
# Renders the shipped model's unconstrained motions for the book's "The model" page
# (`book/src/model.md`): one per action of the model card's done-when list, seed 1,
# `mprog gen` defaults (DDIM 50, guidance 2.5, foot cleanup); 6 s where the list gives
# it, else the length the model's length prior picks for the prompt.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MPROG:-target/release/mprog}
out=book/src/images/model
mkdir -p "$out"
while IFS='|' read -r name seconds text; do
  length=()
  if [ -n "$seconds" ]; then length=(--seconds "$seconds"); fi
  "$bin" gen --text "$text" "${length[@]}" --seed 1 -o "$out/$name.png" 2>&1 | grep -v '^wrote'
done <<'LIST'
walk|6|a person walks forward
run|6|a person runs forward
wave|6|a person waves the right hand
raise_both|6|a person raises both hands
turn_left|6|a man walks and turns left
turn_right|6|a man walks and turns right
jump||a person jumps up and down in place
kick||a man kicks forward with his right leg
crouch||a person crouches down low and stands back up
pick_up||a person picks something up from the floor
lie_down||a person lies down on the floor
LIST
