#!/usr/bin/env bash
# Tracking a person who is not the model (docs/numbers.md, "The person is
# not the model"): the README's three-activity sequence (hand circles,
# horizontal and vertical waving, 3 repetitions each) performed by the
# tracker's own capsules and by every shipped test body (`render --body`),
# front camera, 160×120, tracked with vocab/default.vocab, 25 particles,
# eq. 10, with and without calibration, scored against each body's own
# joints.
#
#   bash scripts/body-trials.sh [WORK_DIR]        # about 3 minutes on 2 cores
#
# Every number is the mean over seeds 1–5 (min–max after it).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
imitate="${CARGO_TARGET_DIR:-$PWD/target}/release/imitate"
vocab="$PWD/vocab/default.vocab"
work="${1:-$(mktemp -d)}"
mkdir -p "$work"
cd "$work"
seeds="1 2 3 4 5"
bodies="capsules slight lanky average skirt broad heavy"

rm -rf sequence
"$imitate" -q synth --sequence circles,wave-h,wave-v --reps 3 -o sequence
echo "| body | calibration | height found (m) | upper body (mm) | hands (mm) | limbs (°) | root (mm) | recognition, settled (%) | likelihoods/frame |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for body in $bodies; do
  "$imitate" -q render sequence/sequence.bvh -o "video-$body" --labels sequence/labels.csv --body "$body" --force
  for mode in on off; do
    extra=()
    [ "$mode" = off ] && extra=(--no-calibrate)
    for seed in $seeds; do
      run="runs/$body-$mode-$seed"
      "$imitate" -q track "video-$body/frames" --vocab "$vocab" -o "$run" --particles 25 --feedback --seed "$seed" \
        --force "${extra[@]}"
      "$imitate" -q score "$run" --truth "video-$body/truth.csv"
    done
    python3 - "$body" "$mode" "$seeds" <<'PY'
import json, sys
body, mode, seeds = sys.argv[1], sys.argv[2], sys.argv[3].split()
runs = [(json.load(open(f"runs/{body}-{mode}-{s}/metrics.json")), json.load(open(f"runs/{body}-{mode}-{s}/summary.json")))
        for s in seeds]
def cell(values, fmt):
    return f"{fmt.format(sum(values) / len(values))} ({fmt.format(min(values))}–{fmt.format(max(values))})"
height = cell([s["body"]["height_m"] for _, s in runs], "{:.2f}") if mode == "on" else "–"
print(f"| {body} | {mode} | {height} "
      f"| {cell([m['upper_body_mm'] for m, _ in runs], '{:.1f}')} "
      f"| {cell([m['hand_mm'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([m['limb_direction_deg'] for m, _ in runs], '{:.1f}')} "
      f"| {cell([m['root_mm'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([100 * m['recognition_accuracy_settled'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([s['likelihood_evaluations_per_frame'] for _, s in runs], '{:.0f}')} |")
PY
  done
done
