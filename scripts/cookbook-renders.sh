#!/usr/bin/env bash
# Renders every program in programs/ into book/src/images/cookbook/ (a PNG strip and the
# per-statement error table each) with `guide` at its defaults (without the unguided
# DDPM-1000 comparison, which would double its time) and with `latent` at a CPU-sized
# chain (with the unguided DDIM-10 sample next to it), programs with several people also
# with `lbfgs` (InterControl's solver) at its defaults, then regenerates the cookbook pages
# so they include them. The runs are listed in src/docgen/book.rs (COOKBOOK_RENDERS).
# Run from the repository root; about one minute per program for guide and 2.5 for
# latent on a 2-core CPU (19 programs: about 70 minutes).
# MPROG=path/to/mprog to use a built binary; ONLY=stem to render one program;
# SOLVERS="guide lbfgs" to render only those solvers (default: guide latent lbfgs).
set -euo pipefail
mprog=${MPROG:-"cargo run --quiet --"}
out=book/src/images/cookbook
solvers=" ${SOLVERS:-guide latent lbfgs} "
wants() { [[ "$solvers" == *" $1 "* ]]; }
mkdir -p "$out"
for prog in programs/*.mprog; do
    stem=$(basename "$prog" .mprog)
    if [ -n "${ONLY:-}" ] && [ "$ONLY" != "$stem" ]; then continue; fi
    if wants guide; then
        echo "== $stem (guide)"
        $mprog run "$prog" --solver guide --seed 1 --no-baseline -o "$out/$stem.png" | tee "$out/$stem.md"
    fi
    if wants latent; then
        echo "== $stem (latent)"
        $mprog run "$prog" --solver latent --knob ddim_steps=10 --knob iterations=60 --knob lr=0.02 \
            --seed 1 -o "$out/$stem-latent.png" | tee "$out/$stem-latent.md"
    fi
    if wants lbfgs && grep -q '^people' "$prog"; then
        echo "== $stem (lbfgs)"
        $mprog run "$prog" --solver lbfgs --seed 1 --no-baseline -o "$out/$stem-lbfgs.png" \
            | tee "$out/$stem-lbfgs.md"
    fi
done
$mprog doc book
