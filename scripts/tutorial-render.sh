#!/usr/bin/env bash
# Makes the tutorial's picture and error table (book/src/tutorial.md, step 6): the
# hand-on-head program solved with guide, seed 1, shipped weights. Run from the
# repository root. MPROG=path/to/mprog to use a built binary.
set -euo pipefail
mprog=${MPROG:-"cargo run --quiet --manifest-path $PWD/Cargo.toml --"}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat > "$dir/hand_on_head.mprog" <<'PROGRAM'
# Walk with the left hand on the head.
prompt "a person walks forward"
length 6s

always { dist(l_hand, head) < 10 cm }
PROGRAM
images=$PWD/book/src/images
# Run from the temporary folder so the picture's title is the file name the tutorial uses.
(cd "$dir" && $mprog run hand_on_head.mprog --seed 1 -o "$images/tutorial_hand_on_head.png") \
    | tee "$images/tutorial_hand_on_head.md"
