#!/usr/bin/env bash
# Tracking a person who is not the model (docs/numbers.md, "The person is
# not the model"): the README's three-activity sequence (hand circles,
# horizontal and vertical waving, 3 repetitions each), front camera,
# 160×120, tracked with vocab/default.vocab, 25 particles, eq. 10.
#
# - Bodies: performed by the tracker's own capsules and by every shipped
#   test body (`render --body`), with and without calibration, scored
#   against each body's own joints.
# - Frame rates: the capsules' performance rendered at 15, 25, 30 and 60
#   frames a second, each tracked at its own rate (read from truth.csv).
#
#   bash scripts/person-trials.sh [WORK_DIR]        # about 3 minutes on 2 cores
#
# Every number is the mean over seeds 1–5 (min–max after it).
source "$(dirname "$0")/common.sh" "$@"
seeds="1 2 3 4 5"
bodies="capsules slight lanky average skirt broad heavy"

rm -rf sequence
"$imitate" -q synth --sequence circles,wave-h,wave-v --reps 3 -o sequence

# Means (min–max) over the seeds of runs/NAME-<seed>: metrics and summary
# figures, the first column LABEL.
row() {
  python3 - "$1" "$2" "$seeds" <<'PY'
import json, sys
name, label, seeds = sys.argv[1], sys.argv[2], sys.argv[3].split()
runs = [(json.load(open(f"runs/{name}-{s}/metrics.json")), json.load(open(f"runs/{name}-{s}/summary.json"))) for s in seeds]
def cell(values, fmt):
    return f"{fmt.format(sum(values) / len(values))} ({fmt.format(min(values))}–{fmt.format(max(values))})"
body = [s["body"] for _, s in runs]
height = cell([b["height_m"] for b in body], "{:.2f}") if all(b["calibrated"] for b in body) else "–"
print(f"| {label} | {height} "
      f"| {cell([m['upper_body_mm'] for m, _ in runs], '{:.1f}')} "
      f"| {cell([m['hand_mm'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([m['limb_direction_deg'] for m, _ in runs], '{:.1f}')} "
      f"| {cell([m['root_mm'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([100 * m['recognition_accuracy_settled'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([s['likelihood_evaluations_per_frame'] for _, s in runs], '{:.0f}')} |")
PY
}

# Tracks VIDEO's frames as runs/NAME-<seed> (extra options after) and scores them.
track() {
  local name=$1 video=$2
  shift 2
  for seed in $seeds; do
    "$imitate" -q track "$video/frames" --vocab "$vocab" -o "runs/$name-$seed" --particles 25 --feedback \
      --seed "$seed" --force "$@"
    "$imitate" -q score "runs/$name-$seed" --truth "$video/truth.csv"
  done
}

echo "### Bodies"
echo
echo "| body, calibration | height found (m) | upper body (mm) | hands (mm) | limbs (°) | root (mm) | recognition, settled (%) | likelihoods/frame |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for body in $bodies; do
  "$imitate" -q render sequence/sequence.bvh -o "video-$body" --labels sequence/labels.csv --body "$body" --force
  track "$body-on" "video-$body"
  row "$body-on" "$body, on"
  track "$body-off" "video-$body" --no-calibrate
  row "$body-off" "$body, off"
done

echo
echo "### Frame rates"
echo
echo "| frames a second | height found (m) | upper body (mm) | hands (mm) | limbs (°) | root (mm) | recognition, settled (%) | likelihoods/frame |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for fps in 15 25 30 60; do
  "$imitate" -q render sequence/sequence.bvh -o "video-$fps-fps" --labels sequence/labels.csv --fps "$fps" --force
  track "fps-$fps" "video-$fps-fps"
  row "fps-$fps" "$fps"
done
