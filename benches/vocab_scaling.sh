#!/usr/bin/env bash
# How `imitate vocab build` scales: synthesizes 120 Hz takes (the six
# activities chained, ten repetitions each, at half, normal and double
# speed, a new seed per take), then builds a vocabulary from the first
# 10k, 50k, 100k and 432k frames (one hour) of them, the last take cut to
# size. Prints frames, seconds per stage, total seconds and peak memory, as
# `imitate vocab build` reports them, and the segments and k found.
#
#   bash benches/vocab_scaling.sh [FRAMES...]   (default: 10000 50000 100000 432000)
#   BUILD_ARGS="--eigen full" bash benches/vocab_scaling.sh 432000   (other settings)
set -euo pipefail
cd "$(dirname "$0")/.."
targets=("${@:-10000 50000 100000 432000}")
read -r -a targets <<<"${targets[*]}"
cargo build --release --quiet
imitate=target/release/imitate
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

largest=0
for t in "${targets[@]}"; do ((t > largest)) && largest=$t; done
mkdir -p "$work/pool"
made=0
seed=0
speeds=(0.5 1 2)
while ((made < largest)); do
    "$imitate" -q synth -o "$work/gen" --sequence circles,wave-h,wave-v,punch,reach,twist \
        --reps 10 --fps 120 --speed "${speeds[$((seed % 3))]}" --seed "$seed"
    file=$(printf '%s/pool/take%03d.bvh' "$work" "$seed")
    mv "$work/gen/sequence.bvh" "$file"
    frames=$(awk '/^Frames:/ {print $2; exit}' "$file")
    made=$((made + frames))
    seed=$((seed + 1))
done

# Frames 0 to n-1 of a BVH file.
cut_bvh() {
    awk -v n="$2" '
        /^Frames:/ { print "Frames: " n; next }
        /^Frame Time:/ { print; body = 1; next }
        body { if (kept < n) { print; kept++ } ; next }
        { print }' "$1" >"$3"
}

printf '%8s  %s\n' frames "imitate vocab build"
for target in "${targets[@]}"; do
    dir="$work/set-$target"
    mkdir -p "$dir"
    left=$target
    for file in "$work"/pool/*.bvh; do
        ((left > 0)) || break
        frames=$(awk '/^Frames:/ {print $2; exit}' "$file")
        if ((frames <= left)); then
            ln -s "$file" "$dir/"
            left=$((left - frames))
        else
            cut_bvh "$file" "$left" "$dir/$(basename "$file")"
            left=0
        fi
    done
    # shellcheck disable=SC2086 # BUILD_ARGS is a list of flags
    out=$("$imitate" vocab build "$dir" -o "$work/v.vocab" ${BUILD_ARGS:-} 2>&1)
    segments=$(grep -o '→ [0-9]* segments' <<<"$out" | head -1)
    k=$(grep -o 'k = [0-9]*' <<<"$out" | head -1)
    line=$(grep '^time:' <<<"$out")
    printf '%8d  %s (%s, %s)\n' "$target" "${line#time: }" "${segments#→ }" "$k"
done
