#!/usr/bin/env bash
# Seeds the corpora from the repository and runs every fuzz target in turn, one worker
# each (the machine is shared). Usage: fuzz/run.sh [seconds per target] [targets…]
# Needs cargo-fuzz (`cargo install cargo-fuzz`); on a stable toolchain RUSTC_BOOTSTRAP=1
# lets it use the nightly-only sanitizer-coverage flags.
set -euo pipefail
cd "$(dirname "$0")"
seconds="${1:-300}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(mprog_check bvh npy json asf mcp)
root=..

seed() { # target, files…
    local dir="corpus/$1"
    shift
    mkdir -p "$dir"
    for f in "$@"; do
        if [ -f "$f" ]; then cp "$f" "$dir/seed-$(basename "$f")"; fi
    done
}
seed mprog_check "$root"/programs/*.mprog "$root"/stdlib/*.mprog "$root"/tests/diagnostics/*.mprog
seed bvh "$root"/tests/fixtures/bandai_like.bvh "$root"/tests/fixtures/adversarial/[a-z]*.bvh \
    "$root"/tests/fixtures/fuzz/bvh/*
# AMC seeds for the test skeleton: the first two frames of the fixture.
mkdir -p corpus/asf
head -n 52 "$root"/tests/fixtures/rigs/asf/HDM_tt_squat1Reps_001_120.amc >corpus/asf/seed-two-frames.amc
seed npy "$root"/tests/fixtures/humanml3d/Mean.npy "$root"/tests/fixtures/adversarial/*.npy \
    "$root"/tests/fixtures/fuzz/npy/*
seed json "$root"/tests/fixtures/adversarial/*.json "$root"/tests/fixtures/fuzz/json/*
seed mprog_check "$root"/tests/fixtures/fuzz/mprog_check/*
seed mcp "$root"/tests/fixtures/fuzz/mcp/*

export RUSTC_BOOTSTRAP=1
for t in "${targets[@]}"; do
    mkdir -p "artifacts/$t"
    # Deep inputs need room: 8 kB for BVH/JSON (a whole small rig), 4 kB otherwise.
    case "$t" in bvh | json | asf | mcp) len=8192 ;; *) len=4096 ;; esac
    cargo fuzz run -O -a -s none "$t" "corpus/$t" -- \
        -workers=1 -max_total_time="$seconds" -max_len="$len" \
        -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="artifacts/$t/" 2>&1 | tee "$t.log" | grep -E "^(#[0-9]+.*DONE|stat::|==|SUMMARY|thread)" || true
done
