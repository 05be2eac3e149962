#!/usr/bin/env bash
# One GPU check on a lent device machine (the `device` tool), run from the repository root:
# `mprog bench model` on wgpu and on flex, then timed training steps on wgpu at batch 32
# (train-default.toml) and batch 128 (train-gpu.toml). Everything it prints is copied
# under $OUT. Expects, carried with the call:
#   .gpu/mprog.xz        a stripped `cargo build --release --features wgpu` binary
#   .gpu/bvh-subset.tar.xz  BVH files to build a training set from there (a quarter of
#                           the Bandai archive fits the 64 MiB carry with the binary)
#   .gl/*.deb            the Vulkan/GL loader packages (see the book's benchmarks page)
# Usage: OUT=dir [STEPS=300] [BIG_STEPS=100] scripts/gpu-check.sh
set -uo pipefail
out=${OUT:-/tmp/gpu-check}
steps=${STEPS:-300}
big_steps=${BIG_STEPS:-100}
mkdir -p "$out"
exec > >(tee "$out/log.txt") 2>&1
t0=$(date +%s)
stamp() { echo "== [$(($(date +%s) - t0)) s] $*"; }

stamp "loaders"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -f "$icd" ] && [ ! -d /usr/share/vulkan/icd.d ]; then
    export VK_DRIVER_FILES=$icd
fi
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.sm --format=csv
ls /usr/share/vulkan/icd.d /etc/vulkan/icd.d /usr/local/nvidia/share/vulkan/icd.d 2>/dev/null

stamp "unpack"
xz -dc .gpu/mprog.xz >/tmp/mprog && chmod +x /tmp/mprog
mkdir -p /tmp/bvh && tar -xJf .gpu/bvh-subset.tar.xz -C /tmp/bvh
/tmp/mprog --version
stamp "data build"
/tmp/mprog data build --bvh /tmp/bvh --out /tmp/data/humanml | tail -4

stamp "bench model, wgpu"
MPROG_DEVICE=wgpu timeout 120 /tmp/mprog bench model --reps 5 | tee "$out/bench-model-wgpu.md"
stamp "bench model, flex on this machine's CPUs"
timeout 60 /tmp/mprog bench model --reps 3 | tee "$out/bench-model-flex.md"

train() { # name config steps seconds
    stamp "train $1: $3 steps with $2"
    MPROG_DEVICE=wgpu timeout "$4" /tmp/mprog train --data /tmp/data/humanml --config "$2" \
        --out "/tmp/run-$1" --steps "$3" </dev/null | tail -5
    cp "/tmp/run-$1/loss.csv" "$out/loss-$1.csv" 2>/dev/null
    tail -3 "/tmp/run-$1/loss.csv" 2>/dev/null
}
train b32 models/train-default.toml "$steps" 200
train b128 models/train-gpu.toml "$big_steps" 120
stamp "done"
