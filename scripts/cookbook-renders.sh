#!/usr/bin/env bash
# Renders every program in programs/ with the guide solver into book/src/images/cookbook/
# (a PNG strip and the per-statement error table each), then regenerates the
# cookbook pages so they include the pictures. Run from the repository root; takes about
# two minutes per program on a 2-core CPU. MPROG=path/to/mprog to use a built binary.
set -euo pipefail
mprog=${MPROG:-"cargo run --release --quiet --"}
out=book/src/images/cookbook
mkdir -p "$out"
for prog in programs/*.mprog; do
    stem=$(basename "$prog" .mprog)
    echo "== $stem"
    $mprog run "$prog" --solver guide --seed 1 -o "$out/$stem.png" | tee "$out/$stem.md"
done
$mprog doc book
