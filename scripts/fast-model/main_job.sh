#!/bin/sh
# The main job through the few-step model (issue 51): `latent-fast` on
# programs/hsc1_hand_on_head.mprog against one unguided `gen` of the same length with
# each model, timed back to back, then what a reviewer checks (error, travel, head height).
# Usage: scripts/fast-model/main_job.sh BIN OUT_DIR [FAST_MODEL]   (PYTHON: numpy)
set -eu
bin=$1
out=$2
fast=${3:-models/fast}
py=${PYTHON:-python3}
mkdir -p "$out"
t() { /usr/bin/time -f "%e" "$@" 2>&1 >/dev/null | tail -1; }
text="a person walks casually forward."
for seed in 1 2 3; do
    g=$(t "$bin" gen --text "$text" --frames 100 --seed $seed --raw -o "$out/gen_$seed.npy")
    f=$(t "$bin" gen --model "$fast" --text "$text" --frames 100 --seed $seed --raw -o "$out/fast_$seed.npy")
    /usr/bin/time -f "%e" -o "$out/wall_$seed.txt" "$bin" run programs/hsc1_hand_on_head.mprog \
        --model "$fast" --solver latent-fast --seed $seed --no-baseline \
        -o "$out/latent_$seed.npy" "$out/latent_$seed.png" > "$out/latent_$seed.txt" 2>&1
    l=$(grep -o 'latent-fast: [0-9.]* s' "$out/latent_$seed.txt" | grep -o '[0-9.]*')
    w=$(tail -1 "$out/wall_$seed.txt")
    echo "seed $seed: gen (default model) $g s, gen (few-step) $f s, latent-fast $l s (the whole run $w s)"
done
"$py" - "$out" <<'PY'
import sys, re, numpy as np
out = sys.argv[1]
for seed in (1, 2, 3):
    j = np.load(f"{out}/latent_{seed}.npy")
    d = np.linalg.norm(j[:, 20] - j[:, 15], axis=1)
    err = np.mean((d**2 - 0.1**2) ** 2) ** 0.5
    travel = np.linalg.norm(j[-1, 0, [0, 2]] - j[0, 0, [0, 2]])
    txt = open(f"{out}/latent_{seed}.txt").read()
    row = [l for l in txt.splitlines() if l.startswith("| 8 |")][0]
    print(f"seed {seed}: table error {row.split('|')[5].strip()} ({row.split('|')[6].strip()}), wrist-head distance mean {d.mean():.3f} m (max {d.max():.3f}), "
          f"travel {travel:.2f} m, head height {j[:, 15, 1].mean():.2f} m, pelvis {j[:, 0, 1].min():.2f}-{j[:, 0, 1].max():.2f} m, "
          f"plausible: {'plausibility: ok' in txt}")
PY
