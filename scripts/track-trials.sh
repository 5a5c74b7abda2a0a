#!/usr/bin/env bash
# The tracker's quality figures (docs/numbers.md, "Tracking"): builds a
# vocabulary of the paper's four activities from synthetic takes, renders
# held-out sequences (another seed), tracks and scores them, and prints one
# table per trial. Real captures are used when ../shared/mocap/real (or
# $IMITATE_REAL_MOCAP) exists.
#
#   bash scripts/track-trials.sh [WORK_DIR]        # about 2.5 minutes on 2 cores; WORK_DIR may be reused
#
# Every number is the mean over seeds 1–5 (min–max after it).
source "$(dirname "$0")/common.sh" "$@"
real="${IMITATE_REAL_MOCAP:-$repo/../shared/mocap/real}"
seeds="1 2 3 4 5"

# Track FRAMES with VOCAB into runs named NAME_<seed>, score each against
# the truth beside FRAMES, and print a row of means (min–max).
trial() {
  local name=$1 frames=$2 vocab=$3
  shift 3
  for seed in $seeds; do
    rm -rf "runs/${name}_$seed"
    "$imitate" -q track "$frames" --vocab "$vocab" -o "runs/${name}_$seed" --seed "$seed" "$@"
    "$imitate" -q score "runs/${name}_$seed" --truth "$(dirname "$frames")/truth.csv"
  done
  python3 - "$name" "$seeds" <<'PY'
import json, sys
name, seeds = sys.argv[1], sys.argv[2].split()
runs = [(json.load(open(f"runs/{name}_{s}/metrics.json")), json.load(open(f"runs/{name}_{s}/summary.json"))) for s in seeds]
def cell(values, fmt):
    values = [v for v in values if v is not None]
    if not values:
        return "–"
    return f"{fmt.format(sum(values) / len(values))} ({fmt.format(min(values))}–{fmt.format(max(values))})"
pct = lambda v: None if v is None else 100 * v
print(f"| {name} | {cell([m['upper_body_mm'] for m, _ in runs], '{:.1f}')} "
      f"| {cell([m['hand_mm'] for m, _ in runs], '{:.0f}')} "
      f"| {cell([pct(m['recognition_accuracy_settled']) for m, _ in runs], '{:.0f}')} "
      f"| {cell([s['likelihood_evaluations_per_frame'] for _, s in runs], '{:.0f}')} "
      f"| {cell([s['timing']['frames_per_second'] for _, s in runs], '{:.0f}')} |")
PY
}
header() {
  echo
  echo "### $1"
  echo
  echo "| run | upper body (mm) | hands (mm) | recognition, settled (%) | likelihoods/frame | frames/s |"
  echo "| --- | --- | --- | --- | --- | --- |"
}

# The vocabulary: the paper's four activities, 12 repetitions, seed 11.
"$imitate" -q synth -o train --activities circles,wave-h,wave-v,punch --reps 12 --seed 11
"$imitate" -q vocab build train --labels train/labels.csv -o paper.vocab

# Held-out sequences: seed 5, 3 repetitions of each activity.
render() { # NAME SPEED CAMERA
  "$imitate" -q synth -o "seq_$1" --sequence circles,wave-h,wave-v --reps 3 --seed 5 --speed "$2"
  "$imitate" -q render "seq_$1/sequence.bvh" -o "video_$1" --labels "seq_$1/labels.csv" --camera "$3" --force
}
render front 1 front
for speed in 0.25 2 4; do render "speed$speed" "$speed" front; done
render side 1 side
render overhead 1 overhead

header "Trial one: particles per primitive (front, 1x, eq. 10)"
for n in 6 12 25 50 100 200; do trial "particles-$n" video_front/frames paper.vocab --particles "$n" --feedback; done

header "Recognition: eq. 7 against eq. 10 (front, 1x)"
for n in 6 200; do
  trial "eq7-$n" video_front/frames paper.vocab --particles "$n"
  trial "eq10-$n" video_front/frames paper.vocab --particles "$n" --feedback
done

header "Trial two: speed, bending cone (K = 5) against the straight line (K = 1), 6 particles, eq. 10"
for speed in 0.25 1 2 4; do
  video=video_speed$speed
  [ "$speed" = 1 ] && video=video_front
  for k in 5 1; do trial "speed$speed-K$k" "$video/frames" paper.vocab --lookahead "$k" --feedback; done
done

header "Viewpoint (eq. 10)"
for camera in side overhead; do
  for n in 6 25; do trial "$camera-$n" "video_$camera/frames" paper.vocab --particles "$n" --feedback; done
done

header "Silhouettes extracted from color frames (front, background subtraction, eq. 10)"
"$imitate" -q render seq_front/sequence.bvh -o video_color --labels seq_front/labels.csv --color --force
for n in 6 25; do trial "color-$n" video_color/color paper.vocab --particles "$n" --feedback; done

header "Baseline: the full-space annealed filter at the same likelihood budget"
for n in 6 200; do trial "full-space-$n" video_front/frames paper.vocab --particles "$n" --baseline full-space; done

if [ -d "$real" ]; then
  # A vocabulary of every real capture but the two tracked; the waving
  # takes share one label, so a waving primitive can recognize waving.
  mkdir -p realtrain
  for f in "$real"/*.bvh; do
    case "$(basename "$f")" in wave_hello.bvh | boxing.bvh) ;; *) ln -sf "$f" realtrain/ ;; esac
  done
  # (The tracked takes' lines go too: a labels file may not name takes
  # that are not there.)
  sed -E -e 's/,(wave_left|wave_right|wave_both),/,wave,/' -e '/^(wave_hello|boxing)\.bvh,/d' \
    "$real/labels.csv" > realtrain/labels.csv
  "$imitate" -q vocab build realtrain --labels realtrain/labels.csv -o real.vocab
  header "Real motion: tracked with a vocabulary of the other real captures (6 particles, eq. 10)"
  # The front camera, turned round for a performer who faces away from it
  # (a silhouette cannot tell front from back; the tracker assumes people
  # face the camera).
  python3 -c 'import json; c = json.load(open("video_front/camera.json")); c["position"][2] *= -1; json.dump(c, open("behind.json", "w"))'
  for take in wave_hello boxing; do
    "$imitate" -q render "$real/$take.bvh" -o "video_$take" --labels "$real/labels.csv" --force
    if python3 -c 'import csv,math,sys; r=next(csv.DictReader(open(sys.argv[1]))); sys.exit(math.cos(float(r["root_heading"])) >= 0)' "video_$take/truth.csv"; then
      echo "$take faces away from the camera: the camera is put behind it" >&2
      "$imitate" -q render "$real/$take.bvh" -o "video_$take" --labels "$real/labels.csv" --camera behind.json --force
    fi
    trial "$take" "video_$take/frames" real.vocab --feedback
  done
  echo
  echo "Vocabulary of the other real captures:"
  "$imitate" vocab info real.vocab | sed -n '/^primitive/,/^$/p'
else
  echo "no real captures at $real: skipped" >&2
fi
echo
echo "runs kept in $work/runs"
