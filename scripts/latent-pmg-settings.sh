#!/usr/bin/env bash
# Runs `latent` on PMG's tasks with each task config's own settings (DDIM-100; the
# learning rate, iteration count and output pull of task_configs/, reference-algorithms
# §1.5), one program after another, writing OUT/<stem>.json and OUT/<stem>.txt (the
# per-statement error table, the wall time and the body metrics).
# About 25 minutes per program on a 2-core CPU: meant for a GPU build
# (`cargo build --release --features wgpu`, then MPROG_DEVICE=wgpu).
# Usage: [MPROG=path/to/mprog] [BUDGET=seconds] scripts/latent-pmg-settings.sh OUT [stem…]
# BUDGET stops starting new programs once that many seconds have passed (default: none).
set -uo pipefail
out=${1:?usage: scripts/latent-pmg-settings.sh OUT [stem…]}
shift
mprog=${MPROG:-"cargo run --release --quiet --"}
mkdir -p "$out"
deadline=$(($(date +%s) + ${BUDGET:-1000000000}))

# stem: knobs of PMG's config (lr × iterations, pulls); GEO-1/2 and HOI-1 are relaxed there.
settings() {
    case $1 in
    hsi1_head_height) echo "lr=0.005 iterations=50" ;;
    hsi2_barrier) echo "lr=0.005 iterations=100" ;;
    hsi3_square) echo "lr=0.005 iterations=50" ;;
    hsi4_overhead_barrier) echo "lr=0.05 iterations=60 ref_root=1" ;;
    hsi5_narrow_gap) echo "lr=0.05 iterations=100" ;;
    geo1_hand_on_wall) echo "lr=0.01 iterations=100 relax=1" ;;
    geo2_balance_beam) echo "lr=0.01 iterations=100 relax=1" ;;
    hoi1_move_object) echo "lr=0.05 iterations=90" ;;
    hoi2_carry_ball) echo "lr=0.05 iterations=60 ref_root=1" ;;
    hsc1_hand_on_head) echo "lr=0.005 iterations=50" ;;
    pbg1_one_leg_balance) echo "lr=0.02 iterations=100 ref_legs=0.1" ;;
    pbg2_heavy_ball) echo "lr=0.05 iterations=100" ;;
    hod1_velocity) echo "lr=0.005 iterations=80" ;;
    *) echo "" ;;
    esac
}

stems=("$@")
if [ ${#stems[@]} -eq 0 ]; then
    stems=(hsi1_head_height hsi2_barrier hsi3_square hsi4_overhead_barrier hsi5_narrow_gap
        geo1_hand_on_wall geo2_balance_beam hoi1_move_object hoi2_carry_ball
        hsc1_hand_on_head pbg1_one_leg_balance pbg2_heavy_ball hod1_velocity)
fi
for stem in "${stems[@]}"; do
    knobs=$(settings "$stem")
    if [ -z "$knobs" ]; then
        echo "no PMG settings for $stem" >&2
        exit 2
    fi
    left=$((deadline - $(date +%s)))
    if [ "$left" -le 0 ]; then
        echo "== $stem: skipped (BUDGET spent)"
        continue
    fi
    args=()
    for k in $knobs; do args+=(--knob "$k"); done
    echo "== $stem ($knobs)"
    timeout "$left" $mprog run "programs/$stem.mprog" --solver latent --seed 1 --no-baseline \
        "${args[@]}" -o "$out/$stem.json" 2>&1 | tee "$out/$stem.txt"
done
